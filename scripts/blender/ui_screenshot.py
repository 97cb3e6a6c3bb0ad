# SPDX-License-Identifier: MIT
"""Drives Blender's UI (under Xvfb) through an F12 render with the Ambient Occlusion (SSAO)
compositor node, checks that the Render Result gets the AO, changes a node property, and takes
a screenshot of the window.

    xvfb-run -a -s "-screen 0 1600x900x24" blender --factory-startup -noaudio \
        --addons ssao_compositor SCENE.blend --python scripts/blender/ui_screenshot.py -- \
        --out DIR [--workspace Compositing|Layout] [--render-display SPLIT|WINDOW|NONE]
        [--after-workspace NAME] [--change radius=1.5] [--timeout 240]

SCENE.blend is a scene whose compositor has an SSAO node between Render Layers and Composite
(tests/blender/build_ssao_scene.py makes one; with BLENDER_USER_SCRIPTS pointing at a folder
whose addons/ holds ssao_compositor when it is not installed in the user's profile).

Everything runs from timers once the UI is up:
  1. layout: the given workspace ("Compositing" has a compositor Node Editor, "Layout" has
     none). With --render-display SPLIT (default; needs Compositing) the compositor editor
     gets the window, its right part becomes an Image Editor showing the Render Result, and F12
     renders into it (preferences: render in "Keep User Interface"); WINDOW is Blender's
     default (F12 opens a new window with an Image Editor); NONE renders with no Image Editor.
     The SSAO node is selected and the node tree framed (its properties are on the node).
  2. F12: bpy.ops.render.render('INVOKE_DEFAULT'); waits for the render job, then for the
     add-on's main-thread timer (the node's status "Frame N: ... ms"), then until no render or
     compositor job ran for --settle seconds (compositor jobs are counted with composite_post).
  3. check: saves the Render Result as a multilayer EXR (its Combined pass = the beauty, its
     Composite layer = what the compositor made) and compares Composite with Combined x AO
     (the node's AO image): "AO applied" when they agree to 1e-3.
  4. screenshots: DIR/compositor_node.png (the main window, bpy.ops.screen.screenshot),
     DIR/window_N.png for any other window (the render window with WINDOW; these come out
     garbled under Xvfb), DIR/screen.png (the whole X screen through ImageMagick's `import`,
     when installed: every window as the user sees it).
  5. --after-workspace NAME: switches the main window to that workspace, waits, checks again.
  6. --change NAME=VALUE: sets that node property (its update callback recomputes from the
     exported passes and nudges the compositor), waits, checks again, counts the renders that
     ran meanwhile (should be 0), and saves DIR/after_change.png.
  7. prints "ui_screenshot [...] RESULT ..." lines, writes DIR/ui_report.json (every
     measurement) and DIR/ui_events.txt (handler events with times), and quits.

Exit status: 0 when the run completed (whatever the checks found: read ui_report.json);
1 on a timeout or an exception. The comparison needs numpy and OpenImageIO importable in
Blender's Python (true for Debian's Blender, which uses the system Python); without
OpenImageIO the EXRs are still written and the check is reported as skipped.
"""
import argparse
import json
import os
import sys
import time
import traceback

import bpy

NODE_IDNAME = "CompositorNodeSSAO"
AGREEMENT = 1e-3  # max |Composite - Combined x AO| for "AO applied" (float EXR, linear)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="ui_screenshot.py")
    parser.add_argument("--out", required=True, help="folder for the PNG, EXRs and report")
    parser.add_argument("--workspace", default="Compositing")
    parser.add_argument("--render-display", choices=("SPLIT", "WINDOW", "NONE"),
                        default="SPLIT")
    parser.add_argument("--after-workspace", default="",
                        help="switch to this workspace after the render, then check again")
    parser.add_argument("--change", default="radius=1.5",
                        help="NAME=VALUE node property to change after the render ('' skips)")
    parser.add_argument("--timeout", type=float, default=240.0, help="seconds for everything")
    parser.add_argument("--settle", type=float, default=2.0,
                        help="seconds without compositor activity that count as done")
    return parser.parse_args(argv)


ARGS = parse_args()
OUT = os.path.abspath(ARGS.out)
START = time.monotonic()
EVENTS = []       # (seconds since start, event name)
REPORT = {"args": vars(ARGS), "blender": bpy.app.version_string}


def now():
    return time.monotonic() - START


def log(message):
    print(f"ui_screenshot [{now():6.1f}s] {message}", flush=True)


def _event(name):
    def handler(*_):
        EVENTS.append((now(), name))  # render thread in the UI: only record
    return handler


_HANDLERS = [(name, _event(name)) for name in
             ("render_pre", "render_post", "render_complete", "render_cancel",
              "composite_pre", "composite_post", "composite_cancel")]


