"""Independent reader for the scanline OpenEXR files the add-on and libvsgl
write (NONE, ZIPS, ZIP compression; HALF/FLOAT channels), from the OpenEXR
file-layout spec. Test helper only."""
import struct
import zlib

import numpy as np

_LINES = {0: 1, 2: 1, 3: 16}  # compression -> scanlines per block


def _header(data, pos):
    """(attrs, position after the header's terminating null)."""
    attrs = {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        pos = end + 1
        end = data.index(b"\0", pos)
        typ = data[pos:end].decode()
        pos = end + 1
        size, = struct.unpack_from("<i", data, pos)
        pos += 4
        attrs[name] = (typ, data[pos:pos + size])
        pos += size
    return attrs, pos + 1


def _channels(attrs):
    chans = []
    raw = attrs["channels"][1]
    p = 0
    while raw[p] != 0:
        end = raw.index(b"\0", p)
        name = raw[p:end].decode()
        ptype, = struct.unpack_from("<i", raw, end + 1)
        chans.append((name, ptype))
        p = end + 1 + 16
    return chans


def _decode_part(data, attrs, offsets, multipart):
    chans = _channels(attrs)
    comp = attrs["compression"][1][0]
    x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"][1])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    lines = _LINES[comp]
    out = {n: np.zeros((h, w), np.float32) for n, _ in chans}
    for off in offsets:
        if multipart:
            off += 4                       # the chunk's part number
        y, size = struct.unpack_from("<ii", data, off)
        block = data[off + 8: off + 8 + size]
        nl = min(lines, y1 + 1 - y)
        expected = sum(nl * w * (2 if t == 1 else 4) for _, t in chans)
        if comp != 0 and size < expected:
            t = np.frombuffer(zlib.decompress(block), np.uint8).astype(np.int32)
            t = np.cumsum(np.concatenate([t[:1], t[1:] - 128])) & 0xFF  # predictor
            t = t.astype(np.uint8)
            half = (len(t) + 1) // 2
            inter = np.empty(len(t), np.uint8)
            inter[0::2] = t[:half]
            inter[1::2] = t[half:]
            block = inter.tobytes()
        q = 0
        for row in range(nl):
            for n, typ in chans:
                dt = np.dtype("<f2") if typ == 1 else np.dtype("<f4")
                nb = w * dt.itemsize
                out[n][y - y0 + row] = np.frombuffer(block[q:q + nb], dt).astype(np.float32)
                q += nb
    return out


def read_exr(path):
    """Return (channels dict name -> (H, W) float32, attributes dict of the
    first part). Single-part and multi-part (Blender 5's multilayer) files."""
    data = open(path, "rb").read()
    magic, version = struct.unpack_from("<ii", data, 0)
    assert magic == 20000630, "not an EXR"
    assert version & 0x200 == 0, "tiled files not supported"
    multipart = bool(version & 0x1000)
    pos = 8
    headers = []
    while True:
        attrs, pos = _header(data, pos)
        headers.append(attrs)
        if not multipart or data[pos] == 0:
            break
    if multipart:
        pos += 1                           # the empty header ending the list
    out = {}
    for attrs in headers:
        x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"][1])
        lines = _LINES[attrs["compression"][1][0]]
        nblocks = (y1 - y0 + lines) // lines
        if "chunkCount" in attrs:
            nblocks, = struct.unpack("<i", attrs["chunkCount"][1])
        offsets = struct.unpack_from("<%dQ" % nblocks, data, pos)
        pos += 8 * nblocks
        out.update(_decode_part(data, attrs, offsets, multipart))
    return out, headers[0]


def read_pass(path, layer_pass, comps="RGB"):
    ch, _ = read_exr(path)
    return np.dstack([ch["%s.%s" % (layer_pass, c)] for c in comps])
