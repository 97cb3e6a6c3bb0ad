# SPDX-License-Identifier: MIT
"""Reading the scanline OpenEXR files Blender writes for multilayer output (channels named
layer.pass.channel; single-part before 5.x, one part per layer in 5.x) with no compression or
ZIP/ZIPS, and writing them single-part: enough to put
the re-composited image and the AO into a render's multilayer file. Blender's Python has no
EXR writer that takes arbitrary channels, so this one is pure numpy + zlib (no bpy: tested
from plain Python against OpenImageIO in tests/python/test_multilayer.py).

Format: OpenEXR file layout, openexr.com "OpenEXR File Layout" (magic, version, header
attributes, offset table, chunks; ZIP = byte interleave + delta predictor + zlib)."""
import concurrent.futures
import os
import struct
import zlib

import numpy as np

MAGIC = 20000630
NO_COMPRESSION, ZIPS_COMPRESSION, ZIP_COMPRESSION = 0, 2, 3
LINES_PER_CHUNK = {NO_COMPRESSION: 1, ZIPS_COMPRESSION: 1, ZIP_COMPRESSION: 16}
HALF, FLOAT = 1, 2
MAX_PIXELS = 1 << 28  # 16384 x 16384: a larger data window is taken for a damaged header
CODECS = {"NONE": NO_COMPRESSION, "ZIPS": ZIPS_COMPRESSION, "ZIP": ZIP_COMPRESSION}
# Written again from the channels; any other attribute of the source is copied as it is.
_REWRITTEN = {"channels", "compression", "dataWindow", "displayWindow", "lineOrder", "chunkCount"}
_DTYPES = {HALF: np.dtype("<f2"), FLOAT: np.dtype("<f4")}


class ExrError(RuntimeError):
    pass


def _cstring(data, at):
    end = data.index(b"\0", at)
    return data[at:end].decode("utf-8", "replace"), end + 1


def _read_headers(data):
    """[(attributes, ...)] of each part, the offset where the offset tables start, multi-part."""
    if len(data) < 8 or struct.unpack_from("<i", data, 0)[0] != MAGIC:
        raise ExrError("not an OpenEXR file")
    version = struct.unpack_from("<I", data, 4)[0]
    if version & 0x200:
        raise ExrError("tiled OpenEXR files are not supported")
    if version & 0x800:
        raise ExrError("deep OpenEXR files are not supported")
    multipart = bool(version & 0x1000)
    at, headers, attributes = 8, [], {}
    while True:
        if at >= len(data):
            raise ExrError("truncated header")
        if data[at] == 0:
            at += 1
            if not multipart:
                return [attributes], at, False
            if not attributes:  # the empty header that ends a multi-part file's list
                return headers, at, True
            headers.append(attributes)
            attributes = {}
            continue
        name, at = _cstring(data, at)
        kind, at = _cstring(data, at)
        size = struct.unpack_from("<i", data, at)[0]
        at += 4
        if size < 0 or at + size > len(data):
            raise ExrError(f"truncated attribute {name}")
        attributes[name] = (kind, data[at:at + size])
        at += size


def _channels(raw):
    out, at = [], 0
    while raw[at] != 0:
        name, at = _cstring(raw, at)
        pixel_type = struct.unpack_from("<i", raw, at)[0]
        x_sampling, y_sampling = struct.unpack_from("<ii", raw, at + 8)
        if pixel_type not in _DTYPES or (x_sampling, y_sampling) != (1, 1):
            raise ExrError(f"channel {name}: only unsubsampled half and float are supported")
        out.append((name, pixel_type))
        at += 16
    return out


def _unzip(block, expected):
    # Never more than the chunk can hold: a damaged chunk could inflate to gigabytes.
    raw = np.frombuffer(zlib.decompressobj().decompress(block, expected + 1), np.uint8)
    if raw.size != expected:
        raise ExrError("corrupt ZIP chunk")
    # Undo the predictor (running sum of deltas - 128, mod 256: uint8 arithmetic wraps), then
    # the interleave.
    values = np.cumsum(raw - np.uint8(128), dtype=np.uint8) + np.uint8(128)
    half = (raw.size + 1) // 2
    out = np.empty(raw.size, np.uint8)
    out[0::2], out[1::2] = values[:half], values[half:]
    return out


def _zip(data):
    raw = np.frombuffer(data, np.uint8)
    interleaved = np.concatenate([raw[0::2], raw[1::2]])
    deltas = np.empty_like(interleaved)
    deltas[0] = interleaved[0]
    deltas[1:] = (interleaved[1:].astype(np.int16) - interleaved[:-1] + 128 + 256) % 256
    return zlib.compress(deltas.tobytes(), 6)


