# SPDX-License-Identifier: MIT
"""Operators: recompute the AO of the scene's SSAO nodes from the last render's passes."""
import bpy

from . import compute, handlers


class SSAO_OT_recompute(bpy.types.Operator):
    """Recompute the ambient occlusion from the passes of the last render (no re-render)"""

    bl_idname = "ssao.recompute"
    bl_label = "Recompute SSAO"
    bl_options = {'REGISTER'}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and bool(compute.ssao_nodes(context.scene))

    def execute(self, context):
        scene = context.scene
        aos = compute.compute_frame(scene, scene.frame_current, outcome="shown")
        if aos:  # a node that failed now passes its Image through: re-composite that too
            handlers.nudge_until_composited(scene)
        if not aos or None in aos.values():
            errors = [n.status for n in compute.ssao_nodes(scene) if n.status.startswith("Error")]
            self.report({'ERROR'}, "; ".join(errors) or "nothing to compute")
            return {'CANCELLED'}
        self.report({'INFO'}, "SSAO recomputed")
        return {'FINISHED'}


def register():
    bpy.utils.register_class(SSAO_OT_recompute)


def unregister():
    bpy.utils.unregister_class(SSAO_OT_recompute)
