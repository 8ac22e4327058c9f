#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Odometry figures of bench/RESULTS.md, "Odometry": `radargauss odometry` on
the NTU Eagle sample, the demo's simulated sequence and two simulated drives
of 3000 scans: five laps of the demo's loop (inside the active radius, so the
active map is the whole world) and one 1.8 km lap that leaves the radius
behind (configs/synthetic_long_drive.yaml). For w_rcs 0 and 0.25
(simulated: RCS), the velocity term on and off, and with --pcl the PCL peers
as the loop's matcher, one thread. Prints a Markdown table: RPE (10-50 % of
the path; translation and horizontal %, deg/m), ATE RMSE, per-scan time
(median, p90), peak memory, and the first and last tenth's median time and
active map size (and the second tenth's map: the first is the fill-up of
the active radius). "sim3 horizontal" is the horizontal RPE of the
estimate scaled by its Sim3 alignment (`evaluate --align sim3`): the drift
that is not a uniform scale.

    scripts/odometry_table.py [--tool build/release/bin/radargauss] [--work /tmp/odometry_table] [--quick] [--pcl]
                              [--only NTU,demo,long,route]
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NTU = os.path.join(ROOT, "..", "shared", "data", "ntu4dradlm_loop1_eagle")


def run(command):
    """Runs a command; returns its peak resident memory in MB (the child's own)."""
    child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(child.pid, 0)
    child.returncode = os.waitstatus_to_exitcode(status)
    if child.returncode != 0:
        sys.exit(f"odometry_table: {' '.join(command)} failed: {child.stderr.read().decode().strip()}")
    return usage.ru_maxrss / 1024.0


def tenths(out):
    with open(os.path.join(out, "per_scan.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    n = max(1, len(rows) // 10)
    first, second, last = rows[:n], rows[n:2 * n], rows[-n:]
    def median(rows, key):
        return statistics.median(float(r[key]) for r in rows)
    return (median(first, "time_ms"), median(last, "time_ms"), median(first, "active_map_bytes") / 1e6,
            median(second, "active_map_bytes") / 1e6, median(last, "active_map_bytes") / 1e6)


def sim3_horizontal(tool, out, reference):
    """Horizontal RPE (%) of the odometry in OUT after a Sim3 alignment to REFERENCE."""
    folder = os.path.join(out, "sim3")
    run(tool + ["evaluate", "--est", os.path.join(out, "odometry.tum"), "--ref", reference,
                "--align", "sim3", "--out", folder])
    e = json.load(open(os.path.join(folder, "evaluation.json")))
    return e["rpe"]["horizontal_percent"], e["scale"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tool", default=os.path.join(ROOT, "build", "release", "bin", "radargauss"))
    parser.add_argument("--work", default="/tmp/odometry_table")
    parser.add_argument("--quick", action="store_true", help="the demo sequence only")
    parser.add_argument("--pcl", action="store_true", help="rows with pcl-ndt and pcl-gicp as the matcher")
    parser.add_argument("--only", default="", help="comma-separated first words of the data sets to run (NTU,demo,long,route)")
    args = parser.parse_args()
    tool = [args.tool, "--threads", "1"]
    os.makedirs(args.work, exist_ok=True)
    only = [word for word in args.only.split(",") if word]
    simulated = [("demo", "demo (simulated, 300 scans)", ["--config", os.path.join(ROOT, "configs", "synthetic_world.yaml")]),
                 ("long", "long loop (simulated, 3000 scans, 5 laps)", ["--scans", "3000"]),
                 ("route", "route (simulated, 3000 scans, 1.8 km)",
                  ["--config", os.path.join(ROOT, "configs", "synthetic_long_drive.yaml")])]
    sets = []
    if os.path.isdir(NTU) and not args.quick:
        sets.append(("NTU Eagle sample", ["--config", os.path.join(ROOT, "configs", "ntu_eagle_odometry.yaml"),
                                          "--sequence", os.path.join(NTU, "points"),
                                          "--gt", os.path.join(NTU, "gt_tum.txt")], False))
    for name, label, config in simulated[:1] if args.quick else simulated:
        if only and name not in only:
            continue
        folder = os.path.join(args.work, name)
        run(tool + ["simulate", "--out", folder, "--force"] + config)
        sets.append((label, ["--sequence", folder, "--gt", os.path.join(folder, "gt_radar_tum.txt")], True))
    print("| data | matcher | w_rcs | velocity term | RPE t % | RPE horizontal % | sim3 horizontal % (scale) "
          "| RPE r deg/m | ATE t RMSE m | ms/scan median | p90 | peak MB "
          "| tenths: ms first / last, active map MB first / second / last |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for label, flags, has_rcs in sets:
        if only and label.split()[0] not in only:
            continue
        reference = flags[flags.index("--gt") + 1]
        runs = [("gaussians", w, velocity) for w in ([0, 0.25] if has_rcs else [0]) for velocity in (1, 0)]
        if args.pcl:
            runs += [("pcl-ndt", 0, 0), ("pcl-gicp", 0, 0)]
        for matcher, w, velocity in runs:
            out = os.path.join(args.work, f"{label.split()[0]}-{matcher}-w{w}-v{velocity}")
            peak = run(tool + ["odometry"] + flags + ["--matcher", matcher, "--w-rcs", str(w),
                                                      "--velocity-weight", str(velocity), "--out", out])
            e = json.load(open(os.path.join(out, "evaluation.json")))
            s = json.load(open(os.path.join(out, "summary.json")))
            t0, t1, m0, m1, m2 = tenths(out)
            horizontal, scale = sim3_horizontal(tool, out, reference)
            rpe = e["rpe"]
            print(f"| {label} | {matcher} | {w} | {'on' if velocity else 'off'} | {rpe['translation_percent']:.2f} "
                  f"| {rpe['horizontal_percent']:.2f} | {horizontal:.2f} ({scale:.4f}) "
                  f"| {rpe['rotation_deg_per_m']:.4f} | {e['ate_translation_m']['rmse']:.3f} "
                  f"| {s['median_time_ms']:.2f} | {s['p90_time_ms']:.2f} | {peak:.0f} "
                  f"| {t0:.2f} / {t1:.2f} ms, {m0:.1f} / {m1:.1f} / {m2:.1f} MB |", flush=True)


if __name__ == "__main__":
    main()
