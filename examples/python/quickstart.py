#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""radargauss from Python in one page: simulate a 4D radar drive, build its
Gaussian-RCS map, match a displaced scan against it, run odometry on the
drive without its ground truth, evaluate, and plot.

    PYTHONPATH=build/release/python examples/python/quickstart.py [OUT.png]
"""
import sys

import matplotlib
import numpy as np

import radargauss as rg

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402 (after the backend)

# A drive with ground truth: scans (points, Doppler, RCS) and their poses.
sequence = rg.simulate(seed=1, scans=150)
print(f"{len(sequence)} scans, first: {sequence.scans[0]}")

# The map of eq. 1: Gaussians whose RCS depends on the viewing direction.
world = rg.build_map(sequence)
degrees = world.rcs_degrees
print(f"{len(world)} Gaussians, {np.count_nonzero(degrees >= 0)} with an RCS model")

# Localisation: scan 60 from its pose moved by 1 m and 3 degrees.
error = rg.initial_errors(1, max_translation=1.0, max_rotation_deg=3.0, seed=7)[0]
start = rg.compose(sequence.poses[60], error)
for w in (0.0, 0.25):
    result = rg.match(sequence.scans[60], world, start, w_rcs=w)
    miss = np.linalg.norm(result.pose_tum[:3] - sequence.poses[60][:3])
    print(f"w_rcs {w}: {'converged' if result.converged else result.reason} in {result.iterations} "
          f"iterations, {miss:.3f} m from the truth")

# Odometry: the same scans, no poses; the map is built as the radar moves.
odometry = rg.RadarOdometry(w_rcs=0.25, initial_pose=sequence.poses[0])
for scan in sequence.scans:
    odometry.register(scan)
estimate = odometry.trajectory()
evaluation = rg.evaluate(estimate, (sequence.stamps, sequence.poses))
rpe = evaluation["rpe"]
print(f"odometry: RPE {rpe['translation_percent']:.2f} % ({rpe['horizontal_percent']:.2f} % horizontal), "
      f"ATE {evaluation['ate_translation_m']['rmse']:.3f} m")

# The map's means coloured by RCS median, the truth and the odometry.
figure, axes = plt.subplots(figsize=(8, 5))
means = world.means
scatter = axes.scatter(means[:, 0], means[:, 1], c=world.rcs_medians, s=2, cmap="viridis")
axes.plot(sequence.poses[:, 0], sequence.poses[:, 1], "k-", label="ground truth")
axes.plot(estimate[1][:, 0], estimate[1][:, 1], "r--", label="odometry")
axes.set_aspect("equal")
axes.set_xlabel("x [m]")
axes.set_ylabel("y [m]")
axes.legend()
figure.colorbar(scatter, label="RCS median [dBsm]")
out = sys.argv[1] if len(sys.argv) > 1 else "quickstart.png"
figure.savefig(out, dpi=120)
print(f"wrote {out}")
