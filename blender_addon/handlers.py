# SPDX-License-Identifier: MIT
"""When the AO is computed and applied: Blender's render, file and UI events.

During a render the node's inner File Output writes the Depth and Normal it is fed (see
inner_tree.py). Then:
  - headless (blender -b ... -f/-a, scripts): render_post computes the AO, saves the Render
    Result's passes and re-runs only the compositor (recomposite.py); render_write writes that
    result over the frame's output file (a multilayer EXR gets every pass, the new Composite and
    the AO);
  - in the UI, handlers run in the render thread and touch no Blender data there (a deadlock,
    see main_thread.py): render_write (an animation, Ctrl+F12) has the main thread save each
    written frame's passes while it waits, render_post records the frame; when the render job
    is over, a main-thread timer re-composites and rewrites every written frame with its own
    AO, then computes the current frame's AO and nudges the UI compositor, which re-composites
    the Render Result on screen.
The frames of one animation render are one sequence (compute.Sequences), whose temporal filter
averages each frame's AO with the frames before it; headless, a job that does not start the shot
renders the frames before its first beforehand (warm_up.py); in the UI a still is computed alone.
Changing a node property recomputes from the exported passes, without rendering.
(Measured facts behind this design: docs/blender.md.)"""
import atexit
import os
import re
import shutil
import time

import bpy

from . import compat, compute, helper_process, hidden_surfaces, inner_tree, recomposite, \
    saved_form, session, warm_up
from .compute import report


def ao_layers(aos):
    """Multilayer names of the nodes' AO ({node name: AO, or None where it failed}): SSAO.AO
    for one node, SSAO.<node name> for more. A node that failed gets no layer."""
    if len(aos) == 1:
        return {"SSAO.AO": ao for ao in aos.values() if ao is not None}
    return {"SSAO." + re.sub(r"[.\s]+", "_", name): ao for name, ao in aos.items()
            if ao is not None}


def _computed(aos):
    return any(ao is not None for ao in aos.values())


def _written_output(scene, frame):
    """The file Blender just wrote for `frame`: the frame path (-f, -a) or, for a still written
    from a script (render(write_still=True)), the output path without frame number."""
    render = scene.render
    still = bpy.path.abspath(render.filepath)
    if render.use_file_extension and not still.lower().endswith(render.file_extension.lower()):
        still += render.file_extension
    candidates = [p for p in (render.frame_path(frame=frame), still)
                  if os.path.isfile(p)]
    return max(candidates, key=os.path.getmtime) if candidates else None


def _warn_movie_once(scene):
    if scene.name not in session.current.movie_warned:
        session.current.movie_warned.add(scene.name)
        report(f"scene '{scene.name}' renders to a movie, which cannot be written again: its "
               "frames get the AO of the frame before. Render to image files (PNG, EXR) and "
               "make the movie from them", error=True)


def _remove(path):
    try:
        os.remove(path)
    except OSError:
        pass


@bpy.app.handlers.persistent
def _on_render_init(*_):
    """Headless, a render job (a still, or every frame of -a) begins: its frames are one
    sequence for the temporal filter (compute.Sequences). In the UI the frames are computed
    after the job (_finish_rendered_frames)."""
    state = session.current
    if not bpy.app.background or state.helper_rendering():
        return
    _end_sequences()
    state.sequences = compute.Sequences(record_to=state.record_to)


@bpy.app.handlers.persistent
def _on_render_done(*_):
    """render_complete, render_cancel."""
    if bpy.app.background and not session.current.helper_rendering():
        _end_sequences()


def _end_sequences():
    state = session.current
    if state.sequences is not None:
        state.sequences.close()
        state.sequences = None