def count(name, since=0.0):
    return sum(1 for t, n in EVENTS if n == name and t >= since)


def last_event_time():
    return max((t for t, _ in EVENTS), default=0.0)


# --- UI helpers -----------------------------------------------------------------------------

def main_window():
    return bpy.context.window_manager.windows[0]


def find_area(window, ui_type):
    areas = [a for a in window.screen.areas if a.ui_type == ui_type]
    return max(areas, key=lambda a: a.width * a.height) if areas else None


def window_region(area):
    return next(r for r in area.regions if r.type == 'WINDOW')


def ssao_node(scene):
    tree = addon_module("compat").compositor_tree(scene)  # scene.node_tree before 5.0
    nodes = [n for n in tree.nodes if n.bl_idname == NODE_IDNAME] if tree else []
    if not nodes:
        raise RuntimeError(f"scene '{scene.name}' has no {NODE_IDNAME} in its compositor")
    return nodes[0]


def tidy_node_editor(window):
    """No backdrop, no sidebar. Region sizes change at the next redraw, which shifts the view:
    frame the tree in a later timer step."""
    area = find_area(window, "CompositorNodeTree")
    if area is not None:
        area.spaces.active.show_backdrop = False
        area.spaces.active.show_region_ui = False
    return area is not None


def frame_node_tree(window, node):
    """Selects the SSAO node (active) and frames the whole tree in the compositor editor."""
    area = find_area(window, "CompositorNodeTree")
    if area is None:
        return False
    tree = node.id_data
    for other in tree.nodes:
        other.select = False
    node.select = True
    tree.nodes.active = node
    region = window_region(area)
    view = region.view2d
    left = min(n.location.x for n in tree.nodes)
    right = max(n.location.x + n.dimensions.x for n in tree.nodes)
    top = max(n.location.y for n in tree.nodes)
    bottom = min(n.location.y - n.dimensions.y for n in tree.nodes)

    def fraction():  # of the visible view the tree (plus a margin) needs
        x0, y0 = view.region_to_view(0, 0)
        x1, y1 = view.region_to_view(region.width, region.height)
        return max(1.1 * (right - left) / (x1 - x0), 1.1 * (top - bottom) / (y1 - y0))

    with bpy.context.temp_override(window=window, area=area, region=region):
        bpy.ops.node.view_all()
        # view_all leaves the tree small here; zoom_in steps by a fixed 7.5 % a side.
        for _ in range(40):
            if fraction() > 0.92:
                break
            bpy.ops.view2d.zoom_in()
        x0, y0 = view.region_to_view(0, 0)
        x1, y1 = view.region_to_view(region.width, region.height)
        scale = region.width / (x1 - x0)  # pixels per view unit
        bpy.ops.view2d.pan(deltax=round(((left + right) - (x0 + x1)) / 2 * scale),
                           deltay=round(((top + bottom) - (y0 + y1)) / 2 * scale))
    return True


def split_for_image_editor(window):
    """The compositor editor gets the whole window (the other areas are closed), and its right
    part becomes an Image Editor (for the Render Result)."""
    area = find_area(window, "CompositorNodeTree")
    if area is None:
        raise RuntimeError("SPLIT needs a compositor Node Editor (use --workspace Compositing)")
    for other in list(window.screen.areas):
        if other.as_pointer() != area.as_pointer():
            with bpy.context.temp_override(window=window, area=other):
                bpy.ops.screen.area_close()
    before = set(a.as_pointer() for a in window.screen.areas)
    with bpy.context.temp_override(window=window, area=area, region=window_region(area)):
        bpy.ops.screen.area_split(direction='VERTICAL', factor=0.56)
    new = [a for a in window.screen.areas if a.as_pointer() not in before]
    if not new:
        raise RuntimeError("area_split made no area")
    # The new area is the one on the right or the left; the image goes to the right one.
    pair = sorted([area, new[0]], key=lambda a: a.x)
    pair[1].ui_type = 'IMAGE_EDITOR'
    return pair[1]


def show_render_result(window):
    image = bpy.data.images.get("Render Result")
    if image is None:
        return None
    for area in window.screen.areas:
        if area.type == 'IMAGE_EDITOR':
            area.spaces.active.image = image
            with bpy.context.temp_override(window=window, area=area,
                                           region=window_region(area)):
                bpy.ops.image.view_all(fit_view=True)
    return image


def image_editors(window_manager):
    """[(window index, what the editor shows)] for every Image Editor of every window."""
    shown = []
    for index, window in enumerate(window_manager.windows):
        for area in window.screen.areas:
            if area.type == 'IMAGE_EDITOR':
                image = area.spaces.active.image
                shown.append((index, image.name if image else None))
    return shown


def screenshot(window, path):
    area = window.screen.areas[0]
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.screen.screenshot(filepath=path, check_existing=False)
    log(f"saved {path}")


