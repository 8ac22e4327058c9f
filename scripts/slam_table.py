#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""SLAM figures of bench/SLAM.md: two laps of the 1.8 km loop
(configs/synthetic_two_laps.yaml) through `radargauss slam` with each place
descriptor (ATE, RPE, true revisits closed, false loops, place recognition's
time, the map's size after one lap and two); the loop rejections of the pose
graph against 0, 10 and 30 % injected false loops; the localisation
experiment against the SLAM map and against the map from the truth; the
relocalisation of another run (configs/synthetic_two_laps_second_run.yaml)
from 20 starts; and the real NTU and highway samples through `slam`.
Prints Markdown tables.

    scripts/slam_table.py [--tool build/release/bin/radargauss] [--work /tmp/slam_table] [--jobs 2]
"""
import argparse
import csv
import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy.spatial.transform import Rotation

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "..", "shared", "data")


def run(command):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"slam_table: {' '.join(command)} failed: {result.stderr.strip()}")
    return result.stdout


def simulate(tool, config, out):
    if not os.path.exists(os.path.join(out, "gt_radar_tum.txt")):
        run(tool + ["simulate", "--config", os.path.join(ROOT, "configs", config), "--out", out])


def matrix(row):
    """T from a TUM row or 'x y z qx qy qz qw' values."""
    m = np.eye(4)
    m[:3, :3] = Rotation.from_quat(row[3:7]).as_matrix()
    m[:3, 3] = row[:3]
    return m


def read_tum(path):
    data = np.loadtxt(path, ndmin=2)
    return data[:, 0], [matrix(r[1:]) for r in data]


def pose_at(stamps, poses, t):
    return poses[int(np.argmin(np.abs(stamps - t)))]


def alignment(estimate, truth):
    """T_truth_estimate (Umeyama without scale) over the estimate's stamps."""
    es, ep = read_tum(estimate)
    ts, tp = read_tum(truth)
    p = np.array([m[:3, 3] for m in ep])
    q = np.array([pose_at(ts, tp, t)[:3, 3] for t in es])
    mp, mq = p.mean(0), q.mean(0)
    u, _, vt = np.linalg.svd((q - mq).T @ (p - mp))
    r = u @ np.diag([1, 1, np.sign(np.linalg.det(u @ vt))]) @ vt
    t = np.eye(4)
    t[:3, :3], t[:3, 3] = r, mq - r @ mp
    return t


def error(a, b):
    d = np.linalg.inv(a) @ b
    return np.linalg.norm(d[:3, 3]), np.degrees(np.linalg.norm(Rotation.from_matrix(d[:3, :3]).as_rotvec()))


def loop_figures(out, truth):
    """True revisits (a keyframe within 5 m of one at least 150 m driven back),
    those closed, and accepted loops whose keyframes lie more than 5 m apart."""
    ts, tp = read_tum(truth)
    keyframes = list(csv.DictReader(open(os.path.join(out, "keyframes.csv"))))
    position = [pose_at(ts, tp, float(k["stamp"]))[:3, 3] for k in keyframes]
    path = [float(k["path_m"]) for k in keyframes]
    loops = [r for r in csv.DictReader(open(os.path.join(out, "loops.csv")))
             if r["accepted"] == "1" and r["injected"] == "0"]
    closed_queries = {int(r["query"]) for r in loops}
    revisits = [q for q in range(len(keyframes))
                if any(path[q] - path[c] >= 150 and np.linalg.norm(position[q] - position[c]) < 5 for c in range(q))]
    false = [r for r in loops if np.linalg.norm(position[int(r["query"])] - position[int(r["candidate"])]) > 5]
    return len(revisits), len([q for q in revisits if q in closed_queries]), len(false), len(loops)


def evaluation(out):
    e = json.load(open(os.path.join(out, "evaluation.json")))
    return e["ate_translation_m"]["rmse"], e["rpe"]["translation_percent"], e["rpe"]["horizontal_percent"]


def map_size(tool, path):
    text = run(tool + ["map-info", path])
    gaussians = int(text.split("gaussians: ")[1].split(",")[0])
    return gaussians, os.path.getsize(path) / 1e6


def slam(tool, work, name, sequence, truth, *extra):
    out = os.path.join(work, name)
    if not os.path.exists(os.path.join(out, "slam.json")):
        run(tool + ["slam", "--sequence", sequence, "--gt", truth, "--extrinsic", "identity", "--out", out, *extra])
    return out


def truth_map(tool, work, laps):
    """build-map from the true poses over the first `laps` laps: the map's
    growth that is the radar's coverage of the place, not the laps' disagreement."""
    path = os.path.join(work, f"truth_map_{laps}.rgm")
    sequence, truth = os.path.join(work, "two_laps"), os.path.join(work, "two_laps", "gt_radar_tum.txt")
    if laps == 1:  # the first lap's scans, linked
        first = os.path.join(work, "first_lap", "ars548", "points")
        os.makedirs(first, exist_ok=True)
        scans = sorted(os.listdir(os.path.join(sequence, "ars548", "points")))[:3000]
        for name in scans:
            if not os.path.exists(os.path.join(first, name)):
                os.symlink(os.path.join(sequence, "ars548", "points", name), os.path.join(first, name))
        sequence = os.path.join(work, "first_lap")
    if not os.path.exists(path):
        run(tool + ["build-map", "--sequence", sequence, "--gt", truth, "--extrinsic", "identity", "--out", path])
    return map_size(tool, path)[0]


def drive_table(tool, work, jobs):
    sequence, truth = os.path.join(work, "two_laps"), os.path.join(work, "two_laps", "gt_radar_tum.txt")
    runs = [(d, laps) for d in ("scan-context", "radon") for laps in (1, 2)]
    with ThreadPoolExecutor(jobs) as pool:
        outs = list(pool.map(lambda r: slam(tool, work, f"slam_{r[0]}_{r[1]}", sequence, truth, "--descriptor", r[0],
                                            "--max-scans", str(3000 * r[1])), runs))
    print("| descriptor | laps | odometry ATE m | SLAM ATE m | odometry RPE % (horizontal) | SLAM RPE % (horizontal) "
          "| true revisits | closed | false loops accepted | place recognition ms/keyframe | map Gaussians (MB) "
          "| odometry's map Gaussians | map from the truth, Gaussians |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for (descriptor, laps), out in zip(runs, outs):
        odometry, mapped = evaluation(os.path.join(out, "odometry")), evaluation(out)
        revisits, closed, false, _ = loop_figures(out, truth)
        summary = json.load(open(os.path.join(out, "slam.json")))
        gaussians, megabytes = map_size(tool, os.path.join(out, "map.rgm"))
        odometry_map, _ = map_size(tool, os.path.join(out, "odometry", "map.rgm"))
        print(f"| {descriptor} | {laps} | {odometry[0]:.2f} | {mapped[0]:.2f} | {odometry[1]:.3f} ({odometry[2]:.3f}) "
              f"| {mapped[1]:.3f} ({mapped[2]:.3f}) | {revisits} | {closed} | {false} "
              f"| {summary['describe_time_ms'] + summary['search_time_ms']:.1f} | {gaussians} ({megabytes:.1f}) "
              f"| {odometry_map} | {truth_map(tool, work, laps)} |")


def loss_table(tool, work, jobs):
    sequence, truth = os.path.join(work, "two_laps"), os.path.join(work, "two_laps", "gt_radar_tum.txt")
    rejections = [("none", ["--loop-rejection", "loss", "--loop-loss", "trivial"]),
                  ("Huber", ["--loop-rejection", "loss", "--loop-loss", "huber", "--loop-loss-scale", "3"]),
                  ("Cauchy", ["--loop-rejection", "loss", "--loop-loss", "cauchy", "--loop-loss-scale", "3"]),
                  ("DCS (Phi 10)", ["--loop-rejection", "loss", "--loop-loss", "dcs", "--loop-loss-scale", "10"]),
                  ("switchable", ["--loop-rejection", "switchable"]),
                  ("graduated (default)", ["--loop-rejection", "graduated"])]
    rates = (0.0, 0.1, 0.3)
    runs = [(name, flags, rate) for name, flags in rejections for rate in rates]
    with ThreadPoolExecutor(jobs) as pool:
        outs = list(pool.map(lambda r: slam(tool, work, f"loss_{r[0].split()[0]}_{r[2]}", sequence, truth, "--no-map",
                                            "--descriptor", "radon", "--false-loop-rate", str(r[2]), *r[1]), runs))
    print("| loop rejection | " + " | ".join(f"ATE m, {int(100 * r)} % false loops" for r in rates) + " |")
    print("|---|" + "---|" * len(rates))
    for k, (name, _) in enumerate(rejections):
        cells = []
        for j in range(len(rates)):
            out = outs[k * len(rates) + j]
            injected = json.load(open(os.path.join(out, "slam.json")))["injected_false_loops"]
            cells.append(f"{evaluation(out)[0]:.2f} ({injected} injected)")
        print(f"| {name} | " + " | ".join(cells) + " |")


def write_tum(path, stamps, poses):
    with open(path, "w") as f:
        for t, m in zip(stamps, poses):
            q = Rotation.from_matrix(m[:3, :3]).as_quat()
            f.write(f"{t:.9f} " + " ".join(f"{v:.9f}" for v in (*m[:3, 3], *q)) + "\n")


def localisation_table(tool, work):
    """The paper's experiment (2 m / 5 deg) on the second run against each map."""
    truth_a = os.path.join(work, "two_laps", "gt_radar_tum.txt")
    second, truth_b = os.path.join(work, "second_run"), os.path.join(work, "second_run", "gt_radar_tum.txt")
    slam_out = os.path.join(work, "slam_radon_2")
    # The second run's truth in the SLAM map's frame (SLAM's trajectory aligned to the truth).
    map_from_truth = np.linalg.inv(alignment(os.path.join(slam_out, "slam.tum"), truth_a))
    stamps, poses = read_tum(truth_b)
    in_map = os.path.join(work, "second_run_in_slam_map.tum")
    write_tum(in_map, stamps, [map_from_truth @ m for m in poses])
    truth_map(tool, work, 2)
    print("| map | w_rcs | within 0.1 m / 1 deg | translation mean m | rotation mean deg |")
    print("|---|---|---|---|---|")
    for name, path, reference in (("SLAM (radon)", os.path.join(slam_out, "map.rgm"), in_map),
                                  ("from the truth", os.path.join(work, "truth_map_2.rgm"), truth_b)):
        out = os.path.join(work, "localize_" + name.split()[0])
        if not os.path.exists(os.path.join(out, "per_scan.csv")):
            run(tool + ["localize", "--map", path, "--sequence", second, "--gt", reference, "--extrinsic", "identity",
                        "--stride", "10", "--w-rcs", "0", "0.5", "--out", out])
        rows = list(csv.DictReader(open(os.path.join(out, "per_scan.csv"))))
        for w in sorted({r["w_rcs"] for r in rows}):
            chosen = [r for r in rows if r["w_rcs"] == w]
            t = np.array([float(r["translation_m"]) for r in chosen])
            a = np.array([float(r["rotation_deg"]) for r in chosen])
            print(f"| {name} | {w} | {100 * np.mean((t < 0.1) & (a < 1)):.1f} % | {t.mean():.3f} | {a.mean():.3f} |")


def relocalisation_table(tool, work, jobs, starts=20, scans=400):
    truth_a = os.path.join(work, "two_laps", "gt_radar_tum.txt")
    second, truth_b = os.path.join(work, "second_run"), os.path.join(work, "second_run", "gt_radar_tum.txt")
    slam_out = os.path.join(work, "slam_radon_2")
    truth_from_map = alignment(os.path.join(slam_out, "slam.tum"), truth_a)
    ts, tp = read_tum(truth_b)
    # The map's own frame near a pose: the truth of run A's scan nearest to it
    # times the inverse of that scan's SLAM pose, so that the map's own error
    # (SLAM's ATE) is not counted against relocalisation.
    map_s, map_p = read_tum(os.path.join(slam_out, "slam.tum"))
    ta_s, ta_p = read_tum(truth_a)
    map_xyz = np.array([m[:3, 3] for m in map_p])

    def local_truth_from_map(estimate):
        k = int(np.argmin(np.linalg.norm(map_xyz - estimate[:3, 3], axis=1)))
        return pose_at(ta_s, ta_p, map_s[k]) @ np.linalg.inv(map_p[k])

    firsts = [k * (len(ts) - scans) // (starts - 1) for k in range(starts)]

    def one(first):
        out = os.path.join(work, f"relocalize_{first}")
        if not os.path.exists(os.path.join(out, "summary.json")):
            run(tool + ["relocalize", "--map", os.path.join(slam_out, "map.rgm"), "--sequence", second,
                        "--descriptor", "radon", "--first-scan", str(first), "--max-scans", str(scans), "--out", out])
        return out

    with ThreadPoolExecutor(jobs) as pool:
        outs = list(pool.map(one, firsts))
    good, false, none, times, fix_errors, tracked = 0, 0, 0, [], [], []
    good_local, fix_errors_local = 0, []
    for out in outs:
        summary = json.load(open(os.path.join(out, "summary.json")))
        rows = [r for r in csv.DictReader(open(os.path.join(out, "per_scan.csv"))) if r["fixed"] == "1"]
        if summary["first_fix_scan"] is None:
            none += 1
            continue
        errors = []
        for r in rows:
            estimate = matrix([float(r[k]) for k in ("x", "y", "z", "qx", "qy", "qz", "qw")])
            errors.append(error(truth_from_map @ estimate, pose_at(ts, tp, float(r["stamp"]))))
        first = matrix([float(rows[0][k]) for k in ("x", "y", "z", "qx", "qy", "qz", "qw")])
        local = error(local_truth_from_map(first) @ first, pose_at(ts, tp, float(rows[0]["stamp"])))
        fix_errors_local.append(local)
        good_local += local[0] < 0.5 and local[1] < 2
        t, a = errors[0]
        fix_errors.append(errors[0])
        tracked += [e[0] < 0.5 and e[1] < 2 for e in errors]
        times.append(summary["time_to_first_fix_s"])
        good += t < 0.5 and a < 2
        false += t > 2 or a > 5
    print("| starts | fixed within 0.5 m / 2 deg: of the truth, of the map's frame | false fixes (> 2 m or 5 deg) "
          "| no fix in 40 s | time to first fix s (median, max) | fix error m / deg (median): of the truth, "
          "of the map's frame | reported poses within 0.5 m / 2 deg of the truth |")
    print("|---|---|---|---|---|---|---|")
    e = np.array(fix_errors) if fix_errors else np.zeros((1, 2))
    el = np.array(fix_errors_local) if fix_errors_local else np.zeros((1, 2))
    print(f"| {starts} | {good}, {good_local} | {false} | {none} | {np.median(times) if times else 0:.1f}, "
          f"{max(times) if times else 0:.1f} | {np.median(e[:, 0]):.2f} / {np.median(e[:, 1]):.2f}, "
          f"{np.median(el[:, 0]):.2f} / {np.median(el[:, 1]):.2f} "
          f"| {100 * np.mean(tracked) if tracked else 0:.1f} % |")


def real_table(tool, work):
    print("| sample | scans | keyframes | candidates verified | loops accepted | place recognition ms/keyframe |")
    print("|---|---|---|---|---|---|")
    samples = [("NTU Eagle", ["--sequence", os.path.join(DATA, "ntu4dradlm_loop1_eagle", "points"), "--config",
                              os.path.join(ROOT, "configs", "ntu_eagle_odometry.yaml")]),
               ("smartmicro highway", ["--sequence", os.path.join(DATA, "smartmicro_umrr_highway", "points")])]
    for name, flags in samples:
        if not os.path.isdir(flags[1]):
            print(f"| {name} | absent | | | | |")
            continue
        out = os.path.join(work, "real_" + name.split()[0])
        if not os.path.exists(os.path.join(out, "slam.json")):
            run(tool + ["slam", *flags, "--out", out])
        s = json.load(open(os.path.join(out, "slam.json")))
        scans = sum(1 for _ in open(os.path.join(out, "slam.tum")))
        print(f"| {name} | {scans} | {s['keyframes']} | {s['candidates_verified']} | {s['loops']} "
              f"| {s['describe_time_ms'] + s['search_time_ms']:.1f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tool", default=os.path.join(ROOT, "build", "release", "bin", "radargauss"))
    parser.add_argument("--work", default="/tmp/slam_table")
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--only", default="drive,losses,localize,relocalize,real")
    args = parser.parse_args()
    tool, only = [args.tool], args.only.split(",")
    os.makedirs(args.work, exist_ok=True)
    simulate(tool, "synthetic_two_laps.yaml", os.path.join(args.work, "two_laps"))
    if "drive" in only:
        drive_table(tool, args.work, args.jobs)
    if "losses" in only:
        loss_table(tool, args.work, args.jobs)
    if "localize" in only or "relocalize" in only:
        simulate(tool, "synthetic_two_laps_second_run.yaml", os.path.join(args.work, "second_run"))
        slam(tool, args.work, "slam_radon_2", os.path.join(args.work, "two_laps"),
             os.path.join(args.work, "two_laps", "gt_radar_tum.txt"), "--descriptor", "radon", "--max-scans", "6000")
    if "localize" in only:
        localisation_table(tool, args.work)
    if "relocalize" in only:
        relocalisation_table(tool, args.work, args.jobs)
    if "real" in only:
        real_table(tool, args.work)


if __name__ == "__main__":
    main()