@bpy.app.handlers.persistent
def _on_render_pre(scene, *_):
    state = session.current
    if state.helper_rendering():
        return
    # A new render: the layers kept, or being rendered, are of the last one.
    hidden_surfaces.forget(scene.name)
    helper_process.cancel(scene.name)
    if bpy.app.background or not state.written_frames:  # (the UI: the animation's 1st frame)
        state.render_started = time.time() - 1.0  # file times may be rounded to the second
    if not bpy.app.background:
        return  # the render thread: nothing more here
    # A frame whose re-composite failed or was never written must not lend its result to this
    # one.
    for passes, _ in state.recomposited.values():
        _remove(passes)
    state.recomposited.clear()
    # A file loaded before the add-on registered (5.x: `blender -b file --addons ...` registers
    # with bpy.data out of reach) still carries its nodes as group nodes: turn them back now.
    set_up_nodes()
    # The render composites with the AO the nodes hold (the last frame's, or one saved in the
    # file), and Blender writes that composite when the add-on cannot write the frame again
    # (its AO failed, or the re-composite did): make it the image without AO. A movie is
    # left as it is: its frames can only ever get the AO of the frame before (docs/blender.md).
    if not compat.is_movie(scene.render.image_settings):
        for node in compute.ssao_nodes(scene):
            compute.without_ao(node, scene)


@bpy.app.handlers.persistent
def _on_render_post(scene, *_):
    state = session.current
    if state.helper_rendering():
        return
    if not bpy.app.background:
        # The render thread: only record (_finish_rendered_frames skips scenes without nodes).
        state.pending_frames.append((scene.name, scene.frame_current))
        return
    if not compute.ssao_nodes(scene):
        return
    frame = scene.frame_current
    if compat.is_movie(scene.render.image_settings):
        _warn_movie_once(scene)
    # Headless, the scene's objects (the camera) still hold the frame the file was saved at.
    scene.frame_set(frame)
    sequences = state.sequences
    if sequences is not None and not sequences.warmed_up and state.record_to is None:
        # The job's first frame: its render is in the Render Result, the rest is below.
        warm_up.warm_up(scene, frame, sequences)
        scene.frame_set(frame)
    aos = compute.compute_frame(scene, frame, state.render_started,
                                sequences=state.sequences)
    # Nothing computed: the render's own composite is already the image without AO.
    if not _computed(aos) or compat.is_movie(scene.render.image_settings):
        return
    passes = recomposite.passes_path(scene, frame)
    try:
        recomposite.save_passes(scene, passes)
        recomposite.recomposite(scene, passes)
        state.recomposited[(scene.name, frame)] = (passes, ao_layers(aos))
    except Exception as error:
        report(f"{scene.name} frame {frame}: written WITHOUT AO: re-compositing it failed: "
               f"{error}", error=True)
        _remove(passes)


@bpy.app.handlers.persistent
def _on_render_write(scene, *_):
    """A frame file was written, with the AO of before this frame: write it again."""
    state = session.current
    if state.helper_rendering():
        return
    frame = scene.frame_current
    if not bpy.app.background:
        # An animation in the UI: the Render Result holds this frame's passes only until the
        # next frame renders. This thread (the render thread) waits while the main thread saves
        # them; the rest is done after the job.
        try:
            state.main_thread.call(_save_written_frame, scene.name, frame)
        except Exception as error:
            report(f"{scene.name} frame {frame}: saving the passes failed, the file keeps the AO "
                   f"of the frame before: {error}", error=True)
        return
    entry = state.recomposited.pop((scene.name, frame), None)
    if entry is None:
        return
    passes, layers = entry
    try:
        output = _written_output(scene, frame)
        if output is None:
            report(f"{scene.name} frame {frame}: cannot find the file this render wrote; it "
                   "keeps the composite WITHOUT AO", error=True)
            return
        # The helper's Render Result holds the re-composited frame.
        helper = recomposite.helper_scene_if_any(scene)
        recomposite.write_output(scene, helper, output, passes, layers)
    except Exception as error:
        report(f"{scene.name} frame {frame}: written WITHOUT AO: writing it with AO failed: "
               f"{error}", error=True)
    finally:
        _remove(passes)


def _save_written_frame(scene_name, frame):
    """UI, main thread, while the render thread waits in render_write: saves the passes of the
    frame just written, for _finish_rendered_frames."""
    scene = bpy.data.scenes.get(scene_name)
    if scene is None:
        return
    if compat.is_movie(scene.render.image_settings):
        _warn_movie_once(scene)
        return
    if not compute.ssao_nodes(scene):
        return
    passes = recomposite.passes_path(scene, frame)
    recomposite.save_passes(scene, passes)
    session.current.written_frames.append((scene.name, frame, _written_output(scene, frame),
                                           passes))