def screenshot_x_root(path):
    """The whole X screen, every window as X shows it (ImageMagick's import), when available."""
    import shutil
    import subprocess
    tool = shutil.which("import")
    if not tool or not os.environ.get("DISPLAY"):
        return
    result = subprocess.run([tool, "-window", "root", path], capture_output=True, text=True,
                            timeout=60)
    log(f"saved {path}" if result.returncode == 0 else f"import failed: {result.stderr}")


def addon_module(name):
    """A module of the enabled add-on, whatever its package is called (ssao_compositor as a
    legacy add-on in 3.x, bl_ext.<repository>.ssao_compositor as an extension in 4.2+)."""
    return next(m for n, m in sys.modules.items() if n.endswith("ssao_compositor." + name))


# --- checking the Render Result --------------------------------------------------------------

def save_render_result(scene, path):
    """The Render Result as a 32-bit multilayer EXR (all passes and the Composite layer)."""
    addon_module("recomposite").save_passes(scene, path)


def node_ao(node):
    """The node's AO image as (height, width), row 0 on top."""
    import numpy as np
    image = node.node_tree.nodes["SSAO AO"].image
    width, height = image.size
    pixels = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(pixels)
    return pixels.reshape(height, width, 4)[::-1, :, 0].copy()


def compare(exr_path, ao):
    """Composite vs Combined and vs Combined x AO, from a multilayer Render Result EXR."""
    try:
        import numpy as np
        import OpenImageIO as oiio
    except ImportError as error:
        return {"skipped": f"no numpy/OpenImageIO in Blender's Python ({error})"}
    image = oiio.ImageBuf(exr_path)
    spec = image.spec()
    names = list(spec.channelnames)
    pixels = image.get_pixels(oiio.FLOAT)  # (height, width, channels), row 0 on top

    def channels(prefix):
        idx = [names.index(f"{prefix}.{c}") for c in "RGB" if f"{prefix}.{c}" in names]
        return pixels[:, :, idx] if len(idx) == 3 else None

    layers = [n[:-len(".R")] for n in names
              if n.endswith(".Combined.R") and not n.startswith("Composite.")]
    combined = channels(layers[0]) if layers else None
    composite = channels("Composite.Combined")
    result = {"channels": len(names)}
    if combined is None or composite is None:
        result["error"] = f"Combined or Composite missing; channels: {names[:20]}"
        return result
    product = combined * ao[:, :, None]
    result.update({
        "max_abs_composite_minus_combined": float(np.abs(composite - combined).max()),
        "max_abs_composite_minus_combined_x_ao": float(np.abs(composite - product).max()),
        "mean_ao": float(ao.mean()),
        "min_ao": float(ao.min()),
    })
    result["ao_applied"] = result["max_abs_composite_minus_combined_x_ao"] < AGREEMENT
    return result


# --- the scenario ---------------------------------------------------------------------------

def wait_until(condition, what, poll=0.2):
    """Generator step: yields poll intervals until condition() is true (or the timeout)."""
    while not condition():
        if now() > ARGS.timeout:
            raise TimeoutError(f"timed out waiting for {what}")
        yield poll


def wait_quiet(since):
    """Waits until no render/compositor job runs and no handler fired for ARGS.settle s."""
    def quiet():
        busy = bpy.app.is_job_running('RENDER') or bpy.app.is_job_running('COMPOSITE')
        return not busy and now() - max(last_event_time(), since) >= ARGS.settle
    yield from wait_until(quiet, "the compositor to settle")


