# SPDX-License-Identifier: MIT
"""Writes the camera JSON of docs/conventions.md, the file `build/bin/ssao --camera` reads, for
every frame of a Blender scene, so that an animated camera can be used on a rendered sequence:

    blender -b shot.blend -P scripts/blender/export_cameras.py -- \\
        --frames 1001-1100 -o 'cams/render.####.camera.json'
    build/bin/ssao 'render.####.exr' -o 'ao.####.exr' \\
        --camera 'cams/render.####.camera.json' --frames 1001-1100

Options (after `--`; `-- --help` prints them):

* ``-o PATTERN`` (required): the output file; its file name holds one frame placeholder as in
  the CLI (``####`` = 4 digits of padding, ``@`` = 1 digit, ``%04d``, ``%d``: unpadded; frames
  wider than the padding are written in full, negative ones as ``-0042``; folders are taken as
  written and created when missing). A name without a placeholder is allowed for one frame
  only. ``//`` at the start is the .blend file's folder, as in Blender.
* ``--frames SPEC``: ``A``, ``A-B``, ``A-BxN`` (every Nth) or a comma-separated list of those,
  the CLI's syntax; negative frames are allowed (``--frames -5--1``). Default: the scene's
  frame_start to frame_end by its frame_step (the frames ``blender -a`` renders).
* ``--camera NAME``: this camera object at every frame instead of the scene's active camera
  (which follows the camera markers of the timeline).
* ``--scene NAME``: this scene instead of the file's current one.
* ``--no-ao-distance``: do not write ``ao_distance``.
* ``-q``, ``--quiet``: only the summary line, not one line per frame.

Each frame is set with scene.frame_set() and the camera read from the evaluated depsgraph, so
parenting, constraints, drivers and animated camera settings are what the render sees; the
scene's active camera is read after frame_set(), so camera markers are honoured. Each file gets
type, lens, sensor_width, sensor_height, sensor_fit, shift_x, shift_y, ortho_scale, clip_start,
clip_end, matrix_world, pixel_aspect_x, pixel_aspect_y (Output > Format > Aspect) and, when the
scene has a world whose World > Ambient Occlusion > Distance is positive, ao_distance: the CLI
takes it as the radius when --radius is not given.

Every frame is evaluated first, then the files are written, each atomically (a temporary file
renamed): an error of the command line or the scene leaves no file, and no file is ever left
half-written. Errors print ``export_cameras: error: ...`` on stderr and exit
Blender with status 2 (command line: unknown option, bad --frames, a name without a placeholder
for several frames) or 1 (no active camera, --camera not a camera, a panoramic camera, a folder
or file that cannot be written), whether or not Blender was given --python-exit-code.

The module also holds the camera description and the JSON writer that make_reference_scene.py
and the other scripts here share; its frame and file name parsing imports without Blender.
"""

import argparse
import json
import os
import sys
import traceback

try:
    import bpy
except ImportError:  # plain Python: the frame and file name parsing below still works
    bpy = None

PROG = "export_cameras"
MAX_FRAMES = 1000000  # as the CLI (core/tools/frames.h: kMaxFrames)
BLENDER_FRAMES = (-1048574, 1048574)  # Blender's MINAFRAME, MAXFRAME: frame_set() clamps to it
SUPPORTED_TYPES = ("PERSP", "ORTHO")  # the library has no panoramic camera


# ---------------------------------------------------------------------------
# Shared with make_reference_scene.py and the scripts that use it

def script_argv():
    """The arguments after '--' (Blender's own arguments come before it)."""
    if "--" in sys.argv:
        return sys.argv[sys.argv.index("--") + 1:]
    return []


def run_script(main, name):
    """Runs main() as a Blender script: on any error, the traceback and 'NAME: FAILED' on stderr
    and exit status 1 (with --python-exit-code 1; Blender itself would carry on)."""
    try:
        main()
    except SystemExit:
        raise
    except BaseException:
        traceback.print_exc()
        print("%s: FAILED" % name, file=sys.stderr)
        sys.stdout.flush()
        sys.stderr.flush()
        sys.exit(1)


def matrix_rows(m):
    return [[float(m[r][c]) for c in range(len(m[r]))] for r in range(len(m))]


