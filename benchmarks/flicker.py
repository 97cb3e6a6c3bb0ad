#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Flicker on camera moves: how much the AO of a static scene changes from frame to frame.

For each kit scene a short camera move is rendered (scripts/blender/benchmark_sequence.py; the
camera trucks sideways, a point at the layout's target moving STEP_PX pixels a frame) with
Cycles' AO pass at REFERENCE_SPP samples (the reference) and at CYCLES_SPP. True AO does not
depend on the view, so frame t's AO carried to frame t + 1's pixels should equal frame t + 1's:

    flicker = RMS over the pixels of frame t + 1 of (AO_t+1 - AO_t carried)

where carried means: unproject the pixel with frame t + 1's depth and camera, project it with
frame t's camera, and read AO_t there bilinearly; a pixel counts when its four taps are geometry
whose depth agrees with the point's within 0.5 % (so what the move uncovered does not). The
same RMS over the occluded pixels alone (reference AO < 0.9) is where a crawling pattern shows.
A converged render's flicker is its own noise plus the resampling.

    benchmarks/flicker.py [--kit DIR] [--threads N] [--set NAME=VALUE ...] [--layers]
                          [--update-docs]

prints per scene the RMSE against the reference (mean over the frames) and both flicker
figures, for libssao (the default, and each --set variant given; with --layers also with the
2nd to 5th hits and a guard band, as the Blender node's defaults) and for Cycles; then, for a
box sliding over `contact`'s floor (the camera still), the error where the AO changed, with
and without the temporal filter: a trail behind a moving object would show there. The renders
are cached in the kit folder (about 25 min the first time on 2 cores); --update-docs puts the
table in docs/performance.md, among the sections scripts/benchmark.sh keeps.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import speed_error as kit  # noqa: E402  (the kit's cached renders and helpers)

SIZE = (320, 180)
FRAMES = 6
STEP_PX = 1.5
REFERENCE_SPP = 1024
CYCLES_SPP = (16, 64)
SCENES = ("contact", "thin", "cavity", "depth_range", "ortho", "heavy")
OCCLUDED_BELOW = 0.9
DEPTH_AGREEMENT = 0.005
# --layers: the guard band of the layered rows (speed_error.py's 64 px at 640x360, scaled).
LAYERS_BAND = 32
NO_HIT = 1e10  # Blender's depth where a ray hits nothing


def read_channels(path, suffixes):
    import OpenImageIO as oiio
    image = oiio.ImageInput.open(path)
    if image is None:
        raise kit.StepFailed("cannot open %s: %s" % (path, oiio.geterror()))
    names = image.spec().channelnames
    out = []
    for suffix in suffixes:
        matches = [i for i, n in enumerate(names) if n == suffix or n.endswith("." + suffix)]
        if not matches:
            raise kit.StepFailed("%s has no channel %s" % (path, suffix))
        out.append(np.array(image.read_image(0, 0, matches[0], matches[0] + 1, "float"))[:, :, 0])
    image.close()
    return out


class View:
    """A frame's camera (the kit's camera JSON: Blender's lens, sensor with fit AUTO, no shift)
    between pixel coordinates with planar depth and world space."""

    def __init__(self, camera_path, width, height):
        with open(camera_path, encoding="utf-8") as f:
            cam = json.load(f)
        self.width, self.height = width, height
        self.ortho = cam["type"] == "ORTHO"
        fit = max(width, height)  # AUTO: the sensor spans the larger side
        # View-space extent per pixel: at unit depth (perspective) or absolute (orthographic).
        self.per_pixel = (cam["ortho_scale"] if self.ortho else cam["sensor_width"] / cam["lens"]) / fit
        self.to_world = np.array(cam["matrix_world"], dtype=np.float64)
        self.to_view = np.linalg.inv(self.to_world)

    def world_points(self, depth):
        """World positions of every pixel centre at its planar depth (H x W x 3)."""
        ys, xs = np.mgrid[0:self.height, 0:self.width].astype(np.float64)
        scale = self.per_pixel * (1.0 if self.ortho else depth)
        view = np.stack([(xs + 0.5 - self.width / 2) * scale,
                         (self.height / 2 - ys - 0.5) * scale, -depth, np.ones_like(depth)], -1)
        return (view @ self.to_world.T)[..., :3]

    def project(self, world):
        """Continuous pixel coordinates (u, v) and planar depth of world points."""
        view = np.concatenate([world, np.ones(world.shape[:-1] + (1,))], -1) @ self.to_view.T
        depth = -view[..., 2]
        scale = self.per_pixel * (1.0 if self.ortho else np.where(depth > 0, depth, np.nan))
        return view[..., 0] / scale + self.width / 2, self.height / 2 - view[..., 1] / scale, depth


def geometry(depth):
    return np.isfinite(depth) & (depth > 0) & (depth < 1e9)


def carried(ao_t, depth_t, view_t, depth_u, view_u):
    """Frame t's AO at frame u's pixels, and the mask of pixels where it is known."""
    u, v, z = view_t.project(view_u.world_points(np.where(geometry(depth_u), depth_u, 1.0)))
    x0, y0 = np.floor(u - 0.5), np.floor(v - 0.5)
    fx, fy = u - 0.5 - x0, v - 0.5 - y0
    h, w = depth_t.shape
    valid = geometry(depth_u) & np.isfinite(z) & (x0 >= 0) & (y0 >= 0) & (x0 + 1 < w) & (y0 + 1 < h)
    xi = np.where(valid, x0, 0).astype(int)
    yi = np.where(valid, y0, 0).astype(int)
    value = np.zeros_like(ao_t, dtype=np.float64)
    for dy, dx, weight in ((0, 0, (1 - fx) * (1 - fy)), (0, 1, fx * (1 - fy)),
                           (1, 0, (1 - fx) * fy), (1, 1, fx * fy)):
        tap_depth = depth_t[yi + dy, xi + dx]
        valid &= geometry(tap_depth) & (np.abs(tap_depth - z) <= DEPTH_AGREEMENT * z)
        value += np.where(valid, weight, 0.0) * ao_t[yi + dy, xi + dx]
    return value, valid


def flicker(frames, aos, reference_aos):
    """(RMS over all carried pixels, RMS over the occluded ones) of a sequence's AO images."""
    all_sq, all_n, occ_sq, occ_n = 0.0, 0, 0.0, 0
    for t in range(len(frames) - 1):
        (depth_t, view_t), (depth_u, view_u) = frames[t], frames[t + 1]
        value, valid = carried(aos[t], depth_t, view_t, depth_u, view_u)
        diff = np.where(valid, aos[t + 1] - value, 0.0)
        occluded = valid & (reference_aos[t + 1] < OCCLUDED_BELOW)
        all_sq += float(np.sum(diff[valid] ** 2))
        all_n += int(valid.sum())
        occ_sq += float(np.sum(diff[occluded] ** 2))
        occ_n += int(occluded.sum())
    return (np.sqrt(all_sq / all_n) if all_n else float("nan"),
            np.sqrt(occ_sq / occ_n) if occ_n else float("nan"))


def rmse(ao, reference, depth):
    g = geometry(depth)
    return float(np.sqrt(np.mean((ao[g] - reference[g]) ** 2)))


def sequence(args, blender_version, scene, samples):
    """Prefixes of the frames of a scene's camera move at `samples` spp (cached renders)."""
    return [kit.kit_render(args, blender_version, scene, SIZE, samples, truck_px=k * STEP_PX)
            for k in range(FRAMES)]


def library_sequence(args, prefixes, settings):
    """libssao's AO of every frame of a move: the command-line tool on the whole sequence, as a
    user runs it (one job from frame to frame, so the temporal filter sees the frames before
    each one). `settings`: NAME=VALUE core parameters, given as the tool's --NAME VALUE."""
    with open(prefixes[0] + ".json", encoding="utf-8") as f:
        radius = json.load(f)["ao_distance"]
    with tempfile.TemporaryDirectory() as tmp:
        for k, prefix in enumerate(prefixes):
            os.symlink(prefix + ".exr", os.path.join(tmp, "in.%04d.exr" % k))
            os.symlink(prefix + ".camera.json", os.path.join(tmp, "cam.%04d.json" % k))
        command = [args.cli, os.path.join(tmp, "in.####.exr"), "-o",
                   os.path.join(tmp, "out.####.exr"), "--camera",
                   os.path.join(tmp, "cam.####.json"), "--frames", "0-%d" % (len(prefixes) - 1),
                   "--radius", repr(radius), "--ao-only", "--threads", str(args.threads), "--quiet"]
        for setting in settings:
            name, _, value = setting.partition("=")
            command += ["--" + name.replace("_", "-"), value]
        proc = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              check=False)
        if proc.returncode != 0:
            raise kit.StepFailed("ssao failed (exit %d): %s\n%s"
                                 % (proc.returncode, " ".join(command), proc.stderr))
        return [read_channels(os.path.join(tmp, "out.%04d.exr" % k), ["AO"])[0]
                for k in range(len(prefixes))]


def hit_count(path):
    """How many surface hits a layers file holds (its Depth, Depth2.Z, Depth3.Z, ...)."""
    import OpenImageIO as oiio
    image = oiio.ImageInput.open(path)
    if image is None:
        raise kit.StepFailed("cannot open %s: %s" % (path, oiio.geterror()))
    names = list(image.spec().channelnames)
    image.close()
    count = 1
    while any(n == "Depth%d.Z" % (count + 1) or n.endswith(".Depth%d.Z" % (count + 1))
              for n in names):
        count += 1
    return count


def merged_with_band(band_plane, frame_plane, band):
    """The layers file's plane (its band around the frame) with the frame's pixels taken from
    the reference render, as the Blender add-on gives them to the library."""
    out = band_plane.copy()
    height, width = frame_plane.shape[:2]
    out[band:band + height, band:band + width] = frame_plane
    return out


def hits_behind(depth, hit_planes, facing_planes):
    """The extra hits (H x W x N) behind `depth`, nearest first, and their facing: a hit not
    behind the depth the library is given is dropped and the later ones move up, as the Blender
    add-on and ssao_eval --layers do; the places left empty are "no hit" (NO_HIT, facing 0)."""
    hits, facing = np.stack(hit_planes, axis=-1), np.stack(facing_planes, axis=-1)
    behind = hits > depth[:, :, None]
    order = np.argsort(np.where(behind, hits, np.inf), axis=-1, kind="stable")
    return (np.take_along_axis(np.where(behind, hits, NO_HIT), order, axis=-1),
            np.take_along_axis(np.where(behind, facing, 0.0), order, axis=-1))


def layered_sequence(args, blender_version, scene, prefixes):
    """libssao's AO of every frame of a move with the hidden surface hits and a LAYERS_BAND px
    guard band (what the Blender node's helper render adds by default: benchmark_layers.py on
    each frame's camera), one ssao.Sequence from frame to frame as the node's animation renders.
    Hits not behind the depth the library is given are dropped and the later ones move up, as
    ssao_eval --layers does."""
    os.environ.setdefault("SSAO_LIBRARY", args.library)
    sys.path.insert(0, os.path.join(kit.REPO_ROOT, "core", "python"))
    import ssao
    with open(prefixes[0] + ".json", encoding="utf-8") as f:
        radius = json.load(f)["ao_distance"]
    shot = ssao.Sequence()
    aos = []
    for k, prefix in enumerate(prefixes):
        layers = kit.kit_layers(args, blender_version, scene, SIZE, band=LAYERS_BAND,
                                truck_px=k * STEP_PX)
        depth, nx, ny, nz = read_channels(prefix + ".exr",
                                          ["Depth.Z", "Normal.X", "Normal.Y", "Normal.Z"])
        extra = hit_count(layers) - 1
        band_planes = read_channels(layers, ["Depth.Z", "Normal.X", "Normal.Y", "Normal.Z"] + [
            "%s%d.%s" % (name, k, axis) for k in range(2, extra + 2)
            for name, axis in (("Depth", "Z"), ("Facing", "V"))])
        big_depth = merged_with_band(band_planes[0], depth, LAYERS_BAND)
        normals = np.stack([merged_with_band(b, f, LAYERS_BAND)
                            for b, f in zip(band_planes[1:4], (nx, ny, nz))], axis=-1)
        hits, facing = hits_behind(big_depth, band_planes[4::2], band_planes[5::2])
        with open(prefix + ".camera.json", encoding="utf-8") as f:
            camera = json.load(f)
        ao = shot.ambient_occlusion(
            np.ascontiguousarray(big_depth, dtype=np.float32), frame=k,
            normals=np.ascontiguousarray(normals, dtype=np.float32), camera=camera,
            depth_layers=[np.ascontiguousarray(hits[:, :, j], dtype=np.float32)
                          for j in range(extra)],
            facing_layers=[np.ascontiguousarray(facing[:, :, j], dtype=np.float32)
                           for j in range(extra)],
            output_window=(LAYERS_BAND, LAYERS_BAND, SIZE[0], SIZE[1]), radius=radius,
            threads=args.threads)
        aos.append(np.where(geometry(depth), ao, 1.0))
    return aos


def measure(args, blender_version, variants):
    """Rows {scene, method, rmse, flicker, flicker_occluded} per scene: libssao's variants
    (label, settings) and Cycles at CYCLES_SPP and REFERENCE_SPP."""
    rows = []
    for scene in args.scenes:
        reference = sequence(args, blender_version, scene, REFERENCE_SPP)
        frames, reference_aos = [], []
        for prefix in reference:
            depth, ao = read_channels(prefix + ".exr", ["Depth.Z", "AO.R"])
            frames.append((depth, View(prefix + ".camera.json", SIZE[0], SIZE[1])))
            reference_aos.append(np.where(geometry(depth), ao, 1.0))
        methods = [("libssao " + name, library_sequence(args, reference, settings))
                   for name, settings in variants]
        if args.layers:
            methods.append(("libssao layers + %d px band" % LAYERS_BAND,
                            layered_sequence(args, blender_version, scene, reference)))
        for samples in CYCLES_SPP:
            aos = []
            for prefix in sequence(args, blender_version, scene, samples):
                depth, ao = read_channels(prefix + ".exr", ["Depth.Z", "AO.R"])
                aos.append(np.where(geometry(depth), ao, 1.0))
            methods.append(("Cycles %d spp" % samples, aos))
        methods.append(("Cycles %d spp (reference)" % REFERENCE_SPP, reference_aos))
        for method, aos in methods:
            everywhere, occluded = flicker(frames, aos, reference_aos)
            error = np.mean([rmse(a, r, f[0]) for a, r, f in zip(aos, reference_aos, frames)])
            rows.append({"scene": scene, "method": method, "rmse": float(error),
                         "flicker": float(everywhere), "flicker_occluded": float(occluded)})
            kit.log("flicker: %s %s: RMSE %.4f, flicker %.4f, occluded %.4f"
                    % (scene, method, error, everywhere, occluded))
    return rows


# A moving object, the camera still: which scene, which of its objects, how far a frame (x).
MOVING = ("contact", "RotatedBox", 0.1)
CHANGED_BY = 0.05


def moving_object(args, blender_version):
    """What the temporal filter does behind a moving object: over the pixels whose reference AO
    changed by more than CHANGED_BY from the frame before (the object and its contact shadow
    moved), the RMSE against the reference of the default and of each frame alone, and the
    largest difference between the two anywhere."""
    scene, name, step = MOVING
    prefixes = [kit.kit_render(args, blender_version, scene, SIZE, REFERENCE_SPP,
                               move="%s,%g,0,0" % (name, k * step)) for k in range(FRAMES)]
    references, depths = [], []
    for prefix in prefixes:
        depth, ao = read_channels(prefix + ".exr", ["Depth.Z", "AO.R"])
        depths.append(depth)
        references.append(np.where(geometry(depth), ao, 1.0))
    filtered = library_sequence(args, prefixes, [])
    alone = library_sequence(args, prefixes, ["temporal_frames=1"])
    sq = {"default": 0.0, "alone": 0.0}
    changed, largest = 0, 0.0
    for t in range(1, FRAMES):
        mask = geometry(depths[t]) & (np.abs(references[t] - references[t - 1]) > CHANGED_BY)
        changed += int(mask.sum())
        sq["default"] += float(np.sum((filtered[t] - references[t])[mask] ** 2))
        sq["alone"] += float(np.sum((alone[t] - references[t])[mask] ** 2))
        g = geometry(depths[t])
        largest = max(largest, float(np.abs(filtered[t] - alone[t])[g].max()))
    result = {"scene": scene, "object": name, "step": step, "pixels": changed,
              "rmse_default": np.sqrt(sq["default"] / max(changed, 1)),
              "rmse_alone": np.sqrt(sq["alone"] / max(changed, 1)), "largest": largest}
    kit.log("flicker: moving %s in %s: %d changed pixels, RMSE there %.4f (default) against "
            "%.4f (each frame alone), largest difference %.4f"
            % (name, scene, changed, result["rmse_default"], result["rmse_alone"], largest))
    return result


def moving_text(m):
    return ("A moving object, the camera still: `%s`'s %s slides %.2f scene units a frame along "
            "x for %d frames (`scripts/blender/benchmark_moving.py`), the same 1024-spp "
            "reference. Over the %d pixels whose reference AO changed by more than %.2f from the "
            "frame before (the box and its contact shadow moved), the default's RMSE is %.4f, "
            "each frame alone %.4f; the largest difference between the two anywhere is %.4f. "
            "Where the depths show that the scene itself moved (a surface where an earlier "
            "frame saw empty space, or one gone from where an earlier frame saw it), no earlier "
            "frame is carried within the AO's radius on screen, so the shadow of what moved "
            "leaves no trail ([variants.md](variants.md), temporal filter)."
            % (m["scene"], m["object"], m["step"], FRAMES, m["pixels"], CHANGED_BY,
               m["rmse_default"], m["rmse_alone"], m["largest"]))


def markdown(rows):
    """The table of rows, one line per scene and method."""
    lines = ["| scene | method | RMSE | flicker | flicker, occluded |",
             "|---|---|--:|--:|--:|"]
    for r in rows:
        rmse_cell = "(0)" if "reference" in r["method"] else "%.4f" % r["rmse"]
        lines.append("| %s | %s | %s | %.4f | %.4f |" % (r["scene"], r["method"], rmse_cell,
                                                          r["flicker"], r["flicker_occluded"]))
    return "\n".join(lines)


SECTION = "## Flicker on camera moves"


LAYERS_TEXT = (
    "`libssao layers + %d px band`: with what the Blender node's helper render adds by default, "
    "the 2nd to 5th surface hits with their facing and a guard band, rendered for each "
    "frame's camera at 1 spp (`scripts/blender/benchmark_layers.py --truck-px`), hits not "
    "behind the frame's depth dropped as `ssao_eval --layers` does, one `ssao.Sequence` over "
    "the frames as the node's animation renders." % LAYERS_BAND)


def section(rows, moving, command, machine):
    """This benchmark's section of docs/performance.md."""
    layered = any("layers" in r["method"] for r in rows)
    return "\n".join([
        SECTION,
        "",
        "Generated by `%s` on %s. Per kit scene a camera move of %d frames at %dx%d, the "
        "camera trucking sideways %.1f px a frame at the layout's target "
        "(`scripts/blender/benchmark_sequence.py`, cached in the kit). Flicker: frame t's AO "
        "carried to frame t + 1's pixels through depth and both cameras (bilinear; pixels "
        "whose four taps agree in depth within %.1f %%), RMS of the difference over every such "
        "pixel and over the occluded ones (reference AO < %.1f). True AO does not depend on "
        "the view; a converged render's flicker is its own noise plus the resampling. RMSE: "
        "against Cycles' AO pass at %d spp, mean over the frames; Cycles keeps one seed for "
        "every frame, as an animation without an animated seed does."
        % (command, machine, FRAMES, SIZE[0], SIZE[1], STEP_PX, 100 * DEPTH_AGREEMENT,
           OCCLUDED_BELOW, REFERENCE_SPP),
        "",
        markdown(rows),
        "",
    ] + ([LAYERS_TEXT, ""] if layered else []) + [
        moving_text(moving),
        "",
    ])


def update_docs(text):
    """Replaces (or adds, among the sections other benchmarks keep) this section of
    docs/performance.md."""
    path = os.path.join(kit.REPO_ROOT, "docs", "performance.md")
    with open(path, encoding="utf-8") as f:
        old = f.read()
    if SECTION in old:
        start = old.index(SECTION)
        end = old.find("\n## ", start + len(SECTION))
        new = old[:start] + text + (old[end + 1:] if end >= 0 else "")
    else:
        if kit.KEPT_MARKER not in old:
            old = old.rstrip("\n") + "\n\n" + kit.KEPT_MARKER + "\n"
        new = old.rstrip("\n") + "\n\n" + text
    with open(path + ".tmp", "w", encoding="utf-8") as f:
        f.write(new.rstrip("\n") + "\n")
    os.replace(path + ".tmp", path)


def parse_args(argv=None):
    parser = argparse.ArgumentParser(prog="flicker.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--kit", default=os.path.join(kit.REPO_ROOT, "build", "benchmark_kit"))
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--cli", default=os.path.join(kit.REPO_ROOT, "build", "bin", "ssao"),
                        help="the command-line tool that computes libssao's rows")
    parser.add_argument("--scenes", default=",".join(SCENES),
                        help="comma-separated kit scenes (default: all six)")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE[,NAME=VALUE]",
                        help="also measure libssao with these settings (repeatable)")
    parser.add_argument("--layers", action="store_true",
                        help="also measure libssao with the 2nd to 5th hits and a %d px guard "
                             "band, as the Blender node's defaults (renders them into the kit, "
                             "1 spp a frame)" % LAYERS_BAND)
    parser.add_argument("--library",
                        default=os.path.join(kit.REPO_ROOT, "build", "lib", "libssao.so"),
                        help="the library of the --layers rows (the Python module's)")
    parser.add_argument("--update-docs", action="store_true",
                        help="write the table into docs/performance.md (section \"%s\")"
                             % SECTION[3:])
    args = parser.parse_args(argv)
    args.scenes = [s for s in args.scenes.split(",") if s]
    unknown = [s for s in args.scenes if s not in SCENES]
    if unknown:
        parser.error("unknown scene(s): %s (choose from %s)" % (", ".join(unknown),
                                                                ", ".join(SCENES)))
    if args.threads < 1:
        parser.error("--threads must be positive")
    if not os.path.isfile(args.cli):
        parser.error("no %s: build the project first" % args.cli)
    args.kit = os.path.abspath(args.kit)
    return args


def blender_version_of(blender):
    out = subprocess.run([blender, "--version"], stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL, text=True, check=False).stdout
    first = out.split("\n")[0].strip()
    if not first.startswith("Blender"):
        kit.fail("'%s --version' does not say which Blender it is" % blender)
    return first


def main():
    args = parse_args()
    variants = [("default", []), ("each frame alone", ["temporal_frames=1"])] + [
        (s, s.split(",")) for s in args.set]
    blender_version = blender_version_of(args.blender)
    try:
        rows = measure(args, blender_version, variants)
        moving = moving_object(args, blender_version)
    except kit.StepFailed as error:
        kit.fail(str(error))
    print(markdown(rows))
    print()
    print(moving_text(moving))
    if args.update_docs:
        command = "benchmarks/flicker.py" + "".join(" --set " + s for s in args.set) + (
            " --layers" if args.layers else "") + (
            " --scenes " + ",".join(args.scenes) if list(args.scenes) != list(SCENES) else "")
        machine = kit.machine_description(args, blender_version)
        update_docs(section(rows, moving, command + " --update-docs", machine))
    return 0


if __name__ == "__main__":
    sys.exit(main())
