# SPDX-License-Identifier: MIT
"""Checks the add-on's helper render in a process of its own (blender_addon/helper_process.py)
on the open .blend, in background Blender (the UI polls it from a timer; here a loop does):
  - "equal": the layers it renders, for each array, equal to hidden_surfaces.render_layers'
    in this process (the same Cycles, settings and camera: bit for bit, the normal to within
    its rounding, NORMAL_ROUNDING); "differ": pixels not equal and the largest difference;
  - "settled": a request replaced before it settles starts no process (only the last one);
  - "cancelled": cancel() kills a running helper process and removes its files;
  - "failure": a helper that fails (a scene without a camera) gives its error, with the
    child's own message, until the scene renders again (cancel());
  - "disabled": disabling the add-on kills a running helper process, and enabling it again
    begins a session (session.py) that remembers nothing of the last.
Writes --out JSON with those results.

    blender -b --factory-startup --addons ssao_compositor SCENE.blend \\
        -P tests/blender/check_helper_process.py -- --out RESULT.json
"""
import argparse
import importlib
import json
import os
import sys
import time

import addon_utils
import bpy
import numpy as np

TIMEOUT = 120.0
# Blender 3.4 sums face normals into vertex normals from several threads (add_v3_v3_atomic in
# mesh_normals.cc), so a smooth normal's last bit varies from run to run: measured 66 of 14400
# pixels 1.2e-7 apart in 1 run of 15, under load. Depth and facing stay bit for bit.
NORMAL_ROUNDING = 5e-7


def addon_module(name):
    package = next(n for n in sys.modules if n.endswith("ssao_compositor"))
    return importlib.import_module(f"{package}.{name}")


helper_process = addon_module("helper_process")
hidden_surfaces = addon_module("hidden_surfaces")
session = addon_module("session")


def poll_until(condition):
    start = time.monotonic()
    while True:
        answered = helper_process.poll()
        if condition(answered):
            return answered
        if time.monotonic() - start > TIMEOUT:
            raise TimeoutError("the helper process did not answer")
        time.sleep(0.05)


def _difference(theirs, ours):
    """How far two arrays differ: pixels not equal and the largest |difference|."""
    if theirs is None or theirs.shape != ours.shape:
        return None
    unequal = theirs != ours
    if unequal.ndim == 3:
        unequal = unequal.any(axis=-1)
    return {"pixels": int(unequal.sum()),
            "largest": float(np.nanmax(np.abs(theirs.astype(np.float64) - ours), initial=0.0))}


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    scene = bpy.context.scene
    hits, overscan = hidden_surfaces.MAX_HITS, 16
    result = {}

    # A request replaced before it settles: only the second starts a process.
    started = session.current.helpers_started
    assert helper_process.layers_or_request(scene, hits, 8, "node") is None
    assert helper_process.layers_or_request(scene, hits, overscan, "node") is None
    start = time.monotonic()
    answered = poll_until(bool)
    result["seconds"] = time.monotonic() - start
    result["settled"] = {"processes": session.current.helpers_started - started,
                         "answered": answered}
    background = helper_process.layers_or_request(scene, hits, overscan, "node")
    hidden_surfaces.forget()
    start = time.monotonic()
    here = hidden_surfaces.render_layers(scene, hits, overscan)
    result["in_process_seconds"] = time.monotonic() - start
    result["equal"] = {name: bool(background is not None and name in background and
                                  background[name].dtype == array.dtype and
                                  np.allclose(background[name], array, rtol=0,
                                              atol=NORMAL_ROUNDING if name == "normal" else 0))
                       for name, array in here.items()}
    result["differ"] = {name: _difference(background.get(name), array)
                        for name, array in here.items() if background is not None}
    result["geometry_pixels"] = int((here["depth"] < hidden_surfaces.BACKGROUND).sum())

    # Cancelled while it runs.
    hidden_surfaces.forget()
    assert helper_process.layers_or_request(scene, hits, overscan, "node") is None
    poll_until(lambda _: helper_process.running())
    render = helper_process.running()[0]
    helper_process.cancel(scene.name)
    result["cancelled"] = {"exit": render.process.poll(),
                           "files_left": os.path.exists(render.folder),
                           "busy": session.current.helpers_busy()}

    # A helper that fails: its error, with the child's message, until the scene renders again.
    camera, scene.camera = scene.camera, None
    assert helper_process.layers_or_request(scene, hits, overscan, "node") is None
    poll_until(bool)
    try:
        helper_process.layers_or_request(scene, hits, overscan, "node")
        result["failure"] = "no error"
    except RuntimeError as error:
        result["failure"] = str(error)
    helper_process.cancel(scene.name)
    result["after_failure_asks_again"] = \
        helper_process.layers_or_request(scene, hits, overscan, "node") is None
    helper_process.cancel(scene.name)
    scene.camera = camera

    # The add-on disabled while a helper renders: the process is killed and its files go;
    # enabled again, a new session remembers nothing of the old one.
    hidden_surfaces.keep(scene.name, "kept before", here)
    assert helper_process.layers_or_request(scene, hits, overscan, "node") is None
    poll_until(lambda _: helper_process.running())
    render = helper_process.running()[0]
    old = session.current
    package = next(n for n in sys.modules if n.endswith("ssao_compositor"))
    addon_utils.disable(package)
    addon_utils.enable(package)
    new = session.current
    result["disabled"] = {"exit": render.process.poll(),
                          "files_left": os.path.exists(render.folder),
                          "new_session": new is not old,
                          "remembered": [name for name in ("kept_layers", "helper_requests",
                                                           "helper_renders", "helper_failed",
                                                           "helpers_started")
                                         if getattr(new, name)]}

    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
    print(f"[measure] helper process: layers in {result['seconds']:.2f} s (in this process "
          f"{result['in_process_seconds']:.2f} s), equal: {result['equal']}, where not: "
          f"{ {name: d for name, d in result['differ'].items() if d and d['pixels']} }",
          flush=True)


main()
