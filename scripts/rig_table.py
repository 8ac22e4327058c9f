#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The rig's twist from Doppler alone (bench/RESULTS.md, "Radar rigs"): rigs
of 1, 2, 4 and 6 radars simulated over one drive (`radargauss simulate
--rig-config`), every radar at 10 Hz on one clock so that their scans are
taken together, and at each instant the body's twist estimated from all
their Doppler (`radargauss.estimate_rig_twist`) against the simulator's true
twist (twist_body.txt).

Per rig and world: the scans estimated, the rank (observed directions), the
median of the error in the observed directions (|P e|, P the projector onto
them) and the share of scans where it is under 0.1 (the others took a
moving object for the world); over those, the velocity's RMSE (m/s, with
all six observed), the yaw rate's (mrad/s, with five or six) and the roll
and pitch rates' (with six), and the mean NEES over the observed directions
against their count; and the time per estimate.

Table 2, odometry on a rig (`radargauss --threads 1 odometry --rig`): the
radars of configs/rig_five_radars.yaml and a rear radar over the demo
world, the realistic faults and the two-lap route; rigs of 1, 2, 4, 5 and
6 of them against the body's reference, and each radar alone (today's
odometry against its own reference): ATE, RPE (and its ratio to the rig's
best radar alone), the median time per scan (a rig: per frame, against
its radars' medians as many as a frame holds) and the run's wall time.

Table 3, SLAM on a rig (`radargauss slam --rig --no-map`): table 2's rigs
over the two-lap route, against the body's reference: ATE, RPE, loops,
the odometry's ATE and the wall time (two threads).

Table 4, an IMU on a rig (`odometry --rig --imu`): table 2's worlds with one
IMU on the body; the rigs of 1, 4, 5 and 6 radars with and without it.

    scripts/rig_table.py [--tool build/release/bin/radargauss] [--work /tmp/rig_table] [--scans 300]
                         [--tables 1,2,3,4]

The module is found beside the tool (build/release/python).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

FRONT = "  - {name: front, mounting_x: 3.7, mounting_z: 0.5}\n"
REAR = "  - {name: rear, mounting_x: -1.0, mounting_z: 0.5, mounting_yaw_deg: 180}\n"
CORNER = ("  - {{name: {name}, mounting_x: {x}, mounting_y: {y}, mounting_z: 0.5, mounting_yaw_deg: {yaw}, "
          "azimuth_fov_deg: 75, max_range: 80, min_detections: 60, max_detections: 200}}\n")
CORNERS = "".join(CORNER.format(name=n, x=x, y=y, yaw=yaw) for n, x, y, yaw in
                  [("front_left", 3.4, 0.9, 45), ("front_right", 3.4, -0.9, -45),
                   ("rear_left", -0.9, 0.9, 135), ("rear_right", -0.9, -0.9, -135)])
RIGS = [("1: front", FRONT), ("2: front and rear (on the axis)", FRONT + REAR),
        ("4: corners", CORNERS), ("6: front, corners, rear", FRONT + CORNERS + REAR)]
WORLDS = [("demo", "configs/synthetic_world.yaml"), ("realistic faults", "configs/synthetic_realistic.yaml")]
# The world's keys a rig takes from a single-radar config (a radar's own
# mounting is the rig's, so the world's is left out).
RADAR_KEYS = ("mounting_roll_deg", "mounting_pitch_deg", "mounting_yaw_deg", "imu_")


def world_section(config, scans):
    lines = []
    for line in open(os.path.join(ROOT, config)):
        line = line.split("#")[0].rstrip()
        if not line or line.startswith(" ") or ":" not in line or line.startswith(RADAR_KEYS):
            continue
        if line.startswith(("scans:", "rate_hz:", "materials:")):
            continue
        lines.append("  " + line)
    lines += [f"  scans: {scans}", "  rate_hz: 10"]
    return "world:\n" + "\n".join(lines) + "\n"


# Table 2: the five radars of configs/rig_five_radars.yaml and a rear radar
# at 10 Hz; rigs of 1, 2, 4, 5 and 6 of them. Each world's keys (but the
# radar's own: its mounting) overlay the rig config's world.
REAR_RADAR = "  - {name: rear, mounting_x: -1.0, mounting_z: 0.6, mounting_yaw_deg: 180, clock_offset: 0.004}\n"
ODOMETRY_RIGS = [("1: front", ["front"]),
                 ("2: front, front_left", ["front", "front_left"]),
                 ("4: corners", ["front_left", "front_right", "rear_left", "rear_right"]),
                 ("5: front, corners", ["front", "front_left", "front_right", "rear_left", "rear_right"]),
                 ("6: front, corners, rear", ["front", "front_left", "front_right", "rear_left", "rear_right", "rear"])]
ODOMETRY_WORLDS = [("demo", None, None), ("realistic faults", "configs/synthetic_realistic.yaml", None),
                   ("two-lap route", "configs/synthetic_two_laps.yaml", 6000)]


def world_keys(config):
    """The world's keys of a single-radar config (no radar's own), as 'key: value' lines."""
    keys = {}
    for line in open(os.path.join(ROOT, config)):
        line = line.split("#")[0].rstrip()
        if line and not line.startswith(" ") and ":" in line and not line.startswith(RADAR_KEYS):
            key, value = line.split(":", 1)
            keys[key.strip()] = value.strip()
    return keys


def odometry_rig_config(world_config, scans):
    """configs/rig_five_radars.yaml with the rear radar, its world overlaid by `world_config`'s keys."""
    text = open(os.path.join(ROOT, "configs/rig_five_radars.yaml")).read()
    world, radars = text.split("radars:", 1)
    keys = {}
    for line in world.splitlines():
        line = line.split("#")[0].rstrip()
        if line.startswith("  ") and ":" in line:
            key, value = line.strip().split(":", 1)
            keys[key] = value.strip()
    if world_config:
        keys.update({k: v for k, v in world_keys(world_config).items() if k not in ("rate_hz", "materials")})
    if scans:
        keys["scans"] = str(scans)
    return ("world:\n" + "".join(f"  {k}: {v}\n" for k, v in keys.items()) + "radars:" + radars.rstrip() + "\n" +
            REAR_RADAR)


def simulate_rig(tool, rig_dir, config_text):
    """`radargauss simulate --rig-config` of the text into rig_dir: the rig file's head and each radar's entry
    by name (to write rig files of some of its radars)."""
    os.makedirs(os.path.dirname(rig_dir), exist_ok=True)
    with open(rig_dir + ".yaml", "w") as f:
        f.write(config_text)
    result = subprocess.run([tool, "simulate", "--rig-config", rig_dir + ".yaml", "--out", rig_dir, "--force"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"rig_table: simulate {rig_dir}.yaml failed: {result.stderr.strip()}")
    head, *radars = open(os.path.join(rig_dir, "rig.yaml")).read().split("  - name:")
    return head, {r.split("\n")[0].strip().strip('"'): "  - name:" + r for r in radars}


def run_odometry(tool, flags, out):
    """ATE m, RPE t %, horizontal %, the median step (ms; a rig's frame), the steps (a rig's frames) and
    the wall time (s) of one odometry run."""
    start = time.perf_counter()
    result = subprocess.run([tool, "--threads", "1", "odometry", "--out", out] + flags, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit(f"rig_table: odometry {' '.join(flags)} failed: {result.stderr.strip()}")
    evaluation = json.load(open(os.path.join(out, "evaluation.json")))
    frames = re.search(r"; ([0-9.]+) ms per frame", result.stdout)
    steps = np.genfromtxt(os.path.join(out, "per_scan.csv"), delimiter=",", names=True, usecols=("time_ms",))
    median = float(frames.group(1)) if frames else float(np.median(steps["time_ms"]))
    return (evaluation["ate_translation_m"]["rmse"], evaluation["rpe"]["translation_percent"],
            evaluation["rpe"]["horizontal_percent"], median, len(steps), wall)


def odometry_table(tool, work):
    print("| world | run | ATE m | RPE t % | horizontal % | median ms per scan or frame | wall s |")
    print("|---|---|---|---|---|---|---|")
    for world, config, scans in ODOMETRY_WORLDS:
        rig_dir = os.path.join(work, "rig_" + world.split()[0].replace("-", "_"))
        head, by_name = simulate_rig(tool, rig_dir, odometry_rig_config(config, scans))
        alone = {}
        for name in by_name:
            sequence = os.path.join(rig_dir, name)
            alone[name] = run_odometry(tool, ["--sequence", sequence, "--gt",
                                              os.path.join(sequence, "gt_radar_tum.txt")],
                                       os.path.join(work, "alone_" + name))
            row = alone[name]
            print(f"| {world} | {name} alone | {row[0]:.3f} | {row[1]:.3f} | {row[2]:.3f} | {row[3]:.2f} | "
                  f"{row[5]:.2f} |")
        every_rate = [(label + ", every rate", names, ["--rig-rotation-rate", "all"])
                      for label, names in ODOMETRY_RIGS if label.startswith("4")]
        for label, names, flags in [(label, names, []) for label, names in ODOMETRY_RIGS] + every_rate:
            rig_file = os.path.join(rig_dir, "rig_" + "_".join(names) + ".yaml")
            with open(rig_file, "w") as f:
                f.write(head + "".join(by_name[n] for n in names))
            row = run_odometry(tool, ["--rig", rig_file, "--gt", os.path.join(rig_dir, "gt_body_tum.txt")] + flags,
                               os.path.join(work, "rig_" + "_".join(names)))
            best = min(alone[n][1] for n in names)
            wall_alone = sum(alone[n][5] for n in names)
            # Its radars' median scans, as many as a frame holds of each.
            per_frame_alone = sum(alone[n][3] * alone[n][4] / row[4] for n in names)
            print(f"| {world} | rig {label} | {row[0]:.3f} | {row[1]:.3f} ({row[1] / best:.2f}x its best radar) | "
                  f"{row[2]:.3f} | {row[3]:.2f} (its radars' {per_frame_alone:.2f}) | "
                  f"{row[5]:.2f} ({row[5] / wall_alone:.2f}x its radars') |")


def slam_table(tool, work):
    """SLAM on the two-lap route's rigs (table 2's radars), against the front radar's SLAM."""
    world, config, scans = ODOMETRY_WORLDS[2]
    rig_dir = os.path.join(work, "rig_two_lap")
    if not os.path.exists(os.path.join(rig_dir, "rig.yaml")):
        os.makedirs(work, exist_ok=True)
        with open(rig_dir + ".yaml", "w") as f:
            f.write(odometry_rig_config(config, scans))
        subprocess.run([tool, "simulate", "--rig-config", rig_dir + ".yaml", "--out", rig_dir, "--force"], check=True,
                       stdout=subprocess.DEVNULL)
    text = open(os.path.join(rig_dir, "rig.yaml")).read()
    head, *radars = text.split("  - name:")
    by_name = {r.split("\n")[0].strip().strip('"'): "  - name:" + r for r in radars}
    print("| rig | ATE m | RPE t % | horizontal % | loops | odometry ATE m | wall s |")
    print("|---|---|---|---|---|---|---|")
    # The loops' consistency bound set for one radar's drift (5 % of the path), and a rig's (2 %).
    tighter = [(label + ", --verify-drift 0.02", names, ["--verify-drift", "0.02"]) for label, names in ODOMETRY_RIGS]
    for label, names, flags in [(label, names, []) for label, names in ODOMETRY_RIGS] + tighter:
        rig_file = os.path.join(rig_dir, "rig_" + "_".join(names) + ".yaml")
        with open(rig_file, "w") as f:
            f.write(head + "".join(by_name[n] for n in names))
        out = os.path.join(work, "slam_" + "_".join(names))
        subprocess.run(["rm", "-rf", out], check=True)
        start = time.perf_counter()
        result = subprocess.run([tool, "slam", "--rig", rig_file, "--gt", os.path.join(rig_dir, "gt_body_tum.txt"),
                                 "--no-map", "--out", out] + flags, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)
        wall = time.perf_counter() - start
        if result.returncode != 0:
            sys.exit(f"rig_table: slam --rig {rig_file} failed: {result.stderr.strip()}")
        evaluation = json.load(open(os.path.join(out, "evaluation.json")))
        odometry = json.load(open(os.path.join(out, "odometry", "evaluation.json")))
        loops = re.search(r"([0-9]+) loops", result.stdout).group(1)
        print(f"| {label} | {evaluation['ate_translation_m']['rmse']:.3f} | "
              f"{evaluation['rpe']['translation_percent']:.3f} | {evaluation['rpe']['horizontal_percent']:.3f} | "
              f"{loops} | {odometry['ate_translation_m']['rmse']:.3f} | {wall:.1f} |")


# Table 4: table 2's worlds with one IMU on the body (200 Hz, 0.3 m above
# the vehicle's origin, turned 90 deg; the simulator's default noise and
# biases). Not ahead of the origin: there the simulated path's yaw-rate
# steps make impulses (docs/design/simulator.md, "The synthetic world").
IMU_WORLD_KEYS = "  imu_rate_hz: 200\n  imu_z: 0.3\n  imu_yaw_deg: 90\n"
IMU_RIGS = [rig for rig in ODOMETRY_RIGS if rig[0][0] in "1456"]


def imu_table(tool, work):
    """Each rig of table 2 with and without the body's IMU (one window over the rig)."""
    print("| world | rig | ATE m | RPE t % | horizontal % | with the IMU: ATE m | RPE t % | horizontal % | "
          "median ms per frame |")
    print("|---|---|---|---|---|---|---|---|---|")
    for world, config, scans in ODOMETRY_WORLDS:
        rig_dir = os.path.join(work, "imu_rig_" + world.split()[0].replace("-", "_"))
        head, by_name = simulate_rig(
            tool, rig_dir, odometry_rig_config(config, scans).replace("world:\n", "world:\n" + IMU_WORLD_KEYS, 1))
        imu = ["--imu", os.path.join(rig_dir, "imu.txt"), "--imu-extrinsic", os.path.join(rig_dir, "imu_extrinsic.txt")]
        for label, names in IMU_RIGS:
            rig_file = os.path.join(rig_dir, "rig_" + "_".join(names) + ".yaml")
            with open(rig_file, "w") as f:
                f.write(head + "".join(by_name[n] for n in names))
            flags = ["--rig", rig_file, "--gt", os.path.join(rig_dir, "gt_body_tum.txt")]
            alone = run_odometry(tool, flags, os.path.join(work, "imu_without_" + "_".join(names)))
            fused = run_odometry(tool, flags + imu, os.path.join(work, "imu_with_" + "_".join(names)))
            print(f"| {world} | {label} | {alone[0]:.3f} | {alone[1]:.3f} | {alone[2]:.3f} | {fused[0]:.3f} | "
                  f"{fused[1]:.3f} ({fused[1] / alone[1]:.2f}x) | {fused[2]:.3f} | {fused[3]:.2f} "
                  f"(without {alone[3]:.2f}) |")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tool", default=os.path.join(ROOT, "build/release/bin/radargauss"))
    parser.add_argument("--work", default="/tmp/rig_table")
    parser.add_argument("--scans", type=int, default=300)
    parser.add_argument("--tables", default="1,2,3")
    args = parser.parse_args()
    tables = args.tables.split(",")
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(args.tool))), "python"))
    import radargauss as rg

    if "2" in tables:
        odometry_table(args.tool, args.work)
        print()
    if "3" in tables:
        slam_table(args.tool, args.work)
        print()
    if "4" in tables:
        imu_table(args.tool, args.work)
        print()
    if "1" not in tables:
        return
    print("| world | rig | scans | rank | observed error median | under 0.1 | velocity RMSE m/s "
          "| yaw rate RMSE mrad/s | roll / pitch rate RMSE mrad/s | mean NEES (dof) | ms per estimate |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for world, config in WORLDS:
        for label, radars in RIGS:
            out = os.path.join(args.work, f"{world.split()[0]}_{label.split(':')[0]}")
            os.makedirs(args.work, exist_ok=True)
            rig_config = out + ".yaml"
            with open(rig_config, "w") as f:
                f.write(world_section(config, args.scans) + "radars:\n" + radars)
            result = subprocess.run([args.tool, "simulate", "--rig-config", rig_config, "--out", out, "--force"],
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            if result.returncode != 0:
                sys.exit(f"rig_table: simulate {rig_config} failed: {result.stderr.strip()}")
            rig = rg.read_rig(os.path.join(out, "rig.yaml"))
            sequences = [rg.read_sequence(radar["sequence"]) for radar in rig]
            mountings = [radar["body_from_radar"] for radar in rig]
            truth = np.loadtxt(os.path.join(out, "twist_body.txt"), comments="#")
            projected, velocity, yaw, tilt, nees, dof, ranks, elapsed = [], [], [], [], [], [], [], 0.0
            for k in range(len(truth)):
                start = time.perf_counter()
                twist = rg.estimate_rig_twist([s.scans[k] for s in sequences], mountings)
                elapsed += time.perf_counter() - start
                if not twist["success"]:
                    continue
                x = np.concatenate([twist["velocity"].ravel(), twist["angular_velocity"].ravel()])
                error = x - truth[k, 1:7]
                observed = twist["observed"]
                error = observed @ error  # an unobserved direction is not an error of the estimate
                projected.append(error @ error)
                velocity.append(np.sum(error[:3] ** 2))
                yaw.append(error[5] ** 2)
                tilt.append(error[3] ** 2 + error[4] ** 2)
                nees.append(error @ np.linalg.pinv(twist["covariance"]) @ error)
                dof.append(twist["rank"])
                ranks.append(twist["rank"])
            rank = int(np.median(ranks))
            norms = np.sqrt(projected)
            good = norms < 0.1

            def rmse(values, scale=1.0, shown=True, parts=1):
                values = np.asarray(values)[good]
                return f"{scale * np.sqrt(np.mean(values) / parts):.4g}" if shown else "-"

            print(f"| {world} | {label} | {len(ranks)} | {rank} | {np.median(norms):.4f} | "
                  f"{100 * np.mean(good):.0f} % | {rmse(velocity, shown=rank == 6)} | {rmse(yaw, 1e3, rank >= 5)} | "
                  f"{rmse(tilt, 1e3, rank == 6, 2)} | {np.mean(np.asarray(nees)[good]):.2f} ({np.mean(dof):.0f}) | "
                  f"{1e3 * elapsed / len(truth):.2f} |")

if __name__ == "__main__":
    main()