def _read_part(data, path, attributes, offsets, multipart, planes, threads):
    for name in ("channels", "compression", "dataWindow"):
        if name not in attributes:
            raise ExrError(f"{path}: the header has no {name}")
    if attributes.get("type", ("", b"scanlineimage"))[1].rstrip(b"\0") != b"scanlineimage":
        raise ExrError(f"{path}: only scanline images are supported")
    channels = _channels(attributes["channels"][1])
    compression = attributes["compression"][1][0]  # checked by _read
    x0, y0, x1, y1 = struct.unpack("<4i", attributes["dataWindow"][1])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    if width <= 0 or height <= 0 or width * height > MAX_PIXELS:
        raise ExrError(f"{path}: a data window of {width} x {height} pixels")
    lines = LINES_PER_CHUNK[compression]
    line_bytes = sum(width * _DTYPES[t].itemsize for _, t in channels)
    for name, _ in channels:
        if name in planes:
            raise ExrError(f"{path}: the channel {name} is in two parts")
    # A line holds each channel's row in turn: with one pixel type, a chunk is a (lines,
    # channels, width) array, copied in one go (a copy per row and channel costs seconds at
    # 2K x 1.5K).
    one_type = len({t for _, t in channels}) == 1
    stack = np.zeros((len(channels), height, width), np.float32)
    filled = np.zeros(height, bool)
    skip = 4 if multipart else 0  # a multi-part file's chunks start with their part number

    def decode(offset):  # one chunk into its rows of `stack` (each chunk has rows of its own)
        if offset + skip + 8 > len(data):
            raise ExrError(f"{path}: truncated")
        y, size = struct.unpack_from("<ii", data, offset + skip)
        block = data[offset + skip + 8:offset + skip + 8 + size]
        row0 = y - y0
        count = min(lines, height - row0)
        if len(block) != size or row0 < 0 or count <= 0:
            raise ExrError(f"{path}: truncated or corrupt chunk")
        if size < count * line_bytes:
            block = _unzip(block, count * line_bytes)
        if one_type and channels:
            values = np.frombuffer(block, _DTYPES[channels[0][1]], count * len(channels) * width)
            stack[:, row0:row0 + count] = values.reshape(count, len(channels), width).swapaxes(0, 1)
        else:
            at_block = 0
            for row in range(row0, row0 + count):
                for index, (_, pixel_type) in enumerate(channels):
                    dtype = _DTYPES[pixel_type]
                    stack[index, row] = np.frombuffer(block, dtype, width, at_block)
                    at_block += width * dtype.itemsize
        filled[row0:row0 + count] = True

    # zlib and numpy let go of Python's lock while they work: the chunks decode on every core
    # (a 4448 x 2768 helper render of 16 channels: 6.5 s in turn, 3.1 s on two threads).
    with concurrent.futures.ThreadPoolExecutor(thread_count(threads)) as pool:
        list(pool.map(decode, offsets))
    if not filled.all():
        raise ExrError(f"{path}: {int((~filled).sum())} rows have no data")
    for index, (name, _) in enumerate(channels):
        planes[name] = stack[index]


def thread_count(threads=None):
    """`threads`, or for None or 0 the cores this process may run on."""
    if threads:
        return threads
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # Windows and macOS have no affinity call
        return os.cpu_count() or 1


def read(path, threads=None):
    """{channel name: (height, width) float32 array, row 0 on top} of every part, and the
    first part's attributes. The chunks decode on `threads` threads (None or 0: one per core)."""
    with open(path, "rb") as f:
        data = f.read()
    try:
        return _read(data, path, threads)
    except (struct.error, zlib.error, ValueError, IndexError, KeyError) as error:
        raise ExrError(f"{path}: corrupt or truncated ({error})") from None


def _read(data, path, threads):
    headers, at, multipart = _read_headers(data)
    planes = {}
    for attributes in headers:
        if "dataWindow" not in attributes or "compression" not in attributes:
            raise ExrError(f"{path}: the header has no dataWindow or compression")
        x0, y0, x1, y1 = struct.unpack("<4i", attributes["dataWindow"][1])
        compression = attributes["compression"][1][0]
        if compression not in LINES_PER_CHUNK:
            raise ExrError(f"{path}: compression {compression} is not supported (NONE, ZIP, "
                           "ZIPS)")
        lines = LINES_PER_CHUNK[compression]
        chunks = (y1 - y0 + lines) // lines
        if chunks <= 0 or chunks > MAX_PIXELS:
            raise ExrError(f"{path}: a data window of {y1 - y0 + 1} rows")
        if at + 8 * chunks > len(data):
            raise ExrError(f"{path}: truncated offset table")
        offsets = struct.unpack_from(f"<{chunks}Q", data, at)
        at += 8 * chunks
        _read_part(data, path, attributes, offsets, multipart, planes, threads)
    first = {k: v for k, v in headers[0].items() if k not in ("name", "type")}
    return planes, first


