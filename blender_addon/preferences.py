# SPDX-License-Identifier: MIT
"""The add-on's preferences: where the passes are exported, and what the library says."""
import bpy

from . import compute, handlers, session


def _to_session(preferences):
    """The session keeps what the preferences say (the one place the add-on reads them)."""
    session.current.export_dir = bpy.path.abspath(preferences.export_dir)
    session.current.use_helper_process = preferences.helper_process


def _on_export_dir_changed(preferences, context):
    _to_session(preferences)
    handlers.set_up_nodes()


def _on_helper_process_changed(preferences, context):
    _to_session(preferences)


class SSAOPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    export_dir: bpy.props.StringProperty(
        name="Keep passes in", subtype='DIR_PATH', update=_on_export_dir_changed,
        description="Folder where the node exports the Depth and Normal it is fed (one 32-bit "
                    "EXR per node and frame), kept for the command-line tool; empty: a "
                    "temporary folder removed when Blender quits "
                    "($SSAO_COMPOSITOR_EXPORT_DIR overrides both)")

    helper_process: bpy.props.BoolProperty(
        name="Helper render in its own process", default=True,
        update=_on_helper_process_changed,
        description="In the UI, render the nodes' hidden surfaces and band in a background "
                    "Blender, so that the UI keeps responding (the scene is loaded a second "
                    "time while it renders). Off: in this Blender, which stops responding "
                    "while it renders. Headless renders always render it here")

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "export_dir")
        layout.prop(self, "helper_process")
        try:
            library = compute.library()
            version = library.ssao_version()
            layout.label(text=f"libssao {version // 10000}.{version // 100 % 100}."
                              f"{version % 100}: {library._name}", icon='CHECKMARK')
        except Exception as error:
            layout.label(text=f"libssao: {error}", icon='ERROR')


def register():
    bpy.utils.register_class(SSAOPreferences)
    addon = bpy.context.preferences.addons.get(__package__)
    if addon is not None and addon.preferences is not None:
        _to_session(addon.preferences)


def unregister():
    bpy.utils.unregister_class(SSAOPreferences)
