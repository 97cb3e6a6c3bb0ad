# SPDX-License-Identifier: MIT
"""The frames before a headless render job's first, for the temporal filter: a farm that cuts a
shot into chunks (`-s A -e B -a`, `-f A..B`, one frame each) gets every frame bit for bit as a
render of the whole shot would, like the command-line tool's chunks (docs/farm.md).

A frame's AO averages its own estimate with those of the `temporal_frames - 1` frames numbered
just before it (compute.Sequences), so the first frame of a job that does not start the shot
needs theirs. They are rendered first and not written: a background Blender of its own (as
helper_process.py starts) opens a copy of the scene and renders those frames with this add-on,
its render output in a temporary folder and the compositor's own File Output nodes muted; its
Sequences records every frame's library inputs, which this process's Sequences then replays.
The shot starts at the scene's frame_start as the file was loaded (handlers.py records it
before `-s` changes it). It costs those frames' render; a job that starts the shot, or nodes with
temporal_frames 1, cost nothing."""
import os
import shutil
import subprocess
import tempfile
import time

import bpy

from . import compat, compute, helper_process, inner_tree, session
from .compute import report

# Run by the child Blender, on the scene's copy.
_CHILD = r"""
import importlib, json, os, sys
import bpy
args = json.loads(sys.argv[sys.argv.index("--") + 1])
sys.path.insert(0, args["addon_parent"])
addon = importlib.import_module(args["package"])
addon.register()
importlib.import_module(args["package"] + ".session").current.record_to = args["record"]
scene = bpy.data.scenes[args["scene"]]
frames = args["frames"]
scene.frame_start, scene.frame_end, scene.frame_step = frames[0], frames[-1], args["step"]
scene.render.filepath = os.path.join(args["folder"], "frame_")
scene.render.use_overwrite, scene.render.use_placeholder = True, False
importlib.import_module(args["package"] + ".compat").set_image_format(
    scene.render.image_settings, 'PNG')
importlib.import_module(args["package"] + ".warm_up").mute_file_outputs(scene)
bpy.ops.render.render(animation=True, scene=scene.name)
"""


def frames_before(scene, first):
    """The frames of the shot whose estimates `first` averages: up to temporal_frames - 1 of
    the scene's nodes, a frame_step apart, none before the shot's start."""
    reach = max((getattr(node, "temporal_frames", 1) for node in compute.ssao_nodes(scene)),
                default=1) - 1
    start = session.current.shot_starts.get(scene.name, scene.frame_start)
    step = max(1, scene.frame_step)
    return [first - k * step for k in range(reach, 0, -1) if first - k * step >= start]


def warm_up(scene, first, sequences):
    """Headless, before the job's first frame `first` is computed: gives `sequences` the frames
    before it. When they cannot be rendered the frame is computed without them (said in the
    console), as a job that starts the shot computes its first."""
    sequences.warmed_up = True
    frames = frames_before(scene, first)
    if not frames:
        return
    folder = tempfile.mkdtemp(prefix="ssao_warm_up_", dir=bpy.app.tempdir or None)
    try:
        start = time.perf_counter()
        record = os.path.join(folder, "record")
        os.makedirs(record)
        command = helper_process.child_command(
            helper_process.write_scene_copy(scene, folder), _CHILD,
            {"scene": scene.name, "frames": frames, "step": max(1, scene.frame_step),
             "folder": folder, "record": record})
        log = os.path.join(folder, "warm_up.log")
        with open(log, "w") as out:
            # The child's exports stay in its own folder (the variable would share ours).
            env = {**os.environ, "SSAO_COMPOSITOR_EXPORT_DIR": os.path.join(folder, "export")}
            returncode = subprocess.run(
                command, stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT,
                cwd=folder, env=env,
                creationflags=getattr(subprocess, "CREATE_NO_WINDOW", 0)).returncode
        if returncode != 0:
            raise RuntimeError(helper_process.log_tail(log, returncode))
        replayed = sequences.replay(record)
        report(f"{scene.name} frame {first}: the temporal filter's frames before it "
               f"({', '.join(map(str, frames))}) rendered first, {replayed} node frames, in "
               f"{time.perf_counter() - start:.1f} s")
    except Exception as error:
        report(f"{scene.name} frame {first}: rendering the frames before it for the temporal "
               f"filter failed, it is computed without them: {error}", error=True)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def mute_file_outputs(scene):
    """The child's: the compositor's own File Output nodes write nothing for these frames (a
    farm's other task may be writing them); the SSAO nodes' inner exporters still do."""
    def mute(tree, seen):
        if tree is None or tree.as_pointer() in seen:
            return
        seen.add(tree.as_pointer())
        for node in tree.nodes:
            if node.bl_idname == 'CompositorNodeOutputFile':
                node.mute = True
            elif getattr(node, "node_tree", None) is not None and \
                    node.bl_idname != inner_tree.NODE_IDNAME:
                mute(node.node_tree, seen)
    mute(compat.compositor_tree(scene), set())
