#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The RCS term's gain with one radar against a rig (bench/RESULTS.md,
"Radar rigs"): the paper's localisation protocol
(configs/synthetic_world_localize.yaml: every scan from its reference pose
composed with a seeded error of up to 2 m and 5 deg, the w_rcs sweep) on
the front radar's scans of scripts/rig_table.py's rig over the demo world,
against two maps built at the reference poses:

- the front radar's map: its own scans alone (the paper's setting);
- the rig's map: every radar's scans, so that a Gaussian gathers members
  seen from several aspects at once.

Each map localises the front radar's scans of its own drive, and of a
second drive over the same world's objects with other noise draws
(world_seed kept, seed + 100): the paper's setting of a map built before.

Per map: its Gaussians, the mean members per Gaussian, the share of
Gaussians whose RCS model varies with the view (degree above 0), and per
w_rcs the translation error's median and RMSE (m); the gain is the median
at w_rcs 0 over the best median of the sweep.

    scripts/rig_rcs_table.py [--tool build/release/bin/radargauss] [--work /tmp/rig_rcs]

The module is found beside the tool (build/release/python).
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rig_table import ODOMETRY_WORLDS, odometry_rig_config  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SEED = 1  # the simulator's default: the first drive's seed and world


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tool", default=os.path.join(ROOT, "build/release/bin/radargauss"))
    parser.add_argument("--work", default="/tmp/rig_rcs")
    args = parser.parse_args()
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(args.tool))), "python"))
    import radargauss as rg

    os.makedirs(args.work, exist_ok=True)
    world, config, scans = ODOMETRY_WORLDS[0]
    # The second drive: the same world's objects (world_seed), other noise draws.
    drives = {"rig_demo": "", "rig_demo_second": f"  world_seed: {SEED}\n  seed: {SEED + 100}\n"}
    for name, keys in drives.items():
        rig_dir = os.path.join(args.work, name)
        if not os.path.exists(os.path.join(rig_dir, "rig.yaml")):
            with open(rig_dir + ".yaml", "w") as f:
                f.write(odometry_rig_config(config, scans).replace("world:\n", "world:\n" + keys, 1))
            subprocess.run([args.tool, "simulate", "--rig-config", rig_dir + ".yaml", "--out", rig_dir], check=True,
                           stdout=subprocess.DEVNULL)
    radars = rg.read_rig(os.path.join(args.work, "rig_demo", "rig.yaml"))
    paths = {r["name"]: r["sequence"] for r in radars}
    sequences = {name: rg.read_sequence(path, os.path.join(path, "gt_radar_tum.txt")) for name, path in paths.items()}
    front = radars[0]["name"]
    second = rg.read_rig(os.path.join(args.work, "rig_demo_second", "rig.yaml"))[0]["sequence"]
    print("| map | scans localised | Gaussians | members per Gaussian | view-dependent RCS | w_rcs: median m (RMSE) | "
          "gain |")
    print("|---|---|---|---|---|---|---|")
    for label, names in [("front radar alone", [front]), ("rig of six", [r["name"] for r in radars])]:
        scans, poses = [], []
        for name in names:
            scans += list(sequences[name].scans)
            poses += list(sequences[name].poses)
        gaussian_map = rg.build_map(scans, poses, builder="kmeans", points_per_gaussian=4.0, incidence="offset",
                                    max_degree=3)
        map_path = os.path.join(args.work, label.split()[0] + ".rgm")
        rg.write_map(map_path, gaussian_map)
        members = np.asarray(gaussian_map.point_counts)
        degrees = np.asarray(gaussian_map.rcs_degrees)
        for drive, path in [("its own", paths[front]), ("a second drive's", second)]:
            out = os.path.join(args.work, "localize_" + label.split()[0] + "_" + drive.split()[0])
            subprocess.run(["rm", "-rf", out], check=True)
            subprocess.run([args.tool, "localize", "--config",
                            os.path.join(ROOT, "configs/synthetic_world_localize.yaml"), "--sequence", path, "--gt",
                            os.path.join(path, "gt_radar_tum.txt"), "--map", map_path, "--out", out], check=True,
                           stdout=subprocess.DEVNULL)
            rows = sorted(json.load(open(os.path.join(out, "summary.json"))), key=lambda c: c["w_rcs"])
            cells = "; ".join(f"{c['w_rcs']:g}: {c['translation_m']['median']:.3f} ({c['translation_m']['rmse']:.3f})"
                              for c in rows)
            gain = rows[0]["translation_m"]["median"] / min(c["translation_m"]["median"] for c in rows)
            print(f"| {label} | {drive} front scans | {len(members)} | {members.mean():.1f} | "
                  f"{100 * np.mean(degrees > 0):.0f} % | {cells} | {gain:.2f}x |")


if __name__ == "__main__":
    main()
