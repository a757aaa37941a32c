#!/usr/bin/env python3
"""Independent reference reader of the scene bundle, written from
docs/bundle-format.md only (struct + zlib.crc32), for the tests.

Usage: bundle_ref.py FILE          prints one line per item, e.g.
  version 1.0
  section POS  esize 12 count 4 crc ok
  ...
  positions 0.0 0.0 0.0 1.0 ...   (every float, %.9g)
Exit status 0 if every check of the document passes, 1 otherwise."""
import struct
import sys
import zlib

MAGIC = b"\x89VSGLB\r\n"


def main(path):
    data = open(path, "rb").read()
    ok = True
    if data[:8] != MAGIC:
        print("bad magic")
        return 1
    major, minor, header_size, nsec, file_size, flags = struct.unpack_from("<IIIIQI", data, 8)
    print("version %d.%d" % (major, minor))
    hcrc = struct.unpack_from("<I", data, header_size - 4)[0]
    if zlib.crc32(data[:header_size - 4]) != hcrc:
        print("header crc bad")
        ok = False
    if file_size != len(data):
        print("file size %d != %d" % (file_size, len(data)))
        ok = False
    at = header_size
    for _ in range(nsec):
        tag, esize, count, reserved, crc = struct.unpack_from("<4sIQII", data, at)
        nbytes = esize * count
        payload = data[at + 24:at + 24 + nbytes]
        good = zlib.crc32(data[at:at + 20] + payload) == crc
        print("section %s esize %d count %d crc %s" % (tag.decode("ascii"), esize, count, "ok" if good else "BAD"))
        ok = ok and good and reserved == 0
        pad = (-nbytes) % 8
        if data[at + 24 + nbytes:at + 24 + nbytes + pad] != b"\0" * pad:
            print("padding not zero")
            ok = False
        name = tag.decode("ascii").strip()
        if name in ("POS", "NRM", "UV", "TAN"):
            vals = struct.unpack_from("<%df" % (nbytes // 4), payload)
            print(name.lower(), " ".join("%.9g" % v for v in vals))
        elif name in ("IDX", "MIDX"):
            vals = struct.unpack_from("<%dI" % (nbytes // 4), payload)
            print(name.lower(), " ".join(str(v) for v in vals))
        elif name == "CAM":
            v = struct.unpack_from("<ii12f8fII2f", payload)
            print("camera type %d fit %d lens %.9g size %dx%d" % (v[0], v[1], v[14], v[22], v[23]))
        elif name == "LGHT":
            for i in range(count):
                v = struct.unpack_from("<ii3ff12f7fI", payload, i * esize)
                print("light %d type %d power %.9g" % (i, v[0], v[5]))
        elif name == "MATL":
            for i in range(count):
                v = struct.unpack_from("<8fII", payload, i * esize)
                print("material %d color %.9g %.9g %.9g roughness %.9g" % (i, v[0], v[1], v[2], v[4]))
        elif name == "RSET":
            v = struct.unpack_from("<iIIiIIiiiiI", payload)
            print("settings method %d aa %d rsm %d fit %d vsgls %d seed %d" % (v[0], v[1], v[2], v[3], v[4], v[10]))
        elif name == "OUTP":
            print("output", payload.decode("utf-8"))
        elif name == "FRME":
            print("frame", struct.unpack_from("<i", payload)[0])
        at += 24 + nbytes + pad
    if at != len(data):
        print("trailing bytes")
        ok = False
    print("ok" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
