#!/usr/bin/env python3
"""Write a small test scene bundle, independently of libvsgl, from
docs/bundle-format.md (struct + zlib.crc32).

  make_scene.py OUT.vsglb [--width W] [--height H] [--output PATH] [--frame N]
                [--no-settings] [--break KIND]

The scene: a 4 m room corner (floor, back wall, red left wall, a glossy
block) lit by a spot light 3.5 m above the floor pointing down, seen by a
50 mm camera 6 m in front. --break makes a bad file: truncate, magic,
version2, nan-position, nan-power, huge-count, crc."""
import argparse
import struct
import sys
import zlib

MAGIC = b"\x89VSGLB\r\n"


def section(tag, esize, count, payload):
    head = struct.pack("<4sIQI", tag.encode("ascii"), esize, count, 0)
    crc = zlib.crc32(head + payload) & 0xFFFFFFFF
    pad = b"\0" * ((-len(payload)) % 8)
    return head + struct.pack("<I", crc) + payload + pad


def quad(verts, tris, a, b, c, d, mat, mids):
    base = len(verts)
    verts += [a, b, c, d]
    tris += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    mids += [mat, mat]


def build(args):
    verts, tris, mids = [], [], []
    quad(verts, tris, (-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0), 0, mids)        # floor, white
    quad(verts, tris, (-2, 2, 0), (2, 2, 0), (2, 2, 4), (-2, 2, 4), 0, mids)          # back wall
    quad(verts, tris, (-2, -2, 0), (-2, 2, 0), (-2, 2, 4), (-2, -2, 4), 1, mids)      # left wall, red
    quad(verts, tris, (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1), 2, mids)            # block top, glossy
    quad(verts, tris, (0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1), 2, mids)            # block front
    pos = b"".join(struct.pack("<3f", *v) for v in verts)
    idx = b"".join(struct.pack("<3I", *t) for t in tris)
    midx = b"".join(struct.pack("<I", m) for m in mids)
    # materials: base_color[3], metallic, roughness, specular_f0, anisotropy, rotation, flags, reserved
    mats = [(0.8, 0.8, 0.8, 0, 0.9, 0.04, 0, 0, 0, 0),
            (0.8, 0.1, 0.1, 0, 0.9, 0.04, 0, 0, 0, 0),
            (0.2, 0.3, 0.8, 0, 0.25, 0.04, 0, 0, 0, 0)]
    matl = b"".join(struct.pack("<8fII", *m) for m in mats)
    # spot light at (0, 0, 3.5), identity rotation: emits along -Z (down)
    m = (1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 3.5)
    power = float("nan") if args.break_ == "nan-power" else 500.0
    light = struct.pack("<ii3ff12f7fI", 1, 0, 1, 1, 1, power, *m, 0.05, 1.2, 0.2, 0, 1, 1, 3.14159265, 0)
    nlights = 1
    if args.light_up:
        # a second spot 3.5 m up pointing up (+Z: rotated 180 degrees about X): lights nothing
        up = (1, 0, 0, 0, 0, -1, 0, 0, 0, 0, -1, 3.5)
        light += struct.pack("<ii3ff12f7fI", 1, 0, 1, 1, 1, 100.0, *up, 0.05, 0.5, 0.2, 0, 1, 1, 3.14159265, 0)
        nlights = 2
    if args.no_lights:
        light, nlights = b"", 0
    # camera at (0, -6, 2) looking along +Y: columns X->(1,0,0), Y->(0,0,1), Z->(0,-1,0)
    cm = (1, 0, 0, 0, 0, 0, -1, -6, 0, 1, 0, 2)
    cam = struct.pack("<ii12f8fII2f", 0, 0, *cm, 35, 36, 24, 6, 0, 0, 0.1, 100,
                      args.width, args.height, 1, 1)
    # settings (format 1.0's 44-byte record, which 1.1 readers still accept: the
    # fields added since read as 0 = default): method, aa, rsm, fit, vsgls,
    # fis_iterations, sharpness, diffuse (0 = accurate), glossy, visibility, seed
    rset = struct.pack("<iIIiIIiiiiI", 0, 1, 64, 0, 4, 8, 0, 0, 0, 0, 3)
    if args.break_ == "nan-position":
        pos = pos[:4] + struct.pack("<f", float("nan")) + pos[8:]
    secs = [section("POS ", 12, len(verts), pos), section("IDX ", 12, len(tris), idx),
            section("MIDX", 4, len(tris), midx), section("MATL", 40, len(mats), matl),
            section("LGHT", 104, nlights, light), section("CAM ", 104, 1, cam)]
    if not args.no_settings:
        secs.append(section("RSET", 44, 1, rset))
    if args.output:
        o = args.output.encode("utf-8")
        secs.append(section("OUTP", 1, len(o), o))
    if args.frame is not None:
        secs.append(section("FRME", 4, 1, struct.pack("<i", args.frame)))
    if args.break_ == "huge-count":
        h = bytearray(secs[0])
        struct.pack_into("<Q", h, 8, 1 << 40)
        secs[0] = bytes(h)
    body = b"".join(secs)
    major = 2 if args.break_ == "version2" else 1
    size = 40 + len(body)
    head = MAGIC + struct.pack("<IIIIQI", major, 0, 40, len(secs), size, 0)
    head += struct.pack("<I", zlib.crc32(head) & 0xFFFFFFFF)
    data = bytearray(head + body)
    if args.break_ == "truncate":
        data = data[:len(data) // 2]
    elif args.break_ == "magic":
        data[0:4] = b"PK\x03\x04"
    elif args.break_ == "crc":
        data[60] ^= 0x10
    return bytes(data)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("out")
    p.add_argument("--width", type=int, default=64)
    p.add_argument("--height", type=int, default=48)
    p.add_argument("--output")
    p.add_argument("--frame", type=int)
    p.add_argument("--no-settings", action="store_true")
    p.add_argument("--light-up", action="store_true", help="add a spot light that lights nothing")
    p.add_argument("--no-lights", action="store_true", help="a scene without lights")
    p.add_argument("--break", dest="break_", default=None)
    args = p.parse_args()
    with open(args.out, "wb") as f:
        f.write(build(args))
    return 0


if __name__ == "__main__":
    sys.exit(main())
