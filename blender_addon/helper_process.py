# SPDX-License-Identifier: MIT
"""The hidden-surface helper render (hidden_surfaces.py) in a Blender process of its own, so that
Blender's UI keeps responding while it renders: in the UI's own process the render stops the UI
for as long as it takes, Cycles' scene synchronisation and BVH build included (1.4 s with 2 M
triangles at 640x360, measured: docs/blender.md, "A responsive UI").

The scene is written to a .blend of its own (bpy.data.libraries.write: the scene and every
data-block it uses, paths made absolute; 50-90 ms for 135 MB, measured), and a background
Blender (the same executable, `-b --factory-startup`) opens it and runs the same
hidden_surfaces.render_layers, with the camera placed as the UI's is, and saves the layers as a
.npz, which a thread reads back. What the helper adds to materials and objects for its render is
added in that copy: the user's file is not touched. It costs Blender's start-up (0.8-0.9 s) and
a second copy of the scene in memory while it runs (the add-on's preference turns it off).

In the UI the add-on asks (layers_or_request()) rather than renders; the main-thread timer
(poll()) starts a render for a request at once, or, when it replaced an earlier request of the
same node, once it has not changed for SETTLE seconds (dragging the band's slider starts none
until it stops); it cancels the renders no request wants any more, and hands the finished
layers to hidden_surfaces' cache. A new render of the scene cancels its helpers
(cancel()): their layers would be of the render before. Requests, renders and failures are kept
in the session (session.py)."""
import atexit
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time

import bpy
import numpy as np

from . import hidden_surfaces, session

SETTLE = 0.25  # seconds a request that replaced another stays unchanged before it starts
LOG_TAIL = 12  # lines of a failed helper's output quoted in the error

# Run by the helper process, after Blender opened the scene's copy.
_CHILD = r"""
import importlib, json, os, sys
import bpy
import numpy as np
args = json.loads(sys.argv[sys.argv.index("--") + 1])
try:
    sys.path.insert(0, args["addon_parent"])
    hidden_surfaces = importlib.import_module(args["package"] + ".hidden_surfaces")
    scene = bpy.data.scenes[args["scene"]]
    scene.frame_set(args["frame"], subframe=args["subframe"])
    layers = hidden_surfaces.render_layers(scene, args["hits"], args["overscan"],
                                           folder=args["folder"],
                                           camera_matrix=args["camera_matrix"])
    part = args["output"] + ".part.npz"
    np.savez(part, **layers)
    os.replace(part, args["output"])
except Exception as error:
    with open(args["output"] + ".error", "w") as f:
        f.write(str(error) or type(error).__name__)
    raise
"""


def write_scene_copy(scene, folder):
    """Writes `scene` and every data-block it uses to folder/scene.blend (paths made absolute),
    for a Blender of its own to open; returns its path."""
    blend = os.path.join(folder, "scene.blend")
    bpy.data.libraries.write(blend, {scene}, path_remap='ABSOLUTE', compress=False)
    return blend


def child_command(blend, script, args):
    """The command that runs `script` (Python) in a background Blender (this executable, its
    factory settings) on `blend`; the script reads json `args`, with "addon_parent" and
    "package" added: where it imports this add-on from."""
    addon = os.path.dirname(os.path.abspath(__file__))
    args = {"addon_parent": os.path.dirname(addon),
            "package": __package__.rpartition(".")[2],  # the folder's name, top-level
            **args}
    # Drivers and other Python in the file run in the copy only where they run here: the
    # preference, or -y on the command line (a farm's render), unless this file's were blocked.
    allowed = bpy.context.preferences.filepaths.use_scripts_auto_execute or \
        any(a in ("-y", "--enable-autoexec") for a in sys.argv)
    autoexec = "-y" if allowed and not bpy.app.autoexec_fail else "-Y"
    return [bpy.app.binary_path, "-b", "--factory-startup", "-noaudio", autoexec, blend,
            "--python-exit-code", "3", "--python-expr", script, "--", json.dumps(args)]


def log_tail(log, returncode):
    """Why a child Blender failed, from the end of its output."""
    try:
        with open(log, errors="replace") as f:
            lines = [line.rstrip() for line in f if line.strip()]
    except OSError:
        lines = []
    return f"Blender exit status {returncode}: " + (" | ".join(lines[-LOG_TAIL:]) or "no output")


class _Request:
    def __init__(self, key, hits, overscan, replacing):
        self.key, self.hits, self.overscan = key, hits, overscan
        # A first request is due at once; one that replaces another (a slider being dragged)
        # once it has not changed for SETTLE seconds.
        self.due = time.monotonic() + (SETTLE if replacing else 0.0)


