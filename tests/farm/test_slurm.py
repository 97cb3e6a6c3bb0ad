# SPDX-License-Identifier: MIT
"""The farm test (ctest label "farm"): a real Slurm on localhost runs a shot as a job array.

Starts munged, slurmctld and slurmd in a scratch folder (no systemd; proctrack/linuxproc and
task/none, since the cgroup plug-ins do not work in containers), submits an 11-frame shot in
chunks of 4 with scripts/farm/submit_ssao.sh (11 is not a multiple of 4: the last chunk must keep
frames 1009-1011), waits with a bounded timeout, and checks that every frame exists and equals a
serial run on another thread count bit for bit. Then a second submission with a missing frame
must fail that frame's task, and only that one. The daemons are stopped by their pid, whatever
happens. Prints the figures: frames, chunks, wall times.

    /usr/bin/python3 tests/farm/test_slurm.py --ssao build/bin/ssao --scratch DIR
Exit status 77 (ctest: skipped) when not run as root: slurmd must be root to start jobs.
"""
import argparse
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tests"))
from image_files import read_image  # noqa: E402

SAMPLE = os.path.join(ROOT, "tests", "data", "sample")
SUBMIT = os.path.join(ROOT, "scripts", "farm", "submit_ssao.sh")
FRAMES = range(1001, 1012)  # 11 frames
CHUNK = 4                   # 3 chunks: 4 + 4 + 3
RADIUS = 0.8
TIMEOUT = 240               # seconds for the cluster to come up and for each submission
SKIP = 77


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_until(what, predicate, timeout):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return
        time.sleep(0.2)
    raise TimeoutError(f"{what}: not within {timeout} s")


class LocalSlurm:
    """munged, slurmctld and slurmd on 127.0.0.1, everything under `folder`; stop() kills the
    processes it started, by pid."""

    DAEMONS = ("/usr/sbin/munged", "/usr/sbin/mungekey", "/usr/sbin/slurmctld",
               "/usr/sbin/slurmd", "/usr/bin/sbatch", "/usr/bin/squeue", "/usr/bin/scontrol",
               "/usr/bin/sinfo")

    def __init__(self, folder):
        self.folder = folder
        self.processes = []
        self.env = dict(os.environ, SLURM_CONF=os.path.join(folder, "slurm.conf"))

    def path(self, *names):
        return os.path.join(self.folder, *names)

    def start(self):
        missing = [p for p in self.DAEMONS if not os.access(p, os.X_OK)]
        if missing:
            raise RuntimeError(f"Slurm or munge is not installed ({', '.join(missing)} missing): "
                               "run scripts/install_deps.sh")
        for sub in ("state", "spool", "log", "munge"):
            os.makedirs(self.path(sub), exist_ok=True)
        os.chmod(self.path("munge"), 0o700)
        key = self.path("munge", "munge.key")
        subprocess.run(["/usr/sbin/mungekey", "--create", "--keyfile", key], check=True)
        socket_path = self.path("munge", "munge.socket")
        self.spawn("munged", ["/usr/sbin/munged", "--foreground", "--force",
                              f"--key-file={key}", f"--socket={socket_path}",
                              f"--pid-file={self.path('munge', 'munged.pid')}",
                              f"--log-file={self.path('munge', 'munged.log')}",
                              f"--seed-file={self.path('munge', 'seed')}"])
        wait_until("munged's socket", lambda: os.path.exists(socket_path), 30)
        with open(self.path("slurm.conf"), "w", encoding="utf-8") as f:
            f.write(self.config(socket_path))
        self.spawn("slurmctld", ["/usr/sbin/slurmctld", "-D", "-f", self.env["SLURM_CONF"]])
        self.spawn("slurmd", ["/usr/sbin/slurmd", "-D", "-f", self.env["SLURM_CONF"],
                              "-N", "localhost"])
        wait_until("the node to be idle",
                   lambda: self.run(["sinfo", "-h", "-o", "%T"], check=False).stdout.strip()
                   == "idle", 60)

    def config(self, munge_socket):
        return "\n".join([
            "ClusterName=ssaotest", "SlurmctldHost=localhost", "SlurmUser=root",
            "SlurmdUser=root",
            f"SlurmctldPort={free_port()}", f"SlurmdPort={free_port()}",
            "AuthType=auth/munge", f"AuthInfo=socket={munge_socket}", "CredType=cred/munge",
            "ProctrackType=proctrack/linuxproc", "TaskPlugin=task/none",
            "SelectType=select/cons_tres", "SelectTypeParameters=CR_Core",
            "JobAcctGatherType=jobacct_gather/none",
            "AccountingStorageType=accounting_storage/none", "MpiDefault=none",
            "ReturnToService=2", "MinJobAge=600", "MailProg=/bin/true",
            f"StateSaveLocation={self.path('state')}", f"SlurmdSpoolDir={self.path('spool')}",
            f"SlurmctldPidFile={self.path('slurmctld.pid')}",
            f"SlurmdPidFile={self.path('slurmd.pid')}",
            f"SlurmctldLogFile={self.path('log', 'slurmctld.log')}",
            f"SlurmdLogFile={self.path('log', 'slurmd.log')}",
            "NodeName=localhost NodeAddr=127.0.0.1 CPUs=2 RealMemory=2000 State=UNKNOWN",
            "PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP", ""])

    def spawn(self, name, command):
        log = open(self.path("log", name + ".out"), "w", encoding="utf-8")
        process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, env=self.env,
                                   start_new_session=True)
        self.processes.append((name, process))
        time.sleep(0.2)
        if process.poll() is not None:
            raise RuntimeError(f"{name} exited at once ({process.returncode}); see "
                               f"{self.path('log')}")

    def run(self, command, check=True, **kwargs):
        proc = subprocess.run(command, env=kwargs.pop("env", self.env), capture_output=True,
                              text=True, **kwargs)
        if check and proc.returncode != 0:
            raise RuntimeError(f"{command[0]} failed ({proc.returncode}): {proc.stderr}")
        return proc

    def wait_for_job(self, job):
        """Waits until no task of `job` is pending or running; returns {task: (state, exit)}."""
        wait_until(f"job {job}", lambda: not self.run(
            ["squeue", "-h", "-j", job, "-o", "%i"], check=False).stdout.strip(), TIMEOUT)
        shown = self.run(["scontrol", "-o", "show", "job", job]).stdout
        tasks = {}
        for line in shown.splitlines():
            fields = dict(re.findall(r"(\w+)=(\S*)", line))
            tasks[int(fields["ArrayTaskId"])] = (fields["JobState"], fields["ExitCode"])
        return tasks

    def stop(self):
        for name, process in reversed(self.processes):  # slurmd, slurmctld, munged
            if process.poll() is None:
                process.send_signal(signal.SIGTERM)
                try:
                    process.wait(15)
                except subprocess.TimeoutExpired:
                    print(f"farm: {name} (pid {process.pid}) ignored SIGTERM; killed")
                    process.kill()
                    process.wait()
        # Job steps are children of slurmd's session only while it runs; none may outlive it.
        self.processes = []


