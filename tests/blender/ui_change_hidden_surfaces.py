# SPDX-License-Identifier: MIT
"""In Blender's UI: F12, then changes the SSAO node's hidden_surfaces and overscan as a user
would (the node's update callback recomputes; the helper render of hidden_surfaces.py runs
there, on the main thread), and writes what happened to a JSON report, then quits. Run under
Xvfb by tests/blender/test_addon.py:

    xvfb-run -a blender --factory-startup -noaudio --addons ssao_compositor SCENE.blend \
        --python tests/blender/ui_change_hidden_surfaces.py -- REPORT.json

The report: for each step (after F12, then each change) the node's status, its AO image's
mean, and how many helper renders ran so far."""
import json
import sys
import time
import traceback

import bpy

REPORT = sys.argv[sys.argv.index("--") + 1]
START = time.monotonic()
TIMEOUT = 180.0
STEPS = [("after F12", None), ("NONE, 0", ('NONE', 0)), ("PEELED, 32", ('PEELED', 32))]
STATE = {"step": -1, "idle_since": None, "report": [], "helper_renders": 0}


def addon_module(name):
    return next(m for n, m in sys.modules.items() if n.endswith("ssao_compositor." + name))


def node():
    return addon_module("compute").ssao_nodes(bpy.context.scene)[0]


def ao_mean(n):
    image = addon_module("inner_tree").ao_image_if_any(n)
    pixels = list(image.pixels)[0::4] if image is not None else []
    return sum(pixels) / len(pixels) if pixels else None


def count_helper_renders(scene, *_):
    if scene.name.startswith(addon_module("hidden_surfaces").HELPER_PREFIX):
        STATE["helper_renders"] += 1


def finish(code):
    with open(REPORT, "w") as f:
        json.dump(STATE["report"], f, indent=1)
    print(f"ui_change_hidden_surfaces: {'done' if code == 0 else 'failed'}", flush=True)
    import os
    os._exit(code)  # Blender's own shutdown can hang under Xvfb


def busy():
    handlers = addon_module("handlers")
    return bpy.app.is_job_running('RENDER') or bool(handlers._pending_frames or
                                                    handlers._written_frames)


def step():
    try:
        if time.monotonic() - START > TIMEOUT:
            finish(1)
        if STATE["step"] < 0:
            window = bpy.context.window_manager.windows[0]
            with bpy.context.temp_override(window=window):
                bpy.ops.render.render('INVOKE_DEFAULT')
            STATE["step"] = 0
            return 1.0
        if busy() or not node().status:
            return 0.5
        if STATE["idle_since"] is None:  # idle twice, a second apart
            STATE["idle_since"] = time.monotonic()
            return 1.0
        n = node()
        STATE["report"].append({"step": STEPS[STATE["step"]][0], "status": n.status,
                                "ao_mean": ao_mean(n),
                                "helper_renders": STATE["helper_renders"]})
        STATE["step"] += 1
        STATE["idle_since"] = None
        if STATE["step"] == len(STEPS):
            finish(0)
        hidden, overscan = STEPS[STATE["step"]][1]
        n.status = ""
        n.hidden_surfaces = hidden  # each assignment runs the node's update callback
        n.overscan = overscan
        return 0.5
    except Exception:
        traceback.print_exc()
        finish(1)
    return None


bpy.app.handlers.render_pre.append(count_helper_renders)
bpy.app.timers.register(step, first_interval=2.0)
