#!/usr/bin/env python3
"""Merges the two real room scans into one cloud: a second real floor to plan (issue 36).

Reads ../shared/data/room-2scans/room_scan1.pcd and room_scan2.pcd (PCD v0.7, binary_compressed,
FIELDS x y z float32; ../shared/data/README.md), moves scan 2 into scan 1's frame with the
estimated relative pose of that README (p1 = R p2 + t, R a yaw of +40.8 degrees about z,
t = (1.974, 0.058, 0.016) m; docs/BENCHMARKS.md checks that direction against the inverse), drops
each scan's points within 0.3 m of its own scanner (returns from the scanning platform), and writes
the union as a binary little-endian PLY (float x, y, z) in scan 1's frame.

Usage: scripts/merge-room-scans.py OUT.ply [DATA_DIR (default ../shared/data/room-2scans)]
No dependencies beyond the Python standard library (LZF is decoded here). Exit code 2 with one
sentence on stderr for a bad input.
"""
import math
import os
import struct
import sys

YAW_DEG = 40.8
T = (1.974, 0.058, 0.016)
PLATFORM_M = 0.3


def fail(msg):
    sys.stderr.write("merge-room-scans: " + msg + "\n")
    sys.exit(2)


def lzf_decompress(data, size):
    out = bytearray()
    i, n = 0, len(data)
    while i < n:
        ctrl = data[i]
        i += 1
        if ctrl < 32:  # a literal run of ctrl + 1 bytes
            out += data[i:i + ctrl + 1]
            i += ctrl + 1
        else:  # a back reference
            length = ctrl >> 5
            if length == 7:
                length += data[i]
                i += 1
            ref = len(out) - ((ctrl & 0x1F) << 8) - data[i] - 1
            i += 1
            if ref < 0:
                fail("corrupt LZF data (a back reference before the start)")
            for _ in range(length + 2):
                out.append(out[ref])
                ref += 1
    if len(out) != size:
        fail(f"LZF data decode to {len(out)} bytes, the header says {size}")
    return bytes(out)


def read_pcd(path):
    try:
        raw = open(path, "rb").read()
    except OSError as e:
        fail(f"cannot read {path}: {e.strerror}")
    header, pos, points = {}, 0, None
    while True:
        end = raw.find(b"\n", pos)
        if end < 0:
            fail(f"{path}: no DATA line in the header")
        line = raw[pos:end].decode("ascii", "replace").strip()
        pos = end + 1
        if not line or line.startswith("#"):
            continue
        key, _, value = line.partition(" ")
        header[key] = value.split()
        if key == "DATA":
            break
    if header.get("FIELDS") != ["x", "y", "z"] or header.get("TYPE") != ["F", "F", "F"] or header.get("SIZE") != [
            "4", "4", "4"]:
        fail(f"{path}: expected FIELDS x y z as float32")
    if header["DATA"] != ["binary_compressed"]:
        fail(f"{path}: expected DATA binary_compressed, got {' '.join(header['DATA'])}")
    points = int(header["POINTS"][0])
    compressed, size = struct.unpack_from("<II", raw, pos)
    data = lzf_decompress(raw[pos + 8:pos + 8 + compressed], size)
    if size != 12 * points:
        fail(f"{path}: {size} bytes for {points} points")
    xs = struct.unpack_from(f"<{points}f", data, 0)
    ys = struct.unpack_from(f"<{points}f", data, 4 * points)
    zs = struct.unpack_from(f"<{points}f", data, 8 * points)
    return [(x, y, z) for x, y, z in zip(xs, ys, zs) if all(map(math.isfinite, (x, y, z)))]


def main():
    if len(sys.argv) not in (2, 3):
        fail("usage: merge-room-scans.py OUT.ply [DATA_DIR]")
    out = sys.argv[1]
    data_dir = sys.argv[2] if len(sys.argv) == 3 else os.path.join(os.path.dirname(__file__), "..", "..", "shared",
                                                                     "data", "room-2scans")
    one = read_pcd(os.path.join(data_dir, "room_scan1.pcd"))
    two = read_pcd(os.path.join(data_dir, "room_scan2.pcd"))
    c, s = math.cos(math.radians(YAW_DEG)), math.sin(math.radians(YAW_DEG))
    far = lambda p: p[0] * p[0] + p[1] * p[1] + p[2] * p[2] > PLATFORM_M * PLATFORM_M
    merged = [p for p in one if far(p)]
    merged += [(c * x - s * y + T[0], s * x + c * y + T[1], z + T[2]) for x, y, z in two if far((x, y, z))]
    with open(out, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                b"property float x\nproperty float y\nproperty float z\nend_header\n" % len(merged))
        f.write(b"".join(struct.pack("<3f", *p) for p in merged))
    print(f"wrote {len(merged)} points ({len(one)} + {len(two)} read, those within {PLATFORM_M} m of their "
          f"scanner dropped) to {out}")


if __name__ == "__main__":
    main()
