#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Corpus test of povray-ssao's POV-Ray scene reader over every scene of Debian's povray-examples
package (396 .pov files in /usr/share/povray-3.7/scenes, a link to /usr/share/doc/povray/examples).

Every scene must either have its camera read, with the same view as POV-Ray's own render, or be
refused with a message that names the construct. The whole corpus (about 5 minutes on 2 busy
cores):
    /usr/bin/python3 tests/povray/scene_corpus.py --bridge build/bin/povray-ssao \
        --scratch /tmp/ssao-scene-corpus --jobs 2 --report /tmp/ssao-scene-corpus.json
CI (ctest -L povray, test povray.scene_corpus_sample) runs a fixed sample: --sample 24.

For each scene, in a scratch copy of the scene's whole folder (local #include files, image maps;
scenes that #write files write there; POV-Ray's standard includes come from its library path):
 1. povray-ssao SCENE.pov -o x.png +W40 +H30 --print-camera prints the camera block it renders
    the beauty with, after the scene (exit 0), or refuses (exit 1, "povray-ssao: error: ...").
    A scene with focal blur keeps its own camera for the beauty: then the block of the depth
    pass is compared, printed with --overscan 0 so that it has the frame's size.
 2. POV-Ray renders the scene as it is (+W40 +H30 +Q0 -A: quick colours, enough for the
    silhouettes; the default clock, so animations show frame 0) and a wrapper holding
    #include "SCENE.pov" followed by that camera block (POV-Ray uses the last camera): what the
    bridge renders. Same view = the two images agree (see MAX_DIFFERING below). Where the quick
    colours render a uniform image (media, glass, radiosity), both are rendered again at +Q9; a
    view still uniform then is reported "uniform image: the view is not checked". A camera whose
    focal blur or normal { } povray-ssao leaves out (as it says) is compared with the scene
    without them: the scratch copy's camera block edited (aperture 0*..., normal { } removed).
