#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""A top view of a run written for a viewer (`radargauss export`, `--mcap`),
drawn from the MCAP file alone through radargauss's own reader: the map's
Gaussians coloured by their RCS, the trajectory, and the reference when the
file has one.

    scripts/render_run_mcap.py RUN.mcap OUT.png
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "build", "release", "python"))
import radargauss as rg  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    path, out = sys.argv[1], sys.argv[2]
    topics = {t["name"]: t for t in rg.read_bag_topics(path)}
    _, poses = rg.read_bag_poses(path, "/radar/pose")
    span = poses[:, :2].max(axis=0) - poses[:, :2].min(axis=0) + 40.0
    figure, axes = plt.subplots(figsize=(11, min(11.0, max(3.5, 11.0 * span[1] / span[0] + 1.0))))
    if "/map/gaussians" in topics:
        means = rg.read_sequence(bag=path, topic="/map/gaussians").scans[0]
        points = means.points
        shown = axes.scatter(points[:, 0], points[:, 1], c=means.rcs, s=0.3, cmap="viridis", vmin=-10, vmax=20)
        figure.colorbar(shown, ax=axes, shrink=0.7, label="Gaussian's RCS median (dBsm)")
    if "/reference/trajectory" in topics:
        _, reference = rg.read_bag_poses(path, "/reference/trajectory")
        axes.plot(reference[:, 0], reference[:, 1], "k--", linewidth=1.0, label="reference")
    axes.plot(poses[:, 0], poses[:, 1], "r-", linewidth=1.0, label="trajectory")
    axes.set_aspect("equal")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.set_title(f"{os.path.basename(path)}: {len(poses)} poses, " +
                   ", ".join(sorted(name for name in topics)), fontsize=7)
    axes.legend(loc="upper right")
    figure.tight_layout()
    figure.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
