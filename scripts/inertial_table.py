#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The radar-inertial tables of bench/RESULTS.md (docs/design/odometry.md,
"Radar-inertial odometry"): simulated drives with a 200 Hz MEMS IMU (the
simulator's defaults: noise densities, turn-on biases, random walks), one
thread, one run at a time.

Table 1, per scene (the demo's world; the demo's world with every fault of
real radars, configs/synthetic_realistic.yaml; the motorway): odometry
radar only at its defaults, radar only with the true mounting given and
the elevation bias estimated (the faulty scenes), the gyro's rates in the
prediction alone (--imu-fusion gyro), and radar-inertial at its defaults:
RPE, horizontal RPE, ATE, per-scan median and p90 time, and the window's
final gyro and accelerometer bias errors against the truth.

Table 2, the window's solvers on the faulty demo world: Ceres LM, dogleg
and the own Gauss-Newton at window sizes 5 / 10 / 20, with the iterations
per solve.

Table 3, calibration, per faulty scene (the realistic world; the motorway
with the same faults) with the IMU's stamps 20 ms late: radar only with
the true mounting given and its elevation bias estimated; radar-inertial
with the true T_radar_imu, clock offset and elevation bias given; and
radar-inertial from a nominal (identity) T_radar_imu, a zero offset and no
bias, all three estimated. Both radar-inertial rows use the vehicle's
motion term (--vehicle-motion-std 0.1; the simulated IMU is aligned with
the vehicle). Errors against the truth: the radar-IMU rotation's roll,
pitch and yaw (deg), the clock offset (ms), the elevation bias (deg) and
the gyro bias in units of the window's own standard deviation (largest axis).

Table 4, real radar with a made IMU: the NTU Eagle sample
(../shared/data/ntu4dradlm_loop1_eagle) with an IMU made from its reference
by `radargauss simulate-imu` (200 Hz, the simulator's MEMS noise and
biases, its stamps 12 ms late, mounted at roll 1.5 / pitch -1 / yaw 2 deg
to the radar): the radar alone and radar-inertial at the defaults and with
configs/ntu_eagle_odometry.yaml, the IMU's extrinsic and clock given, and
from a nominal (identity) extrinsic file stated rough (`std 3 0 0.05`: the
rotation and the clock offset estimated from zero).
Horizontal RPE and rotation drift (the sample's vertical reference is
uncertain: its README), ATE, per-scan median, and the calibration's errors.

    scripts/inertial_table.py [--tool build/release/bin/radargauss] [--work /tmp/inertial_table] [--scenes demo,realistic,motorway] [--tables 1,2,3,4]
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = {"demo": [], "realistic": ["synthetic_realistic.yaml"], "motorway": ["synthetic_motorway.yaml"],
          "realistic_late": ["synthetic_realistic.yaml"],
          "motorway_late": ["synthetic_motorway.yaml", "synthetic_realistic.yaml"],
          "yard": ["synthetic_yard.yaml"]}
LATE = 0.020  # s: the IMU's stamps behind the radar's in the *_late scenes
ELEVATION_BIAS = 0.5  # deg: synthetic_realistic.yaml's
NTU = os.path.join(ROOT, "..", "shared", "data", "ntu4dradlm_loop1_eagle")
NTU_IMU = ["--imu-clock-offset", "0.012", "--imu-roll-deg", "1.5", "--imu-pitch-deg", "-1", "--imu-yaw-deg", "2"]
MOUNTED = ["--mounting", "0.5", "1.5", "-1", "--estimate-elevation-bias"]


def run(command):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"inertial_table: {' '.join(command)} failed: {result.stderr.strip()}")
    return result.stdout