def scenario():
    yield 1.0  # the UI is up
    window = main_window()
    scene = bpy.context.scene
    node = ssao_node(scene)
    prefs = bpy.context.preferences
    prefs.use_preferences_save = False  # never write the user's preferences
    prefs.view.smooth_view = 0  # framing takes effect at once
    REPORT["workspace"] = ARGS.workspace
    window.workspace = bpy.data.workspaces[ARGS.workspace]
    yield 0.5
    if ARGS.render_display == "SPLIT":
        split_for_image_editor(window)
        prefs.view.render_display_type = 'NONE'
    else:
        prefs.view.render_display_type = ARGS.render_display
    yield 0.5
    tidy_node_editor(window)
    yield 0.5
    REPORT["compositor_editor_open"] = frame_node_tree(window, node)
    REPORT["status_before"] = node.status
    yield 0.5

    # F12
    log("render (F12)")
    area = find_area(window, "CompositorNodeTree") or window.screen.areas[0]
    t_render = now()
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.render.render('INVOKE_DEFAULT')
    yield 0.5
    if ARGS.render_display == "SPLIT":
        show_render_result(window)
    yield from wait_until(lambda: count("render_post", t_render) > 0, "the render")
    yield from wait_until(lambda: not bpy.app.is_job_running('RENDER'), "the render job")
    REPORT["render_seconds"] = now() - t_render
    log(f"render done in {REPORT['render_seconds']:.1f} s; waiting for the add-on")
    t_post = min(t for t, n in EVENTS if n == "render_post" and t >= t_render)
    yield from wait_until(lambda: node.status.startswith(("Frame", "Error")),
                          "the add-on's AO computation")
    REPORT["status_after_render"] = node.status
    log(f"node status: {node.status}")
    yield from wait_quiet(now())
    if ARGS.render_display == "SPLIT":
        show_render_result(window)
        yield 0.5
    REPORT["after_render"] = check("after_render", scene, node, t_post)
    REPORT["image_editors"] = image_editors(bpy.context.window_manager)

    frame_node_tree(window, node)  # again: the areas have their final sizes now
    yield 1.0
    screenshot(window, os.path.join(OUT, "compositor_node.png"))
    for index, other in enumerate(bpy.context.window_manager.windows[1:], start=1):
        screenshot(other, os.path.join(OUT, f"window_{index}.png"))
    screenshot_x_root(os.path.join(OUT, "screen.png"))

    # a workspace switch after the render (e.g. from Layout to Compositing)
    if ARGS.after_workspace:
        t_switch = now()
        window.workspace = bpy.data.workspaces[ARGS.after_workspace]
        log(f"switched to workspace {ARGS.after_workspace}")
        yield 1.0
        yield from wait_quiet(t_switch)
        REPORT["after_workspace"] = check("after_workspace", scene, node, t_switch)

    # a property change: recompute from the exported passes, no render
    if ARGS.change:
        name, value = ARGS.change.split("=", 1)
        old = getattr(node, name)
        t_change = now()
        renders_before = count("render_pre")
        setattr(node, name, type(old)(value))
        log(f"set {name} {old} -> {getattr(node, name)}")
        REPORT["change"] = {"property": name, "old": old, "new": getattr(node, name),
                            "status": node.status}
        yield 0.5
        yield from wait_quiet(t_change)
        REPORT["change"]["renders_meanwhile"] = count("render_pre") - renders_before
        REPORT["change"]["check"] = check("after_change", scene, node, t_change)
        screenshot(window, os.path.join(OUT, "after_change.png"))


def check(label, scene, node, since):
    path = os.path.join(OUT, f"render_result_{label}.exr")
    save_render_result(scene, path)
    result = compare(path, node_ao(node))
    result["compositor_jobs_since"] = count("composite_post", since)
    log(f"{label}: {json.dumps(result)}")
    return result


def verdict(result):
    if not result:
        return "not checked"
    if "ao_applied" not in result:
        return result.get("skipped") or result.get("error", "?")
    difference = result["max_abs_composite_minus_combined_x_ao"]
    return ("AO applied" if result["ao_applied"] else "AO NOT applied") + \
        f" (max |Composite - Combined x AO| {difference:.2g}," \
        f" compositor jobs {result['compositor_jobs_since']})"


def finish(code):
    log(f"RESULT workspace {ARGS.workspace}, render display {ARGS.render_display}: "
        f"after F12: {verdict(REPORT.get('after_render'))}")
    if ARGS.after_workspace:
        log(f"RESULT after switching to {ARGS.after_workspace}: "
            f"{verdict(REPORT.get('after_workspace'))}")
    if "change" in REPORT:
        change = REPORT["change"]
        log(f"RESULT after {change['property']} {change['old']!r} -> {change['new']!r}: "
            f"{verdict(change.get('check'))}, renders meanwhile "
            f"{change.get('renders_meanwhile')}")
    REPORT["seconds"] = now()
    REPORT["exit_code"] = code
    with open(os.path.join(OUT, "ui_report.json"), "w") as stream:
        json.dump(REPORT, stream, indent=2, default=str)
    with open(os.path.join(OUT, "ui_events.txt"), "w") as stream:
        stream.writelines(f"{t:8.2f} {name}\n" for t, name in EVENTS)
    log(f"report: {os.path.join(OUT, 'ui_report.json')}")
    if code:
        os._exit(code)
    bpy.ops.wm.quit_blender()


_steps = None


def _tick():
    global _steps
    try:
        if _steps is None:
            _steps = scenario()
        return next(_steps)
    except StopIteration:
        finish(0)
    except Exception as error:  # report and quit, never leave a UI Blender hanging
        traceback.print_exc()
        REPORT["error"] = f"{type(error).__name__}: {error}"
        finish(1)
    return None


def main():
    os.makedirs(OUT, exist_ok=True)
    for name, handler in _HANDLERS:
        getattr(bpy.app.handlers, name).append(handler)
    bpy.app.timers.register(_tick, first_interval=1.0, persistent=True)


main()
