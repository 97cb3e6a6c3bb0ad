#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""What povray-ssao costs next to the plain beauty render and to POV-Ray's own radiosity, and
how much its default radius darkens contact regions, on POV-Ray's shipped example scenes.

    /usr/bin/python3 benchmarks/povray_cost.py [--bridge build/bin/povray-ssao] [-n 3]
        [--scenes woodbox,pawns,...] [--work DIR] [--json F]

Per scene (640x480, 480x480 for cornell; POV-Ray's default thread count, every core), in
interleaved rounds (A B C D A B C D ...), wall-clock seconds of whole processes, median of N:
  beauty     povray on the wrapper povray-ssao renders as its beauty (the scene with its camera
             declared again: the same image povray-ssao starts from; focal blur removed)
  ssao       povray-ssao with its defaults (all passes, AO, outputs written)
  multiply   povray-ssao --apply-to beauty (no ambient pass)
  radiosity  the beauty wrapper with `global_settings { radiosity { } }` added: POV-Ray's own
             indirect light at its default settings (not for scenes that have radiosity)
Then, from one more povray-ssao run with --exr: the radius it chose and the contact darkening:
over the 5% of the geometry pixels with the lowest AO (the contact regions), the mean of
1 - AO and the mean darkening of the output against the beauty, 1 - sum(out) / sum(beauty);
the same for the previous default radius (5% of the median distance from the camera).

Exit status: 0 success, 1 a run failed, 2 usage error.
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from image_files import read_image  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = "/usr/share/povray-3.7/scenes"
# name: (path under EXAMPLES or tests/povray/scenes, local includes, width, height)
SCENES = {
    "woodbox": ("advanced/woodbox.pov", (), 640, 480),
    "pawns": ("advanced/pawns.pov", (), 640, 480),
    "chess2": ("advanced/chess2.pov", (), 640, 480),
    "cornell": ("radiosity/cornell.pov", (), 480, 480),
    "glasschess": ("advanced/glasschess/glasschess.pov", ("chesspiece1.inc",), 640, 480),
    "sunlit_wall": ("tests/povray/scenes/sunlit_wall.pov", (), 640, 480),
}


def fail(message):
    print("povray_cost.py: " + message, file=sys.stderr)
    sys.exit(1)


def run(cmd, cwd):
    start = time.perf_counter()
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if proc.returncode != 0:
        fail("failed: %s\n%s%s" % (" ".join(cmd), proc.stdout[-2000:], proc.stderr[-2000:]))
    return seconds, proc.stdout


def contact_darkening(exr, beauty_exr):
    names, pixels = read_image(exr)
    ao = pixels[..., names.index("AO")].astype(np.float64)
    z = pixels[..., names.index("Z")]
    out = sum(pixels[..., names.index(c)].astype(np.float64) for c in "RGB")
    beauty = read_image(beauty_exr)[1][..., :3].astype(np.float64).sum(-1)
    geometry = np.isfinite(z)
    values = ao[geometry]
    contact = geometry & (ao <= np.quantile(values, 0.05))
    return (float(1.0 - ao[contact].mean()),
            float(1.0 - out[contact].sum() / max(beauty[contact].sum(), 1e-12)))


def measure(name, args, work):
    relative, extra, width, height = SCENES[name]
    source = os.path.join(ROOT, relative) if relative.startswith("tests/") else \
        os.path.join(EXAMPLES, relative)
    if not os.path.isfile(source):
        fail("%s missing (Debian package povray-examples)" % source)
    folder = os.path.join(work, name)
    os.makedirs(folder, exist_ok=True)
    shutil.copy(source, folder)
    for include in extra:
        shutil.copy(os.path.join(os.path.dirname(source), include), folder)
    scene = os.path.join(folder, os.path.basename(relative))
    size = ["+W%d" % width, "+H%d" % height]
    keep = os.path.join(folder, "keep")
    exr = os.path.join(folder, "out.exr")
    bridge = [args.bridge, scene, "-o", os.path.join(folder, "out.png")] + size
    # One untimed run: the wrappers (and the page cache), the AO figures.
    _, log = run(bridge + ["--exr", exr, "--keep", keep], folder)
    radius = float(re.search(r"radius ([0-9.e+-]+) scene units", log).group(1))
    mode = "ambient" if "applied to the ambient light" in log else "beauty"
    # The beauty wrapper includes the scene from the scene's folder.
    beauty_pov = os.path.join(folder, "beauty_wrapper.pov")
    shutil.copy(os.path.join(keep, "beauty.pov"), beauty_pov)
    has_radiosity = "radiosity" in open(scene, encoding="latin-1").read()
    radiosity_pov = os.path.join(folder, "radiosity_wrapper.pov")
    with open(radiosity_pov, "w") as f:
        f.write(open(beauty_pov).read() + "global_settings { radiosity { } }\n")
    povray = ["povray", "-D", "-P", "+FE", "+L" + folder] + size
    commands = {
        "beauty": povray + ["+I" + beauty_pov, "+O" + os.path.join(folder, "b.exr")],
        "ssao": bridge,
        "multiply": bridge + ["--apply-to", "beauty"],
    }
    if not has_radiosity:
        commands["radiosity"] = povray + ["+I" + radiosity_pov,
                                          "+O" + os.path.join(folder, "r.exr")]
    times = {key: [] for key in commands}
    for _ in range(args.n):
        for key, cmd in commands.items():
            times[key].append(run(cmd, folder)[0])
    row = {key: statistics.median(values) for key, values in times.items()}
    row.update(scene=name, size="%dx%d" % (width, height), radius=radius, mode=mode)
    row["contact_ao"], row["contact_out"] = contact_darkening(exr, os.path.join(keep, "beauty.exr"))
    # The previous default: 5% of the median distance from the camera.
    names, pixels = read_image(exr)
    radial = pixels[..., names.index("Radial")]
    old_radius = 0.05 * float(np.median(radial[np.isfinite(radial)]))
    old_exr = os.path.join(folder, "old.exr")
    run(bridge + ["--exr", old_exr, "--radius", repr(old_radius), "--keep", keep], folder)
    row["old_radius"] = old_radius
    row["old_contact_ao"], row["old_contact_out"] = contact_darkening(
        old_exr, os.path.join(keep, "beauty.exr"))
    return row


def table(rows):
    head = ("| scene | size | beauty | povray-ssao (mode) | / beauty | --apply-to beauty | / beauty "
            "| default radiosity | povray-ssao / radiosity |")
    lines = [head, "|" + "---|" * 2 + "--:|" * 7]
    for r in rows:
        rad = r.get("radiosity")
        lines.append("| %s | %s | %.2f s | %.2f s (%s) | %.2f | %.2f s | %.2f | %s | %s |" % (
            r["scene"], r["size"], r["beauty"], r["ssao"], r["mode"], r["ssao"] / r["beauty"],
            r["multiply"], r["multiply"] / r["beauty"],
            "%.2f s" % rad if rad else "(scene has radiosity)",
            "%.2f" % (r["ssao"] / rad) if rad else ""))
    lines += ["", "| scene | default radius | contact 1 - AO | contact darkening of the image "
              "| previous radius | contact 1 - AO | contact darkening |",
              "|---|--:|--:|--:|--:|--:|--:|"]
    for r in rows:
        lines.append("| %s | %.3g | %.3f | %.3f | %.3g | %.3f | %.3f |" % (
            r["scene"], r["radius"], r["contact_ao"], r["contact_out"], r["old_radius"],
            r["old_contact_ao"], r["old_contact_out"]))
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bridge", default=os.path.join(ROOT, "build", "bin", "povray-ssao"))
    parser.add_argument("-n", type=int, default=3, help="rounds (default 3)")
    parser.add_argument("--scenes", default=",".join(SCENES),
                        help="comma-separated, of: " + ", ".join(SCENES))
    parser.add_argument("--work", default=None, help="folder for the runs (default: temporary)")
    parser.add_argument("--json", default=None, help="also write the rows as JSON here")
    args = parser.parse_args()
    names = [s for s in args.scenes.split(",") if s]
    unknown = [s for s in names if s not in SCENES]
    if unknown or args.n < 1:
        parser.error("unknown scene(s) %s" % ", ".join(unknown) if unknown else "-n must be >= 1")
    if not os.access(args.bridge, os.X_OK):
        fail("no %s: build the project first (scripts/build.sh)" % args.bridge)
    if shutil.which("povray") is None:
        fail("povray not found (apt-get install povray povray-examples)")
    work = args.work or tempfile.mkdtemp(prefix="povray-cost-")
    rows = []
    for name in names:
        print("[%s] %s ..." % (time.strftime("%H:%M:%S"), name), file=sys.stderr, flush=True)
        rows.append(measure(name, args, work))
    print("%d cores, POV-Ray's default threads; wall-clock seconds, median of %d interleaved "
          "rounds" % (os.cpu_count(), args.n))
    print(table(rows))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    if not args.work:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