def simulate(tool, work, scene):
    out = os.path.join(work, scene)
    if not os.path.exists(os.path.join(out, "imu.txt")):
        os.makedirs(work, exist_ok=True)
        lines = []
        for name in SCENES[scene]:
            lines += [line for line in open(os.path.join(ROOT, "configs", name)).read().splitlines()
                      if line and not line.startswith("#")]
        if not any(line.startswith("imu_rate_hz:") for line in lines):
            lines.append("imu_rate_hz: 200")
        if scene.endswith("_late"):
            lines.append(f"imu_clock_offset: {LATE}")
        config = out + ".yaml"
        with open(config, "w") as f:
            f.write("\n".join(lines) + "\n")
        run(tool + ["simulate", "--config", config, "--out", out, "--force"])
    return out


def true_bias_at_end(sequence):
    rows = np.loadtxt(os.path.join(sequence, "imu_biases.txt"), comments="#")
    return rows[-1, 1:4], rows[-1, 4:7]


def odometry(tool, sequence, name, flags, imu, imu_extrinsic=None):
    out = os.path.join(sequence + "_runs", name)
    shutil.rmtree(out, ignore_errors=True)
    command = tool + ["odometry", "--sequence", sequence, "--gt", os.path.join(sequence, "gt_radar_tum.txt"),
                      "--extrinsic", "identity", "--out", out] + flags
    if imu:
        command += ["--imu", os.path.join(sequence, "imu.txt"), "--imu-extrinsic",
                    imu_extrinsic or os.path.join(sequence, "imu_extrinsic.txt")]
    run(command)
    evaluation = json.load(open(os.path.join(out, "evaluation.json")))
    summary = json.load(open(os.path.join(out, "summary.json")))
    row = {"rpe": evaluation["rpe"]["translation_percent"], "horizontal": evaluation["rpe"]["horizontal_percent"],
           "ate": evaluation["ate_translation_m"]["rmse"], "median": summary["median_time_ms"],
           "p90": summary["p90_time_ms"], "gyro": "", "accel": ""}
    states = os.path.join(out, "inertial.csv")
    if os.path.exists(states):
        last = list(csv.DictReader(open(states)))[-1]
        gyro, accel = true_bias_at_end(sequence)
        row["gyro"] = "%.5f" % np.linalg.norm([float(last[k]) for k in ("bgx", "bgy", "bgz")] - gyro)
        row["accel"] = "%.4f" % np.linalg.norm([float(last[k]) for k in ("bax", "bay", "baz")] - accel)
        row["gyro_sigmas"] = np.max(np.abs([float(last[k]) for k in ("bgx", "bgy", "bgz")] - gyro) /
                                    np.array(summary["calibration"]["gyro_bias_std"]))
        row["iterations"] = summary["window"]["iterations_mean"]
    row["summary"] = summary
    return row


def rotation_vector(quaternion_xyzw):
    """The rotation vector (rad) of a unit quaternion x y z w."""
    q = np.array(quaternion_xyzw, dtype=float)
    q = q / np.linalg.norm(q) * (1.0 if q[3] >= 0 else -1.0)
    angle = 2.0 * np.arctan2(np.linalg.norm(q[:3]), q[3])
    return q[:3] / np.linalg.norm(q[:3]) * angle if np.linalg.norm(q[:3]) > 1e-12 else np.zeros(3)


def so3(vector):
    """The rotation matrix of a rotation vector (rad)."""
    angle = np.linalg.norm(vector)
    if angle < 1e-12:
        return np.eye(3)
    k = np.asarray(vector) / angle
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def log(R):
    """The rotation vector (rad) of a rotation matrix."""
    angle = np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))
    if angle < 1e-12:
        return np.zeros(3)
    return angle / (2 * np.sin(angle)) * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])


def calibration_errors(sequence, summary):
    """Roll, pitch, yaw (deg) of R_radar_imu^T estimated, clock (ms), elevation bias (deg)."""
    truth = np.loadtxt(os.path.join(sequence, "imu_extrinsic.txt"), comments="#")
    c = summary["calibration"]
    estimated = so3(np.radians(c["radar_from_imu_rotation_vector_deg"]))
    rotation = np.degrees(log(so3(rotation_vector(truth[3:7])).T @ estimated))
    return (rotation, (c["clock_offset_s"] - LATE) * 1e3, c["elevation_bias_deg"] - ELEVATION_BIAS)


