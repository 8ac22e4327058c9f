#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The radar-inertial tables of bench/RESULTS.md (docs/design.md,
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
and the own Gauss-Newton at window sizes 5 / 10 / 20.

    scripts/inertial_table.py [--tool build/release/bin/radargauss] [--work /tmp/inertial_table] [--scenes demo,realistic,motorway]
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
SCENES = {"demo": [], "realistic": ["synthetic_realistic.yaml"], "motorway": ["synthetic_motorway.yaml"]}
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
        lines.append("imu_rate_hz: 200")
        config = out + ".yaml"
        with open(config, "w") as f:
            f.write("\n".join(lines) + "\n")
        run(tool + ["simulate", "--config", config, "--out", out, "--force"])
    return out


def true_bias_at_end(sequence):
    rows = np.loadtxt(os.path.join(sequence, "imu_biases.txt"), comments="#")
    return rows[-1, 1:4], rows[-1, 4:7]


def odometry(tool, sequence, name, flags, imu):
    out = os.path.join(sequence + "_runs", name)
    shutil.rmtree(out, ignore_errors=True)
    command = tool + ["odometry", "--sequence", sequence, "--gt", os.path.join(sequence, "gt_radar_tum.txt"),
                      "--extrinsic", "identity", "--out", out] + flags
    if imu:
        command += ["--imu", os.path.join(sequence, "imu.txt"), "--imu-extrinsic",
                    os.path.join(sequence, "imu_extrinsic.txt")]
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
    return row


def line(label, r):
    return (f"| {label} | {r['rpe']:.3f} | {r['horizontal']:.3f} | {r['ate']:.3f} | {r['median']:.2f} | "
            f"{r['p90']:.2f} | {r['gyro']} | {r['accel']} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tool", default=os.path.join(ROOT, "build", "release", "bin", "radargauss"))
    parser.add_argument("--work", default="/tmp/inertial_table")
    parser.add_argument("--scenes", default="demo,realistic,motorway")
    args = parser.parse_args()
    tool = [args.tool, "--threads", "1"] if "--threads" in run([args.tool, "--help"]) else [args.tool]
    print("| scene, front end | RPE % | horizontal % | ATE m | median ms | p90 ms | gyro bias error rad/s | "
          "accel bias error m/s^2 |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in args.scenes.split(","):
        sequence = simulate(tool, args.work, scene)
        print(line(f"{scene}: radar only", odometry(tool, sequence, "radar", [], False)))
        if scene == "realistic":
            print(line(f"{scene}: radar only, mounting given, bias estimated",
                       odometry(tool, sequence, "radar_mounted", MOUNTED, False)))
        print(line(f"{scene}: gyro in the prediction", odometry(tool, sequence, "gyro", ["--imu-fusion", "gyro"],
                                                                True)))
        print(line(f"{scene}: radar-inertial", odometry(tool, sequence, "inertial", [], True)), flush=True)
    sequence = simulate(tool, args.work, "realistic")
    print()
    print("| window solver | size | RPE % | horizontal % | ATE m | median ms | p90 ms | gyro bias error rad/s | "
          "accel bias error m/s^2 |")
    print("|---|---|---|---|---|---|---|---|---|")
    for solver in ("ceres-lm", "ceres-dogleg", "gn"):
        for size in (5, 10, 20):
            r = odometry(tool, sequence, f"{solver}_{size}", ["--window-solver", solver, "--window-size", str(size)],
                         True)
            print(line(f"{solver} | {size}", r), flush=True)


if __name__ == "__main__":
    main()
