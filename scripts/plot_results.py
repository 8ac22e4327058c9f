#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Plots of a `radargauss localize` results folder (matplotlib, Debian's python3).

    scripts/plot_results.py RESULTS [--sequence-tum GT.tum] [--map-points POINTS.csv]

Writes into RESULTS:
  error_vs_w_rcs.png  mean and median translation / rotation error against w_rcs,
                      with the 25-75 % band, one line per configuration family
  error_cdf.png       cumulative distributions of the errors per configuration
  top_view.png        top view of the reference and estimated trajectories
                      (and map Gaussian means when RESULTS/map_means.csv exists)
"""
import argparse
import csv
import os
import re
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_per_scan(path):
    rows = defaultdict(list)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            rows[row["configuration"]].append(row)
    if not rows:
        sys.exit(f"plot_results: {path}: no rows")
    return rows


def percentile(values, q):
    values = sorted(values)
    if not values:
        return float("nan")
    position = q * (len(values) - 1)
    low = int(position)
    high = min(low + 1, len(values) - 1)
    return values[low] + (values[high] - values[low]) * (position - low)


def family(name):
    """The configuration without its w_rcs, e.g. gn-w0.25-trivial-offset-L3 -> gn-trivial-offset-L3."""
    return re.sub(r"-w[0-9.]+", "", name)


def read_tum(path):
    xs, ys = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if len(parts) == 8 and not line.startswith("#"):
                xs.append(float(parts[1]))
                ys.append(float(parts[2]))
    return xs, ys


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", help="results folder of radargauss localize")
    parser.add_argument("--reference", help="reference TUM trajectory (radar frame) for the top view")
    args = parser.parse_args()
    per_scan = os.path.join(args.results, "per_scan.csv")
    if not os.path.isfile(per_scan):
        sys.exit(f"plot_results: {per_scan}: not found")
    rows = read_per_scan(per_scan)

    # Error against w_rcs, per family.
    families = defaultdict(list)
    for name, scans in rows.items():
        families[family(name)].append((float(scans[0]["w_rcs"]), scans))
    figure, axes = plt.subplots(1, 2, figsize=(11, 4))
    for key, (column, label) in enumerate([("translation_m", "translation error [m]"),
                                           ("rotation_deg", "rotation error [deg]")]):
        for name, points in sorted(families.items()):
            points.sort(key=lambda p: p[0])
            ws = [p[0] for p in points]
            values = [[float(r[column]) for r in p[1]] for p in points]
            axes[key].plot(ws, [sum(v) / len(v) for v in values], "o-", label=f"{name} mean")
            axes[key].plot(ws, [percentile(v, 0.5) for v in values], "s--", label=f"{name} median")
            axes[key].fill_between(ws, [percentile(v, 0.25) for v in values],
                                   [percentile(v, 0.75) for v in values], alpha=0.2)
        axes[key].set_xlabel("w_rcs")
        axes[key].set_ylabel(label)
        axes[key].grid(True, alpha=0.3)
    axes[0].legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(os.path.join(args.results, "error_vs_w_rcs.png"), dpi=120)

    # CDFs.
    figure, axes = plt.subplots(1, 2, figsize=(11, 4))
    for name, scans in sorted(rows.items()):
        for key, column in enumerate(["translation_m", "rotation_deg"]):
            values = sorted(float(r[column]) for r in scans)
            axes[key].plot(values, [(i + 1) / len(values) for i in range(len(values))], label=name)
    axes[0].set_xlabel("translation error [m]")
    axes[1].set_xlabel("rotation error [deg]")
    for axis in axes:
        axis.set_ylabel("fraction of scans")
        axis.grid(True, alpha=0.3)
    axes[1].legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(os.path.join(args.results, "error_cdf.png"), dpi=120)

    # Top view.
    figure, axis = plt.subplots(figsize=(7, 6))
    means = os.path.join(args.results, "map_means.csv")
    if os.path.isfile(means):
        with open(means, newline="") as f:
            points = [(float(r["x"]), float(r["y"])) for r in csv.DictReader(f)]
        axis.scatter([p[0] for p in points], [p[1] for p in points], s=0.5, c="0.6", label="map Gaussians")
    if args.reference:
        xs, ys = read_tum(args.reference)
        axis.plot(xs, ys, "k-", linewidth=2, label="reference")
    trajectories = os.path.join(args.results, "trajectories")
    for name in sorted(os.listdir(trajectories)) if os.path.isdir(trajectories) else []:
        xs, ys = read_tum(os.path.join(trajectories, name))
        axis.plot(xs, ys, linewidth=0.8, label=name[:-4])
    axis.set_aspect("equal", adjustable="datalim")
    axis.set_xlabel("x [m]")
    axis.set_ylabel("y [m]")
    axis.legend(fontsize=6)
    figure.tight_layout()
    figure.savefig(os.path.join(args.results, "top_view.png"), dpi=120)
    print(f"plots written to {args.results}: error_vs_w_rcs.png error_cdf.png top_view.png")


if __name__ == "__main__":
    main()