class _Render:
    """A helper process rendering one scene's layers; poll() until it gives them."""

    def __init__(self, scene, hits, overscan):
        self.folder = tempfile.mkdtemp(prefix="ssao_helper_", dir=bpy.app.tempdir or None)
        self.process = self.loader = None
        self.layers = self.error = None
        try:
            self._start(scene, hits, overscan)
        except BaseException:
            self.cancel()
            raise

    def _start(self, scene, hits, overscan):
        blend = write_scene_copy(scene, self.folder)
        self.output = os.path.join(self.folder, "layers.npz")
        camera = scene.camera
        command = child_command(blend, _CHILD, {
            "scene": scene.name, "frame": scene.frame_current,
            "subframe": scene.frame_subframe, "hits": hits, "overscan": overscan,
            "camera_matrix": camera and [list(row) for row in camera.matrix_world],
            "folder": self.folder, "output": self.output})
        self.log = os.path.join(self.folder, "helper.log")
        with open(self.log, "w") as log:
            self.process = subprocess.Popen(
                command, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                cwd=self.folder, creationflags=getattr(subprocess, "CREATE_NO_WINDOW", 0))
        session.current.helpers_started += 1

    def poll(self):
        """False while it runs; True when self.layers or self.error is set."""
        if self.loader is None:
            # The layers are read as soon as they are written (freeing a big scene makes the
            # process end a few tenths of a second later).
            ended = self.process.poll() is not None  # before looking for the file
            if not os.path.isfile(self.output):
                if not ended:
                    return False
                self.error = f"the helper render failed: {self._why()}"
                self.cancel()
                return True
            # A 4K frame's layers are hundreds of MB: read outside the main thread.
            self.loader = threading.Thread(target=self._load, daemon=True)
            self.loader.start()
            return False
        return not self.loader.is_alive()

    def _load(self):
        try:
            with np.load(self.output) as stored:
                self.layers = {name: stored[name] for name in stored.files}
        except Exception as error:
            self.error = f"reading the helper render's layers failed: {error}"
        finally:
            shutil.rmtree(self.folder, ignore_errors=True)

    def _why(self):
        """The child's error, or the end of its output (it crashed)."""
        try:
            with open(self.output + ".error", errors="replace") as f:
                return f.read()
        except OSError:
            return log_tail(self.log, self.process.returncode)

    def cancel(self):
        """Stops the process (if it runs) and removes its files."""
        if self.process is not None and self.process.poll() is None:
            self.process.kill()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                pass
        if self.loader is None:  # else the loader removes them when it has read them
            shutil.rmtree(self.folder, ignore_errors=True)


def layers_or_request(scene, hits, overscan, requester):
    """The layers of `scene` (hidden_surfaces.render_layers') if they are kept; else None, and
    `requester` (a node's name) asks for them, replacing what it asked for before. Raises the
    error of a helper render that failed for the same layers since the scene last rendered."""
    hidden_surfaces.check_request(hits, overscan)
    key = hidden_surfaces.layers_key(scene, hits, overscan)
    layers = hidden_surfaces.kept_layers(scene.name, key)
    if layers is not None:
        return layers
    state = session.current
    with state.helper_lock:
        error = state.helper_failed.get((scene.name, key))
        if error is not None:
            raise RuntimeError(error)
        asked = state.helper_requests.get((scene.name, requester))
        if asked is None or asked.key != key:
            state.helper_requests[(scene.name, requester)] = _Request(
                key, hits, overscan, replacing=asked is not None)
    return None


def withdraw(scene_name, requester):
    """`requester` needs no layers any more (its settings changed)."""
    state = session.current
    with state.helper_lock:
        state.helper_requests.pop((scene_name, requester), None)


def waiting(scene_name, requester):
    """Whether `requester` waits for layers of scene `scene_name`."""
    return (scene_name, requester) in session.current.helper_requests


def running():
    """The helper renders running now (tests look at their processes)."""
    state = session.current
    with state.helper_lock:
        return list(state.helper_renders.values())


def poll():
    """Main thread, from the add-on's timer: starts the requests that are due (one render for
    the nodes that ask for the same layers), cancels the renders no request wants, collects the
    finished ones. Returns {scene name: frame} of the scenes whose requests were answered
    (layers kept, an error recorded, or dropped: the scene changed): compute them again."""
    answered = {}
    rendering = bpy.app.is_job_running('RENDER')  # a new render cancels these anyway
    state = session.current
    requests, renders = state.helper_requests, state.helper_renders
    with state.helper_lock:
        wanted = {(scene, request.key) for (scene, _), request in requests.items()}
        for id_ in [i for i in renders if i not in wanted]:
            renders.pop(id_).cancel()
        now = time.monotonic()
        due = {(scene, request.key): request for (scene, _), request in requests.items()
               if now >= request.due and (scene, request.key) not in renders}
    for (scene_name, _), request in due.items() if not rendering else ():
        scene = bpy.data.scenes.get(scene_name)
        if scene is None or hidden_surfaces.layers_key(
                scene, request.hits, request.overscan) != request.key:
            # The frame or the camera changed since: computed again, it asks again (or says
            # the frame changed).
            _drop_requests(scene_name, request.key)
            answered[scene_name] = request.key[0]
            continue
        try:
            render = _Render(scene, request.hits, request.overscan)
        except Exception as error:
            _answer(scene_name, request.key, error=f"starting the helper render failed: {error}")
            answered[scene_name] = request.key[0]
            continue
        with state.helper_lock:
            renders[(scene_name, request.key)] = render
    with state.helper_lock:
        started = list(renders.items())
    for (scene_name, key), render in started:
        if render.poll():
            with state.helper_lock:
                renders.pop((scene_name, key), None)
            _answer(scene_name, key, render.layers, render.error)
            answered[scene_name] = key[0]
    return answered


def _answer(scene_name, key, layers=None, error=None):
    if layers is not None:
        hidden_surfaces.keep(scene_name, key, layers)
    else:
        state = session.current
        with state.helper_lock:
            state.helper_failed[(scene_name, key)] = error
    _drop_requests(scene_name, key)


def _drop_requests(scene_name, key):
    state = session.current
    with state.helper_lock:
        requests = state.helper_requests
        for id_ in [i for i, r in requests.items() if i[0] == scene_name and r.key == key]:
            del requests[id_]


def cancel(scene_name=None):
    """Forgets the requests, renders and failures of `scene_name` (every scene with None): it
    renders again. Safe from any thread."""
    state = session.current
    with state.helper_lock:
        for table in (state.helper_requests, state.helper_renders, state.helper_failed):
            for id_ in [i for i in table if scene_name is None or i[0] == scene_name]:
                item = table.pop(id_)
                if table is state.helper_renders:
                    item.cancel()


atexit.register(cancel)  # no helper outlives Blender
