# SPDX-License-Identifier: MIT
"""Drives Blender's UI (under Xvfb) through an F12 render with the Ambient Occlusion (SSAO)
compositor node, checks that the Render Result gets the AO, changes a node property, and takes
a screenshot of the window.

    xvfb-run -a -s "-screen 0 1600x900x24" blender --factory-startup -noaudio \
        --addons ssao_compositor SCENE.blend --python scripts/blender/ui_screenshot.py -- \
        --out DIR [--workspace Compositing|Layout] [--render-display SPLIT|WINDOW|NONE]
        [--after-workspace NAME] [--change radius=1.5] [--compositor-device CPU|GPU]
        [--sidebar] [--timeout 240]

With the add-on installed as an extension (4.2+; e.g. Blender 5.2 through
scripts/blender/blender52.sh), enable it as --addons bl_ext.user_default.ssao_compositor.
Tested in Blender 3.4.1 and 5.2.2.

SCENE.blend is a scene whose compositor has an SSAO node between Render Layers and Composite
(in 5.x: the compositing node group's Group Output) (tests/blender/build_ssao_scene.py makes
one; with BLENDER_USER_SCRIPTS pointing at a folder whose addons/ holds ssao_compositor when it
is not installed in the user's profile).

Everything runs from timers once the UI is up:
  0. the file is opened again (when it is saved and unchanged): this closes the Quick Setup
     splash that 5.2 showed over the file given on the command line (measured with a fresh
     BLENDER_USER_CONFIG, i.e. no saved preferences); it would cover the editors.
  1. layout: the given workspace ("Compositing" has a compositor Node Editor, "Layout" has
     none). With --render-display SPLIT (default; needs Compositing) the compositor editor
     gets the window, its right part becomes an Image Editor showing the Render Result, and F12
     renders into it (preferences: render in "Keep User Interface"); WINDOW is Blender's
     default (F12 opens a new window with an Image Editor); NONE renders with no Image Editor.
     The SSAO node is selected and the node tree framed (its properties are on the node).
     --sidebar opens the compositor editor's sidebar (N panel) on its Node tab, whose
     Properties panel shows the active node's draw_buttons_ext (3.4 closes that panel by
     default: the script registers Blender's panel class again without DEFAULT_CLOSED). In
     3.4 choosing the tab needs Blender's --enable-event-simulate (a simulated click; real
     input, such as Xvfb's pointer in the middle of the screen, is then ignored: with it, no
     tooltip shows in the screenshots).
     --compositor-device sets the scene's compositor device first (4.2+; 5.2's default is
     GPU; 3.4 has only the CPU one); the report says which one ran.
  2. F12: bpy.ops.render.render('INVOKE_DEFAULT'); waits for the render job, then for the
     add-on's main-thread timer (the node's status "Frame N: ... ms", or "AO computed; open a
     compositor Node Editor ..." when none is open), then until no render or
     compositor job ran for --settle seconds (compositor jobs are counted with composite_post).
  3. check: saves the Render Result as a multilayer EXR (its Combined pass = the beauty, its
     Composite layer = what the compositor made; single-part before 5.0, one part per layer in
     5.x) and compares Composite with Combined x AO (the node's AO image): "AO applied" when
     they agree to 1e-3. The EXR is read with the add-on's own reader (multilayer.py: numpy +
     zlib), so no OpenImageIO is needed in Blender's Python (5.2 in its Debian sid folder has
     none).
  4. screenshots: DIR/compositor_node.png (the main window), DIR/window_N.png for any other
     window (the render window with WINDOW), DIR/screen.png (the whole X screen: every window
     as the user sees it). Each is bpy.ops.screen.screenshot's image when that has any
     non-black pixel (3.4 under Xvfb; its other windows come out garbled), else the window's
     rectangle read from the X server (GetImage, x11_capture below): 5.2 under Xvfb with Mesa's
     llvmpipe reads back an all-black frame buffer. screen.png comes from ImageMagick's
     `import` when installed, else from x11_capture.
  5. --after-workspace NAME: switches the main window to that workspace, waits, checks again.
  6. --change NAME=VALUE: sets that node property (its update callback recomputes from the
     exported passes and nudges the compositor), waits, checks again, counts the renders that
     ran meanwhile (should be 0), and saves DIR/after_change.png.
  7. prints "ui_screenshot [...] RESULT ..." lines, writes DIR/ui_report.json (every
     measurement) and DIR/ui_events.txt (handler events with times), and quits.

Exit status: 0 when the run completed (whatever the checks found: read ui_report.json);
1 on a timeout or an exception. The comparison needs numpy in Blender's Python (bundled with
Blender; Debian's Blender uses the system's python3-numpy).
"""
import argparse
import json
import os
import socket
import struct
import sys
import time
import traceback
import zlib

