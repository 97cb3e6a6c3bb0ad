# SPDX-License-Identifier: MIT
"""Renders the open file's animation from Blender's UI as Ctrl+F12 does (render.render
INVOKE_DEFAULT, animation=True), waits for the render job and for the add-on's work after it,
then quits. Run under Xvfb by tests/blender/test_addon.py:

    xvfb-run -a blender --factory-startup -noaudio --addons ssao_compositor SCENE.blend \
        --python tests/blender/ui_render_animation.py -- [--timeout 300] [--fail-frame N]

--fail-frame N: the SSAO nodes start with an AO of 0.5 (one left by an earlier render), and the
library fails on frame N, whose file must then get no AO at all, not that one nor another
frame's. Prints "ui_render_animation [...] done" when everything finished, and exits non-zero on
a timeout or an exception. Before that it prints the add-on's export folder and the files left
in it ("exports left in FOLDER: [names]"): Blender quits without its atexit functions here.

Also probes, from a panel's draw() (where Blender refuses data-block writes), whether the add-on's
handlers.with_writes() can still write, and prints "read-only draw: direct write refused: ..."
and "read-only draw: with_writes wrote: ..." (see handlers.py for why the timers need it)."""
import json
import os
import sys
import time
import traceback

import bpy

TIMEOUT = float(sys.argv[sys.argv.index("--timeout") + 1]) if "--timeout" in sys.argv else 300.0
FAIL_FRAME = int(sys.argv[sys.argv.index("--fail-frame") + 1]) if "--fail-frame" in sys.argv \
    else None
START = time.monotonic()
STATE = {"started": False, "idle_since": None, "logged_frames": 0}
WRITTEN = []  # frames Blender wrote (render_write, the render thread: only record)


def log(message):
    print(f"ui_render_animation [{time.monotonic() - START:6.1f}s] {message}", flush=True)


def addon_module(name):
    module = next((m for n, m in sys.modules.items() if n.endswith("ssao_compositor." + name)),
                  None)
    if module is None:
        raise RuntimeError("the ssao_compositor add-on is not loaded")
    return module


def addon_busy():
    """The add-on's main-thread timer still has frames to finish."""
    state = addon_module("session").current
    return bool(state.written_frames or state.pending_frames)


def break_frame(frame):
    """An AO of 0.5 in every SSAO node, and a library that fails on `frame` (the AO is
    computed on the main thread, after the render job, with the scene set to the frame)."""
    compute, inner_tree, native = (addon_module(n) for n in ("compute", "inner_tree",
                                                             "ssao"))
    scene = bpy.context.scene
    width, height = scene.render.resolution_x, scene.render.resolution_y
    for node in compute.ssao_nodes(scene):
        image = inner_tree.ao_image(node, width, height)
        image.pixels.foreach_set([0.5] * (width * height * 4))
        image.update()  # as the add-on sets an AO (compute.py)
        image.update_tag()
    run = native.Job.run

    def failing_run(self, progress=None):
        if bpy.context.scene.frame_current == frame:
            raise native.SSAOError("ssao_job_run: simulated library failure")
        return run(self, progress)

    native.Job.run = failing_run


PROBE = {}


class SSAO_TEST_PT_read_only_probe(bpy.types.Panel):
    """Blender draws panels in a read-only context: writes to data-blocks raise there."""
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = 'render'
    bl_label = "SSAO read-only probe"

    def draw(self, context):
        if PROBE:
            return
        scene = bpy.data.scenes[0]
        try:
            scene.frame_preview_start = scene.frame_preview_start
            PROBE["direct"] = "write allowed"
        except Exception as error:
            PROBE["direct"] = f"write refused: {error}"
        try:
            addon_module("handlers").with_writes(
                lambda: setattr(scene, "frame_preview_start", scene.frame_preview_start))
            PROBE["with_writes"] = "wrote"
        except Exception as error:
            PROBE["with_writes"] = f"failed: {error}"


def show_render_properties():
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == 'PROPERTIES':
                area.spaces.active.context = 'RENDER'
                area.tag_redraw()


def quit_blender(code):
    log(f"read-only draw: direct {PROBE.get('direct', 'not drawn')}")
    log(f"read-only draw: with_writes {PROBE.get('with_writes', 'not drawn')}")
    try:
        folder = addon_module("compute").export_dir()
        names = sorted(os.path.relpath(os.path.join(where, name), folder)
                       for where, _, files in os.walk(folder) for name in files)
        log(f"exports left in {folder}: {json.dumps(names)}")
    except Exception as error:
        log(f"exports left: cannot list them: {error}")
    log("done" if code == 0 else "failed")
    sys.stdout.flush()
    # os._exit skips Blender's own shutdown, which can hang under Xvfb; files are written.
    os._exit(code)


def step():
    try:
        if time.monotonic() - START > TIMEOUT:
            log(f"timeout after {TIMEOUT:.0f} s")
            quit_blender(1)
        if not STATE["started"]:
            # The probe writes to the scene: drawn before the render starts, never beside the
            # render thread (a write then crashed Blender 3.4.1 once).
            if "shown" not in STATE:
                show_render_properties()
                STATE["shown"] = time.monotonic()
            if not PROBE and time.monotonic() - STATE["shown"] < 10:
                return 0.2
            if FAIL_FRAME is not None:
                break_frame(FAIL_FRAME)
            window = bpy.context.window_manager.windows[0]
            with bpy.context.temp_override(window=window):
                bpy.ops.render.render('INVOKE_DEFAULT', animation=True)
            STATE["started"] = True
            log("render job started (Ctrl+F12)")
            return 1.0
        if len(WRITTEN) != STATE["logged_frames"]:  # a hang's log then says where it stopped
            STATE["logged_frames"] = len(WRITTEN)
            log(f"{len(WRITTEN)} frame(s) written, the last {WRITTEN[-1]}")
        if bpy.app.is_job_running('RENDER') or addon_busy():
            STATE["idle_since"] = None
            return 0.5
        # Idle twice in a row, a second apart: the timer ran and registered nothing new.
        if STATE["idle_since"] is None:
            STATE["idle_since"] = time.monotonic()
            return 1.0
        quit_blender(0)
    except Exception:
        traceback.print_exc()
        quit_blender(1)
    return None


@bpy.app.handlers.persistent
def record_written(scene, *_):
    WRITTEN.append(scene.frame_current)


bpy.app.handlers.render_write.append(record_written)
bpy.utils.register_class(SSAO_TEST_PT_read_only_probe)
bpy.app.timers.register(step, first_interval=2.0)
