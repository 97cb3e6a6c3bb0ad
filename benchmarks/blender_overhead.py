#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Per-frame overhead of the Ambient Occlusion (SSAO) compositor node in a headless render.

    /usr/bin/python3 benchmarks/blender_overhead.py [-n 3] [--width 640 --height 480]
        [--samples 16] [--engine cycles|eevee] [--blender blender]
        [--zip build/blender/ssao_compositor.zip | --user-scripts DIR] [--work DIR] [--json F]

What it does:
  1. installs the add-on zip (cmake --build build --target blender_addon) into a temporary
     BLENDER_USER_SCRIPTS folder (or uses DIR/addons/ssao_compositor with --user-scripts);
  2. builds the test scene (tests/blender/build_ssao_scene.py: Render Layers -> SSAO ->
     Composite) at the given size and samples, with a PNG output;
  3. in ONE background Blender process (this file run with -P), renders the frame with
     bpy.ops.render.render(write_still=True), which runs the same handlers as `blender -b ...
     -f 1` (render_post: AO + re-composite; render_write: the frame file rewritten with AO):
     one warm-up render per mode (not counted), then N rounds of (node muted, node active).
     Each render is timed with a wall clock around the call; handlers around the add-on's own
     time its render_post work (AO computation + compositing-only helper render) and its
     render_write work (saving the frame again). The AO computation time is the one the
     add-on reports on the node and in the console ("ssao_compositor: ... in N ms").
  4. prints, per mode, min and median seconds per frame, the differences (active - muted),
     and the breakdown of the add-on's part.

Exit status: 0 success; 1 a Blender run failed or the add-on reported no AO; 2 usage error.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import zipfile

try:
    import bpy  # inside Blender: the measuring half
except ImportError:
    bpy = None

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ADDON = "ssao_compositor"
NODE_IDNAME = "CompositorNodeSSAO"
RESULT_TAG = "blender_overhead: RESULT "


# --- inside Blender -------------------------------------------------------------------------

class _Timeline:
    """Times of the outermost render's phases (the add-on's helper render nests inside)."""

    def __init__(self):
        self.depth = 0
        self.marks = {}

    def handler(self, name):
        def record(*_):
            if name == "init":
                self.depth += 1
            if self.depth == 1:
                self.marks[name] = time.perf_counter()
            if name in ("complete", "cancel"):
                self.depth -= 1
        return bpy.app.handlers.persistent(record)

    def install(self):
        handlers = bpy.app.handlers
        # Ours before and after the add-on's own handlers (registered when it was enabled).
        handlers.render_init.insert(0, self.handler("init"))
        handlers.render_post.insert(0, self.handler("post_start"))
        handlers.render_post.append(self.handler("post_end"))
        handlers.render_write.insert(0, self.handler("write_start"))
        handlers.render_write.append(self.handler("write_end"))
        handlers.render_complete.append(self.handler("complete"))
        handlers.render_cancel.append(self.handler("cancel"))

    def span(self, start, end):
        if start in self.marks and end in self.marks:
            return self.marks[end] - self.marks[start]
        return None


def _ms_from_status(status):
    """'Frame 1: 640x480 in 187 ms' -> 187.0"""
    words = status.split()
    if len(words) >= 2 and words[-1] == "ms":
        try:
            return float(words[-2])
        except ValueError:
            return None
    return None