import bpy

NODE_IDNAME = "CompositorNodeSSAO"
# max |Composite - Combined x AO| for "AO applied" (float EXR, linear), the AO as the node
# composites it: lighter on silhouettes against the sky (the factor of node_ao's channel 1).
AGREEMENT = 1e-3


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
    parser.add_argument("--compositor-device", choices=("CPU", "GPU"), default=None,
                        help="set scene.render.compositor_device (4.2+); default: the file's")
    parser.add_argument("--sidebar", action="store_true",
                        help="open the compositor editor's sidebar on its Node tab")
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
    @bpy.app.handlers.persistent  # kept when the file is opened again (step 0)
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


def tidy_node_editor(window, node):
    """No backdrop, no sidebar (unless --sidebar), no asset shelf (4.x/5.x). Region sizes change
    at the next redraw, which shifts the view: frame the tree in a later timer step."""
    area = find_area(window, "CompositorNodeTree")
    if area is not None:
        space = area.spaces.active
        space.show_backdrop = False
        if ARGS.sidebar:
            open_node_properties_panel()
            node.id_data.nodes.active = node  # the Node tab shows the active node
        space.show_region_ui = ARGS.sidebar
        if hasattr(space, "show_region_asset_shelf"):
            space.show_region_asset_shelf = False
    return area is not None


def open_node_properties_panel():
    """Blender 3.4's Node tab has its Properties panel (the active node's draw_buttons_ext)
    closed by default (bl_options DEFAULT_CLOSED; 4.x and 5.x open) and no Python API opens
    a panel: the class is registered again without that option, before the sidebar first
    draws."""
    panel = getattr(bpy.types, "NODE_PT_active_node_properties", None)
    if panel is None or 'DEFAULT_CLOSED' not in getattr(panel, "bl_options", ()):
        return
    bpy.utils.unregister_class(panel)
    panel.bl_options = set(panel.bl_options) - {'DEFAULT_CLOSED'}
    bpy.utils.register_class(panel)


def sidebar_on_node_tab(window):
    """Generator step: the compositor editor's sidebar on its Node tab. 5.2 chooses tabs from
    Python (Region.active_panel_category). 3.4 cannot, and its factory startup file opens
    the sidebar on the Tool tab: the script clicks the Node tab (the top one, at the region's
    right edge) when Blender runs with --enable-event-simulate (Window.event_simulate; the
    pointer must have moved there in an earlier event loop). REPORT["sidebar_tab"] says
    how the tab was chosen."""
    area = find_area(window, "CompositorNodeTree")
    region = next((r for r in area.regions if r.type == 'UI'), None) if area else None
    if region is None or region.width <= 1:
        REPORT["sidebar_tab"] = "no sidebar"
    elif hasattr(region, "active_panel_category"):
        try:
            region.active_panel_category = "Node"
            REPORT["sidebar_tab"] = region.active_panel_category
        except (TypeError, AttributeError, ValueError) as error:
            REPORT["sidebar_tab"] = f"cannot choose the Node tab: {error}"
    elif not bpy.app.use_event_simulate:
        REPORT["sidebar_tab"] = "not chosen (3.4: run Blender with --enable-event-simulate)"
    else:
        scale = bpy.context.preferences.system.ui_scale
        x = region.x + region.width - round(10 * scale)
        y = region.y + region.height - round(30 * scale)
        window.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=y)
        yield 0.3
        window.event_simulate(type='LEFTMOUSE', value='PRESS', x=x, y=y)
        yield 0.1
        window.event_simulate(type='LEFTMOUSE', value='RELEASE', x=x, y=y)
        yield 0.3
        REPORT["sidebar_tab"] = f"clicked at ({x}, {y}) in the window"
    if area is not None and bpy.app.use_event_simulate:
        # the pointer to an empty spot of the editor: no tooltip in the screenshots
        window.event_simulate(type='MOUSEMOVE', value='NOTHING', x=area.x + 40, y=area.y + 40)
        yield 0.3
    log(f"sidebar tab: {REPORT['sidebar_tab']}")