Classes (one per scene):
  read, same view          the camera was read and renders the same image
  read, different view     FAILURE: read, but the images differ
  read, wrapper fails      FAILURE: the scene renders, the scene followed by the block does not
  refused                  povray-ssao refused with a message that names the construct
  refused, generic message FAILURE: refused with a message that does not (see names_construct)
  bridge error             FAILURE: povray-ssao crashed, hung, or printed no camera block
  povray fails             POV-Ray itself cannot render the original scene (not the reader's
                           fault; povray-ssao's answer is still recorded)
  timeout                  POV-Ray takes longer than --timeout on the original (or wrapper)
A refusal names the construct when the first line of its message holds a quoted fragment
('...', "..." or `...`) with an SDL keyword or identifier in it (a bare file name does not
count), or a file:line reference (NAME.pov:23, NAME.inc:7). Exit status: 1 if any scene is in a
FAILURE class, 77 (skip) if the examples folder or povray is missing, 2 on bad usage, else 0.
"""

import argparse
import concurrent.futures
import json
import os
import re
import shutil
import subprocess
import sys
import threading
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from image_files import read_image  # noqa: E402
from povray_process import run_povray  # noqa: E402

DEFAULT_EXAMPLES = ["/usr/share/povray-3.7/scenes", "/usr/share/doc/povray/examples"]
SKIP = 77
W, H = 40, 30
# POV-Ray's flags for both renders: quick colours only, no antialiasing, no display or pause,
# 8-bit PPM, one render thread (the scenes run in parallel instead).
RENDER_FLAGS = [f"+W{W}", f"+H{H}", "+Q0", "-A", "-D", "-P", "+FP", "-V", "-GS", "-GR", "+WT1"]
# Same view: a pixel differs when one of its channels differs by more than PIXEL_TOLERANCE (of
# 255), and the view is the same when at most MAX_DIFFERING of the pixels differ. The camera
# block is printed with 17 significant digits, so a correctly read camera traces the same rays
# up to the last bits. Measured over the whole corpus (POV-Ray 3.7.0.10, 40x30): 354 of the 355
# scenes read right render bit-identical images; lights/glassthing.pov (glass and photons, at
# +Q9) amplifies the last-bit differences: 0.5% of the pixels (6 of 1200) differ by more than 24,
# 1.9% at all (largest 55). The three wrong cameras found differ in 65%, 66% and 100%.
PIXEL_TOLERANCE = 24
MAX_DIFFERING = 0.02  # 4x the worst scene read right (0.5%)

FAILURES = ("read, different view", "read, wrapper fails", "refused, generic message",
            "bridge error")
CLASSES = ("read, same view",) + FAILURES[:2] + ("refused",) + FAILURES[2:] + (
    "povray fails", "timeout")

BLOCK_HEADERS = ("the beauty and the ambient pass are rendered with (after the scene):",
                 "every pass is rendered with (after the scene):")
FOCAL_BLUR_HEADER = "the beauty and the ambient pass are rendered with the scene's own camera"


def find_examples(requested):
    """The folder with the scenes: --examples, else the first default that holds .pov files."""
    candidates = [requested] if requested else DEFAULT_EXAMPLES
    for folder in candidates:
        if os.path.isdir(folder) and list_scenes(folder):
            return folder
    return None


def list_scenes(folder):
    """Every .pov file under folder (following links), as sorted relative paths."""
    scenes = []
    for root, _dirs, files in os.walk(folder, followlinks=True):
        for name in files:
            if name.endswith(".pov"):
                scenes.append(os.path.relpath(os.path.join(root, name), folder))
    return sorted(scenes)


def sample(scenes, count):
    """A fixed sample: every k-th scene of the sorted list, k = len // count."""
    if not count or count >= len(scenes):
        return scenes
    return scenes[::len(scenes) // count][:count]


def read_pixels(path):
    """A render (8- or 16-bit PPM) as a height x width x 3 array of 0-255 levels."""
    return (read_image(path)[1].astype(np.float64) * 255.0).round()


def is_uniform(pixels):
    """Whether no colour of the image varies by more than PIXEL_TOLERANCE: such an image cannot
    tell views apart."""
    return bool((pixels.max(axis=(0, 1)) - pixels.min(axis=(0, 1))).max() <= PIXEL_TOLERANCE)


def uniform_image(path):
    return is_uniform(read_pixels(path))


def compare(first, second):
    """(fraction of pixels differing by more than PIXEL_TOLERANCE, fraction differing at all,
    largest difference, whether the first image is uniform) of two renders."""
    a, b = read_pixels(first), read_pixels(second)
    uniform = is_uniform(a)
    if a.shape != b.shape:
        return 1.0, 1.0, 255.0, uniform
    diff = np.abs(a - b).max(axis=2)
    return (float((diff > PIXEL_TOLERANCE).mean()), float((diff > 0).mean()), float(diff.max()),
            uniform)


def povray_message(stderr):
    """POV-Ray's error from its stderr: the lines from the first one that names an error."""
    lines = stderr.splitlines()
    for i, line in enumerate(lines):
        if line.startswith("==== [Parsing"):
            lines = lines[i + 1:]
            break
    lines = [line for line in lines if line.strip() and not line.startswith("==== [")]
    for i, line in enumerate(lines):
        if re.search(r"error|Error|ERROR", line):
            return " ".join(s.strip() for s in lines[i:i + 3])
    return " ".join(s.strip() for s in lines[-3:])


def first_error_line(stderr):
    lines = [line.strip() for line in stderr.splitlines() if line.strip()]
    for line in lines:
        if "error" in line.lower():
            return line
    return lines[0] if lines else "(no message)"


def names_construct(message):
    """Whether a refusal's first line names the construct (see the module docstring)."""
    for match in re.finditer(r"['\"`\u2018]([^'\"`\u2019]{1,120})['\"`\u2019]", message):
        text = match.group(1).strip()
        if re.search(r"[A-Za-z_#][A-Za-z0-9_]*", text) and not re.fullmatch(
                r"[\w./-]+\.(pov|inc|ini|mcr|ttf|png|jpg|tga|df3)", text):
            return True
    return re.search(r"[\w.-]+\.(pov|inc|mcr|ini):\d+", message) is not None


def camera_block(stdout, header):
    """The camera { } block printed after the line starting with header, or None."""
    lines = stdout.splitlines()
    for i, line in enumerate(lines):
        if line.startswith(header):
            block = []
            for following in lines[i + 1:]:
                block.append(following)
                if following.strip() == "}":
                    return "\n".join(block) + "\n"
            return None
    return None


def skip_to_block_end(text, pos):
    """The index just past the } closing the { at text[pos] (comments and strings skipped)."""
    depth = 0
    while pos < len(text):
        if text.startswith("//", pos):
            pos = text.find("\n", pos)
            pos = len(text) if pos < 0 else pos
        elif text.startswith("/*", pos):
            pos = text.find("*/", pos)
            pos = len(text) if pos < 0 else pos + 2
            continue
        elif text[pos] == '"':
            pos = text.find('"', pos + 1)
            pos = len(text) if pos < 0 else pos + 1
            continue
        elif text[pos] == "{":
            depth += 1
        elif text[pos] == "}":
            depth -= 1
            if depth == 0:
                return pos + 1
        pos += 1
    return len(text)


def neutralize_camera(path, line):
    """Takes the focal blur (aperture 0) and the ray perturbation (normal { }) out of the camera
    block at path:line, in place (a scratch copy): the reference for the cameras whose blur and
    perturbation povray-ssao leaves out. Returns whether the file changed."""
    with open(path, encoding="latin-1") as f:
        text = f.read()
    start = sum(len(s) for s in text.splitlines(True)[:line - 1])
    match = re.compile(r"\bcamera\s*{").search(text, start)
    if not match:
        return False
    end = skip_to_block_end(text, match.end() - 1)
    block = text[match.start():end]
    pieces, pos = [], 0
    for normal in re.finditer(r"\bnormal\s*{", block):
        if normal.start() < pos:
            continue
        pieces.append(block[pos:normal.start()])
        pos = skip_to_block_end(block, normal.end() - 1)
    block = "".join(pieces) + block[pos:]
    # "aperture 0*EXPR": no blur, whatever the expression (a product binds tighter than +).
    block = re.sub(r"\baperture\b", "aperture 0*", block)
    if block == text[match.start():end]:
        return False
    with open(path, "w", encoding="latin-1") as f:
        f.write(text[:match.start()] + block + text[end:])
    return True


def scene_notes(path):
    """#version, file writes and clock use of the scene's own text (for the report)."""
    try:
        with open(path, encoding="latin-1") as f:
            text = f.read()
    except OSError:
        return {}
    notes = {}
    version = re.search(r"^\s*#version\s+([^;\n]+)", text, re.M)
    if version:
        notes["version"] = version.group(1).strip()
    if re.search(r"#fopen\s+\w+\s+\S+\s+(write|append)", text):
        notes["writes_files"] = True
    if re.search(r"\bclock\b", text):
        notes["uses_clock"] = True
    return notes


class Corpus:
    def __init__(self, args, examples):
        self.args = args
        self.examples = examples
        self.lock = threading.Lock()
        self.done = 0
        self.total = 0

    def povray(self, folder, scene, output, *extra):
        """Renders scene in folder: 'ok', 'timeout' or the error message."""
        cmd = ([self.args.povray, "+I" + scene, "+O" + output, "+L" + folder] + RENDER_FLAGS
               + list(extra))
        try:
            proc = run_povray(cmd, cwd=folder, errors="replace", timeout=self.args.timeout)
        except subprocess.TimeoutExpired:
            return "timeout"
        if proc.returncode != 0 or not os.path.isfile(os.path.join(folder, output)):
            return f"exit {proc.returncode}: {povray_message(proc.stderr)}"
        return "ok"

    def bridge(self, folder, name, *extra):
        cmd = [self.args.bridge, name, "-o", "ssao_corpus_x.png", f"+W{W}", f"+H{H}",
               "--print-camera", "--povray", self.args.povray] + list(extra)
        try:
            return subprocess.run(cmd, cwd=folder, capture_output=True, text=True,
                                  errors="replace", timeout=self.args.timeout)
        except subprocess.TimeoutExpired:
            return None

    def run_scene(self, relative):
        start = time.monotonic()
        result = {"scene": relative}
        source = os.path.join(self.examples, relative)
        result.update(scene_notes(source))
        folder = os.path.join(self.args.scratch, relative[:-4].replace(os.sep, "__"))
        shutil.rmtree(folder, ignore_errors=True)
        shutil.copytree(os.path.dirname(source), folder)
        name = os.path.basename(relative)
        try:
            self.classify(folder, name, result)
        except Exception as e:  # noqa: BLE001 (one scene's surprise must not stop the corpus)
            result["class"] = "bridge error"
            result["detail"] = f"corpus script: {type(e).__name__}: {e}"
        result["seconds"] = round(time.monotonic() - start, 2)
        if result["class"] not in FAILURES and not self.args.keep:
            shutil.rmtree(folder, ignore_errors=True)
        else:
            result["folder"] = folder
        with self.lock:
            self.done += 1
            print(f"[{self.done:3d}/{self.total}] {relative}: {result['class']}"
                  + (f" ({result['detail']})" if result.get("detail") else ""), flush=True)
        return result

    def classify(self, folder, name, result):
        proc = self.bridge(folder, name)
        if proc is None:
            bridge = ("hang", "")
        elif proc.returncode == 0:
            stdout = proc.stdout
            if FOCAL_BLUR_HEADER in stdout:
                # The beauty keeps the scene's camera; compare the depth pass's, frame-sized.
                result["focal_blur"] = True
                proc = self.bridge(folder, name, "--overscan", "0")
                stdout = proc.stdout if proc is not None and proc.returncode == 0 else ""
                block = camera_block(stdout, "the depth and normal passes")
            else:
                block = next(filter(None, (camera_block(stdout, h) for h in BLOCK_HEADERS)),
                             None)
            summary = stdout.splitlines()[:2]
            result["camera"] = " ".join(s.strip() for s in summary)
            warnings = [line for line in proc.stderr.splitlines() if "warning" in line]
            if warnings:
                result["warnings"] = warnings
            bridge = ("read", block) if block else ("no block", stdout[-500:])
        elif proc.returncode == 1:
            bridge = ("refused", first_error_line(proc.stderr))
        else:
            bridge = ("crash", f"exit {proc.returncode}: {first_error_line(proc.stderr)}")

        original = self.povray(folder, name, "ssao_corpus_original.ppm")
        if original != "ok":
            result["class"] = "timeout" if original == "timeout" else "povray fails"
            result["povray"] = original
            if bridge[0] == "refused":
                result["message"] = bridge[1]
            result["detail"] = original if original != "timeout" else (
                f"povray > {self.args.timeout:g} s")
            return
        if bridge[0] == "refused":
            result["message"] = bridge[1]
            named = names_construct(bridge[1])
            result["class"] = "refused" if named else "refused, generic message"
            result["detail"] = bridge[1]
            return
        if bridge[0] != "read":
            result["class"] = "bridge error"
            result["detail"] = {"hang": f"povray-ssao > {self.args.timeout:g} s",
                                "no block": "no camera block in the output"}.get(
                                    bridge[0], bridge[1])
            return
        result["block"] = bridge[1]
        reference, quality = "ssao_corpus_original.ppm", []
        if uniform_image(os.path.join(folder, reference)):
            # Nothing to see in quick colours (media, glass, radiosity): all of POV-Ray's
            # features, still fast at 40x30 (under 1.1 s for each such scene of the corpus).
            full = self.povray(folder, name, "ssao_corpus_original_q9.ppm", "+Q9")
            if full == "ok" and not uniform_image(os.path.join(folder,
                                                               "ssao_corpus_original_q9.ppm")):
                reference, quality = "ssao_corpus_original_q9.ppm", ["+Q9"]
                result["quality"] = "+Q9 (uniform at +Q0)"
        with open(os.path.join(folder, "ssao_corpus_wrap.pov"), "w") as f:
            f.write(f'#include "{name}"\n{bridge[1]}')
        wrapped = self.povray(folder, "ssao_corpus_wrap.pov", "ssao_corpus_wrapped.ppm",
                              *quality)
        if wrapped == "timeout":
            result["class"] = "timeout"
            result["detail"] = f"the wrapper: povray > {self.args.timeout:g} s"
            return
        if wrapped != "ok":
            result["class"] = "read, wrapper fails"
            result["detail"] = wrapped
            return
        left_out = result.get("focal_blur") or any(
            "normal { }" in w for w in result.get("warnings", []))
        source = re.search(r"read from the camera at (\S+):(\d+)", result["camera"])
        if left_out and source and os.path.isfile(os.path.join(folder, source.group(1))):
            # povray-ssao says it leaves the camera's focal blur or normal { } out: compare with
            # the scene without them.
            if neutralize_camera(os.path.join(folder, source.group(1)), int(source.group(2))):
                reference = "ssao_corpus_reference.ppm"
                rendered = self.povray(folder, name, reference, *quality)
                if rendered != "ok":
                    result["class"] = "timeout" if rendered == "timeout" else "povray fails"
                    result["detail"] = "the scene without the camera's blur/normal: " + rendered
                    return
                result["reference"] = "the scene without the camera's focal blur and normal { }"
        differing, any_change, largest, uniform = compare(
            os.path.join(folder, reference), os.path.join(folder, "ssao_corpus_wrapped.ppm"))
        result["differing"] = differing
        result["changed"] = any_change
        result["largest"] = largest
        if uniform:
            result["uniform"] = True
        if differing <= MAX_DIFFERING:
            result["class"] = "read, same view"
            if uniform:
                result["detail"] = "uniform image: the view is not checked"
        else:
            result["class"] = "read, different view"
            result["detail"] = (f"{differing:.1%} of the pixels differ by more than "
                                f"{PIXEL_TOLERANCE}")

    def run(self, scenes):
        self.total = len(scenes)
        with concurrent.futures.ThreadPoolExecutor(max_workers=self.args.jobs) as pool:
            return list(pool.map(self.run_scene, scenes))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bridge", required=True, help="build/bin/povray-ssao")
    parser.add_argument("--povray", default="povray", help="POV-Ray 3.7 (default: povray)")
    parser.add_argument("--scratch", required=True, help="scratch folder (created)")
    parser.add_argument("--examples", help="the scenes (default: " +
                        " or ".join(DEFAULT_EXAMPLES) + ")")
    parser.add_argument("--sample", type=int, default=0,
                        help="only every k-th scene of the sorted list, N in all")
    parser.add_argument("--jobs", type=int, default=2, help="scenes in parallel (default 2)")
    parser.add_argument("--timeout", type=float, default=30.0,
                        help="seconds per POV-Ray render (default 30)")
    parser.add_argument("--report", help="write every scene's result to this JSON file")
    parser.add_argument("--keep", action="store_true",
                        help="keep every scene's scratch folder (default: failures' only)")
    parser.add_argument("scenes", nargs="*", help="only these scenes (relative paths)")
    args = parser.parse_args()

    examples = find_examples(args.examples)
    if examples is None:
        print("SKIP: no POV-Ray example scenes in "
              + (args.examples or " or ".join(DEFAULT_EXAMPLES))
              + " (Debian package povray-examples)")
        return SKIP
    povray = shutil.which(args.povray)
    if povray is None:
        print(f"SKIP: POV-Ray ({args.povray}) not found")
        return SKIP
    args.povray = povray
    if not os.access(args.bridge, os.X_OK):
        print(f"error: {args.bridge} is not an executable", file=sys.stderr)
        return 2
    args.bridge = os.path.abspath(args.bridge)
    args.scratch = os.path.abspath(args.scratch)
    os.makedirs(args.scratch, exist_ok=True)

    scenes = list_scenes(examples)
    if args.scenes:
        unknown = sorted(set(args.scenes) - set(scenes))
        if unknown:
            print(f"error: not in {examples}: {' '.join(unknown)}", file=sys.stderr)
            return 2
        scenes = [s for s in scenes if s in args.scenes]
    scenes = sample(scenes, args.sample)
    print(f"{len(scenes)} scenes of {examples}, {args.jobs} at a time, scratch {args.scratch}",
          flush=True)
    start = time.monotonic()
    results = Corpus(args, examples).run(scenes)
    wall = time.monotonic() - start

    counts = {c: sum(r["class"] == c for r in results) for c in CLASSES}
    print(f"\n{len(results)} scenes in {wall:.0f} s:")
    for c in CLASSES:
        print(f"  {counts[c]:4d}  {c}" + ("  (FAILURE)" if c in FAILURES else ""))
    uniform = [r["scene"] for r in results if r["class"] == "read, same view" and r.get("uniform")]
    if uniform:
        print(f"  ({len(uniform)} of the same views are uniform images, which check nothing: "
              f"{' '.join(uniform)})")
    refusals = {}
    for r in results:
        if r["class"].startswith("refused"):
            kind = re.sub(r"^povray-ssao: error: [\w./-]+:\d+: ", "", r["message"])
            refusals.setdefault(kind, []).append(r["scene"])
    if refusals:
        print("\nrefusals:")
        for kind, names in sorted(refusals.items()):
            print(f"  {len(names):3d}  {kind}\n       {' '.join(names)}")
    failed = [r for r in results if r["class"] in FAILURES]
    if failed:
        print("\nFAILURES:")
        for r in failed:
            print(f"  {r['scene']}: {r['class']}: {r.get('detail', '')}")
            if r.get("camera"):
                print(f"      povray-ssao: {r['camera']}")
            if r.get("folder"):
                print(f"      kept in {r['folder']}")
    if args.report:
        with open(args.report, "w") as f:
            json.dump({"examples": examples, "wall_seconds": round(wall, 1),
                       "pixel_tolerance": PIXEL_TOLERANCE, "max_differing": MAX_DIFFERING,
                       "counts": counts, "scenes": results}, f, indent=1)
        print(f"\nreport: {args.report}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