def line(label, r):
    return (f"| {label} | {r['rpe']:.3f} | {r['horizontal']:.3f} | {r['ate']:.3f} | {r['median']:.2f} | "
            f"{r['p90']:.2f} | {r['gyro']} | {r['accel']} |")


def scenes_table(tool, work, scenes):
    print("| scene, front end | RPE % | horizontal % | ATE m | median ms | p90 ms | gyro bias error rad/s | "
          "accel bias error m/s^2 |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in scenes:
        sequence = simulate(tool, work, scene)
        print(line(f"{scene}: radar only", odometry(tool, sequence, "radar", [], False)))
        if scene == "realistic":
            print(line(f"{scene}: radar only, mounting given, bias estimated",
                       odometry(tool, sequence, "radar_mounted", MOUNTED, False)))
        print(line(f"{scene}: gyro in the prediction", odometry(tool, sequence, "gyro", ["--imu-fusion", "gyro"],
                                                                True)))
        print(line(f"{scene}: radar-inertial", odometry(tool, sequence, "inertial", [], True)), flush=True)


def solver_table(tool, work):
    sequence = simulate(tool, work, "realistic")
    print("| window solver | size | RPE % | horizontal % | ATE m | median ms | p90 ms | gyro bias error rad/s | "
          "accel bias error m/s^2 | iterations per solve |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for solver in ("ceres-lm", "ceres-dogleg", "gn"):
        for size in (5, 10, 20):
            r = odometry(tool, sequence, f"{solver}_{size}", ["--window-solver", solver, "--window-size", str(size)],
                         True)
            print(line(f"{solver} | {size}", r) + f" {r['iterations']:.2f} |", flush=True)


def calibration_table(tool, work):
    print("| scene, calibration | RPE % | horizontal % | ATE m | median ms | p90 ms | roll, pitch, yaw error deg | "
          "clock error ms | elevation bias error deg | gyro bias error / std |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    nominal = os.path.join(work, "nominal.txt")
    for scene in ("realistic_late", "motorway_late"):
        sequence = simulate(tool, work, scene)
        with open(nominal, "w") as f:
            f.write("0 0 0 0 0 0 1\n")
        r = odometry(tool, sequence, "radar_mounted", MOUNTED, False)
        print(f"| {scene}: radar only, mounting given | {r['rpe']:.3f} | {r['horizontal']:.3f} | {r['ate']:.3f} | "
              f"{r['median']:.2f} | {r['p90']:.2f} | | | | |")
        given = ["--vehicle-motion-std", "0.1", "--imu-clock-offset", str(LATE), "--elevation-bias",
                 str(ELEVATION_BIAS)]
        r = odometry(tool, sequence, "inertial_given", given, True)
        print(f"| {scene}: radar-inertial, given | {r['rpe']:.3f} | {r['horizontal']:.3f} | {r['ate']:.3f} | "
              f"{r['median']:.2f} | {r['p90']:.2f} | | | | {r['gyro_sigmas']:.1f} |")
        estimated = ["--vehicle-motion-std", "0.1", "--estimate-extrinsic-rotation", "--estimate-clock-offset",
                     "--estimate-elevation-bias"]
        r = odometry(tool, sequence, "inertial_estimated", estimated, True, nominal)
        rotation, clock, bias = calibration_errors(sequence, r["summary"])
        print(f"| {scene}: radar-inertial, estimated | {r['rpe']:.3f} | {r['horizontal']:.3f} | {r['ate']:.3f} | "
              f"{r['median']:.2f} | {r['p90']:.2f} | {rotation[0]:.2f}, {rotation[1]:.2f}, {rotation[2]:.2f} | "
              f"{clock:.1f} | {bias:.2f} | {r['gyro_sigmas']:.1f} |", flush=True)


def ntu_table(tool, work):
    imu = os.path.join(work, "ntu_imu")
    if not os.path.exists(os.path.join(imu, "imu.txt")):
        run(tool + ["simulate-imu", "--gt", os.path.join(NTU, "gt_tum.txt"), "--out", imu, "--force"] + NTU_IMU)
    truth = np.loadtxt(os.path.join(imu, "imu_extrinsic.txt"), comments="#")
    nominal = os.path.join(work, "nominal_rough.txt")  # identity, stated rough: rotation and clock estimated
    with open(nominal, "w") as f:
        f.write("0 0 0 0 0 0 1\nstd 3 0 0.05\n")
    print("| NTU, front end | horizontal RPE % | rotation drift deg/m | ATE m | median ms | rotation error deg | "
          "clock error ms |")
    print("|---|---|---|---|---|---|---|")
    config = ["--config", os.path.join(ROOT, "configs", "ntu_eagle_odometry.yaml")]
    rows = [("radar alone, defaults", [], None), ("radar alone, NTU config", config, None),
            ("radar-inertial, defaults, given", ["--imu-clock-offset", "0.012"], "given"),
            ("radar-inertial, NTU config, given", config + ["--imu-clock-offset", "0.012"], "given"),
            ("radar-inertial, defaults, rough", [], "nominal"),
            ("radar-inertial, NTU config, rough", config, "nominal")]
    for label, flags, extrinsic in rows:
        out = os.path.join(work, "ntu_runs", label.replace(", ", "_").replace(" ", "_"))
        shutil.rmtree(out, ignore_errors=True)
        command = tool + ["odometry", "--sequence", os.path.join(NTU, "points"), "--gt",
                          os.path.join(NTU, "gt_tum.txt"), "--out", out] + flags
        if extrinsic:
            command += ["--imu", os.path.join(imu, "imu.txt"), "--imu-extrinsic",
                        os.path.join(imu, "imu_extrinsic.txt") if extrinsic == "given" else nominal]
        run(command)
        evaluation = json.load(open(os.path.join(out, "evaluation.json")))
        summary = json.load(open(os.path.join(out, "summary.json")))
        rotation, clock = "", ""
        c = summary.get("calibration", {})
        if "radar_from_imu_rotation_vector_deg" in c:
            estimated = so3(np.radians(c["radar_from_imu_rotation_vector_deg"]))
            rotation = "%.2f" % np.degrees(np.linalg.norm(log(so3(rotation_vector(truth[3:7])).T @ estimated)))
        if "clock_offset_s" in c:
            clock = "%.1f" % ((c["clock_offset_s"] - 0.012) * 1e3)
        print(f"| {label} | {evaluation['rpe']['horizontal_percent']:.3f} | "
              f"{evaluation['rpe']['rotation_deg_per_m']:.4f} | {evaluation['ate_translation_m']['rmse']:.3f} | "
              f"{summary['median_time_ms']:.2f} | {rotation} | {clock} |", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tool", default=os.path.join(ROOT, "build", "release", "bin", "radargauss"))
    parser.add_argument("--work", default="/tmp/inertial_table")
    parser.add_argument("--scenes", default="demo,realistic,motorway", help="table 1's scenes")
    parser.add_argument("--tables", default="1,2,3,4", help="which tables to make")
    args = parser.parse_args()
    tool = [args.tool, "--threads", "1"] if "--threads" in run([args.tool, "--help"]) else [args.tool]
    tables = args.tables.split(",")
    if "1" in tables:
        scenes_table(tool, args.work, args.scenes.split(","))
        print()
    if "2" in tables:
        solver_table(tool, args.work)
        print()
    if "3" in tables:
        calibration_table(tool, args.work)
        print()
    if "4" in tables:
        ntu_table(tool, args.work)


if __name__ == "__main__":
    main()