def preview_height(node):
    """5.x draws a node's preview above the node, outside node.dimensions (3.4 inside): about
    the node's width x the render's aspect ratio."""
    if bpy.app.version < (5, 0, 0) or not getattr(node, "show_preview", False):
        return 0.0
    render = bpy.context.scene.render
    return node.dimensions.x * render.resolution_y / max(render.resolution_x, 1)


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
    top = max(n.location.y + preview_height(n) for n in tree.nodes)
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
    """Generator step: the compositor editor gets the whole window (the other areas are
    closed), and its right part becomes an Image Editor (for the Render Result)."""
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
    # Its final type at once, before any redraw: Blender 3.4 sets up the split-off copy of
    # the Node Editor only when it first draws it, and a scene/nodes notifier that reaches
    # the copy before then crashes Blender (a NULL write in the node editor's listener; every
    # run with an empty shader cache, whose first draw takes seconds). A vertical split puts
    # the new area on the right (3.4, 4.3, 5.2); its x and width are 0 until the next redraw.
    new[0].ui_type = 'IMAGE_EDITOR'
    yield 0.5
    REPORT["image_editor_on_the_right"] = new[0].x > area.x


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


def is_black(path):
    """True when the PNG at `path` has no non-black pixel (or cannot be read)."""
    import numpy as np
    try:
        image = bpy.data.images.load(path, check_existing=False)
    except RuntimeError:
        return True
    try:
        width, height = image.size
        pixels = np.empty(width * height * image.channels, np.float32)
        image.pixels.foreach_get(pixels)
        colour = pixels.reshape(-1, image.channels)[:, :3]
        return colour.size == 0 or float(colour.max()) == 0.0
    finally:
        bpy.data.images.remove(image)


def screenshot(window, path):
    """Blender's screenshot of `window`; when it is all black (5.2 under Xvfb), the window's
    rectangle as the X server shows it."""
    area = window.screen.areas[0]
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.screen.screenshot(filepath=path, check_existing=False)
    how = "bpy.ops.screen.screenshot"
    if is_black(path):
        try:
            write_png(path, x11_capture((window.x, window.y, window.width, window.height)))
            how = "X server (Blender's screenshot was all black)"
        except Exception as error:  # keep the black one, say why
            how = f"bpy.ops.screen.screenshot, all black; X capture failed: {error}"
    REPORT.setdefault("screenshots", {})[path] = how
    log(f"saved {path} ({how})")


def screenshot_x_root(path):
    """The whole X screen, every window as X shows it: ImageMagick's import when installed,
    else x11_capture."""
    import shutil
    import subprocess
    if not os.environ.get("DISPLAY"):
        return
    tool = shutil.which("import")
    if tool:
        result = subprocess.run([tool, "-window", "root", path], capture_output=True,
                                text=True, timeout=60)
        how = "import" if result.returncode == 0 else f"import failed: {result.stderr}"
    else:
        try:
            write_png(path, x11_capture())
            how = "X server"
        except Exception as error:
            how = f"X capture failed: {error}"
    REPORT.setdefault("screenshots", {})[path] = how
    log(f"saved {path} ({how})")


# --- reading the X screen without any X library (Blender's Python has none) ------------------
# X11 protocol (x.org "X Window System Protocol"): connection setup with the display's
# MIT-MAGIC-COOKIE-1 from $XAUTHORITY, then one GetImage (ZPixmap) of the root window.

def _pad4(n):
    return (4 - n % 4) % 4


def _xauth_cookie(display_number):
    """(auth name, cookie) for the display from the Xauthority file, or (b"", b"")."""
    path = os.environ.get("XAUTHORITY") or os.path.expanduser("~/.Xauthority")
    try:
        with open(path, "rb") as stream:
            data = stream.read()
    except OSError:
        return b"", b""
    at = 0

    def field():
        nonlocal at
        size, = struct.unpack_from(">H", data, at)
        value = data[at + 2:at + 2 + size]
        at += 2 + size
        return value

    while at + 2 <= len(data):
        at += 2  # address family
        field()  # address
        number, name, cookie = field(), field(), field()
        if name == b"MIT-MAGIC-COOKIE-1" and number in (b"", display_number.encode()):
            return name, cookie
    return b"", b""


