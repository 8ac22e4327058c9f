#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The peer tables of bench/RESULTS.md, "Odometry against kiss-icp" and "The
map build against small_gicp": `radargauss odometry` against kiss-icp's C++
core (bench/kiss_icp_peer.cpp) on the NTU Eagle sample, the demo's simulated
sequence and the 1.8 km route (3000 scans), and the map build against
small_gicp's default VGICP target (bench/small_gicp_target_peer.cpp) on the
same data. Odometry: ROUNDS alternated runs of each, first one thread with
both pinned to core 0 (`taskset -c 0`), then two threads each; the median
over the rounds of each run's per-scan median and p90, and the RPE and ATE
of the last round. Map build: ROUNDS runs on core 0, the middle one.
Build the peers first (scripts/kiss_icp_peer.sh, scripts/small_gicp_peer.sh).

    scripts/peer_table.py [--tool build/release/bin/radargauss] [--kiss build/kiss_icp_peer]
                          [--small-gicp build/small_gicp_target_peer] [--work /tmp/peer_table]
                          [--rounds 3] [--only NTU,demo,route]
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NTU = os.path.join(ROOT, "..", "shared", "data", "ntu4dradlm_loop1_eagle")


def run(command):
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"peer_table: {' '.join(command)} failed: {result.stderr.strip()}")
    return result.stdout


def percentile(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))]


def kiss_times(path):
    with open(path) as f:
        ms = [float(line.split(",")[1]) for line in f.readlines()[1:]]
    return statistics.median(ms), percentile(ms, 0.9)


def evaluation(tool, estimate, reference, out):
    run(tool + ["evaluate", "--est", estimate, "--ref", reference, "--out", out])
    e = json.load(open(os.path.join(out, "evaluation.json")))
    return e["rpe"]["translation_percent"], e["ate_translation_m"]["rmse"]


def odometry_rows(args, name, flags, sequence, reference):
    """Alternated rounds of radargauss and kiss-icp at one and two threads."""
    rows = []
    for threads in (1, 2):
        pin = ["taskset", "-c", "0"] if threads == 1 else []
        ours, theirs = [], []
        for k in range(args.rounds):
            out = os.path.join(args.work, f"{name}-ours-t{threads}")
            run(pin + [args.tool, "--threads", str(threads), "odometry"] + flags + ["--out", out])
            s = json.load(open(os.path.join(out, "summary.json")))
            ours.append((s["median_time_ms"], s["p90_time_ms"]))
            kiss = os.path.join(args.work, f"{name}-kiss-t{threads}")
            os.makedirs(kiss, exist_ok=True)
            run(pin + [args.kiss, sequence, os.path.join(kiss, "odometry.tum"), os.path.join(kiss, "times.csv"),
                       "1", "100", str(threads)])
            theirs.append(kiss_times(os.path.join(kiss, "times.csv")))
        e = json.load(open(os.path.join(out, "evaluation.json")))
        ours_rpe, ours_ate = e["rpe"]["translation_percent"], e["ate_translation_m"]["rmse"]
        kiss_rpe, kiss_ate = evaluation([args.tool], os.path.join(kiss, "odometry.tum"), reference,
                                        os.path.join(kiss, "evaluation"))
        for method, times, rpe, ate in (("radargauss", ours, ours_rpe, ours_ate),
                                        ("kiss-icp", theirs, kiss_rpe, kiss_ate)):
            rows.append(f"| {name} | {method} | {threads} | {statistics.median(t[0] for t in times):.2f} "
                        f"| {statistics.median(t[1] for t in times):.2f} | {rpe:.2f} | {ate:.3f} |")
    return rows


def map_build_row(args, name, sequence, reference, points_per_gaussian):
    totals = []
    for _ in range(args.rounds):
        text = run(["taskset", "-c", "0", args.small_gicp, sequence, reference] +
                   ([str(points_per_gaussian)] if points_per_gaussian else []))
        ours = re.search(r"radargauss: (\d+) Gaussians ([\d.]+) s, MatchingMap ([\d.]+) s, RCS fit ([\d.]+) s", text)
        theirs = re.search(r"small_gicp: (\d+) points .* all ([\d.]+) s", text)
        g, m, r = (float(ours.group(i)) for i in (2, 3, 4))
        totals.append((g + m + r, g, m, r, float(theirs.group(2)), int(theirs.group(1))))
    total, g, m, r, peer, points = sorted(totals)[len(totals) // 2]
    return (f"| {name} | {g:.3f} + {m:.3f} + {r:.3f} = {total:.3f} | {peer:.3f} ({points} points) "
            f"| {(g + m) / peer:.1f}x | {total / peer:.1f}x |")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tool", default=os.path.join(ROOT, "build", "release", "bin", "radargauss"))
    parser.add_argument("--kiss", default=os.path.join(ROOT, "build", "kiss_icp_peer"))
    parser.add_argument("--small-gicp", default=os.path.join(ROOT, "build", "small_gicp_target_peer"))
    parser.add_argument("--work", default="/tmp/peer_table")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--only", default="", help="comma-separated data sets to run (NTU,demo,route)")
    args = parser.parse_args()
    for binary in (args.tool, args.kiss, args.small_gicp):
        if not os.access(binary, os.X_OK):
            sys.exit(f"peer_table: no {binary} (build radargauss and the peers first)")
    if args.rounds < 1:
        sys.exit("peer_table: --rounds must be >= 1")
    os.makedirs(args.work, exist_ok=True)
    only = [word for word in args.only.split(",") if word]
    sets = []
    if os.path.isdir(NTU):
        points = os.path.join(NTU, "points")
        reference = os.path.join(NTU, "gt_tum.txt")
        sets.append(("NTU", ["--config", os.path.join(ROOT, "configs", "ntu_eagle_odometry.yaml"),
                             "--sequence", points, "--gt", reference], points, reference, 16))
    for name, config in (("demo", "synthetic_world.yaml"), ("route", "synthetic_long_drive.yaml")):
        if only and name not in only:
            continue
        folder = os.path.join(args.work, name)
        run([args.tool, "simulate", "--out", folder, "--force", "--config", os.path.join(ROOT, "configs", config)])
        reference = os.path.join(folder, "gt_radar_tum.txt")
        sets.append((name, ["--sequence", folder, "--gt", reference], folder, reference, 0))
    sets = [s for s in sets if not only or s[0] in only]
    print("| data | method | threads | ms/scan median | p90 | RPE t % | ATE m |")
    print("|---|---|---|---|---|---|---|")
    for name, flags, sequence, reference, _ in sets:
        for row in odometry_rows(args, name, flags, sequence, reference):
            print(row, flush=True)
    print()
    print("| data | radargauss: Gaussians + MatchingMap + RCS fit s | small_gicp s | ratio, geometry | ratio, all |")
    print("|---|---|---|---|---|")
    for name, _, sequence, reference, points_per_gaussian in sets:
        print(map_build_row(args, name, sequence, reference, points_per_gaussian), flush=True)


if __name__ == "__main__":
    main()
