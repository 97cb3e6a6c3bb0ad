# SPDX-License-Identifier: MIT
"""How long Blender's UI stops responding during an F12 with the Ambient Occlusion (SSAO) node
(issue 33). In the UI (under Xvfb): a timer probe asks to run every 20 ms; F12 renders the open
scene; when the render, the AO, the helper render (helper_process.py) and the re-composite are
done, the longest gaps between two probe runs (the main thread's stalls) are written to a JSON
report and printed, then Blender quits.

    xvfb-run -a -s "-screen 0 1280x720x24" blender --factory-startup -noaudio \\
        --addons ssao_compositor SCENE.blend --python tests/blender/ui_stall_probe.py -- \\
        OUT.json [--keep-viewport] [--in-process]

SCENE.blend: a scene whose compositor has the SSAO node (tests/blender/build_ssao_scene.py;
tests/blender/measure_hidden_surfaces.py's heavy_mesh for the 2M-triangle case).

The 3D viewports are turned into Outliners first (--keep-viewport keeps them): under Xvfb, Mesa
draws in software, and one redraw of 2 M triangles stops the main thread for 1-1.7 s with or
without the node (measured in 3.4.1 with the node muted: longest stall 1.76 s with the
viewport, 0.16 s without), where a GPU draws them in milliseconds. --in-process renders the
helper in Blender's own process (the add-on's preference off), as the add-on did before."""
import json
import os
import sys
import time
import traceback

import bpy

ARGS = sys.argv[sys.argv.index("--") + 1:]
REPORT = ARGS[0]
PERIOD = 0.02
TIMEOUT = 600.0
STATE = {"ticks": [], "f12": None, "idle_since": None, "start": time.monotonic()}


def addon_module(name):
    return next(m for n, m in sys.modules.items() if n.endswith("ssao_compositor." + name))


def probe():
    STATE["ticks"].append(time.monotonic())
    return PERIOD


def busy():
    return bpy.app.is_job_running('RENDER') or addon_module("session").current.busy()


def set_helper_process(on):
    """The add-on's preference "Helper render in its own process" (--addons enables the add-on
    without an entry in the preferences, so it is set where the preference puts it)."""
    addon_module("session").current.use_helper_process = on


def finish(code):
    ticks = [t for t in STATE["ticks"] if STATE["f12"] is not None and t >= STATE["f12"]]
    gaps = sorted((b - a for a, b in zip(ticks, ticks[1:])), reverse=True)
    nodes = addon_module("compute").ssao_nodes(bpy.context.scene)
    report = {"blender": bpy.app.version_string, "longest_stall_s": gaps[0] if gaps else None,
              "next_stalls_s": gaps[1:5], "f12_to_idle_s": (ticks[-1] - ticks[0]) if ticks
              else None, "status": nodes[0].status if nodes else "no active SSAO node",
              "helper_processes": addon_module("session").current.helpers_started}
    with open(REPORT, "w") as f:
        json.dump(report, f, indent=1)
    print(f"[measure] UI stall during F12: {report}", flush=True)
    os._exit(code)  # Blender's own shutdown can hang under Xvfb


def step():
    try:
        now = time.monotonic()
        if now - STATE["start"] > TIMEOUT:
            finish(1)
        if STATE["f12"] is None:
            window = bpy.context.window_manager.windows[0]
            with bpy.context.temp_override(window=window):
                bpy.ops.render.render('INVOKE_DEFAULT')
            STATE["f12"] = time.monotonic()
            return 1.0
        nodes = addon_module("compute").ssao_nodes(bpy.context.scene)
        if busy() or (nodes and not nodes[0].status):
            STATE["idle_since"] = None
            return 0.5
        if STATE["idle_since"] is None:  # idle twice, a second apart
            STATE["idle_since"] = now
            return 1.0
        finish(0)
    except Exception:
        traceback.print_exc()
        finish(1)
    return None


set_helper_process("--in-process" not in ARGS)
if "--keep-viewport" not in ARGS:
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == 'VIEW_3D':
                area.type = 'OUTLINER'
bpy.app.timers.register(probe, first_interval=1.0)
bpy.app.timers.register(step, first_interval=3.0)
