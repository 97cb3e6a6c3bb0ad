# SPDX-License-Identifier: MIT
"""libssao camera parameters from a Blender scene's active camera (same names as the library)."""


class CameraError(RuntimeError):
    pass


# The camera settings a cropped render changes (cropped()).
CROPPED = ("sensor_width", "sensor_height", "sensor_fit", "shift_x", "shift_y", "ortho_scale")


def full_size(render):
    """The frame's size in pixels (resolution x percentage)."""
    scale = render.resolution_percentage / 100.0
    return int(render.resolution_x * scale), int(render.resolution_y * scale)


def crop_window(render):
    """(x0, y0, width, height): the rendered image within the frame, in pixels, y up from the
    bottom: the render border when the render is cropped to it (Blender truncates border x
    size to whole pixels), else the whole frame."""
    width, height = full_size(render)
    if not (render.use_border and render.use_crop_to_border):
        return 0, 0, width, height
    x0, x1 = int(render.border_min_x * width), int(render.border_max_x * width)
    y0, y1 = int(render.border_min_y * height), int(render.border_max_y * height)
    if x1 <= x0 or y1 <= y0:
        raise CameraError("the render border crops the frame to nothing")
    return x0, y0, x1 - x0, y1 - y0


def render_size(scene):
    """The rendered image's size in pixels, as the passes have it (crop_window's)."""
    return crop_window(scene.render)[2:]


def render_threads(scene):
    """The render's thread count when it is fixed (Render Properties > Performance), else 0:
    every core."""
    render = scene.render
    return render.threads if render.threads_mode == 'FIXED' else 0


def framed(settings, render, window):
    """Camera settings {name: value} (CROPPED's names) of the image `window` = (x0, y0, width,
    height), in the frame's pixels (y up from the bottom; it may reach beyond the frame: a guard
    band), as a frame of its own on the same pixel grid: the fitted side's sensor size or
    ortho_scale grows with its pixel count, the fit is made explicit (AUTO: the frame's larger
    side, pixel aspect included; the window's may differ), and the shift, a fraction of the
    fitted side, moves the view to the window's centre."""
    x0, y0, width, height = window
    full_width, full_height = full_size(render)
    aspect_x, aspect_y = render.pixel_aspect_x, render.pixel_aspect_y
    out = dict(settings)
    fit = settings["sensor_fit"]
    if fit == 'AUTO':
        fit = 'HORIZONTAL' if full_width * aspect_x >= full_height * aspect_y else 'VERTICAL'
        if fit == 'VERTICAL':
            out["sensor_height"] = settings["sensor_width"]  # AUTO fits sensor_width
    out["sensor_fit"] = fit
    # The fitted side before and after, in units of pixel aspect.
    if fit == 'HORIZONTAL':
        side, new_side = full_width * aspect_x, width * aspect_x
        out["sensor_width"] = settings["sensor_width"] * width / full_width
    else:
        side, new_side = full_height * aspect_y, height * aspect_y
        out["sensor_height"] = out["sensor_height"] * height / full_height
    out["ortho_scale"] = settings["ortho_scale"] * new_side / side
    dx = (x0 + 0.5 * width - 0.5 * full_width) * aspect_x
    dy = (y0 + 0.5 * height - 0.5 * full_height) * aspect_y
    out["shift_x"] = (settings["shift_x"] * side + dx) / new_side
    out["shift_y"] = (settings["shift_y"] * side + dy) / new_side
    return out


def cropped(settings, render, band=0):
    """Camera settings (framed's) of the rendered image (crop_window's), widened by `band`
    pixels on every side. Unchanged when the render is neither cropped nor widened."""
    x0, y0, width, height = crop_window(render)
    if not band and (width, height) == full_size(render):
        return dict(settings)
    return framed(settings, render, (x0 - band, y0 - band, width + 2 * band, height + 2 * band))


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
    frame = cropped({name: getattr(data, name) for name in CROPPED}, scene.render)
    return {
        "camera_type": data.type,
        "lens": data.lens,
        "sensor_width": frame["sensor_width"],
        "sensor_height": frame["sensor_height"],
        "sensor_fit": frame["sensor_fit"],
        "shift_x": frame["shift_x"],
        "shift_y": frame["shift_y"],
        "ortho_scale": frame["ortho_scale"],
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