# Blender keeps one process-wide "no data-block writes" flag, set around read-only Python
# callbacks (panel drawing, some render-engine callbacks) and restored by each caller without
# regard to other threads (Blender issue #127767): a render-thread callback can leave it set on
# the main thread, and every later write from a timer then fails ("Writing to ID classes in this
# context is not allowed"; seen once in 3.4.1 after 98 Ctrl+F12 frames, and all 100 frames
# were then written without AO). Writes to the window manager are always allowed, and Blender
# allows every write inside a Python property's update callback: the timers' work runs there.
_WRITES_PROPERTY = "ssao_compositor_timer_tick"


def _run_with_writes(_window_manager, _context):
    if session.current.run_with_writes is not None:
        session.current.run_with_writes()


def with_writes(function):
    """function() where Blender allows data-block writes (see above); returns its result."""
    outcome = {}

    def run():
        try:
            outcome["result"] = function()
        except Exception as error:  # raised again below, outside Blender's callback
            outcome["error"] = error

    state = session.current
    previous, state.run_with_writes = state.run_with_writes, run
    try:
        window_manager = bpy.context.window_manager
        tick = getattr(window_manager, _WRITES_PROPERTY)
        setattr(window_manager, _WRITES_PROPERTY, (tick + 1) % 1000000)
    finally:
        state.run_with_writes = previous
    if not outcome:  # no update callback (the property is gone): try as it is
        run()
    if "error" in outcome:
        raise outcome["error"]
    return outcome.get("result")


def _process_pending():
    """UI: the main thread's share of a render (handlers run in the render thread there, where
    no timer may be registered): the work render handlers ask for while they wait, then, after
    the job, every frame's AO. This timer polls from register() on (often during a render: the
    render thread waits on it) and must never raise, or Blender drops it."""
    rendering = False
    state = session.current
    try:
        if state.main_thread.pending():
            with_writes(state.main_thread.serve)
        else:
            state.main_thread.serve()  # no work: only the render thread's sign of life
        rendering = bpy.app.is_job_running('RENDER')
        if not rendering and (state.written_frames or state.pending_frames):
            with_writes(_finish_rendered_frames)
        if state.helpers_busy():
            _poll_helpers()
    except Exception as error:
        report(f"after the render: {error}", error=True)
    return 0.05 if rendering else 0.1 if state.helpers_busy() else 0.2


def _poll_helpers():
    """UI: the helper renders' progress (helper_process); a scene whose layers came (or whose
    helper failed) is computed again. Polling writes nothing: with_writes (a window-manager
    property's update) redraws Blender's windows, which every 0.1 s kept a core busy."""
    for scene_name, frame in helper_process.poll().items():
        scene = bpy.data.scenes.get(scene_name)
        if scene is not None and compute.ssao_nodes(scene):
            with_writes(lambda: _answered(scene, frame))


def _answered(scene, frame):
    if scene.frame_current == frame:
        _show_frame(scene, frame)
        return
    for node in compute.ssao_nodes(scene):
        if node.status == compute.WAITING_STATUS.format(frame=frame):
            node.status = (f"Frame {frame}: without hidden surfaces (the frame changed before "
                           "they rendered)")


def _finish_rendered_frames():
    state = session.current
    if state.written_frames:
        # Outside a render handler the helper scene can go: the next one copies the compositor
        # as it is now (before 5.0 a scene's tree cannot be swapped, only copied with it).
        recomposite.remove_helpers()
    # The written frames are those of one animation render (the job is over): one sequence,
    # so that the temporal filter averages each frame with those before it, as headless.
    sequences = compute.Sequences()
    try:
        _finish_written_frames(state, sequences)
        last = state.pending_frames[-1] if state.pending_frames else None
        state.pending_frames.clear()
        scene = bpy.data.scenes.get(last[0]) if last else None
        if scene is None or not compute.ssao_nodes(scene):
            return
        # The Render Result's frame: after an animation its last, as it was written.
        _show_frame(scene, last[1], sequences)
    finally:
        sequences.close()