def camera_description(cam_obj, render=None, ao_distance=None):
    """The camera JSON of docs/conventions.md (fields named after bpy.types.Camera) of the camera
    object `cam_obj` as it is (pass the evaluated object for an animated camera); with `render`
    (scene.render) also pixel_aspect_x / pixel_aspect_y, with `ao_distance` also ao_distance."""
    cam = cam_obj.data
    description = {
        "type": cam.type,
        "lens": float(cam.lens),
        "sensor_width": float(cam.sensor_width),
        "sensor_height": float(cam.sensor_height),
        "sensor_fit": cam.sensor_fit,
        "shift_x": float(cam.shift_x),
        "shift_y": float(cam.shift_y),
        "ortho_scale": float(cam.ortho_scale),
        "clip_start": float(cam.clip_start),
        "clip_end": float(cam.clip_end),
        "matrix_world": matrix_rows(cam_obj.matrix_world),
    }
    if render is not None:
        description["pixel_aspect_x"] = float(render.pixel_aspect_x)
        description["pixel_aspect_y"] = float(render.pixel_aspect_y)
    if ao_distance is not None:
        description["ao_distance"] = float(ao_distance)
    return description


def write_json(path, data):
    """Writes `data` to `path` atomically: a temporary file in the same folder, renamed."""
    tmp = "%s.tmp%d" % (path, os.getpid())
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(data, f, indent=1)
            f.write("\n")
        os.replace(tmp, path)
    except BaseException:
        try:
            os.remove(tmp)
        except OSError:
            pass
        raise


# ---------------------------------------------------------------------------
# Frames and file name patterns, as the CLI reads them (core/tools/frames.cpp)

class UsageError(Exception):
    """A command-line error (exit status 2)."""


class ExportError(Exception):
    """An error of the scene or the output (exit status 1)."""


DIGITS = "0123456789"


def _read_int(text, pos):
    """(value, new position) of an optionally signed integer of at most 12 digits at text[pos],
    or (None, pos)."""
    start = pos
    if pos < len(text) and text[pos] in "+-":
        pos += 1
    digits = pos
    while pos < len(text) and text[pos] in DIGITS:
        pos += 1
    if pos == digits or pos - digits > 12:
        return None, start
    return int(text[start:pos]), pos


def parse_frames(spec):
    """The frames of a --frames specification, in the order given: comma-separated parts A,
    A-B or A-BxN (every Nth from A); negative numbers allowed ("-5--1"). Raises UsageError for a
    part it cannot read, a range that runs backwards, a step below 1, a frame given twice, a
    frame outside Blender's range or more than MAX_FRAMES frames."""
    frames, seen = [], set()
    for part in spec.split(","):
        where = "--frames '%s': '%s'" % (spec, part)
        first, pos = _read_int(part, 0)
        if first is None:
            raise UsageError(where + " is not a frame number or range (A, A-B or A-BxN)")
        last, step = first, 1
        if pos < len(part) and part[pos] == "-":
            last, pos = _read_int(part, pos + 1)
            if last is None:
                raise UsageError(where + ": the range has no valid end")
            if pos < len(part) and part[pos] == "x":
                step, pos = _read_int(part, pos + 1)
                if step is None or step <= 0:
                    raise UsageError(where + ": the step after 'x' must be a positive number")
        if pos != len(part):
            raise UsageError(where + " has extra characters")
        if last < first:
            raise UsageError(where + " runs backwards")
        for frame in (first, last):
            if not BLENDER_FRAMES[0] <= frame <= BLENDER_FRAMES[1]:
                raise UsageError("%s: frame %d is outside Blender's frames (%d to %d)"
                                 % (where, frame, BLENDER_FRAMES[0], BLENDER_FRAMES[1]))
        if (last - first) // step + 1 > MAX_FRAMES - len(frames):
            raise UsageError("--frames '%s': more than %d frames" % (spec, MAX_FRAMES))
        for frame in range(first, last + 1, step):
            if frame in seen:
                raise UsageError("--frames '%s': frame %d is given twice" % (spec, frame))
            seen.add(frame)
            frames.append(frame)
    return frames


class FramePattern:
    """A file name with at most one frame placeholder in its last component: a run of '#' or of
    '@' (one digit of padding each), or printf's %d / %0Nd / %Nd (N of one or two digits)."""

    def __init__(self, text):
        self.text = text
        self.width = None  # digits of padding; None: no placeholder
        start = end = None
        i = text.rfind("/") + 1  # folders keep their '#', '@' and '%' as they are
        while i < len(text):
            run_end, width = i, None
            if text[i] in "#@":
                while run_end < len(text) and text[run_end] == text[i]:
                    run_end += 1
                width = run_end - i
            elif text[i] == "%":
                j = i + 1
                zero = j < len(text) and text[j] == "0"
                if zero:
                    j += 1
                digits = j
                while j < len(text) and text[j] in DIGITS:
                    j += 1
                if j < len(text) and text[j] == "d" and (j > digits or not zero) \
                        and j - digits <= 2:
                    width = int(text[digits:j]) if j > digits else 0
                    run_end = j + 1
            if width is None:
                i += 1
                continue
            if start is not None:
                raise UsageError("the file name '%s' has more than one frame placeholder" % text)
            start, end, self.width = i, run_end, width
            i = run_end
        if start is not None:
            self.prefix, self.suffix = text[:start], text[end:]

    def has_frame(self):
        return self.width is not None

    def path(self, frame):
        """The file name of `frame`; the text itself when it has no placeholder."""
        if not self.has_frame():
            return self.text
        digits = str(abs(frame)).rjust(self.width, "0")
        return self.prefix + ("-" if frame < 0 else "") + digits + self.suffix