def inner_main(argv):
    parser = argparse.ArgumentParser(prog="blender_overhead.py (in Blender)")
    parser.add_argument("--inner", action="store_true")
    parser.add_argument("-n", type=int, default=3)
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)

    scene = bpy.context.scene
    compat = next(m for n, m in sys.modules.items() if n.endswith("ssao_compositor.compat"))
    tree = compat.compositor_tree(scene)  # scene.node_tree before 5.0, a node group after
    nodes = [n for n in tree.nodes if n.bl_idname == NODE_IDNAME] if tree else []
    if not nodes:
        raise SystemExit(f"blender_overhead: scene '{scene.name}' has no {NODE_IDNAME}")
    timeline = _Timeline()
    timeline.install()

    def render(mode, index):
        for node in nodes:
            node.mute = (mode == "muted")
            node.status = ""
        scene.render.filepath = os.path.join(args.out, f"{mode}_{index}")
        timeline.marks.clear()
        start = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        row = {"mode": mode, "index": index, "seconds": time.perf_counter() - start,
               "render_post_s": timeline.span("post_start", "post_end"),
               "render_write_s": timeline.span("write_start", "write_end"),
               "status": nodes[0].status}
        row["ao_ms"] = _ms_from_status(row["status"]) if mode == "active" else None
        print(f"blender_overhead: {mode} #{index}: {row['seconds']:.3f} s "
              f"(post {row['render_post_s'] or 0:.3f} s, write {row['render_write_s'] or 0:.3f} s"
              f"{', AO ' + str(row['ao_ms']) + ' ms' if row['ao_ms'] is not None else ''})",
              flush=True)
        return row

    import numpy as np
    rows = [dict(render("muted", "warmup"), warmup=True),
            dict(render("active", "warmup"), warmup=True)]
    for index in range(args.n):
        rows.append(render("muted", index))
        rows.append(render("active", index))
    # The frames written must differ: with the node active they carry the AO.
    means = {}
    for mode in ("muted", "active"):
        image = bpy.data.images.load(os.path.join(args.out, f"{mode}_0.png"))
        pixels = np.empty(image.size[0] * image.size[1] * 4, np.float32)
        image.pixels.foreach_get(pixels)
        means[mode] = float(pixels.reshape(-1, 4)[:, :3].mean())
        bpy.data.images.remove(image)
    print(RESULT_TAG + json.dumps({
        "frame_mean_muted": means["muted"], "frame_mean_active": means["active"],
        "blender": bpy.app.version_string, "engine": scene.render.engine,
        "size": [scene.render.resolution_x * scene.render.resolution_percentage // 100,
                 scene.render.resolution_y * scene.render.resolution_percentage // 100],
        "samples": scene.cycles.samples if scene.render.engine == "CYCLES"
        else scene.eevee.taa_render_samples,
        "threads": os.cpu_count(), "rows": rows}), flush=True)


# --- the driver (plain Python) --------------------------------------------------------------

def run(command, env=None, log=None):
    result = subprocess.run(command, env=env, capture_output=True, text=True)
    if log:
        with open(log, "w") as stream:
            stream.write(result.stdout + result.stderr)
    if result.returncode != 0:
        tail = "\n".join((result.stdout + result.stderr).splitlines()[-20:])
        raise RuntimeError(f"{' '.join(command)} failed ({result.returncode}):\n{tail}")
    return result.stdout


def summarize(data):
    rows = [r for r in data["rows"] if not r.get("warmup")]
    muted = [r["seconds"] for r in rows if r["mode"] == "muted"]
    active = [r["seconds"] for r in rows if r["mode"] == "active"]
    # pairs of the same round, so that slow spells of the machine hit both
    paired = [a["seconds"] - m["seconds"] for m, a in
              zip([r for r in rows if r["mode"] == "muted"],
                  [r for r in rows if r["mode"] == "active"])]
    post = [r["render_post_s"] for r in rows if r["mode"] == "active" and r["render_post_s"]]
    write = [r["render_write_s"] for r in rows if r["mode"] == "active" and r["render_write_s"]]
    ao = [r["ao_ms"] for r in rows if r["mode"] == "active" and r["ao_ms"] is not None]
    return {"muted": muted, "active": active, "paired_difference": paired,
            "post": post, "write": write, "ao_ms": ao}


def _fmt(values, scale=1.0, digits=3):
    if not values:
        return "n/a", "n/a"
    return (f"{min(values) * scale:.{digits}f}", f"{statistics.median(values) * scale:.{digits}f}")


def print_table(data, summary, n):
    width, height = data["size"]
    print(f"\nBlender {data['blender']}, {data['engine']}, {width}x{height}, "
          f"{data['samples']} samples, {data['threads']} CPU threads, N={n} "
          "(after one warm-up render per mode)\n")
    print("| per frame | min | median |")
    print("|---|---|---|")
    lines = [
        ("node muted (s)", summary["muted"], 1.0, 3),
        ("node active (s)", summary["active"], 1.0, 3),
        ("difference, paired by round (s)", summary["paired_difference"], 1.0, 3),
        ("add-on render_post: AO + re-composite (s)", summary["post"], 1.0, 3),
        ("add-on render_write: frame saved again (s)", summary["write"], 1.0, 3),
        ("AO computation reported by the add-on (ms)", summary["ao_ms"], 1.0, 0),
    ]
    for label, values, scale, digits in lines:
        low, mid = _fmt(values, scale, digits)
        print(f"| {label} | {low} | {mid} |")
    warmup = {r["mode"]: r["seconds"] for r in data["rows"] if r.get("warmup")}
    print(f"\nfirst render of the process (warm-up, not in the table): muted "
          f"{warmup['muted']:.3f} s, active {warmup['active']:.3f} s")
    print(f"mean of the frame written: muted {data['frame_mean_muted']:.4f}, active "
          f"{data['frame_mean_active']:.4f} (darker: the AO is in the file)")
    mins = (min(summary["active"]) - min(summary["muted"]),
            statistics.median(summary["active"]) - statistics.median(summary["muted"]))
    print(f"\nactive - muted: difference of the mins {mins[0]:.3f} s, of the medians "
          f"{mins[1]:.3f} s")


def install_addon(zip_path, work):
    scripts = os.path.join(work, "scripts")
    addons = os.path.join(scripts, "addons")
    os.makedirs(addons, exist_ok=True)
    with zipfile.ZipFile(zip_path) as archive:
        archive.extractall(addons)
    if not os.path.isdir(os.path.join(addons, ADDON)):
        raise RuntimeError(f"{zip_path} has no {ADDON}/ folder")
    return scripts


def driver_main():
    parser = argparse.ArgumentParser(
        prog="blender_overhead.py",
        description="Per-frame overhead of the SSAO compositor node (headless renders).")
    parser.add_argument("-n", "--repeat", type=int, default=3, help="renders per mode (3)")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--engine", choices=("cycles", "eevee"), default="cycles")
    parser.add_argument("--blender", default=os.environ.get("BLENDER", "blender"))
    parser.add_argument("--zip", default=os.path.join(REPO_ROOT, "build", "blender",
                                                      ADDON + ".zip"))
    parser.add_argument("--user-scripts", default=None,
                        help="a BLENDER_USER_SCRIPTS folder that already has the add-on")
    parser.add_argument("--work", default=None, help="keep scene, frames and logs here")
    parser.add_argument("--json", default=None, help="also write the measurements here")
    args = parser.parse_args()
    if shutil.which(args.blender) is None:
        print(f"blender_overhead: error: no Blender executable '{args.blender}'", file=sys.stderr)
        return 2
    if args.user_scripts is None and not os.path.exists(args.zip):
        print(f"blender_overhead: error: {args.zip} not found (cmake --build build --target "
              "blender_addon)", file=sys.stderr)
        return 2

    work = args.work or tempfile.mkdtemp(prefix="ssao_overhead_")
    os.makedirs(work, exist_ok=True)
    env = dict(os.environ)
    env["BLENDER_USER_SCRIPTS"] = args.user_scripts or install_addon(args.zip, work)
    base = [args.blender, "-b", "--factory-startup", "-noaudio", "--addons", ADDON]
    scene = os.path.join(work, "scene.blend")
    try:
        run(base + ["--python-exit-code", "1",
                    "-P", os.path.join(REPO_ROOT, "tests", "blender", "build_ssao_scene.py"),
                    "--", "--out", scene, "--engine", args.engine,
                    "--width", str(args.width), "--height", str(args.height),
                    "--samples", str(args.samples), "--output", "//frame_####.png"],
            env=env, log=os.path.join(work, "build_scene.log"))
        # --addons before the .blend: enabled after the file is loaded, the add-on does not
        # reconfigure the file's nodes (see docs/blender.md).
        out = run(base + [scene, "--python-exit-code", "1", "-P", os.path.abspath(__file__),
                          "--", "--inner", "-n", str(args.repeat), "--out", work],
                  env=env, log=os.path.join(work, "benchmark.log"))
    except RuntimeError as error:
        print(f"blender_overhead: error: {error}", file=sys.stderr)
        return 1
    lines = [line for line in out.splitlines() if line.startswith(RESULT_TAG)]
    if not lines:
        print(f"blender_overhead: error: no result (see {work}/benchmark.log)", file=sys.stderr)
        return 1
    data = json.loads(lines[-1][len(RESULT_TAG):])
    summary = summarize(data)
    if len(summary["ao_ms"]) != args.repeat:
        print("blender_overhead: error: the add-on did not report an AO for every active "
              f"render (see {work}/benchmark.log)", file=sys.stderr)
        return 1
    if not data["frame_mean_active"] < 0.999 * data["frame_mean_muted"]:
        print("blender_overhead: error: the frame written with the node active is not darker "
              f"than the muted one (means {data['frame_mean_active']:.4f} vs "
              f"{data['frame_mean_muted']:.4f}): no AO in the output", file=sys.stderr)
        return 1
    print_table(data, summary, args.repeat)
    print(f"\nscene, frames and logs: {work}")
    if args.json:
        with open(args.json, "w") as stream:
            json.dump({"measurements": data, "summary": summary}, stream, indent=2)
    return 0


if __name__ == "__main__":
    if bpy is not None:
        inner_main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
    else:
        sys.exit(driver_main())
