#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Inflated against merged coarse levels on the same scans and initial
errors: `radargauss localize` per setting and error seed, one thread, own
Gauss-Newton; prints a Markdown table of time per scan, the share of scans
within 0.1 m / 1 deg and beyond 1 m, over all seeds.
  scripts/compare_coarse_levels.py TOOL OUT [--seeds 5] [--errors 2/5,4/10] [--data-dir ../shared/data]
--errors lists the initial error bounds, metres/degrees."""
import argparse
import csv
import pathlib
import statistics
import subprocess
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent


def run(command):
    subprocess.run([str(c) for c in command], check=True, stdout=subprocess.DEVNULL)


def data_sets(tool, out, data_dir):
    """(name, localize flags, weights) per data set, with the map built once."""
    sets = []
    demo = out / "demo"
    run([tool, "simulate", "--out", demo / "sequence", "--config", ROOT / "configs/synthetic_world.yaml", "--force"])
    demo_flags = ["--sequence", demo / "sequence", "--gt", demo / "sequence/gt_radar_tum.txt"]
    run([tool, "build-map", *demo_flags, "--out", demo / "map.rgm"])
    sets.append(("demo world (300 scans)", demo_flags + ["--map", demo / "map.rgm"], "0,0.25"))
    ntu = data_dir / "ntu4dradlm_loop1_eagle"
    if (ntu / "points").is_dir():
        ntu_flags = ["--sequence", ntu / "points", "--gt", ntu / "gt_tum.txt", "--extrinsic", "identity"]
        run([tool, "build-map", *ntu_flags, "--points-per-gaussian", "16", "--out", out / "ntu.rgm"])
        sets.append(("NTU Eagle (every scan)", ntu_flags + ["--map", out / "ntu.rgm"], "0"))
    return sets


def summarise(rows):
    translation = [float(r["translation_m"]) for r in rows]
    rotation = [float(r["rotation_deg"]) for r in rows]
    within = sum(t < 0.1 and r < 1.0 for t, r in zip(translation, rotation)) / len(rows)
    beyond = sum(t > 1.0 for t in translation) / len(rows)
    return within, beyond, statistics.median(float(r["time_ms"]) for r in rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tool")
    parser.add_argument("out", type=pathlib.Path)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--errors", default="2/5,4/10")
    parser.add_argument("--data-dir", type=pathlib.Path, default=ROOT.parent / "shared" / "data")
    args = parser.parse_args()
    print("| data | initial error | w | coarse levels | median ms/scan | within 0.1 m / 1 deg | beyond 1 m "
          "| localize wall s |")
    print("|---|---|---|---|---|---|---|---|")
    sets = data_sets(args.tool, args.out, args.data_dir)
    for (name, flags, weights), bounds in ((s, b) for s in sets for b in args.errors.split(",")):
        translation, rotation = bounds.split("/")
        for setting in ("inflated", "merged"):
            rows, wall = [], 0.0
            for seed in range(1, args.seeds + 1):
                results = args.out / f"{name.split()[0]}-{translation}-{setting}-{seed}"
                start = time.monotonic()
                run([args.tool, "--threads", "1", "localize", *flags, "--solver", "gn", "--w-rcs", weights,
                     "--coarse-levels", setting, "--seed", seed, "--max-translation", translation,
                     "--max-rotation", rotation, "--out", results])
                wall += time.monotonic() - start
                with open(results / "per_scan.csv") as f:
                    rows += list(csv.DictReader(f))
            for w in sorted({r["w_rcs"] for r in rows}, key=float):
                within, beyond, median = summarise([r for r in rows if r["w_rcs"] == w])
                print(f"| {name} | {translation} m / {rotation} deg | {w} | {setting} | {median:.2f} | {100 * within:.1f}% | {100 * beyond:.1f}% | "
                      f"{wall / args.seeds:.1f} |")


if __name__ == "__main__":
    main()
