#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The paper's localisation experiment on a sequence without reference
poses, and on the simulator beside it: "RCS on real radar" in bench/RESULTS.md.

Real: the smartmicro highway sample (real RCS, no poses). Odometry
(configs/smartmicro_highway_odometry.yaml) gives the trajectory, build-map
the Gaussian-RCS map from it, and localize matches every scan from 2 m / 5 deg
off that trajectory for each w_rcs and error seed. Simulated: the demo's
world (configs/synthetic_world.yaml), its map from the true poses, the same
sweep. Prints one Markdown table.

    scripts/real_rcs_table.py [--tool build/release/bin/radargauss] [--work /tmp/real_rcs] [--seeds 1 2 3 4 5]
"""
import argparse
import csv
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HIGHWAY = os.path.join(ROOT, "..", "shared", "data", "smartmicro_umrr_highway", "points")
WEIGHTS = ("0", "0.25", "0.5", "0.75")


def run(command):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"real_rcs_table: {' '.join(command)} failed: {result.stderr.strip()}")


def prepare_real(tool, work):
    """Odometry, then the map from its trajectory: (sequence, reference, map)."""
    odometry = os.path.join(work, "highway_odometry")
    if not os.path.exists(os.path.join(odometry, "odometry.tum")):
        run(tool + ["odometry", "--config", os.path.join(ROOT, "configs", "smartmicro_highway_odometry.yaml"),
                    "--sequence", HIGHWAY, "--out", odometry])
    reference = os.path.join(odometry, "odometry.tum")
    path = os.path.join(work, "highway_map.rgm")
    if not os.path.exists(path):
        run(tool + ["build-map", "--sequence", HIGHWAY, "--gt", reference, "--extrinsic", "identity", "--out", path])
    return HIGHWAY, reference, path


def prepare_simulated(tool, work):
    sequence = os.path.join(work, "synthetic_world")
    reference = os.path.join(sequence, "gt_radar_tum.txt")
    if not os.path.exists(reference):
        run(tool + ["simulate", "--config", os.path.join(ROOT, "configs", "synthetic_world.yaml"), "--out", sequence])
    path = os.path.join(work, "synthetic_map.rgm")
    if not os.path.exists(path):
        run(tool + ["build-map", "--sequence", sequence, "--gt", reference, "--extrinsic", "identity", "--out", path])
    return sequence, reference, path


def sweep(tool, work, name, inputs, seeds):
    """Per w_rcs: every scan of every seed's run from 2 m / 5 deg."""
    sequence, reference, path = inputs
    rows = []
    for seed in seeds:
        out = os.path.join(work, f"{name}_localize_{seed}")
        if not os.path.exists(os.path.join(out, "per_scan.csv")):
            run(tool + ["localize", "--map", path, "--sequence", sequence, "--gt", reference, "--extrinsic",
                        "identity", "--w-rcs", *WEIGHTS, "--seed", str(seed), "--out", out])
        rows += list(csv.DictReader(open(os.path.join(out, "per_scan.csv"))))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--tool", default=os.path.join(ROOT, "build", "release", "bin", "radargauss"))
    parser.add_argument("--work", default="/tmp/real_rcs")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    tool = [args.tool]
    print("| data | w_rcs | scans | t mean m | t median m | r mean deg | r median deg | within 0.1 m / 1 deg "
          "| converged |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, inputs in (("highway (real RCS)", prepare_real(tool, args.work)),
                         ("simulated world", prepare_simulated(tool, args.work))):
        rows = sweep(tool, args.work, name.split()[0], inputs, args.seeds)
        for w in WEIGHTS:
            chosen = [r for r in rows if float(r["w_rcs"]) == float(w)]
            t = np.array([float(r["translation_m"]) for r in chosen])
            a = np.array([float(r["rotation_deg"]) for r in chosen])
            converged = np.mean([r["converged"] == "1" for r in chosen])
            print(f"| {name} | {w} | {len(chosen)} | {t.mean():.3f} | {np.median(t):.3f} | {a.mean():.3f} "
                  f"| {np.median(a):.3f} | {100 * np.mean((t < 0.1) & (a < 1)):.1f} % | {100 * converged:.0f} % |")


if __name__ == "__main__":
    main()
