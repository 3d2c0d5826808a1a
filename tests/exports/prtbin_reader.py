#!/usr/bin/env python3
"""A reader of prtbake's plain binary export (PRTBIN), written from formats/SCHEMA.md "Exports"
with the standard library only (struct, json): an independent second reader for the tests.

    python3 prtbin_reader.py FILE.bin OUT.json

checks the layout the spec promises (magic, version, header length and padding, every array's
offset aligned, inside the file, not overlapping another, nbytes = prod(shape) * itemsize) and
writes {"header": <the JSON header>, "arrays": {name: flat list of values}} to OUT.json.
Exit status 1 with one line on stderr if the file breaks the spec.
"""
import json
import struct
import sys

ITEM = {"float32": ("f", 4), "float64": ("d", 8), "uint32": ("I", 4), "uint8": ("B", 1)}


def fail(msg):
    sys.stderr.write("prtbin_reader: " + msg + "\n")
    sys.exit(1)


def read_prtbin(path):
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 16 or data[:8] != b"PRTBIN\0\0":
        fail("bad magic")
    version, header_len = struct.unpack_from("<II", data, 8)
    if version != 1:
        fail("version %d" % version)
    if header_len % 16 != 0 or 16 + header_len > len(data):
        fail("header length %d" % header_len)
    header = json.loads(data[16:16 + header_len].decode("utf-8"))  # trailing spaces are JSON whitespace
    if header.get("format") != "prtbake-bin" or header.get("byte_order") != "little":
        fail("not a little-endian prtbake-bin header")
    arrays = {}
    spans = []
    for a in header["arrays"]:
        code, size = ITEM[a["dtype"]]
        count = 1
        for s in a["shape"]:
            count *= s
        off, nbytes = a["offset"], a["nbytes"]
        if nbytes != count * size:
            fail("%s: nbytes %d != %d" % (a["name"], nbytes, count * size))
        if off % header["alignment"] != 0 or off < 16 + header_len or off + nbytes > len(data):
            fail("%s: offset %d" % (a["name"], off))
        spans.append((off, off + nbytes, a["name"]))
        arrays[a["name"]] = list(struct.unpack_from("<%d%s" % (count, code), data, off))
    spans.sort()
    for (b0, e0, n0), (b1, _, n1) in zip(spans, spans[1:]):
        if b1 < e0:
            fail("%s overlaps %s" % (n0, n1))
    return header, arrays


if __name__ == "__main__":
    hdr, arrs = read_prtbin(sys.argv[1])
    with open(sys.argv[2], "w") as out:
        json.dump({"header": hdr, "arrays": arrs}, out)
