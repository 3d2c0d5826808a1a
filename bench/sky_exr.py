#!/usr/bin/env python3
"""bench/sky_exr.py — a two-tone lat-long environment as an uncompressed OpenEXR file (no
dependencies): constant radiance SKY above the horizon and GROUND below it, for bench/figures.sh's
paper-kind FIV scenes (paper 004 Fig. 15: an overcast sky, the overlap correction's own assumption of
uniform radiance; Fig. 17: a bright ground, where light from below a receiver's horizon matters).

  bench/sky_exr.py OUT.exr SKY_R,SKY_G,SKY_B GROUND_R,GROUND_G,GROUND_B [WIDTH HEIGHT]

Rows follow the project's lat-long convention (formats/SCHEMA.md "environment": the first row at
+Y, the last at -Y, texel centres at integer rows); rows whose centre lies below the equator are
ground. Channels B, G, R as 32-bit floats, scanline order, no compression.
"""
import struct
import sys


def attr(name, kind, data):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(data)) + data


def write(path, sky, ground, width=128, height=64):
    channels = b"".join(c.encode() + b"\0" + struct.pack("<iBBBBii", 2, 0, 0, 0, 0, 1, 1) for c in "BGR") + b"\0"
    header = struct.pack("<ii", 20000630, 2)
    header += attr("channels", "chlist", channels)
    header += attr("compression", "compression", b"\0")
    header += attr("dataWindow", "box2i", struct.pack("<iiii", 0, 0, width - 1, height - 1))
    header += attr("displayWindow", "box2i", struct.pack("<iiii", 0, 0, width - 1, height - 1))
    header += attr("lineOrder", "lineOrder", b"\0")
    header += attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    header += attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0))
    header += attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
    header += b"\0"
    lines = []
    for y in range(height):
        value = ground if y > (height - 1) / 2 else sky
        data = b"".join(struct.pack("<%df" % width, *([value[c]] * width)) for c in (2, 1, 0))
        lines.append(struct.pack("<ii", y, len(data)) + data)
    offset = len(header) + 8 * height
    table = b""
    for line in lines:
        table += struct.pack("<Q", offset)
        offset += len(line)
    with open(path, "wb") as f:
        f.write(header + table + b"".join(lines))


if __name__ == "__main__":
    if len(sys.argv) not in (4, 6):
        sys.exit(__doc__)
    rgb = lambda s: tuple(float(x) for x in s.split(","))
    size = (int(sys.argv[4]), int(sys.argv[5])) if len(sys.argv) == 6 else (128, 64)
    write(sys.argv[1], rgb(sys.argv[2]), rgb(sys.argv[3]), *size)
