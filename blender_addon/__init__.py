# SPDX-License-Identifier: MIT
"""Ambient Occlusion (SSAO) compositor node, computed by libssao from the Depth and Normal passes.

Blender 3.x installs this folder (zipped) as a legacy add-on (bl_info); Blender 4.2+ installs
the same zip as an extension (blender_manifest.toml). All imports are relative. The version here
and in the manifest is the project's (CMakeLists.txt), written in when the zip is packaged.

Modules: node (the node type), inner_tree (its built-in inner nodes), compute (libssao),
ssao (the Python module core/python/ssao, the one ctypes binding; a link in the source tree, a
copy in the zip), recomposite (running the compositor again), multilayer (EXR layers),
saved_form (how a .blend carries the node), handlers (render and file events), main_thread
(render-thread handlers' work done on the main thread), session (everything the add-on
remembers between events: one object, begun by register()), helper_process and warm_up
(background Blenders: the UI's helper render, the frames before a headless job's first),
operators, preferences, camera, compat (every Blender-version difference)."""

bl_info = {
    "name": "Ambient Occlusion (SSAO) compositor node",
    "author": "ssao project",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Compositor > Add > Filter > Ambient Occlusion (SSAO)",
    "description": "Screen-space ambient occlusion from the render's Depth and Normal passes",
    "category": "Compositing",
}

from . import compute, handlers, node, operators, preferences, session  # noqa: E402

# Scripting entry point: ssao_compositor.compute_ao(scene) -> numpy array (height, width).
compute_ao = compute.compute_ao

_modules = (preferences, node, handlers, operators)


def register():
    session.begin()
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
    session.end()
