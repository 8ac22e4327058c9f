#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The calibration of a rig (bench/RESULTS.md, "Radar rigs"; docs/design/rig.md,
"Calibration of a rig"): the radars of scripts/rig_table.py's table 2 (the
five of configs/rig_five_radars.yaml and a rear radar) simulated over a
world, their mountings given 2 deg (about a random axis) and 5 cm (in a
random direction) off, and their clocks 20 ms off (either sign), then
`radargauss calibrate --compare` against the simulator's rig.yaml.

Per world and radar: the error after calibration of the rotation (deg),
the translation (m) and the clock offset (ms), beside the stated standard
deviations; the last row per world counts the errors within 3 sigma
(per axis: rotation and translation as their norms against the norm of
the stds). Draws of the offsets: --draws (seeds 1..N).

With --imu, the same radars (the same scans) with scripts/rig_table.py's
table-4 IMU on the body, given to calibrate --imu: the reference's
odometry with its window and its rates from the gyro.

With --online, the same given rigs to `radargauss odometry --rig
--rig-calibrate` (docs/design/rig.md, "Online calibration"): per radar the
errors of the rig it writes, beside the stated stds (their norms), and per
world and draw the RPE of the odometry at the true rig, at the given one,
and with the online calibration.

    scripts/rig_calibration_table.py [--tool build/release/bin/radargauss] [--work /tmp/rig_calibration]
                                     [--worlds demo,realistic] [--draws 1] [--imu] [--online]
"""
import argparse
import json
import os
import re
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rig_table import IMU_WORLD_KEYS, ODOMETRY_WORLDS, odometry_rig_config  # noqa: E402


def rotation(axis_angle):
    angle = np.linalg.norm(axis_angle)
    if angle == 0.0:
        return np.eye(3)
    k = axis_angle / angle
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def quaternion(R):
    w = np.sqrt(max(0.0, 1.0 + np.trace(R))) / 2.0
    x = np.copysign(np.sqrt(max(0.0, 1.0 + R[0, 0] - R[1, 1] - R[2, 2])) / 2.0, R[2, 1] - R[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1.0 - R[0, 0] + R[1, 1] - R[2, 2])) / 2.0, R[0, 2] - R[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1.0 - R[0, 0] - R[1, 1] + R[2, 2])) / 2.0, R[1, 0] - R[0, 1])
    return np.array([x, y, z, w])


def matrix(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def perturbed_rig(text, rng):
    """The rig file's text with every radar but the first moved 2 deg / 5 cm and its clock 20 ms."""
    out, index = [], -1
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("- name:"):
            index += 1
        if index >= 1 and stripped.startswith("extrinsic:"):
            values = np.array(json.loads(stripped.split(":", 1)[1]))
            axis = rng.normal(size=3)
            direction = rng.normal(size=3)
            R = matrix(values[3:]) @ rotation(np.radians(2.0) * axis / np.linalg.norm(axis))
            t = values[:3] + 0.05 * direction / np.linalg.norm(direction)
            line = line.split("extrinsic:")[0] + "extrinsic: " + json.dumps([float(v) for v in np.concatenate([t, quaternion(R)])])
        if index >= 1 and stripped.startswith("clock_offset:"):
            offset = float(stripped.split(":", 1)[1]) + (0.02 if rng.uniform() < 0.5 else -0.02)
            line = line.split("clock_offset:")[0] + f"clock_offset: {offset}"
        out.append(line)
    return "\n".join(out) + "\n"


def read_rig(path):
    """Each radar's name, rotation matrix, translation and clock offset from a rig file."""
    radars = []
    for line in open(path):
        stripped = line.strip()
        if stripped.startswith("- name:"):
            radars.append({"name": stripped.split(":", 1)[1].strip().strip('"'), "clock": 0.0})
        elif stripped.startswith("extrinsic:") and radars:
            values = np.array(json.loads(stripped.split(":", 1)[1]))
            radars[-1]["R"], radars[-1]["t"] = matrix(values[3:]), values[:3]
        elif stripped.startswith("clock_offset:") and radars:
            radars[-1]["clock"] = float(stripped.split(":", 1)[1])
    return radars


