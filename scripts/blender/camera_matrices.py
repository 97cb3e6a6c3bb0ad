# SPDX-License-Identifier: MIT
"""Prints Blender's own projection matrices for a set of camera settings, as C++ initialisers
for tests/unit/test_internals.cpp (the independent reference for libssao's camera model).

    blender -b --factory-startup -noaudio --python-exit-code 1 -P scripts/blender/camera_matrices.py
"""
import bpy

CASES = [
    # name, type, lens, sensor_w, sensor_h, fit, shift_x, shift_y, ortho_scale, W, H, aspx, aspy
    ("persp_auto_wide", "PERSP", 35.0, 36.0, 24.0, "AUTO", 0.0, 0.0, 6.0, 640, 360, 1, 1),
    ("persp_auto_tall", "PERSP", 50.0, 36.0, 24.0, "AUTO", 0.0, 0.0, 6.0, 300, 500, 1, 1),
    ("persp_shift", "PERSP", 28.0, 36.0, 24.0, "AUTO", 0.15, -0.1, 6.0, 320, 240, 1, 1),
    ("persp_vertical", "PERSP", 40.0, 36.0, 24.0, "VERTICAL", 0.05, 0.2, 6.0, 400, 300, 1, 1),
    ("persp_horizontal_tall", "PERSP", 40.0, 30.0, 20.0, "HORIZONTAL", 0.0, 0.1, 6.0, 200, 400,
     1, 1),
    ("persp_pixel_aspect", "PERSP", 35.0, 36.0, 24.0, "AUTO", 0.1, 0.0, 6.0, 480, 480, 1, 1.25),
    ("ortho_auto", "ORTHO", 50.0, 36.0, 24.0, "AUTO", 0.0, 0.0, 7.5, 640, 360, 1, 1),
    ("ortho_shift_vertical", "ORTHO", 50.0, 36.0, 24.0, "VERTICAL", -0.2, 0.1, 4.0, 300, 400,
     1, 1),
]

scene = bpy.context.scene
camera_data = bpy.data.cameras.new("probe")
camera = bpy.data.objects.new("probe", camera_data)
scene.collection.objects.link(camera)
for name, kind, lens, sw, sh, fit, sx, sy, scale, w, h, ax, ay in CASES:
    camera_data.type = kind
    camera_data.lens = lens
    camera_data.sensor_width = sw
    camera_data.sensor_height = sh
    camera_data.sensor_fit = fit
    camera_data.shift_x = sx
    camera_data.shift_y = sy
    camera_data.ortho_scale = scale
    # The matrix comes from the evaluated copy: refresh it after changing the properties.
    bpy.context.view_layer.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    m = camera.evaluated_get(depsgraph).calc_matrix_camera(depsgraph, x=w, y=h, scale_x=ax, scale_y=ay)
    values = ", ".join(f"{m[r][c]:.9g}" for r in range(4) for c in range(4))
    print(f'CASE {{"{name}", {"true" if kind == "ORTHO" else "false"}, {lens}, {sw}, {sh}, '
          f'"{fit}", {sx}, {sy}, {scale}, {w}, {h}, {ax}, {ay}, {{{values}}}}},')