# ---------------------------------------------------------------------------
# Command line

def parse_args(argv):
    argv = list(argv)
    for i in range(len(argv) - 1):
        # argparse takes "-5--1" for an option, not for the value of --frames.
        if argv[i] == "--frames" and argv[i + 1][:2] in ("-%d" % d for d in range(10)):
            argv[i:i + 2] = ["--frames=" + argv[i + 1]]
            break
    parser = argparse.ArgumentParser(
        prog=PROG,
        usage="blender -b FILE.blend -P scripts/blender/export_cameras.py -- "
              "-o 'cams/render.####.camera.json' [--frames SPEC] [options]",
        description="Write the camera JSON that build/bin/ssao --camera reads (docs/"
                    "conventions.md) for every frame of the scene's active camera (camera "
                    "markers honoured), evaluated as the render sees it. Errors exit with 1 "
                    "(scene, output) or 2 (command line); all frames are evaluated before any "
                    "file is written, each file atomically.")
    parser.add_argument("-o", "--output", required=True, metavar="PATTERN",
                        help="output file; its name holds one frame placeholder as in the CLI "
                             "(#### = 4 digits, @ = 1 digit, %%04d; none for a single frame); "
                             "missing folders are created; // is the .blend file's folder")
    parser.add_argument("--frames", metavar="SPEC",
                        help="A, A-B, A-BxN (every Nth) or a comma-separated list of those, as in "
                             "the CLI (negative frames too: -5--1); default: the scene's "
                             "frame_start-frame_end by frame_step")
    parser.add_argument("--camera", metavar="NAME",
                        help="use this camera object at every frame instead of the scene's "
                             "active camera and its markers")
    parser.add_argument("--scene", metavar="NAME",
                        help="export from this scene (default: the file's current scene)")
    parser.add_argument("--no-ao-distance", action="store_true",
                        help="do not write ao_distance (World > Ambient Occlusion > Distance, "
                             "which the CLI uses as the radius when --radius is not given)")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="print only the summary, not a line per frame")
    args = parser.parse_args(argv)
    try:
        args.frame_list = parse_frames(args.frames) if args.frames is not None else None
        args.pattern = FramePattern(args.output)
    except UsageError as e:
        parser.error(str(e))
    if args.frame_list is not None and len(args.frame_list) > 1 and not args.pattern.has_frame():
        parser.error("-o '%s' has no frame placeholder (#### for 4 digits, @, or %%04d) for %d "
                     "frames" % (args.output, len(args.frame_list)))
    return args


# ---------------------------------------------------------------------------
# Export

def find_scene(name):
    if name is None:
        return bpy.context.scene
    scene = bpy.data.scenes.get(name)
    if scene is None:
        raise ExportError("no scene named '%s' (scenes: %s)"
                          % (name, ", ".join(s.name for s in bpy.data.scenes)))
    return scene


def find_camera_object(scene, name):
    """The object of --camera, or None (the scene's active camera, frame by frame)."""
    if name is None:
        return None
    obj = bpy.data.objects.get(name)
    if obj is None:
        raise ExportError("no object named '%s'" % name)
    if obj.type != "CAMERA":
        raise ExportError("--camera '%s' is not a camera but an object of type %s"
                          % (name, obj.type))
    if scene.objects.get(name) is None:
        raise ExportError("camera '%s' is not in scene '%s'" % (name, scene.name))
    return obj


def evaluated_view_layer(scene):
    """The view layer whose depsgraph is read: the context's, else the first one rendered."""
    if scene == bpy.context.scene and bpy.context.view_layer is not None:
        return bpy.context.view_layer
    for layer in scene.view_layers:
        if layer.use:
            return layer
    return scene.view_layers[0]


