#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Seed corpora of the fuzz targets (fuzz/entry_points.hpp), one folder per
target under OUT: small valid inputs of every format, written here from
scratch, plus the project's YAML configs and a few files of the real samples
in ../shared/data when that folder is there. Nothing of it is committed.

    scripts/fuzz_seeds.py OUT
"""
import glob
import math
import os
import random
import struct
import sys
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(ROOT, "..", "shared", "data")


def points(n, rng):
    return [(rng.uniform(-40, 40), rng.uniform(-40, 40), rng.uniform(-2, 5), rng.uniform(-10, 20),
             rng.uniform(-8, 8)) for _ in range(n)]


def pcd_header(fields, n, data, sizes=None, types=None):
    sizes = sizes or ["4"] * len(fields)
    types = types or ["F"] * len(fields)
    return (f"# .PCD v0.7\nVERSION 0.7\nFIELDS {' '.join(fields)}\nSIZE {' '.join(sizes)}\n"
            f"TYPE {' '.join(types)}\nCOUNT {' '.join(['1'] * len(fields))}\nWIDTH {n}\nHEIGHT 1\n"
            f"VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {data}\n").encode()


def lzf_literals(raw):
    """LZF of literal runs only (a valid stream the reader must decode)."""
    out = bytearray()
    for i in range(0, len(raw), 32):
        chunk = raw[i:i + 32]
        out += bytes([len(chunk) - 1]) + chunk
    return bytes(out)


def pcd_seeds(rng):
    fields = ["x", "y", "z", "rcs", "doppler"]
    cloud = points(12, rng)
    ascii_body = "".join(" ".join(f"{v:.3f}" for v in p) + "\n" for p in cloud).encode()
    binary_body = b"".join(struct.pack("<5f", *p) for p in cloud)
    columns = b"".join(struct.pack(f"<{len(cloud)}f", *[p[k] for p in cloud]) for k in range(5))
    packed = lzf_literals(columns)
    yield "ascii.pcd", pcd_header(fields, len(cloud), "ascii") + ascii_body
    yield "binary.pcd", pcd_header(fields, len(cloud), "binary") + binary_body
    yield "compressed.pcd", (pcd_header(fields, len(cloud), "binary_compressed") +
                             struct.pack("<II", len(packed), len(columns)) + packed)
    mixed = pcd_header(["x", "y", "z", "intensity", "velocity"], 2, "binary", ["8", "8", "8", "2", "1"],
                       ["F", "F", "F", "U", "I"])
    yield "mixed.pcd", mixed + b"".join(struct.pack("<dddHb", 1.0, 2.0, 3.0, 7, -3) for _ in range(2))
    for path in sorted(glob.glob(os.path.join(SHARED, "ntu4dradlm_loop1_eagle", "points", "*.pcd")))[:3]:
        with open(path, "rb") as f:
            yield "ntu_" + os.path.basename(path), f.read()


def kitti_seeds(rng):
    cloud = points(10, rng)
    yield "vod.bin", bytes([0]) + b"".join(struct.pack("<7f", *p, p[4], 0.1) for p in cloud)
    yield "xyz.bin", bytes([1]) + b"".join(struct.pack("<3f", *p[:3]) for p in cloud)


def tum_seeds(rng):
    lines = ["# timestamp tx ty tz qx qy qz qw"]
    for k in range(20):
        yaw = 0.05 * k
        lines.append(f"{1702450000 + 0.1 * k:.9f} {k * 0.6:.4f} {0.1 * k:.4f} 0.8 0 0 "
                     f"{math.sin(yaw / 2):.9f} {math.cos(yaw / 2):.9f}")
    yield "drive.txt", ("\n".join(lines) + "\n").encode()
    gt = os.path.join(SHARED, "ntu4dradlm_loop1_eagle", "gt_tum.txt")
    if os.path.exists(gt):
        with open(gt, "rb") as f:
            yield "ntu_gt.txt", b"".join(f.readlines()[:40])


def map_bytes(gaussians, incidence=1):
    """A .rgm (include/radargauss/map/map_file.hpp) with a valid CRC."""
    body = b"RGAUSMAP" + struct.pack("<IB3xQ", 1, incidence, len(gaussians))
    for mean, cov, degree in gaussians:
        coefficients = [0.0] * 16
        coefficients[0] = 1.0
        body += struct.pack("<3d6dIiddd I16d", *mean, *cov, 12, degree, -3.0, 2.0, 0.5, 10, *coefficients)
    return body + struct.pack("<I", zlib.crc32(body) & 0xFFFFFFFF)


def places_map_bytes(gaussians, places):
    """A version-2 .rgm with places (pose, then points x y z rcs as float32)."""
    body = map_bytes(gaussians)[:-4]
    body = body[:8] + struct.pack("<I", 2) + body[12:]
    body += struct.pack("<Q", len(places))
    for (x, y, yaw), points in places:
        body += struct.pack("<4d3dQ", 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2), x, y, 0.0, len(points))
        for point in points:
            body += struct.pack("<4f", *point)
    return body + struct.pack("<I", zlib.crc32(body) & 0xFFFFFFFF)


def map_places_seeds(rng):
    gaussians = [((rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(0, 3)),
                  (0.3, 0.01, 0.0, 0.2, 0.0, 0.05), 0) for _ in range(3)]
    place = [(rng.uniform(-40, 40), rng.uniform(-40, 40), rng.uniform(0, 2), rng.uniform(-10, 20)) for _ in range(40)]
    yield "two_places.rgm", places_map_bytes(gaussians, [((0.0, 0.0, 0.0), place), ((10.0, 2.0, 0.3), place[:7])])
    yield "empty_place.rgm", places_map_bytes(gaussians, [((0.0, 0.0, 0.0), [])])
    yield "far_points.rgm", places_map_bytes(gaussians, [((5.0, 5.0, 1.0), place[:5] + [(9e4, -9e4, 0.0, 1.0)])])


def map_seeds(rng):
    gaussians = [((rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(0, 3)),
                  (0.3, 0.01, 0.0, 0.2, 0.0, 0.05), rng.choice([-1, 0, 2])) for _ in range(6)]
    yield "six.rgm", map_bytes(gaussians)
    yield "empty.rgm", map_bytes([], 0)


def pointcloud2_bytes(height, width, fields, point_step, rows):
    out = struct.pack("<IIB", height, width, len(fields))
    for name, offset, datatype in fields:
        out += struct.pack("<B", len(name)) + name.encode() + struct.pack("<IBI", offset, datatype, 1)
    return out + struct.pack("<BII", 0, point_step, point_step * width) + rows


def pointcloud2_seeds(rng):
    cloud = points(8, rng)
    fields = [("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("intensity", 12, 7), ("velocity", 16, 7)]
    yield "ti_like.bin", pointcloud2_bytes(1, len(cloud), fields, 20,
                                           b"".join(struct.pack("<5f", *p) for p in cloud))
    wide = [("x", 0, 8), ("y", 8, 8), ("z", 16, 8), ("rcs", 24, 3), ("doppler", 26, 7)]
    yield "doubles.bin", pointcloud2_bytes(2, 1, wide, 30, b"".join(
        struct.pack("<dddhf", *p[:3], int(p[3]), p[4]) for p in cloud[:2]))


def mcap_record(opcode, body):
    return struct.pack("<BQ", opcode, len(body)) + body


def mcap_string(text):
    return struct.pack("<I", len(text)) + text.encode()


def mcap_bytes(chunked):
    """An MCAP file of one channel and three messages, chunked (uncompressed) or not, with a summary."""
    magic = b"\x89MCAP0\r\n"
    schema = mcap_record(0x03, struct.pack("<H", 1) + mcap_string("std_msgs/msg/String") + mcap_string("ros2msg") +
                         mcap_string("string data\n"))
    channel = mcap_record(0x04, struct.pack("<HH", 1, 1) + mcap_string("/chatter") + mcap_string("cdr") +
                          struct.pack("<I", 0))
    messages = b"".join(mcap_record(0x05, struct.pack("<HIQQ", 1, k, 100 + k, 100 + k) + b"\x00\x01\x00\x00" +
                                    struct.pack("<I", 3) + b"hi\x00") for k in range(3))
    data = schema + channel + messages
    if chunked:
        data = mcap_record(0x06, struct.pack("<QQQI", 100, 102, len(data), zlib.crc32(data)) + mcap_string("") +
                           struct.pack("<Q", len(data)) + data)
    head = magic + mcap_record(0x01, mcap_string("ros2") + mcap_string("seed")) + data
    head += mcap_record(0x0F, struct.pack("<I", zlib.crc32(head)))
    summary_start = len(head)
    summary = schema + channel + mcap_record(0x0B, struct.pack("<QHIIIIQQI", 3, 1, 1, 0, 0, int(chunked), 100, 102,
                                                                 10) + struct.pack("<HQ", 1, 3))
    footer_head = struct.pack("<BQQQ", 0x02, 20, summary_start, 0)
    crc = zlib.crc32(summary + footer_head)
    return head + summary + footer_head + struct.pack("<I", crc) + magic


def mcap_seeds(rng):
    yield "unchunked.mcap", mcap_bytes(False)
    yield "chunked.mcap", mcap_bytes(True)
    yield from files("tests/data/rosbag2/*.mcap", "tests/data/rosbag2/talker/*.mcap")


def cdr_header(stamp, frame):
    out = b"\x00\x01\x00\x00" + struct.pack("<iI", int(stamp), 0) + struct.pack("<I", len(frame) + 1)
    return out + frame.encode() + b"\x00"


def cdr_align(out, n):
    return out + b"\x00" * ((-(len(out) - 4)) % n)


def cdr_seeds(rng):
    cloud = points(6, rng)
    msg = cdr_header(1702450000, "radar")
    msg = cdr_align(msg, 4) + struct.pack("<II", 1, len(cloud)) + struct.pack("<I", 5)
    for k, name in enumerate(["x", "y", "z", "rcs", "doppler"]):
        msg = cdr_align(msg, 4) + struct.pack("<I", len(name) + 1) + name.encode() + b"\x00"
        msg = cdr_align(msg, 4) + struct.pack("<I", 4 * k) + struct.pack("<B", 7)
        msg = cdr_align(msg, 4) + struct.pack("<I", 1)
    msg += struct.pack("<B", 0)
    msg = cdr_align(msg, 4) + struct.pack("<III", 20, 20 * len(cloud), 20 * len(cloud))
    msg += b"".join(struct.pack("<5f", *p) for p in cloud) + b"\x01"
    yield "pointcloud2.bin", b"\x00" + msg
    imu = cdr_align(cdr_header(5, "imu"), 8) + struct.pack("<4d", 0, 0, 0, 1) + struct.pack("<9d", *[0] * 9)
    imu += struct.pack("<3d", 0.01, -0.02, 0.3) + struct.pack("<9d", *[0] * 9)
    imu += struct.pack("<3d", 0.1, 0.2, 9.81) + struct.pack("<9d", *[0] * 9)
    yield "imu.bin", b"\x01" + imu
    pose = struct.pack("<7d", 1, 2, 3, 0, 0, 0, 1)
    yield "pose_stamped.bin", b"\x02" + cdr_align(cdr_header(7, "map"), 8) + pose
    odometry = cdr_header(8, "odom")
    odometry = cdr_align(odometry, 4) + struct.pack("<I", 10) + b"base_link\x00"
    yield "odometry.bin", b"\x03" + cdr_align(odometry, 8) + pose + struct.pack("<36d", *[0] * 36)
    tf = b"\x00\x01\x00\x00" + struct.pack("<I", 1) + struct.pack("<iI", 9, 0) + struct.pack("<I", 4) + b"map\x00"
    tf = cdr_align(tf + struct.pack("<I", 10) + b"base_link\x00", 8) + pose
    yield "tf.bin", b"\x04" + tf


def shard_json_seeds(rng):
    """Valid shard.json files (one shard of one and the first of two)."""
    import json

    def pose():
        q = [rng.gauss(0, 1) for _ in range(4)]
        n = math.sqrt(sum(v * v for v in q))
        return [rng.uniform(-50, 50) for _ in range(3)] + [v / n for v in q]

    def outcome(scan):
        return {"scan": scan, "time": 1702450000.0 + scan / 10, "initial": [1.2, 3.4], "error": [0.01, 0.2],
                "pose": pose(), "iterations": 7, "cost": 0.5, "n_geo": 300, "n_rcs": 280, "converged": True,
                "reason": "", "time_ms": 0.4}

    for index, count, scans in ((1, 1, 3), (1, 2, 4)):
        first, end = (index - 1) * scans // count, index * scans // count
        shard = {"shard": index, "of": count, "scans": scans, "first_scan": first, "end_scan": end,
                 "experiment": {"--seed": "1", "--w-rcs": "0,0.25", "scans": f"{scans} scans, crc32 0badf00d"},
                 "references": [pose() for _ in range(first, end)],
                 "runs": [{"name": f"gn-w{w}-trivial-offset-L3", "w_rcs": w,
                           "outcomes": [outcome(k) for k in range(first, end)]} for w in (0, 0.25)]}
        yield f"shard_{index}_of_{count}.json", json.dumps(shard).encode()


def map_tiles_seeds(rng):
    """The true index of the tiles the map_tiles entry point writes (three
    Gaussians at x = 10, 150, 20 m in 100 m tiles), and one with a place list."""
    import json
    tiles = [{"x": 0, "y": 0, "file": "tile_0_0.rgm", "gaussians": 2, "places": []},
             {"x": 1, "y": 0, "file": "tile_1_0.rgm", "gaussians": 1, "places": []}]
    index = {"format": "radargauss map tiles", "gaussians": 3, "incidence": "offset", "order": [[0, 1], [1, 1], [0, 1]],
             "places": 0, "tile_size": 100.0, "tiles": tiles, "version": 1}
    yield "true.json", json.dumps(index).encode()
    index["order"] = [[0, 2], [1, 1]]
    yield "reordered.json", json.dumps(index, indent=1).encode()


def rig_yaml_seeds(rng):
    """A rig of folders with a quaternion and a matrix mounting, and one of a bag's topics."""
    yield "folders.yaml", (b"radars:\n"
                           b"  - {name: front, sequence: front, extrinsic: [3.7, 0, 0.5, 0, 0, 0, 1]}\n"
                           b"  - name: rear_left\n    sequence: rear_left\n"
                           b"    rotation: [[-0.7071067811865476, -0.7071067811865476, 0],"
                           b" [0.7071067811865476, -0.7071067811865476, 0], [0, 0, 1]]\n"
                           b"    translation: [-0.9, 0.9, 0.6]\n    clock_offset: -0.012\n")
    yield "bag.yaml", (b"bag: drive.mcap\nradars:\n"
                       b"  - {name: a, topic: /a/points, extrinsic: [1, 0, 0, 0, 0, 0, 1], clock_offset: 0.02}\n"
                       b"  - {name: b, topic: /b/points, extrinsic: [-1, 0, 0, 0, 0, 1, 0]}\n")


