#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Is the radar-inertial window consistent? (docs/design/odometry.md, "Consistency,
measured"). A Monte Carlo over seeds on three simulated worlds: the demo
world, the demo world with the faults of real radars and the IMU 20 ms
late (configs/synthetic_realistic.yaml), and the yard (configs/
synthetic_yard.yaml: another mounting, a poorer 100 Hz IMU 12 ms late,
which no default was set on). Each seed is a new drive (its noise and its
scene). Each run is radar-inertial odometry at the defaults, estimating
the clock offset, the radar-IMU rotation and the elevation bias from a
T_radar_imu 1 deg off the truth with --vehicle-motion-std 0.1.

Per world and quantity (the gyro and accelerometer biases at the last
scan, the clock offset, the rotation's three angles, the elevation bias):
the mean NEES over the runs, e^T P^-1 e with P the window's stated
(diagonal) variances, against its 95 % band (the mean of N chi-square
draws of d degrees of freedom; Wilson-Hilferty), and the share of
components within 3 stated sigmas (99.7 % if consistent).

    scripts/consistency_table.py [--tool build/release/bin/radargauss] [--work /tmp/consistency] [--seeds 25]
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from inertial_table import log, rotation_vector, so3  # noqa: E402

WORLDS = {
    "demo": {"configs": [], "extra": ["imu_rate_hz: 200", "scans: 250"], "late": 0.0, "bias": 0.0},
    "realistic": {"configs": ["synthetic_realistic.yaml"],
                  "extra": ["imu_rate_hz: 200", "scans: 250", "imu_clock_offset: 0.02"], "late": 0.02, "bias": 0.5},
    "yard": {"configs": ["synthetic_yard.yaml"], "extra": ["scans: 300"], "late": 0.012, "bias": 0.5},
}
ROUGH = np.radians([0.6, -0.5, 0.6])  # the rotation's start off the truth (1 deg)


def run(command):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"consistency_table: {' '.join(command)} failed: {result.stderr.strip()}")


def band(n, d):
    """The 95 % band of the mean of n chi-square(d) draws (Wilson-Hilferty)."""
    k = n * d
    return [k * (1 - 2 / (9 * k) + z * np.sqrt(2 / (9 * k))) ** 3 / n for z in (-1.96, 1.96)]


def one_run(tool, work, world, seed):
    w = WORLDS[world]
    folder = os.path.join(work, f"{world}_{seed}")
    sequence = os.path.join(folder, "sequence")
    if not os.path.exists(os.path.join(sequence, "imu.txt")):
        os.makedirs(folder, exist_ok=True)
        lines = []
        for name in w["configs"]:
            lines += [line for line in open(os.path.join(ROOT, "configs", name)).read().splitlines()
                      if line and not line.startswith("#") and not line.startswith("scans:")]
        config = os.path.join(folder, "world.yaml")
        with open(config, "w") as f:
            f.write("\n".join(lines + w["extra"]) + "\n")
        run(tool + ["simulate", "--config", config, "--seed", str(seed), "--out", sequence, "--force"])
    truth = np.loadtxt(os.path.join(sequence, "imu_extrinsic.txt"), comments="#")
    true_rotation = so3(rotation_vector(truth[3:7]))
    rough = true_rotation @ so3(ROUGH)
    q = rough_quaternion(rough)
    extrinsic = os.path.join(folder, "rough.txt")
    with open(extrinsic, "w") as f:
        f.write(" ".join(str(v) for v in list(truth[:3]) + list(q)) + "\n")
    out = os.path.join(folder, "run")
    shutil.rmtree(out, ignore_errors=True)
    run(tool + ["odometry", "--sequence", sequence, "--extrinsic", "identity", "--out", out, "--imu",
                os.path.join(sequence, "imu.txt"), "--imu-extrinsic", extrinsic, "--vehicle-motion-std", "0.1",
                "--estimate-clock-offset", "--estimate-extrinsic-rotation", "--estimate-elevation-bias"])
    c = json.load(open(os.path.join(out, "summary.json")))["calibration"]
    if c is None:  # the IMU was dropped (imu_health) before the window could start
        return None
    biases = np.loadtxt(os.path.join(sequence, "imu_biases.txt"), comments="#")[-1]
    estimated = so3(np.radians(c["radar_from_imu_rotation_vector_deg"]))
    errors = {
        "gyro bias": (np.array(c["gyro_bias"]) - biases[1:4], np.array(c["gyro_bias_std"])),
        "accel bias": (np.array(c["accel_bias"]) - biases[4:7], np.array(c["accel_bias_std"])),
        "clock offset": (np.array([c["clock_offset_s"] - w["late"]]), np.array([c["clock_offset_std_s"]])),
        # On the right of R_imu_radar, as the window states its std.
        "rotation": (log(estimated @ true_rotation.T), np.radians(c["imu_from_radar_rotation_std_deg"])),
        "elevation bias": (np.array([c["elevation_bias_deg"] - w["bias"]]), np.array([c["elevation_bias_std_deg"]])),
    }
    return errors


def rough_quaternion(R):
    """x y z w of a rotation matrix."""
    w = np.sqrt(max(0.0, 1 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    x = np.copysign(np.sqrt(max(0.0, 1 + R[0, 0] - R[1, 1] - R[2, 2])) / 2, R[2, 1] - R[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1 - R[0, 0] + R[1, 1] - R[2, 2])) / 2, R[0, 2] - R[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1 - R[0, 0] - R[1, 1] + R[2, 2])) / 2, R[1, 0] - R[0, 1])
    return [x, y, z, w]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tool", default=os.path.join(ROOT, "build", "release", "bin", "radargauss"))
    parser.add_argument("--work", default="/tmp/consistency")
    parser.add_argument("--seeds", type=int, default=25)
    parser.add_argument("--worlds", default="demo,realistic,yard")
    args = parser.parse_args()
    tool = [args.tool, "--threads", "1"]
    print("| world | quantity | runs | mean NEES | 95 % band | within 3 sigma | mean error / mean std |")
    print("|---|---|---|---|---|---|---|")
    for world in args.worlds.split(","):
        runs = [one_run(tool, args.work, world, seed) for seed in range(1, args.seeds + 1)]
        dropped = sum(r is None for r in runs)
        runs = [r for r in runs if r is not None]
        if dropped:
            print(f"| {world} | IMU dropped | {dropped} | | | | |")
        for quantity in runs[0]:
            e = np.array([r[quantity][0] for r in runs])
            s = np.array([r[quantity][1] for r in runs])
            z = e / np.where(s > 0, s, np.nan)
            nees = np.nanmean(np.nansum(z * z, axis=1))
            low, high = band(len(runs), e.shape[1])
            within = np.mean(np.abs(z) <= 3)
            ratio = np.sqrt(np.mean(e * e)) / np.mean(s)
            print(f"| {world} | {quantity} | {len(runs)} | {nees:.1f} | {low:.1f}-{high:.1f} | {100 * within:.0f} % | "
                  f"{ratio:.1f} |", flush=True)


if __name__ == "__main__":
    main()
