# SPDX-License-Identifier: MIT
"""Renders the open file's animation from Blender's UI as Ctrl+F12 does (render.render
INVOKE_DEFAULT, animation=True), waits for the render job and for the add-on's work after it,
then quits. Run under Xvfb by tests/blender/test_addon.py:

    xvfb-run -a blender --factory-startup -noaudio --addons ssao_compositor SCENE.blend \
        --python tests/blender/ui_render_animation.py -- [--timeout 300]

Prints "ui_render_animation [...] done" when everything finished, and exits non-zero on a timeout or
an exception."""
import sys
import time
import traceback

import bpy

TIMEOUT = float(sys.argv[sys.argv.index("--timeout") + 1]) if "--timeout" in sys.argv else 300.0
START = time.monotonic()
STATE = {"started": False, "idle_since": None}


def log(message):
    print(f"ui_render_animation [{time.monotonic() - START:6.1f}s] {message}", flush=True)


def addon_busy():
    """The add-on's main-thread timer still has frames to finish."""
    handlers = next((m for n, m in sys.modules.items() if n.endswith("ssao_compositor.handlers")),
                    None)
    if handlers is None:
        raise RuntimeError("the ssao_compositor add-on is not loaded")
    return bool(handlers._written_frames or handlers._pending_frames)


def quit_blender(code):
    log("done" if code == 0 else "failed")
    sys.stdout.flush()
    # os._exit skips Blender's own shutdown, which can hang under Xvfb; files are written.
    import os
    os._exit(code)


def step():
    try:
        if time.monotonic() - START > TIMEOUT:
            log(f"timeout after {TIMEOUT:.0f} s")
            quit_blender(1)
        if not STATE["started"]:
            window = bpy.context.window_manager.windows[0]
            with bpy.context.temp_override(window=window):
                bpy.ops.render.render('INVOKE_DEFAULT', animation=True)
            STATE["started"] = True
            log("render job started (Ctrl+F12)")
            return 1.0
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


bpy.app.timers.register(step, first_interval=2.0)
