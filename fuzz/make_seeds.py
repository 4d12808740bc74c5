#!/usr/bin/env python3
"""Writes the tiny seed inputs of every fuzz target into fuzz/corpus/<target>/ (checked in).

Usage: fuzz/make_seeds.py [OUT_DIR]   (default: fuzz/corpus beside this script)
scripts/fuzz.sh adds slices of ../shared/data at run time; nothing big is checked in.
The E57 seeds (corpus/e57_fuzzer/, and copies in corpus/read_scene_fuzzer/) need CRC-32C pages and
bit-packed sections, so they come from the tests' E57 writer instead of this script:
  cmake --build --preset release --target write_e57_seeds
  build/release/tests/write_e57_seeds fuzz/corpus/e57_fuzzer
"""
import bz2
import gzip
import os
import struct
import sys

OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "corpus")

XYZ = b"0 0 0\n1 0 0\n0 1 0\n0 0 1.5\n"
CSV = b"x,y,z,intensity\n0,0,0,7\n1,0,0,7\n0,1,0,7\n"
PLY_ASCII = (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
             b"property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
             b"end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
PLY_BIN = (b"ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
           b"property float y\nproperty double z\nend_header\n" +
           struct.pack("<ffd", 1, 2, 3) + struct.pack("<ffd", 4, 5, 6))
PLY_BE = (b"ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\n"
          b"property float y\nproperty float z\nend_header\n" + struct.pack(">fff", 1, 2, 3))
PCD_HEAD = ("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {n}\nHEIGHT 1\n"
            "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {d}\n")
PCD_ASCII = PCD_HEAD.format(n=2, d="ascii").encode() + b"1 2 3\n4 5 6\n"
PCD_BIN = PCD_HEAD.format(n=2, d="binary").encode() + struct.pack("<6f", 1, 2, 3, 4, 5, 6)
# binary_compressed: sizes, then LZF of the field-major data as literal runs (ctrl = len - 1).
_raw = struct.pack("<6f", 1, 4, 2, 5, 3, 6)
_lzf = bytes([len(_raw) - 1]) + _raw
PCD_LZF = (PCD_HEAD.format(n=2, d="binary_compressed").encode() +
           struct.pack("<II", len(_lzf), len(_raw)) + _lzf)


def las(points):
    """LAS 1.2, point format 0 (20-byte records), scale 0.01."""
    header = bytearray(227)
    header[0:4] = b"LASF"
    header[24:26] = bytes([1, 2])
    struct.pack_into("<H", header, 94, 227)      # header size
    struct.pack_into("<I", header, 96, 227)      # offset to point data
    struct.pack_into("<I", header, 100, 0)       # VLRs
    header[104] = 0                               # point format
    struct.pack_into("<H", header, 105, 20)      # record length
    struct.pack_into("<I", header, 107, len(points))
    struct.pack_into("<3d", header, 131, 0.01, 0.01, 0.01)
    struct.pack_into("<3d", header, 155, 0, 0, 0)
    body = b"".join(struct.pack("<3i", *p) + bytes(8) for p in points)
    return bytes(header) + body


LAS = las([(0, 0, 0), (100, 0, 0), (0, 100, 50)])
# .bt: root with an occupied leaf (01) in child 0 and an inner child (11) in child 1 whose
# children are a free (10) and an occupied leaf.
BT = (b"# Octomap OcTree binary file\nid OcTree\nsize 4\nres 0.1\ndata\n" +
      bytes([0b1101, 0]) + bytes([0b0110, 0]))
# .ot: a node is a float log-odds value and a child-flag byte.
OT = (b"# Octomap OcTree file\nid OcTree\nsize 3\nres 0.1\ndata\n" +
      struct.pack("<f", 2.0) + bytes([0b11]) + struct.pack("<f", 2.0) + bytes([0]) +
      struct.pack("<f", -2.0) + bytes([0]))


def graph():
    """ScanGraph: one scan of two points, an identity pose, id 0, no edges."""
    out = struct.pack("<I", 1) + struct.pack("<I", 2)
    for p in [(1, 2, 3), (4, 5, 6)]:
        out += struct.pack("<i3d", 3, *p)
    out += struct.pack("<i3d", 3, 0, 0, 0) + struct.pack("<i4d", 4, 1, 0, 0, 0)
    return out + struct.pack("<I", 0) + struct.pack("<I", 0)


GRAPH = graph()
STATIONS = b"x_m,y_m,z_m\n0,0,1.5\n2.5,1,1.5\n# comment\n3 4 1.6\n"
# A plan's own stations.csv (vc/report/field_exports.h): x_m, y_m, z_m among named columns.
PLAN_STATIONS = (b"# vc stations: lengths in metres\n"
                 b"station,name,x_m,y_m,z_m,floor,floor_z_m,tripod_height_m,fixed,route_order,selection_order,"
                 b"gain_voxels,cumulative_coverage\n"
                 b"1,S01,3.500000,2.500000,1.600000,L0,0.100,1.500,new,1,2,25,1.000000\n"
                 b"2,BM 7,0.500000,0.500000,1.600000,,,,existing,0,1,100,0.800000\n")

KEEP_OUT = (b"# keep-out zones: boxes and polygons over a z range\n\nbox, -1, -1, -2, 1, 1, 4  # the tripod\n"
            b"POLYGON,0,3.5,10,10,12,10,12,12,10,12\npolygon,-1e3,1e3,0,0,1,0,0,1\n")

def upload_actions(max_upload, queue, *actions):
    """An upload_assembler_fuzzer input: the config bytes, then actions (fuzz/upload_assembler_fuzzer.cc)."""
    return bytes([max_upload, queue]) + b"".join(actions)


def op(slot, kind, *args):
    return bytes([(slot << 4) | kind]) + b"".join(bytes([a]) if isinstance(a, int) else a for a in args)


def spec(slot, payload=None, size=None, size_mode=0, fmt=0, crc=0, name=b"x.ply", params_refused=False):
    """A spec message: the CRC of `payload` (sent later by payload chunks), or `crc`, for `size` bytes."""
    flags = (1 if params_refused else 0) | (2 if payload is not None else 0) | (size_mode << 2)
    out = bytes([flags])
    if size_mode == 0:
        out += bytes([len(payload) if size is None else size])
    elif size_mode == 3:
        out += struct.pack("<Q", size)
    out += bytes([fmt]) if fmt < 8 else bytes([8]) + struct.pack("<i", fmt)
    out += payload if payload is not None else struct.pack("<I", crc)
    return op(slot, 2, out + bytes([len(name)]) + name)


NEW, DROP, CHUNK, FINISH, TAKE_DATA, TAKE_HOLD, TAKE_DROP, RELEASE, DROP_HELD = 0, 1, 3, 4, 5, 6, 7, 8, 9
SCENE = b"ply\nformat ascii"
UPLOADS = {
    # New, spec, the payload in two chunks, Finish, TakeData, the ticket held then released.
    "whole.bin": upload_actions(64, 0, op(0, NEW), spec(0, SCENE, fmt=1), op(0, CHUNK, 0x85),
                                op(0, CHUNK, 0x80), op(0, FINISH), op(0, TAKE_DATA), op(0, TAKE_HOLD),
                                op(0, RELEASE)),
    # One worker, no queue: the second call is busy until the first is dropped; a second spec.
    "busy.bin": upload_actions(64, 0, op(0, NEW), op(1, NEW), spec(0, SCENE), spec(1, SCENE),
                               op(0, DROP), spec(1, SCENE), op(1, NEW), spec(1, SCENE),
                               op(1, CHUNK, 0x80), op(1, FINISH), op(1, TAKE_DROP)),
    # A 1-job queue: two calls admitted, the third busy; refusals of size, format, emptiness.
    "queue.bin": upload_actions(16, 1, op(0, NEW), op(1, NEW), op(2, NEW), spec(0, b"abc"),
                                spec(1, b"defg"), spec(2, b"hi"), op(2, NEW), spec(2, b"", size_mode=2),
                                op(2, NEW), spec(2, b"xy", fmt=99), op(2, NEW), spec(2, b"", size=0),
                                op(2, NEW), spec(2, None, size=1 << 40, size_mode=3, crc=7)),
    # Corrupted and short uploads, bytes past the declared size, chunks after refused parameters.
    "bad.bin": upload_actions(32, 0, op(0, NEW), spec(0, SCENE), op(0, CHUNK, 3, b"ply"), op(0, FINISH),
                              op(0, CHUNK, 14, b"\nformat ASCII"), op(0, FINISH), op(0, CHUNK, 1, b"!"),
                              op(0, TAKE_HOLD), op(1, NEW), spec(1, b"abc", params_refused=True),
                              op(1, CHUNK, 0), op(1, FINISH), op(1, CHUNK, 2, b"ab"), op(2, CHUNK, 1, b"a"),
                              op(2, NEW), op(2, FINISH), op(0, DROP_HELD)),
}

SEEDS = {
    "ply_fuzzer": {"ascii.ply": PLY_ASCII, "binary_le.ply": PLY_BIN, "binary_be.ply": PLY_BE},
    "pcd_fuzzer": {"ascii.pcd": PCD_ASCII, "binary.pcd": PCD_BIN, "lzf.pcd": PCD_LZF},
    "xyz_fuzzer": {"points.xyz": XYZ, "points.csv": CSV},
    "las_fuzzer": {"points.las": LAS},
    "octomap_bt_fuzzer": {"tree.bt": BT},
    "octomap_ot_fuzzer": {"tree.ot": OT},
    "octomap_graph_fuzzer": {"scan.graph": GRAPH},
    "gzip_fuzzer": {"xyz.gz": gzip.compress(XYZ, mtime=0), "two_members.gz":
                    gzip.compress(XYZ, mtime=0) + gzip.compress(CSV, mtime=0)},
    "bzip2_fuzzer": {"xyz.bz2": bz2.compress(XYZ), "two_streams.bz2": bz2.compress(XYZ) +
                     bz2.compress(CSV)},
    "lzf_fuzzer": {"literal.lzf": struct.pack("<H", len(_raw)) + _lzf,
                   "backref.lzf": struct.pack("<H", 12) + bytes([3]) + b"abcd" + bytes([0xc0, 3])},
    "stations_csv_fuzzer": {"stations.csv": STATIONS, "plan_stations.csv": PLAN_STATIONS},
    "keep_out_csv_fuzzer": {"zones.csv": KEEP_OUT, "box.csv": b"box,0,0,0,1,1,1\n",
                            "polygon.csv": b"polygon,0,3,0,0,2,0,2,1,1,1,1,2,0,2\n"},
    "upload_assembler_fuzzer": UPLOADS,
}
SEEDS["read_scene_fuzzer"] = {
    name: data for target in ("ply_fuzzer", "pcd_fuzzer", "xyz_fuzzer", "las_fuzzer",
                              "octomap_bt_fuzzer", "octomap_ot_fuzzer", "octomap_graph_fuzzer",
                              "gzip_fuzzer", "bzip2_fuzzer") for name, data in SEEDS[target].items()
}

for target, files in SEEDS.items():
    os.makedirs(os.path.join(OUT, target), exist_ok=True)
    for name, data in files.items():
        with open(os.path.join(OUT, target, name), "wb") as f:
            f.write(data)
print(f"make_seeds: wrote {sum(len(f) for f in SEEDS.values())} seeds under {OUT}")