def _finish_written_frames(state, sequences):
    while state.written_frames:
        scene_name, frame, output, passes = state.written_frames.pop(0)
        scene = bpy.data.scenes.get(scene_name)
        if scene is None or output is None:
            _remove(passes)
            continue
        # The camera (and the re-composite's frame) of that frame, not of the current one.
        current = scene.frame_current
        try:
            scene.frame_set(frame)
            aos = compute.compute_frame(scene, frame, state.render_started,
                                        sequences=sequences)
            # Written again even when every node failed: the file has the AO of the frame
            # before, and must get none (the failed nodes' AO is now 1).
            if aos:
                helper = recomposite.recomposite(scene, passes)
                recomposite.write_output(scene, helper, output, passes, ao_layers(aos))
        except Exception as error:
            report(f"{scene_name} frame {frame}: writing it again failed, it may keep the AO "
                   f"of the frame before: {error}", error=True)
        finally:
            scene.frame_set(current)
            _remove(passes)


def _show_frame(scene, frame, sequences=None):
    """UI: the AO of the Render Result's frame, re-composited. The helper render a node needs
    renders in its own process (helper_process): the node shows the AO without it meanwhile,
    and this runs again when it is done (then alone). After an animation the Render Result
    shows its last frame and the scene is back at its own: that frame's camera for the AO (its
    helper rendered here, at once; in the animation's `sequences`), then the scene as it
    was."""
    current = scene.frame_current
    try:
        if frame != current:
            scene.frame_set(frame)
        aos = compute.compute_frame(scene, frame, session.current.render_started,
                                    outcome="shown", wait=frame != current,
                                    sequences=sequences)
    finally:
        if scene.frame_current != current:
            scene.frame_set(current)
    # A failed node's AO is now 1: re-composite too, or the Render Result keeps an older AO.
    if aos:
        nudge_until_composited(scene)
        if _computed(aos) and not _compositor_editor_open():
            message = ("AO computed; open a compositor Node Editor (and an Image Editor "
                       "showing Render Result) to see it applied")
            for node in compute.ssao_nodes(scene):
                # A failed node keeps its error, a waiting one says so.
                if aos.get(node.name) is not None and \
                        not helper_process.waiting(scene.name, node.name):
                    node.status = message
            report(message)


def nudge_until_composited(scene):
    """Nudges the scene's SSAO nodes so that the UI compositor runs again; then, when the
    compositor jobs of the moment are over, once more (one of them may have started before the
    new AO was in place: measured in 3.4 under load), and again while no job starts (right
    after a short render the nudge can be lost: measured in 5.2.2 after a 0.5 s render)."""
    _nudge_nodes(scene)
    state = session.current
    state.nudge_scene, state.nudge_tries, state.nudge_composited = scene.name, 0, False
    if _compositor_editor_open() and not bpy.app.timers.is_registered(_check_nudge):
        bpy.app.timers.register(_check_nudge, first_interval=0.3)


def _nudge_nodes(scene):
    for node in compute.ssao_nodes(scene):
        inner_tree.nudge(node)


def _check_nudge():
    state = session.current
    scene = bpy.data.scenes.get(state.nudge_scene or "")
    if scene is None or state.nudge_tries >= 4:
        return None
    if bpy.app.is_job_running('COMPOSITE'):
        return 0.2
    if state.nudge_tries > 0 and state.nudge_composited:
        return None
    state.nudge_tries += 1
    state.nudge_composited = False
    with_writes(lambda: _nudge_nodes(scene))
    return 0.5


@bpy.app.handlers.persistent
def _on_composite_pre(*_):
    session.current.nudge_composited = True


def _compositor_editor_open():
    """Blender re-composites the Render Result only from a visible compositor Node Editor."""
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            for space in area.spaces:
                if space.type == 'NODE_EDITOR' and space.tree_type == "CompositorNodeTree":
                    return True
    return False


def parameter_changed(node, scene):
    """A node property changed: recompute from the last export, then re-composite (UI)."""
    state = session.current
    if state.helper_rendering() or state.restoring_settings or bpy.app.background or \
            scene is None:
        return
    path = inner_tree.export_path(node, scene.frame_current)
    if path is None:
        node.status = "Render (F12) to compute the AO"
        return
    try:
        compute.compute_node(node, scene, compute.read_export(path), wait=False)
        node.status = compute.waiting_status(node, scene, scene.frame_current) or \
            f"Frame {scene.frame_current}: recomputed"
    except Exception as error:
        compute.without_ao(node, scene)
        node.status = f"Error: {error}"
        report(f"{scene.name} frame {scene.frame_current} node '{node.name}': shown WITHOUT "
               f"AO: {error}", error=True)
    nudge_until_composited(scene)