def frame_camera(scene, view_layer, forced, frame, with_ao_distance):
    """(camera object name, description) of `frame`: scene.frame_set(frame), then the active
    camera (or `forced`) and the world as evaluated."""
    scene.frame_set(frame)
    cam_obj = forced or scene.camera
    if cam_obj is None:
        raise ExportError("scene '%s' has no active camera at frame %d (set one in Scene "
                          "properties, or give --camera NAME)" % (scene.name, frame))
    if cam_obj.type != "CAMERA":
        raise ExportError("the active camera '%s' of scene '%s' is not a camera but an object "
                          "of type %s" % (cam_obj.name, scene.name, cam_obj.type))
    depsgraph = view_layer.depsgraph
    evaluated = cam_obj.evaluated_get(depsgraph)
    if not evaluated.is_evaluated:
        raise ExportError("camera '%s' is not evaluated in view layer '%s' of scene '%s' (is its "
                          "collection excluded?)" % (cam_obj.name, view_layer.name, scene.name))
    if evaluated.data.type not in SUPPORTED_TYPES:
        raise ExportError("camera '%s' at frame %d is %s: only %s cameras are supported"
                          % (cam_obj.name, frame, evaluated.data.type,
                             " and ".join(SUPPORTED_TYPES)))
    ao_distance = None
    if with_ao_distance and scene.world is not None:
        distance = scene.world.evaluated_get(depsgraph).light_settings.distance
        ao_distance = distance if distance > 0.0 else None
    render = depsgraph.scene_eval.render
    return cam_obj.name, camera_description(evaluated, render, ao_distance)


def export(args):
    scene = find_scene(args.scene)
    forced = find_camera_object(scene, args.camera)
    frames = args.frame_list
    if frames is None:
        frames = list(range(scene.frame_start, scene.frame_end + 1, max(1, scene.frame_step)))
        if len(frames) > 1 and not args.pattern.has_frame():
            raise UsageError("-o '%s' has no frame placeholder (#### for 4 digits, @, or %%04d) "
                             "for the scene's %d frames %d-%d"
                             % (args.output, len(frames), frames[0], frames[-1]))
    output = args.output
    if output.startswith("//"):
        if not bpy.data.filepath:
            raise UsageError("-o '%s': '//' is the .blend file's folder, and this file was never "
                             "saved" % output)
        output = bpy.path.abspath(output)
    pattern = FramePattern(output)
    view_layer = evaluated_view_layer(scene)

    # Every frame first: a frame that cannot be exported leaves no file.
    original_frame = scene.frame_current
    cameras = [(frame,) + frame_camera(scene, view_layer, forced, frame,
                                       not args.no_ao_distance) for frame in frames]
    scene.frame_set(original_frame)

    folder = os.path.dirname(pattern.text)
    if folder and not os.path.isdir(folder):
        try:
            os.makedirs(folder, exist_ok=True)
        except OSError as e:
            raise ExportError("cannot create the folder '%s': %s" % (folder, e.strerror or e))
    for frame, name, description in cameras:
        path = pattern.path(frame)
        try:
            write_json(path, description)
        except OSError as e:
            raise ExportError("cannot write '%s' (frame %d): %s" % (path, frame, e.strerror or e))
        if not args.quiet:
            detail = ("lens %g mm" % description["lens"] if description["type"] == "PERSP"
                      else "ortho_scale %g" % description["ortho_scale"])
            print("%s: frame %d: %s (%s, %s) -> %s"
                  % (PROG, frame, name, description["type"], detail, path))

    names = sorted({name for _, name, _ in cameras})
    written_distances = {d.get("ao_distance") for _, _, d in cameras}
    distances = sorted(d for d in written_distances if d is not None)
    if args.no_ao_distance:
        radius = "no ao_distance (--no-ao-distance)"
    elif not distances:
        radius = ("no ao_distance (%s; give the CLI --radius)"
                  % ("the scene has no world" if scene.world is None
                     else "World > Ambient Occlusion > Distance is 0"))
    else:
        radius = "ao_distance %s" % " to ".join("%g" % d for d in sorted({distances[0],
                                                                         distances[-1]}))
    print("%s: wrote %d camera file%s (%s) from scene '%s', camera%s %s, %s"
          % (PROG, len(cameras), "" if len(cameras) == 1 else "s", pattern.text, scene.name,
             "" if len(names) == 1 else "s", ", ".join(names), radius))
    if len(written_distances) > 1:
        print("%s: warning: ao_distance changes between frames; the CLI's radius would too "
              "(give it --radius)" % PROG, file=sys.stderr)
    if pattern.has_frame() and os.path.isfile(pattern.text):
        print("%s: warning: a file named '%s' exists: the CLI would use it for every frame "
              "instead of these files" % (PROG, pattern.text), file=sys.stderr)


def fail(message, status):
    print("%s: error: %s" % (PROG, message), file=sys.stderr)
    sys.stdout.flush()
    sys.stderr.flush()
    sys.exit(status)


def main(argv=None):
    args = parse_args(script_argv() if argv is None else argv)
    if bpy is None:
        fail("run this script in Blender: blender -b FILE.blend -P export_cameras.py -- ...", 2)
    try:
        export(args)
    except UsageError as e:
        fail(str(e), 2)
    except ExportError as e:
        fail(str(e), 1)


if __name__ == "__main__":
    run_script(main, PROG)