def report(name, failures):
    """Prints the failures and the closing line ctest's log shows; returns the exit status."""
    for failure in failures:
        print("FAIL:", failure)
    print(f"{name}: {0 if failures else 1} passed, {1 if failures else 0} failed")
    return 1 if failures else 0


def write_shot(folder, frames=FRAMES, size=None):
    """The bundled sample render as a shot, each frame's depth scaled a little more (so that
    frames differ and a frame written under the wrong number is caught); `size` (width,
    height) resamples it (benchmarks/farm_throughput.py)."""
    names, pixels = read_image(SAMPLE + ".exr")
    if size is not None:
        source = oiio.ImageBuf(pixels)
        resized = oiio.ImageBufAlgo.resize(source, roi=oiio.ROI(0, size[0], 0, size[1], 0, 1, 0,
                                                                pixels.shape[2]))
        pixels = np.asarray(resized.get_pixels(oiio.FLOAT), np.float32)
    depth = names.index("ViewLayer.Depth.Z")
    for frame in frames:
        data = pixels.copy()
        data[:, :, depth] *= 1.0 + 0.01 * (frame - frames[0])
        path = os.path.join(folder, f"render.{frame:04d}.exr")
        spec = oiio.ImageSpec(data.shape[1], data.shape[0], data.shape[2], oiio.FLOAT)
        spec.channelnames = tuple(names)
        spec.attribute("compression", "zip")
        out = oiio.ImageOutput.create(path)
        assert out is not None and out.open(path, spec), oiio.geterror()
        assert out.write_image(data)
        out.close()
    shutil.copy(SAMPLE + ".camera.json", os.path.join(folder, "render.camera.json"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ssao", required=True, help="build/bin/ssao")
    parser.add_argument("--scratch", required=True, help="a folder the test may empty")
    args = parser.parse_args()
    if os.geteuid() != 0:
        print("farm: skipped: slurmd must run as root to start jobs")
        return SKIP

    scratch = os.path.abspath(args.scratch)
    shutil.rmtree(scratch, ignore_errors=True)
    shot, farm_out, serial_out = (os.path.join(scratch, d) for d in ("shot", "farm", "serial"))
    for folder in (shot, farm_out, serial_out):
        os.makedirs(folder)
    write_shot(shot)
    frames = f"{FRAMES[0]}-{FRAMES[-1]}"
    ssao_args = [os.path.join(shot, "render.####.exr"), "--camera",
                 os.path.join(shot, "render.camera.json"), "--radius", str(RADIUS),
                 "--frames", frames]

    # The serial reference: one process, all frames, 2 threads.
    start = time.monotonic()
    serial = subprocess.run([args.ssao, *ssao_args, "-o", os.path.join(serial_out, "ao.####.exr"),
                             "--threads", "2", "--quiet"], capture_output=True, text=True)
    serial_seconds = time.monotonic() - start
    assert serial.returncode == 0, serial.stderr

    cluster = LocalSlurm(os.path.join(scratch, "slurm"))
    failures = []
    try:
        start = time.monotonic()
        cluster.start()
        startup_seconds = time.monotonic() - start

        # The shot, 1 core per task: both cores of the node run a task at once.
        env = dict(cluster.env, SSAO_BIN=os.path.abspath(args.ssao))
        start = time.monotonic()
        submit = cluster.run([SUBMIT, "--chunk-size", str(CHUNK), "--cpus-per-task", "1",
                              "--log-dir", os.path.join(scratch, "logs"), "--",
                              *ssao_args, "-o", os.path.join(farm_out, "ao.####.exr")], env=env)
        job = submit.stdout.strip()
        tasks = cluster.wait_for_job(job)
        farm_seconds = time.monotonic() - start
        chunks = -(-len(FRAMES) // CHUNK)
        if tasks != {i: ("COMPLETED", "0:0") for i in range(chunks)}:
            failures.append(f"job {job}: expected {chunks} completed tasks, got {tasks}")
        for frame in FRAMES:
            name = f"ao.{frame:04d}.exr"
            farm_file = os.path.join(farm_out, name)
            if not os.path.isfile(farm_file):
                failures.append(f"frame {frame}: the farm wrote no {name}")
                continue
            farm_names, farm_pixels = read_image(farm_file)
            serial_names, serial_pixels = read_image(os.path.join(serial_out, name))
            if farm_names != serial_names or not np.array_equal(farm_pixels, serial_pixels):
                failures.append(f"frame {frame}: the farm's {name} differs from the serial run's")
        logs = sorted(os.listdir(os.path.join(scratch, "logs")))
        if len(logs) != chunks:
            failures.append(f"expected {chunks} task logs, got {logs}")

        # A missing frame fails its task alone; --skip-existing leaves the frames already there.
        os.remove(os.path.join(shot, f"render.{FRAMES[-1]:04d}.exr"))
        os.remove(os.path.join(farm_out, f"ao.{FRAMES[-1]:04d}.exr"))
        os.remove(os.path.join(farm_out, f"ao.{FRAMES[0]:04d}.exr"))
        submit = cluster.run([SUBMIT, "--chunk-size", str(CHUNK), "--cpus-per-task", "1",
                              "--log-dir", os.path.join(scratch, "logs2"), "--", *ssao_args,
                              "--skip-existing", "-o", os.path.join(farm_out, "ao.####.exr")],
                             env=env)
        job2 = submit.stdout.strip()
        tasks = cluster.wait_for_job(job2)
        expected = {0: ("COMPLETED", "0:0"), 1: ("COMPLETED", "0:0"), 2: ("FAILED", "1:0")}
        if tasks != expected:
            failures.append(f"job {job2} (frame {FRAMES[-1]} missing): expected {expected}, "
                            f"got {tasks}")
        if not os.path.isfile(os.path.join(farm_out, f"ao.{FRAMES[0]:04d}.exr")):
            failures.append(f"job {job2}: frame {FRAMES[0]} was not written again")
        log = open(os.path.join(scratch, "logs2", f"ssao-{job2}_2.log"), encoding="utf-8").read()
        if f"failed: {FRAMES[-1]}" not in log:
            failures.append(f"job {job2}: task 2's log does not name frame {FRAMES[-1]}:\n{log}")
    finally:
        cluster.stop()
    leftovers = subprocess.run(["pgrep", "-f", cluster.path("slurm.conf")], capture_output=True,
                               text=True).stdout.split()
    if leftovers:
        failures.append(f"daemons still running after stop: {leftovers}")

    print(f"farm: {len(FRAMES)} frames ({frames}) in {chunks} chunks of {CHUNK} "
          f"(1 core per task, 2 at once): {farm_seconds:.2f} s from submission to the last task "
          f"(cluster start-up {startup_seconds:.2f} s); serial run with 2 threads "
          f"{serial_seconds:.2f} s")
    return report("farm", failures)


if __name__ == "__main__":
    sys.exit(main())