def rotation_angle_deg(R):
    return float(np.degrees(np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0))))


def run_rig_odometry(tool, rig, gt, out, flags):
    """The RPE t % of `odometry --rig`, and its standard output."""
    subprocess.run(["rm", "-rf", out], check=True)
    result = subprocess.run([tool, "odometry", "--rig", rig, "--gt", gt, "--out", out] + flags,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"rig_calibration_table: odometry failed: {result.stderr.strip()}")
    return json.load(open(os.path.join(out, "evaluation.json")))["rpe"]["translation_percent"], result.stdout


TRUTH_RPE = {}


def online_rows(args, world, rig_dir, given, draw):
    """The online calibration of one given rig: rows per radar, and the RPEs at the truth, given and online."""
    truth_file = os.path.join(rig_dir, "rig.yaml")
    gt = os.path.join(rig_dir, "gt_body_tum.txt")
    tag = f"{os.path.basename(rig_dir)}_{draw}"
    if rig_dir not in TRUTH_RPE:  # once per world
        TRUTH_RPE[rig_dir] = run_rig_odometry(args.tool, truth_file, gt, os.path.join(args.work, f"truth_{tag}"),
                                              [])[0]
    rpe_truth = TRUTH_RPE[rig_dir]
    rpe_given, _ = run_rig_odometry(args.tool, given, gt, os.path.join(args.work, f"given_{tag}"), [])
    out = os.path.join(args.work, f"online_{tag}")
    rpe_online, stdout = run_rig_odometry(args.tool, given, gt, out, ["--rig-calibrate"] + args.flags.split())
    stds = {m.group(1): (float(m.group(2)), float(m.group(3)), float(m.group(4)))
            for m in re.finditer(r"^  (\S+): moved .*; std \(norm\) ([\d.]+) deg, ([\d.]+) m, ([\d.]+) ms", stdout, re.M)}
    rows = []
    truth, before, after = read_rig(truth_file), read_rig(given), read_rig(os.path.join(out, "rig.yaml"))
    for true_radar, given_radar, radar in list(zip(truth, before, after))[1:]:
        errors = [(rotation_angle_deg(true_radar["R"].T @ r["R"]), float(np.linalg.norm(r["t"] - true_radar["t"])),
                   1e3 * abs(r["clock"] - true_radar["clock"])) for r in (given_radar, radar)]
        rows.append((radar["name"], errors[0], errors[1], stds.get(radar["name"], (np.inf,) * 3)))
    return rows, (rpe_truth, rpe_given, rpe_online)


def online_table(args):
    print("| world | radar | given: deg, m, ms | online: rotation deg (std) | translation m (std) | clock ms (std) |")
    print("|---|---|---|---|---|---|")
    rpes = []
    for world, rig_dir in selected_worlds(args):
        within, count = np.zeros(3), 0
        for draw in range(1, args.draws + 1):
            rows, rpe = online_rows(args, world, rig_dir, given_rig(rig_dir, draw), draw)
            rpes.append((world, draw) + rpe)
            for name, before, after, std in rows:
                within += [after[k] <= 3 * std[k] for k in range(3)]
                count += 1
                print(f"| {world} | {name} | {before[0]:.2f}, {before[1]:.3f}, {before[2]:.1f} | {after[0]:.3f} "
                      f"({std[0]:.3f}) | {after[1]:.4f} ({std[1]:.4f}) | {after[2]:.2f} ({std[2]:.2f}) |")
        print(f"| {world} | within 3 sigma | | {within[0]:.0f} of {count} | {within[1]:.0f} of {count} | "
              f"{within[2]:.0f} of {count} |")
    print()
    print("| world | draw | RPE t % at the true rig | at the given rig | with the online calibration |")
    print("|---|---|---|---|---|")
    for world, draw, truth, given, online in rpes:
        print(f"| {world} | {draw} | {truth:.3f} | {given:.3f} | {online:.3f} |")