def _each_node(action, what):
    """Runs action(scene, node) for every SSAO node; one node's failure (a damaged inner tree,
    a linked library tree) is reported and does not stop the others or the event."""
    for scene, node in list(compute.all_ssao_nodes()):
        try:
            action(scene, node)
        except Exception as error:
            report(f"node '{node.name}' of scene '{scene.name}': {what} failed: {error}",
                   error=True)


def set_up_nodes():
    """The file's nodes ready for this session: group nodes of a saved file turned back into
    SSAO nodes, exporters pointed at this session's folder, AO images of the render's size."""
    saved_form.from_group_nodes()
    _each_node(lambda scene, node: compute.configure_node(node), "setting up")


def _pack_and_point_at_saved_folder(scene, node):
    image = inner_tree.ao_image_if_any(node)
    # Pack what is in memory; packing an unchanged packed image again would re-read a file
    # that does not exist and drop the pixels.
    if image is not None and image.has_data and (image.is_dirty or not image.packed_file):
        image.pack()
    inner_tree.point_exporter(node, compute.SAVED_EXPORT_DIR)


@bpy.app.handlers.persistent
def _on_load_post(*_):
    helper_process.cancel()  # another file: its scenes are others, even under the same names
    _record_shot_starts()
    set_up_nodes()


def _record_shot_starts():
    """Where each scene's shot starts, as saved: before `-s` on the command line changes it
    (warm_up.py)."""
    session.current.shot_starts = {s.name: s.frame_start for s in bpy.data.scenes}


@bpy.app.handlers.persistent
def _on_save_pre(*_):
    # The AO must travel inside the .blend; exporters point at a folder every session has, so
    # that a file opened without the add-on (or before it is enabled) writes somewhere harmless
    # and, with the add-on, where it will look.
    recomposite.remove_helpers()
    hidden_surfaces.remove_helpers()
    _each_node(_pack_and_point_at_saved_folder, "packing the AO")
    saved_form.to_group_nodes()


@bpy.app.handlers.persistent
def _on_save_post(*_):
    set_up_nodes()


_HANDLERS = (("render_init", _on_render_init), ("render_complete", _on_render_done),
             ("render_cancel", _on_render_done), ("render_pre", _on_render_pre),
             ("render_post", _on_render_post), ("render_write", _on_render_write),
             ("composite_pre", _on_composite_pre),
             ("load_post", _on_load_post), ("save_pre", _on_save_pre),
             ("save_post", _on_save_post))


def register():
    for name, handler in _HANDLERS:
        getattr(bpy.app.handlers, name).append(handler)
    # This session's exports are of no use to any other: remove them when Blender quits.
    atexit.register(shutil.rmtree, compute.PROCESS_EXPORT_DIR, ignore_errors=True)
    setattr(bpy.types.WindowManager, _WRITES_PROPERTY, bpy.props.IntProperty(
        options={'HIDDEN', 'SKIP_SAVE'}, update=_run_with_writes))
    if not bpy.app.background:
        session.current.main_thread.start()
        bpy.app.timers.register(_process_pending, first_interval=0.2, persistent=True)
    # Nodes of a file that is already open (enabling the add-on after loading).
    try:
        _record_shot_starts()
        set_up_nodes()
    except AttributeError:  # bpy.data is restricted while add-ons register at start-up
        pass


def unregister():
    # A render thread waiting for the timer goes on without its work.
    session.current.main_thread.stop()
    helper_process.cancel()
    for timer in (_process_pending, _check_nudge):
        if bpy.app.timers.is_registered(timer):
            bpy.app.timers.unregister(timer)
    # Without the add-on a node is undefined (5.x: a black composite); as a group node it
    # still multiplies by its last AO.
    try:
        saved_form.to_group_nodes()
    except Exception as error:
        report(f"keeping the nodes as group nodes failed: {error}", error=True)
    for name, handler in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler in handlers:
            handlers.remove(handler)
    if hasattr(bpy.types.WindowManager, _WRITES_PROPERTY):
        delattr(bpy.types.WindowManager, _WRITES_PROPERTY)
