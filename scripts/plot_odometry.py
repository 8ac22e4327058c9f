#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Plots of a `radargauss odometry` output folder (matplotlib, Debian's python3).

    scripts/plot_odometry.py OUT --reference REF.tum

Both trajectories start at the same pose (the estimate is moved onto the
reference's first matched pose). Writes into OUT:
  odometry_top_view.png  the reference and the estimate from above
  odometry_error.png     position error (total and horizontal) over the distance driven
"""
import argparse
import bisect
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_tum(path):
    poses = []
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                v = [float(x) for x in line.split()]
                poses.append((v[0], v[1:4], v[4:8]))
    return poses


def rotation(q):
    x, y, z, w = q
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def apply(R, v):
    return [sum(R[i][k] * v[k] for k in range(3)) for i in range(3)]


def transpose(R):
    return [[R[k][i] for k in range(3)] for i in range(3)]


def matched_pairs(estimate, reference, tolerance=0.02):
    times = [p[0] for p in reference]
    pairs = []
    for stamp, t, q in estimate:
        i = bisect.bisect_left(times, stamp)
        best = min((j for j in (i - 1, i) if 0 <= j < len(times)), key=lambda j: abs(times[j] - stamp), default=None)
        if best is not None and abs(times[best] - stamp) <= tolerance:
            pairs.append(((t, q), reference[best][1:]))
    return pairs


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out")
    parser.add_argument("--reference", required=True)
    args = parser.parse_args()
    estimate = read_tum(os.path.join(args.out, "odometry.tum"))
    pairs = matched_pairs(estimate, read_tum(args.reference))
    if len(pairs) < 2:
        sys.exit("plot_odometry: fewer than two estimate poses match the reference in time")
    # T_ref0 T_est0^-1 applied to the estimate: both start at the reference's first pose.
    (t0, q0), (r0, s0) = pairs[0]
    A = [[sum(rotation(s0)[i][k] * transpose(rotation(q0))[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    moved = []
    for (t, _), _ in pairs:
        d = apply(A, [t[i] - t0[i] for i in range(3)])
        moved.append([r0[i] + d[i] for i in range(3)])
    ref = [r for _, (r, _) in pairs]
    distance, total, horizontal, driven = [], [], [], 0.0
    for k in range(len(ref)):
        if k:
            driven += math.dist(ref[k], ref[k - 1])
        e = [moved[k][i] - ref[k][i] for i in range(3)]
        distance.append(driven)
        total.append(math.sqrt(sum(x * x for x in e)))
        horizontal.append(math.hypot(e[0], e[1]))
    fig, ax = plt.subplots(figsize=(7, 6))
    ax.plot([p[0] for p in ref], [p[1] for p in ref], "k-", label="reference")
    ax.plot([p[0] for p in moved], [p[1] for p in moved], "C0-", label="odometry")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend()
    fig.savefig(os.path.join(args.out, "odometry_top_view.png"), dpi=120, bbox_inches="tight")
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(distance, total, label="position error")
    ax.plot(distance, horizontal, label="horizontal")
    ax.set_xlabel("distance driven (m)")
    ax.set_ylabel("error from the same start (m)")
    ax.legend()
    fig.savefig(os.path.join(args.out, "odometry_error.png"), dpi=120, bbox_inches="tight")
    print(f"plots: {args.out}/odometry_top_view.png, odometry_error.png ({len(pairs)} poses, {driven:.1f} m)")


if __name__ == "__main__":
    main()