def _receive(sock, size):
    chunks, left = [], size
    while left:
        chunk = sock.recv(min(left, 1 << 20))
        if not chunk:
            raise ConnectionError("the X server closed the connection")
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def x11_capture(rect=None):
    """The X screen ($DISPLAY), or its rectangle (x, y, width, height) in Blender's window
    coordinates (y from the bottom of the screen up: window.x, .y, .width, .height; measured
    with 5.2's render window under Xvfb, which has no window manager), as an (height, width,
    3) uint8 RGB array, row 0 on top. Needs a 24-bit TrueColor root window with 32 bits per
    pixel, least significant byte first (Xvfb's -screen WxHx24)."""
    import numpy as np
    host, _, rest = os.environ["DISPLAY"].rpartition(":")
    number = rest.split(".")[0]
    if host in ("", "unix"):
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.connect(f"/tmp/.X11-unix/X{number}")
    else:
        sock = socket.create_connection((host, 6000 + int(number)))
    with sock:
        sock.settimeout(30)
        name, cookie = _xauth_cookie(number)
        sock.sendall(struct.pack("<BxHHHHxx", ord("l"), 11, 0, len(name), len(cookie)) +
                     name + b"\0" * _pad4(len(name)) + cookie + b"\0" * _pad4(len(cookie)))
        status, reason_length, _, _, length = struct.unpack("<BBHHH", _receive(sock, 8))
        setup = _receive(sock, length * 4)
        if status != 1:
            raise ConnectionError("the X server refused the connection: " +
                                  setup[:reason_length].decode(errors="replace"))
        vendor_length, = struct.unpack_from("<H", setup, 16)
        format_count, byte_order = struct.unpack_from("<BB", setup, 21)
        bits_per_pixel = {}
        at = 32 + vendor_length + _pad4(vendor_length)
        for _ in range(format_count):
            depth, bits = struct.unpack_from("<BB", setup, at)
            bits_per_pixel[depth] = bits
            at += 8
        root, = struct.unpack_from("<I", setup, at)
        screen_width, screen_height = struct.unpack_from("<HH", setup, at + 20)
        x, y, width, height = rect or (0, 0, screen_width, screen_height)
        y = screen_height - y - height  # X counts from the top
        x, y = max(0, x), max(0, y)
        width, height = min(width, screen_width - x), min(height, screen_height - y)
        # GetImage (opcode 73), format ZPixmap (2), all planes
        sock.sendall(struct.pack("<BBHIhhHHI", 73, 2, 5, root, x, y, width, height,
                                 0xFFFFFFFF))
        reply = _receive(sock, 32)
        if reply[0] != 1:
            raise RuntimeError(f"X GetImage failed (error code {reply[1]})")
        depth = reply[1]
        length, = struct.unpack_from("<I", reply, 4)
        data = _receive(sock, length * 4)
    if depth != 24 or bits_per_pixel.get(depth) != 32 or byte_order != 0:
        raise RuntimeError(f"unsupported X screen: depth {depth}, "
                           f"{bits_per_pixel.get(depth)} bits per pixel, byte order {byte_order}")
    pixels = np.frombuffer(data, np.uint8, width * height * 4).reshape(height, width, 4)
    return pixels[:, :, 2::-1].copy()  # B, G, R, unused -> R, G, B


