#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The RCS term on real radar and on faithful simulations: "RCS on real
radar" in bench/REAL_RADAR.md.

The paper's localisation experiment (every scan from 2 m / 5 deg off its
reference, five error seeds) for w_rcs 0, 0.1, 0.25, 0.5, 0.75 and the
map's data-chosen weight, with each RCS residual (the paper's decibel one
with its Cauchy loss; the Swerling I and III likelihoods; each with the
per-Gaussian confidence), on:
- the smartmicro highway sample (real RCS, no poses): odometry
  (configs/smartmicro_highway_odometry.yaml) gives the reference, build-map
  the Gaussian-RCS map from it;
- the demo's world (configs/synthetic_world.yaml), clean;
- the same world with Swerling I fluctuation;
- the world with the real set's RCS statistics
  (configs/synthetic_real_rcs.yaml);
the simulated maps from the true poses. Then odometry's RPE with and without
the RCS term (w 0.25) on the simulated drives. Prints Markdown tables.

    scripts/real_rcs_table.py [--tool build/release/bin/radargauss] [--work /tmp/real_rcs]
                              [--seeds 1 2 3 4 5] [--only highway,clean,swerling,real-statistics]
                              [--residuals decibel,swerling1,...] [--no-odometry]
"""
import argparse
import csv
import json
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HIGHWAY = os.path.join(ROOT, "..", "shared", "data", "smartmicro_umrr_highway", "points")
WEIGHTS = ("0", "0.1", "0.25", "0.5", "0.75")
# name -> the flags of localize and odometry that select it
RESIDUALS = {
    "decibel": [],
    "decibel+confidence": ["--rcs-confidence"],
    "swerling1": ["--rcs-likelihood", "swerling1"],
    "swerling1+confidence": ["--rcs-likelihood", "swerling1", "--rcs-confidence"],
    "swerling3": ["--rcs-likelihood", "swerling3"],
    "swerling3+confidence": ["--rcs-likelihood", "swerling3", "--rcs-confidence"],
}
SIMULATED = {  # name -> (config, overrides of its keys)
    "clean": ("synthetic_world.yaml", {}),
    "swerling": ("synthetic_world.yaml", {"rcs_swerling": "1"}),
    "real-statistics": ("synthetic_real_rcs.yaml", {}),
}


def run(command):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"real_rcs_table: {' '.join(command)} failed: {result.stderr.strip()}")
    return result.stdout


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


def prepare_simulated(tool, work, name):
    config, overrides = SIMULATED[name]
    text = open(os.path.join(ROOT, "configs", config)).read().splitlines()
    for key, value in overrides.items():
        text = [f"{key}: {value}" if line.split(":")[0] == key else line for line in text]
    config_path = os.path.join(work, f"{name}.yaml")
    with open(config_path, "w") as f:
        f.write("\n".join(text) + "\n")
    sequence = os.path.join(work, name)
    reference = os.path.join(sequence, "gt_radar_tum.txt")
    if not os.path.exists(reference):
        run(tool + ["simulate", "--config", config_path, "--out", sequence])
    path = os.path.join(work, f"{name}_map.rgm")
    if not os.path.exists(path):
        run(tool + ["build-map", "--sequence", sequence, "--gt", reference, "--extrinsic", "identity", "--out", path])
    return sequence, reference, path


def sweep(tool, work, name, inputs, residual, seeds):
    """Per configuration (w_rcs, or "map" for the data-chosen one): every scan of every seed."""
    sequence, reference, path = inputs
    rows = []
    for seed in seeds:
        out = os.path.join(work, f"{name}_{residual}_localize_{seed}")
        if not os.path.exists(os.path.join(out, "per_scan.csv")):
            run(tool + ["localize", "--map", path, "--sequence", sequence, "--gt", reference, "--extrinsic",
                        "identity", "--w-rcs", ",".join(WEIGHTS), "--w-rcs-from-map", "--seed", str(seed),
                        "--out", out] + RESIDUALS[residual])
        rows += list(csv.DictReader(open(os.path.join(out, "per_scan.csv"))))
    return rows


def statistics(rows):
    t = np.array([float(r["translation_m"]) for r in rows])
    a = np.array([float(r["rotation_deg"]) for r in rows])
    return {"scans": len(rows), "t_mean": t.mean(), "t_median": np.median(t), "r_mean": a.mean(),
            "r_median": np.median(a), "within": 100 * np.mean((t < 0.1) & (a < 1)),
            "converged": 100 * np.mean([r["converged"] == "1" for r in rows])}


def localisation_table(tool, work, sets, residuals, seeds):
    """Two tables: within 0.1 m / 1 deg per weight (and the map's own), then
    each residual's errors at w 0, 0.25 and the map's weight."""
    results = []
    for name, inputs in sets:
        for residual in residuals:
            rows = sweep(tool, work, name, inputs, residual, seeds)
            by_weight = {w: statistics([r for r in rows if float(r["w_rcs"]) == float(w)
                                        and "-wmap" not in r["configuration"]]) for w in WEIGHTS}
            chosen = [r for r in rows if "-wmap" in r["configuration"]]
            weights = sorted({float(r["w_rcs"]) for r in chosen})
            results.append((name, residual, by_weight, statistics(chosen), weights))
    print("| data | residual | scans | " + " | ".join(f"w {w}" for w in WEIGHTS) +
          " | the map's w | within 0.1 m / 1 deg at it | swept best - it |")
    print("|---|---|---|" + "---|" * len(WEIGHTS) + "---|---|---|")
    for name, residual, by_weight, chosen, weights in results:
        best = max(s["within"] for s in by_weight.values())
        print(f"| {name} | {residual} | {by_weight['0']['scans']} | "
              + " | ".join(f"{by_weight[w]['within']:.1f}" for w in WEIGHTS)
              + f" | {', '.join(f'{w:.3f}' for w in weights)} | {chosen['within']:.1f} | {best - chosen['within']:+.1f} |")
    print("\n| data | residual | w | t mean / median m | r mean / median deg | within | converged |")
    print("|---|---|---|---|---|---|---|")
    for name, residual, by_weight, chosen, weights in results:
        if residual.endswith("+confidence"):
            continue  # the first table has them; here the residuals themselves
        for label, s in (("0", by_weight["0"]), ("0.25", by_weight["0.25"]), ("map", chosen)):
            if label == "0" and residual != residuals[0]:
                continue  # w 0 is the same match for every residual
            print(f"| {name} | {residual} | {label} | {s['t_mean']:.3f} / {s['t_median']:.3f} "
                  f"| {s['r_mean']:.3f} / {s['r_median']:.3f} | {s['within']:.1f} % | {s['converged']:.0f} % |",
                  flush=True)


def odometry_table(tool, work, sets, residuals):
    print("\n| data | residual | w_rcs | RPE t % | RPE r deg/m | ATE m |")
    print("|---|---|---|---|---|---|")
    for name, (sequence, reference, _) in sets:
        if name == "highway":
            continue  # no reference poses
        for residual, w in [("decibel", "0")] + [(r, "0.25") for r in residuals]:
            out = os.path.join(work, f"{name}_{residual}_odometry_w{w}")
            if not os.path.exists(os.path.join(out, "evaluation.json")):
                run(tool + ["--threads", "1", "odometry", "--sequence", sequence, "--gt", reference, "--w-rcs", w,
                            "--out", out] + RESIDUALS[residual])
            e = json.load(open(os.path.join(out, "evaluation.json")))
            print(f"| {name} | {'none' if w == '0' else residual} | {w} | {e['rpe']['translation_percent']:.2f} "
                  f"| {e['rpe']['rotation_deg_per_m']:.4f} | {e['ate_translation_m']['rmse']:.3f} |", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--tool", default=os.path.join(ROOT, "build", "release", "bin", "radargauss"))
    parser.add_argument("--work", default="/tmp/real_rcs")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    parser.add_argument("--only", default="", help="comma-separated data sets (highway,clean,swerling,real-statistics)")
    parser.add_argument("--residuals", default=",".join(RESIDUALS), help="comma-separated residuals to sweep")
    parser.add_argument("--no-odometry", action="store_true", help="the localisation table only")
    args = parser.parse_args()
    residuals = [r for r in args.residuals.split(",") if r]
    unknown = [r for r in residuals if r not in RESIDUALS]
    if unknown:
        sys.exit(f"real_rcs_table: unknown residuals {unknown} (known: {', '.join(RESIDUALS)})")
    only = [word for word in args.only.split(",") if word]
    os.makedirs(args.work, exist_ok=True)
    tool = [args.tool]
    sets = []
    if not only or "highway" in only:
        sets.append(("highway", prepare_real(tool, args.work)))
    for name in SIMULATED:
        if not only or name in only:
            sets.append((name, prepare_simulated(tool, args.work, name)))
    localisation_table(tool, args.work, sets, residuals, args.seeds)
    if not args.no_odometry:
        odometry_table(tool, args.work, sets, residuals)


if __name__ == "__main__":
    main()