def simulated_rig_dir(args, world, config, scans):
    """The world's simulated rig (once per --work), with table 4's IMU under --imu."""
    rig_dir = os.path.join(args.work, world.split()[0].replace("-", "_") + ("_imu" if args.imu else ""))
    if not os.path.exists(os.path.join(rig_dir, "rig.yaml")):
        with open(rig_dir + ".yaml", "w") as f:
            text = odometry_rig_config(config, scans)
            f.write(text.replace("world:\n", "world:\n" + IMU_WORLD_KEYS, 1) if args.imu else text)
        subprocess.run([args.tool, "simulate", "--rig-config", rig_dir + ".yaml", "--out", rig_dir], check=True,
                       stdout=subprocess.DEVNULL)
    return rig_dir


def selected_worlds(args):
    """Each world of --worlds and its simulated rig's folder."""
    for world, config, scans in ODOMETRY_WORLDS:
        if world.split()[0].replace("-", "_") in args.worlds.split(","):
            yield world, simulated_rig_dir(args, world, config, scans)


def given_rig(rig_dir, draw):
    """The draw's given rig: the simulated one moved off (seed `draw`)."""
    given = os.path.join(rig_dir, f"rig_off_{draw}.yaml")
    with open(given, "w") as f:
        f.write(perturbed_rig(open(os.path.join(rig_dir, "rig.yaml")).read(), np.random.default_rng(draw)))
    return given


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parser.add_argument("--tool", default=os.path.join(root, "build/release/bin/radargauss"))
    parser.add_argument("--work", default="/tmp/rig_calibration")
    parser.add_argument("--worlds", default="demo,realistic")
    parser.add_argument("--draws", type=int, default=1)
    parser.add_argument("--flags", default="", help="further flags of radargauss calibrate")
    parser.add_argument("--imu", action="store_true",
                        help="the same radars with table 4's IMU on the body (calibrate --imu): the same scans")
    parser.add_argument("--online", action="store_true",
                        help="the online calibration of odometry --rig --rig-calibrate instead of calibrate")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    if args.online:
        if args.imu:
            sys.exit("rig_calibration_table: --online runs without the IMU")
        online_table(args)
        return
    print("| world | radar | rotation error deg (std) | translation error m (std) | clock error ms (std) |")
    print("|---|---|---|---|---|")
    for world, rig_dir in selected_worlds(args):
        within, count = np.zeros(3), 0
        for draw in range(1, args.draws + 1):
            given = given_rig(rig_dir, draw)
            out = os.path.join(args.work, f"calibrated_{os.path.basename(rig_dir)}_{draw}")
            subprocess.run(["rm", "-rf", out], check=True)
            result = subprocess.run([args.tool, "calibrate", "--rig", given, "--compare",
                                     os.path.join(rig_dir, "rig.yaml"), "--out", out] + args.flags.split() +
                                    (["--imu", os.path.join(rig_dir, "imu.txt"), "--imu-extrinsic",
                                      os.path.join(rig_dir, "imu_extrinsic.txt")] if args.imu else []),
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            if result.returncode != 0:
                sys.exit(f"rig_calibration_table: calibrate failed: {result.stderr.strip()}")
            for radar in json.load(open(os.path.join(out, "calibration.json")))["radars"]:
                e = radar["error"]
                sr = np.linalg.norm([s if s is not None else np.inf for s in radar["rotation_std_deg"]])
                st = np.linalg.norm([s if s is not None else np.inf for s in radar["translation_std_m"]])
                sc = radar["clock_offset_std_ms"] if radar["clock_offset_std_ms"] is not None else np.inf
                within += [e["rotation_deg"] <= 3 * sr, e["translation_m"] <= 3 * st, abs(e["clock_ms"]) <= 3 * sc]
                count += 1
                print(f"| {world} | {radar['name']} | {e['rotation_deg']:.3f} ({sr:.3f}) | "
                      f"{e['translation_m']:.4f} ({st:.4f}) | {e['clock_ms']:.2f} ({sc:.2f}) |")
        print(f"| {world} | within 3 sigma | {within[0]:.0f} of {count} | {within[1]:.0f} of {count} | "
              f"{within[2]:.0f} of {count} |")


if __name__ == "__main__":
    main()