def write_png(path, rgb):
    """An 8-bit RGB PNG from an (height, width, 3) uint8 array, row 0 on top."""
    height, width, _ = rgb.shape
    raw = b"".join(b"\0" + rgb[row].tobytes() for row in range(height))

    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body +
                struct.pack(">I", zlib.crc32(kind + body)))

    with open(path, "wb") as stream:
        stream.write(b"\x89PNG\r\n\x1a\n" +
                     chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
                     chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def addon_module(name):
    """A module of the enabled add-on, whatever its package is called (ssao_compositor as a
    legacy add-on in 3.x, bl_ext.<repository>.ssao_compositor as an extension in 4.2+)."""
    return next(m for n, m in sys.modules.items() if n.endswith("ssao_compositor." + name))


# --- checking the Render Result --------------------------------------------------------------

def save_render_result(scene, path):
    """The Render Result as a 32-bit multilayer EXR (all passes and the Composite layer)."""
    addon_module("recomposite").save_passes(scene, path)


def node_ao(node, channel=0):
    """The node's AO image as (height, width), row 0 on top: channel 0 the AO, 1 the factor
    the node multiplies its Image by (the AO, lighter on silhouettes against the sky)."""
    import numpy as np
    image = node.node_tree.nodes["SSAO AO"].image
    width, height = image.size
    pixels = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(pixels)
    return pixels.reshape(height, width, 4)[::-1, :, channel].copy()


def compare(exr_path, ao, factor=None):
    """Composite vs Combined and vs Combined x AO (x `factor`, the node's, when given), from a
    multilayer Render Result EXR (read with the add-on's reader: every part of 5.x's
    multi-part files)."""
    import numpy as np
    planes, _ = addon_module("multilayer").read(exr_path)  # {channel: (h, w)}, row 0 on top
    names = list(planes)

    def channels(prefix):
        found = [planes.get(f"{prefix}.{c}") for c in "RGB"]
        return None if any(p is None for p in found) else np.stack(found, axis=-1)

    layers = [n[:-len(".R")] for n in names
              if n.endswith(".Combined.R") and not n.startswith("Composite.")]
    combined = channels(layers[0]) if layers else None
    composite = channels("Composite.Combined")
    result = {"channels": len(names), "combined_layer": layers[0] if layers else None}
    if combined is None or composite is None:
        result["error"] = f"Combined or Composite missing; channels: {names[:20]}"
        return result
    if composite.shape != ao.shape + (3,):
        result["error"] = f"Composite is {composite.shape[:2]}, the AO {ao.shape}"
        return result
    product = combined * (ao if factor is None else factor)[:, :, None]
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


def reopen_file():
    """Opens the file again (step 0): closes 5.2's Quick Setup splash. Only a saved, unchanged
    file (nothing is lost)."""
    if not bpy.data.filepath or bpy.data.is_dirty:
        return False
    bpy.ops.wm.open_mainfile(filepath=bpy.data.filepath)
    return True


def scenario():
    yield 1.0  # the UI is up
    REPORT["reopened"] = reopen_file()
    yield 1.0
    window = main_window()
    scene = bpy.context.scene
    node = ssao_node(scene)
    prefs = bpy.context.preferences
    prefs.use_preferences_save = False  # never write the user's preferences
    prefs.view.smooth_view = 0  # framing takes effect at once
    if ARGS.compositor_device and hasattr(scene.render, "compositor_device"):
        scene.render.compositor_device = ARGS.compositor_device
    REPORT["compositor_device"] = getattr(scene.render, "compositor_device", "CPU (only one)")
    REPORT["workspace"] = ARGS.workspace
    window.workspace = bpy.data.workspaces[ARGS.workspace]
    yield 0.5
    if ARGS.render_display == "SPLIT":
        yield from split_for_image_editor(window)
        prefs.view.render_display_type = 'NONE'
    else:
        prefs.view.render_display_type = ARGS.render_display
    yield 0.5
    tidy_node_editor(window, node)
    yield 0.5
    if ARGS.sidebar:
        yield 0.5
        yield from sidebar_on_node_tab(window)
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
    # "AO computed; open a compositor Node Editor ..." when none is open (e.g. Layout)
    yield from wait_until(lambda: node.status.startswith(("Frame", "Error", "AO computed")),
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
    """Saves DIR/render_result_LABEL.exr and the node's AO as DIR/ao_LABEL.npy (row 0 on top;
    for checking outside Blender), and compares them."""
    import numpy as np
    path = os.path.join(OUT, f"render_result_{label}.exr")
    save_render_result(scene, path)
    ao = node_ao(node)
    np.save(os.path.join(OUT, f"ao_{label}.npy"), ao)
    result = compare(path, ao, node_ao(node, channel=1))
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
    log(f"RESULT Blender {bpy.app.version_string}, workspace {ARGS.workspace}, render display "
        f"{ARGS.render_display}, compositor device {REPORT.get('compositor_device')}: "
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