def files(*patterns):
    for path in sorted(p for pattern in patterns for p in glob.glob(os.path.join(ROOT, pattern))):
        with open(path, "rb") as f:
            yield os.path.basename(path), f.read()


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    rng = random.Random(1)
    seeds = {
        "pcd": pcd_seeds(rng), "kitti_bin": kitti_seeds(rng), "tum": tum_seeds(rng), "map_file": map_seeds(rng),
        "pointcloud2": pointcloud2_seeds(rng), "simulator_yaml": files("configs/synthetic_world.yaml", "configs/synthetic_long_drive.yaml"),
        "cli_yaml": files("configs/*_localize.yaml", "configs/*_odometry.yaml"),
        "shard_json": shard_json_seeds(rng), "map_places": map_places_seeds(rng),
        "mcap": mcap_seeds(rng), "cdr": cdr_seeds(rng), "map_tiles": map_tiles_seeds(rng),
        "rig_yaml": rig_yaml_seeds(rng),
    }
    for target, items in seeds.items():
        folder = os.path.join(sys.argv[1], target)
        os.makedirs(folder, exist_ok=True)
        count = 0
        for name, data in items:
            with open(os.path.join(folder, "seed_" + name), "wb") as f:
                f.write(data)
            count += 1
        print(f"fuzz_seeds: {target}: {count} seeds")


if __name__ == "__main__":
    main()
