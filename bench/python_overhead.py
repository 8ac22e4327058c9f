#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""What calling radargauss.match from Python costs: the wall time of the
Python call (argument checks, the numpy pose, the scan already built) against
the C++ matcher's own time for the same match (MatchResult.time_ms, measured
inside ScanMatcher::Match), on a simulated scan of 800 points, one thread.

    PYTHONPATH=build/release/python bench/python_overhead.py [--repeats 200]
"""
import argparse
import statistics
import time

import radargauss as rg


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=200)
    args = parser.parse_args()
    rg.set_threads(1)
    sequence = rg.simulate(seed=1, scans=120)
    world = rg.build_map(sequence)
    index = max(range(len(sequence)), key=lambda i: len(sequence.scans[i]))
    full = sequence.scans[index]
    scan = rg.Scan(full.points[:800], doppler=full.doppler[:800], rcs=full.rcs[:800], stamp=full.stamp)
    initial = rg.compose(sequence.poses[index], rg.initial_errors(1, 0.5, 2.0, seed=3)[0])
    rg.match(scan, world, initial, w_rcs=0.25)  # builds and caches the coarse-to-fine levels
    wall, inside = [], []
    for _ in range(args.repeats):
        start = time.perf_counter()
        result = rg.match(scan, world, initial, w_rcs=0.25)
        wall.append((time.perf_counter() - start) * 1e3)
        inside.append(result.time_ms)
    w, c = statistics.median(wall), statistics.median(inside)
    print(f"{len(scan)} points, {result.iterations} iterations, w_rcs 0.25, gn: Python call {w:.3f} ms, "
          f"C++ matcher {c:.3f} ms (medians of {args.repeats}); ratio {w / c:.3f}, overhead {w - c:.3f} ms")


if __name__ == "__main__":
    main()
