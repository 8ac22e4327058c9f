#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The fault table of bench/REAL_RADAR.md: the simulator's faults of real
radars (docs/design/simulator.md, "The faults of real radars"), each alone and all
together, on the demo's world and on the motorway (configs/synthetic_motorway.yaml).
Per row: odometry (one thread, defaults) RPE and ATE against the truth, and
the paper's localisation from 2 m / 5 deg in the map built from the truth:
within 0.1 m / 1 deg at w_rcs 0 and 0.25. Counter-measures as extra rows:
the robust RCS loss (off), the mounting given (--mounting), the elevation
bias estimated (--estimate-elevation-bias) or given to every command
(--elevation-bias), the map's angular noise.
Prints a Markdown table.

    scripts/fault_table.py [--tool build/release/bin/radargauss] [--work /tmp/fault_table] [--only demo,motorway]
"""
import argparse
import csv
import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ALL = {"elevation_bias_deg": 0.5, "elevation_noise_growth": 1, "mounting_roll_deg": 0.5,
       "mounting_pitch_deg": 1.5, "mounting_yaw_deg": -1, "rcs_swerling": 1, "multipath_probability": 0.2}
MOUNTED = ["--mounting", "0.5", "1.5", "-1"]
FAULTS = [("none", {}),
          ("ghosts (20 % of wall rays)", {"multipath_probability": 0.2}),
          ("Swerling I", {"rcs_swerling": 1}),
          ("Swerling III", {"rcs_swerling": 3}),
          ("elevation bias 1 deg", {"elevation_bias_deg": 1.0}),
          ("elevation noise 3x at the edges", {"elevation_noise_growth": 2}),
          ("mounting 0.5 / 1.5 / -1 deg", {"mounting_roll_deg": 0.5, "mounting_pitch_deg": 1.5,
                                            "mounting_yaw_deg": -1}),
          ("all (configs/synthetic_realistic.yaml)", ALL)]
SCENES = {"demo": [], "motorway": open(os.path.join(ROOT, "configs", "synthetic_motorway.yaml")).read().splitlines()}
# Counter-measures per fault, "as is" for every one: (name, flags of the
# sequence (odometry, build-map and localize), of odometry, of localize).
AS_IS = ("as is", [], [], [])
NO_ROBUST_RCS = ("RCS loss trivial (robust Cauchy off)", [], [], ["--rcs-loss", "trivial"])
MEASURES = {"none": [AS_IS, NO_ROBUST_RCS],
            "Swerling I": [AS_IS, NO_ROBUST_RCS],
            "Swerling III": [AS_IS, NO_ROBUST_RCS],
            "elevation bias 1 deg": [AS_IS, ("bias estimated", [], ["--estimate-elevation-bias"], []),
                                     ("bias given (--elevation-bias 1 to every command)", ["--elevation-bias", "1"],
                                      [], [])],
            "mounting 0.5 / 1.5 / -1 deg": [AS_IS, ("mounting given", [], MOUNTED, [])],
            "all (configs/synthetic_realistic.yaml)": [
                AS_IS, ("mounting given, bias estimated", [], MOUNTED + ["--estimate-elevation-bias"], []),
                ("both, and the map's azimuth noise 0.2 deg", [], MOUNTED + ["--estimate-elevation-bias",
                                                                            "--azimuth-std", "0.2"], [])]}


def run(command):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"fault_table: {' '.join(command)} failed: {result.stderr.strip()}")


def simulate(tool, work, scene, name, faults):
    out = os.path.join(work, f"{scene}_{name.split()[0]}_{'_'.join(f'{v}' for v in faults.values())}")
    if not os.path.exists(os.path.join(out, "gt_radar_tum.txt")):
        os.makedirs(work, exist_ok=True)
        config = out + ".yaml"
        lines = [line for line in SCENES[scene] if line and not line.startswith("#")]
        lines += [f"{key}: {value}" for key, value in faults.items()]
        with open(config, "w") as f:
            f.write("\n".join(lines) + "\n")
        run(tool + ["simulate", "--config", config, "--out", out, "--force"])
    return out


def measure(tool, sequence, measure):
    name, sequence_flags, odometry_flags, localize_flags = measure
    truth = os.path.join(sequence, "gt_radar_tum.txt")
    tag = "_".join(name.split()[:2]).replace(",", "")
    odometry = os.path.join(sequence + f"_odometry_{tag}")
    if not os.path.exists(os.path.join(odometry, "evaluation.json")):
        run(tool + ["odometry", "--sequence", sequence, "--gt", truth, "--out", odometry, *sequence_flags,
                    *odometry_flags])
    e = json.load(open(os.path.join(odometry, "evaluation.json")))
    path = sequence + (f"_map_{tag}.rgm" if sequence_flags else "_map.rgm")
    if not os.path.exists(path):
        run(tool + ["build-map", "--sequence", sequence, "--gt", truth, "--extrinsic", "identity", "--out", path,
                    *sequence_flags])
    localize = os.path.join(sequence + f"_localize_{tag}")
    if not os.path.exists(os.path.join(localize, "per_scan.csv")):
        run(tool + ["localize", "--map", path, "--sequence", sequence, "--gt", truth, "--extrinsic", "identity",
                    "--w-rcs", "0", "0.25", "--stride", "2", "--out", localize, *sequence_flags, *localize_flags])
    rows = list(csv.DictReader(open(os.path.join(localize, "per_scan.csv"))))
    within = []
    for w in ("0", "0.25"):
        chosen = [r for r in rows if float(r["w_rcs"]) == float(w)]
        t = np.array([float(r["translation_m"]) for r in chosen])
        a = np.array([float(r["rotation_deg"]) for r in chosen])
        within.append(100 * np.mean((t < 0.1) & (a < 1)))
    return (e["rpe"]["translation_percent"], e["rpe"]["horizontal_percent"], e["ate_translation_m"]["rmse"],
            *within)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--tool", default=os.path.join(ROOT, "build", "release", "bin", "radargauss"))
    parser.add_argument("--work", default="/tmp/fault_table")
    parser.add_argument("--only", default="demo,motorway")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    tool = [args.tool, "--threads", "1"]
    cases = [(scene, name, faults, m) for scene in args.only.split(",") for name, faults in FAULTS
             for m in MEASURES.get(name, [AS_IS]) if scene == "demo" or name in ("none", FAULTS[-1][0])]
    with ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(lambda c: measure(tool, simulate(tool, args.work, c[0], c[1], c[2]), c[3]), cases))
    print("| scene | faults | counter-measure | odometry RPE % | horizontal % | ATE m | localisation within 0.1 m / 1 deg, "
          "w 0 | w 0.25 |")
    print("|---|---|---|---|---|---|---|---|")
    for (scene, name, _, m), r in zip(cases, results):
        print(f"| {scene} | {name} | {m[0]} | {r[0]:.2f} | {r[1]:.2f} | {r[2]:.3f} | {r[3]:.1f} % | {r[4]:.1f} % |")


if __name__ == "__main__":
    main()
