#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""SLAM at scale (bench/RESULTS.md, "SLAM"): `radargauss slam` on drives of
1, 2, 4 and 10 laps of the 1.8 km route (configs/synthetic_two_laps.yaml's
world, 3,000 scans a lap), one run at a time.

Table 1, one thread, per drive: wall time and wall time per scan; the
per-scan median and p99 (slam.json); the mean and p99 per scan over the
first lap and over the last tenth of the drive (per_scan.csv); the
odometry's own time (the sum of odometry/per_scan.csv) and slam's wall time
against it; peak memory (the process's maximum resident set); the map file;
loops and ATE.

Table 1 also has the back end's time per keyframe (description, search,
verification, graph solves), the mean over the first lap and over the last
tenth. Table 2, threads: the two-lap drive with 1, 2, 4 threads and all
cores: wall time, its ratio to one thread's, the per-scan p99, the back
end's p99 per keyframe, and whether the trajectory equals one thread's.

    scripts/scale_table.py [--tool build/release/bin/radargauss] [--work /tmp/scale_table] [--laps 1,2,4,10]
                           [--threads 1,2,4,0] [--tables 1,2] [--slam-flags "--loop-spacing 25"]

--slam-flags are added to every slam run (its outputs then go to folders
named after them).
"""
import argparse
import csv
import filecmp
import json
import os
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCANS_PER_LAP = 3000


def run(command):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"scale_table: {' '.join(command)} failed: {result.stderr.strip()}")


def peak_mb(command):
    """The peak resident memory (MB) of one run, from GNU time."""
    result = subprocess.run(["/usr/bin/time", "-f", "%M"] + command, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"scale_table: {' '.join(command)} failed: {result.stderr.strip()}")
    return float(result.stderr.strip().splitlines()[-1]) / 1024.0


def drive(tool, work, laps):
    out = os.path.join(work, f"laps_{laps}")
    if not os.path.exists(os.path.join(out, "gt_radar_tum.txt")):
        os.makedirs(work, exist_ok=True)
        config = out + ".yaml"
        lines = [line for line in open(os.path.join(ROOT, "configs", "synthetic_two_laps.yaml")).read().splitlines()
                 if line and not line.startswith("#") and not line.startswith("scans:")]
        with open(config, "w") as f:
            f.write("\n".join(lines + [f"scans: {SCANS_PER_LAP * laps}"]) + "\n")
        run([tool, "simulate", "--config", config, "--out", out, "--force"])
    return out


def slam(tool, sequence, out, threads, flags):
    command = [tool, "--threads", str(threads), "slam", "--sequence", sequence, "--gt",
               os.path.join(sequence, "gt_radar_tum.txt"), "--out", out] + flags
    start = time.perf_counter()
    memory = peak_mb(command)
    wall = time.perf_counter() - start
    summary = json.load(open(os.path.join(out, "slam.json")))
    rows = list(csv.DictReader(open(os.path.join(out, "per_scan.csv"))))
    total = np.array([float(r["total_ms"]) for r in rows])
    odometry = sum(float(r["time_ms"]) for r in csv.DictReader(open(os.path.join(out, "odometry", "per_scan.csv"))))
    evaluation = json.load(open(os.path.join(out, "evaluation.json")))
    first, last = total[:SCANS_PER_LAP], total[-len(total) // 10:]
    keyframes = list(csv.DictReader(open(os.path.join(out, "keyframes.csv"))))
    back = np.array([float(k["describe_ms"]) + float(k["search_ms"]) for k in keyframes])
    first_keyframes = sum(int(k["scan"]) < SCANS_PER_LAP for k in keyframes)
    return {"wall": wall, "scans": len(total), "median": summary["scan_time_ms"]["median"],
            "p99": summary["scan_time_ms"]["p99"], "back_p99": summary["back_end_time_ms"]["p99"],
            "first_mean": first.mean(), "first_p99": np.percentile(first, 99), "last_mean": last.mean(),
            "last_p99": np.percentile(last, 99), "odometry_s": odometry / 1000.0, "memory": memory,
            "keyframe_first": back[:first_keyframes].mean(), "keyframe_last": back[-len(back) // 10:].mean(),
            "keyframe_p99": summary["keyframe_back_end_ms"]["p99"],
            "map_mb": os.path.getsize(os.path.join(out, "map.rgm")) / 1e6, "loops": summary["loops"],
            "ate": evaluation["ate_translation_m"]["rmse"]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tool", default=os.path.join(ROOT, "build", "release", "bin", "radargauss"))
    parser.add_argument("--work", default="/tmp/scale_table")
    parser.add_argument("--laps", default="1,2,4,10")
    parser.add_argument("--threads", default="1,2,4,0")
    parser.add_argument("--tables", default="1,2")
    parser.add_argument("--slam-flags", default="")
    args = parser.parse_args()
    flags = args.slam_flags.split()
    suffix = "".join(f.strip("-").replace("-", "_") + "_" for f in flags)
    tables = args.tables.split(",")
    if "1" in tables:
        print("| laps | scans | wall s | ms per scan | median ms | p99 ms | first lap mean / p99 ms | last tenth "
              "mean / p99 ms | back end per keyframe, first lap / last tenth ms | odometry s | wall / odometry | peak MB | "
              "map MB | loops | ATE m |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for laps in [int(n) for n in args.laps.split(",")]:
            sequence = drive(args.tool, args.work, laps)
            r = slam(args.tool, sequence, os.path.join(args.work, f"slam_{suffix}{laps}"), 1, flags)
            print(f"| {laps} | {r['scans']} | {r['wall']:.1f} | {1000 * r['wall'] / r['scans']:.2f} | "
                  f"{r['median']:.2f} | {r['p99']:.1f} | {r['first_mean']:.2f} / {r['first_p99']:.1f} | "
                  f"{r['last_mean']:.2f} / {r['last_p99']:.1f} | "
                  f"{r['keyframe_first']:.1f} / {r['keyframe_last']:.1f} | {r['odometry_s']:.1f} | "
                  f"{r['wall'] / r['odometry_s']:.1f} | {r['memory']:.0f} | {r['map_mb']:.1f} | {r['loops']} | "
                  f"{r['ate']:.3f} |", flush=True)
    if "2" in tables:
        print()
        print("| threads | wall s | against one thread | per-scan p99 ms | back end per keyframe p99 ms | "
              "trajectory as one thread's |")
        print("|---|---|---|---|---|---|")
        sequence = drive(args.tool, args.work, 2)
        reference = None
        for threads in [int(n) for n in args.threads.split(",")]:
            out = os.path.join(args.work, f"threads_{suffix}{threads}")
            r = slam(args.tool, sequence, out, threads, flags)
            if reference is None:
                reference = (r["wall"], out)
            same = filecmp.cmp(os.path.join(reference[1], "slam.tum"), os.path.join(out, "slam.tum"), shallow=False)
            label = threads if threads > 0 else f"all ({os.cpu_count()})"
            print(f"| {label} | {r['wall']:.1f} | {r['wall'] / reference[0]:.2f} | {r['p99']:.1f} | "
                  f"{r['keyframe_p99']:.1f} | "
                  f"{'yes' if same else 'no'} |", flush=True)


if __name__ == "__main__":
    main()
