# SPDX-License-Identifier: MIT
"""libssao camera parameters from a Blender scene's active camera (same names as the library)."""


class CameraError(RuntimeError):
    pass


def render_size(scene):
    """The rendered image's size in pixels (resolution x percentage), as the passes have it."""
    r = scene.render
    scale = r.resolution_percentage / 100.0
    return int(r.resolution_x * scale), int(r.resolution_y * scale)


def camera_params(scene):
    """Returns {library parameter: value} describing the scene's active camera."""
    camera = scene.camera
    if camera is None:
        raise CameraError(f"scene '{scene.name}' has no active camera")
    if camera.type != 'CAMERA':
        raise CameraError(f"the active object '{camera.name}' is not a camera")
    data = camera.data
    if data.type not in {'PERSP', 'ORTHO'}:
        raise CameraError(f"camera '{camera.name}' is {data.type}: only perspective and "
                          "orthographic cameras are supported")
    matrix = camera.matrix_world
    return {
        "camera_type": data.type,
        "lens": data.lens,
        "sensor_width": data.sensor_width,
        "sensor_height": data.sensor_height,
        "sensor_fit": data.sensor_fit,
        "shift_x": data.shift_x,
        "shift_y": data.shift_y,
        "ortho_scale": data.ortho_scale,
        "clip_start": data.clip_start,
        "clip_end": data.clip_end,
        "pixel_aspect_x": scene.render.pixel_aspect_x,
        "pixel_aspect_y": scene.render.pixel_aspect_y,
        "camera_to_world": [matrix[r][c] for r in range(4) for c in range(4)],
    }


def view_frame(scene):
    """The rendered frame in camera space, as Blender's own camera model gives it (aspect, fit
    and shift included): (left, right, bottom, top, distance, orthographic). A perspective
    camera's frame lies at z = -distance; an orthographic one's spans the view."""
    camera = scene.camera
    corners = camera.data.view_frame(scene=scene)
    xs, ys = [c.x for c in corners], [c.y for c in corners]
    return (min(xs), max(xs), min(ys), max(ys), -corners[0].z,
            camera.data.type == 'ORTHO')


def rotation(scene):
    """The active camera's world rotation (3x3 rows, scale removed)."""
    return [list(row) for row in scene.camera.matrix_world.to_3x3().normalized()]
