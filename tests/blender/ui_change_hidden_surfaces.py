# SPDX-License-Identifier: MIT
"""In Blender's UI: F12, then changes the SSAO node's hidden_surfaces and overscan as a user
would (the node's update callback recomputes; the helper render it needs runs in a Blender
process of its own, helper_process.py, or, with --in-process, in this one), and writes what
happened to a JSON report, then quits. Run under Xvfb by tests/blender/test_addon.py:

    xvfb-run -a blender --factory-startup -noaudio --addons ssao_compositor SCENE.blend \
        --python tests/blender/ui_change_hidden_surfaces.py -- REPORT.json [--in-process]

With helper processes, F12 is pressed a second time while the first F12's helper process
renders: a new render cancels it (its exit status is reported).

The report: for each step (after F12, then each change) the node's status, its AO image's
mean, and how many helper renders ran so far (in this process and in helper processes)."""
import json
import sys
import time
import traceback

import bpy

ARGS = sys.argv[sys.argv.index("--") + 1:]
REPORT = ARGS[0]
START = time.monotonic()
TIMEOUT = 180.0
STEPS = [("after F12", None), ("NONE, 0", ('NONE', 0)), ("PEELED, 32", ('PEELED', 32))]
STATE = {"step": -1, "idle_since": None, "report": [], "helper_renders": 0, "stale": None}


def addon_module(name):
    return next(m for n, m in sys.modules.items() if n.endswith("ssao_compositor." + name))


def node():
    return addon_module("compute").ssao_nodes(bpy.context.scene)[0]


def ao_summary(n):
    """The AO image's mean and every 37th pixel's AO (enough to tell two results apart where
    their means agree), from one read of its pixels."""
    image = addon_module("inner_tree").ao_image_if_any(n)
    pixels = list(image.pixels)[0::4] if image is not None else []
    return (sum(pixels) / len(pixels) if pixels else None), pixels[::37]


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
    return bpy.app.is_job_running('RENDER') or addon_module("session").current.busy()


def set_helper_process(on):
    """The add-on's preference "Helper render in its own process" (--addons enables the add-on
    without an entry in the preferences, so it is set where the preference puts it)."""
    addon_module("session").current.use_helper_process = on


def f12():
    window = bpy.context.window_manager.windows[0]
    with bpy.context.temp_override(window=window):
        bpy.ops.render.render('INVOKE_DEFAULT')


def step():
    try:
        if time.monotonic() - START > TIMEOUT:
            finish(1)
        if STATE["step"] < 0:
            f12()
            STATE["step"] = 0
            return 1.0
        state = addon_module("session").current
        if STATE["step"] == 0 and state.use_helper_process and STATE["stale"] is None:
            # F12 again while the first F12's helper process renders: it must be cancelled.
            running = addon_module("helper_process").running()
            if not running:
                return 0.05
            STATE["stale"] = running[0].process
            f12()
            return 1.0
        if busy() or not node().status:
            return 0.5
        if STATE["idle_since"] is None:  # idle twice, a second apart
            STATE["idle_since"] = time.monotonic()
            return 1.0
        n = node()
        mean, sample = ao_summary(n)
        STATE["report"].append({"step": STEPS[STATE["step"]][0], "status": n.status,
                                "ao_mean": mean, "ao_sample": sample,
                                "helper_renders": STATE["helper_renders"] +
                                state.helpers_started})
        if STATE["stale"] is not None:
            STATE["report"][-1]["stale_helper_exit"] = STATE["stale"].poll()
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


set_helper_process("--in-process" not in ARGS)
bpy.app.handlers.render_pre.append(count_helper_renders)
bpy.app.timers.register(step, first_interval=2.0)