def _attribute(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def write(path, planes, attributes=None, half=False, codec="ZIP", overscan=0):
    """Writes {channel name: (height, width) array, row 0 on top} as a single-part scanline
    EXR; `attributes` (as read() returns them) are copied but for the ones written anew. half:
    colour channels (R, G, B, A) in 16 bits, the others (depth, normals, vectors, AO's V) in 32,
    as Blender writes a 16-bit multilayer file. overscan G: the planes are a guard band of G
    pixels around the image, written as OpenEXR's overscan: a data window from (-G, -G) around
    a display window of (width - 2G) x (height - 2G) at (0, 0)."""
    compression = CODECS.get(codec, ZIP_COMPRESSION)
    names = sorted(planes)
    height, width = planes[names[0]].shape
    for name in names:
        if planes[name].shape != (height, width):
            raise ExrError(f"{path}: channel {name} is {planes[name].shape[1]} x "
                           f"{planes[name].shape[0]}, not {width} x {height}")
    types = {n: HALF if half and n.rsplit(".", 1)[-1] in ("R", "G", "B", "A") else FLOAT
             for n in names}
    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", types[n], 0, 1, 1)
                      for n in names) + b"\0"
    if not 0 <= 2 * overscan < min(width, height):
        raise ExrError(f"{path}: an overscan of {overscan} pixels does not fit {width} x {height}")
    data_window = struct.pack("<4i", -overscan, -overscan, width - overscan - 1,
                              height - overscan - 1)
    display_window = struct.pack("<4i", 0, 0, width - 2 * overscan - 1,
                                 height - 2 * overscan - 1)
    header = [_attribute("channels", "chlist", chlist),
              _attribute("compression", "compression", bytes([compression])),
              _attribute("dataWindow", "box2i", data_window),
              _attribute("displayWindow", "box2i", display_window),
              _attribute("lineOrder", "lineOrder", b"\0")]
    defaults = {"pixelAspectRatio": ("float", struct.pack("<f", 1.0)),
                "screenWindowCenter": ("v2f", struct.pack("<2f", 0.0, 0.0)),
                "screenWindowWidth": ("float", struct.pack("<f", 1.0))}
    for name, (kind, value) in {**defaults, **(attributes or {})}.items():
        if name not in _REWRITTEN:
            header.append(_attribute(name, kind, value))
    long_names = any(len(n) > 31 for n in names) or \
        any(len(n) > 31 for n in (attributes or {}))
    head = struct.pack("<iI", MAGIC, 2 | (0x400 if long_names else 0)) + b"".join(header) + b"\0"

    lines = LINES_PER_CHUNK[compression]
    columns = [np.ascontiguousarray(planes[n], dtype=_DTYPES[types[n]]) for n in names]
    chunks = []
    for row0 in range(0, height, lines):
        rows = range(row0, min(row0 + lines, height))
        block = b"".join(column[row].tobytes() for row in rows for column in columns)
        if compression != NO_COMPRESSION:
            packed = _zip(block)
            if len(packed) < len(block):
                block = packed
        # A chunk names its first line by its y, the data window's (-G on top).
        chunks.append(struct.pack("<ii", row0 - overscan, len(block)) + block)
    offset = len(head) + 8 * len(chunks)
    table = []
    for chunk in chunks:
        table.append(offset)
        offset += len(chunk)
    temporary = path + ".part"
    try:
        with open(temporary, "wb") as f:
            f.write(head)
            f.write(struct.pack(f"<{len(table)}Q", *table))
            for chunk in chunks:
                f.write(chunk)
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.remove(temporary)
        raise


def rewrite(passes_path, composite_path, ao_layers, out_path, half=False, codec="ZIP"):
    """The render's multilayer file, written anew: every pass of `passes_path`, its Composite
    layer replaced by the RGBA of `composite_path`, and `ao_layers` ({layer.pass name: (height,
    width) AO}) added as one-channel passes (channel V)."""
    planes, attributes = read(passes_path)
    composite, _ = read(composite_path)
    for channel in "RGBA":
        if channel in composite:
            planes[f"Composite.Combined.{channel}"] = composite[channel]
    for name, ao in ao_layers.items():
        planes[f"{name}.V"] = ao
    write(out_path, planes, attributes, half=half, codec=codec)
