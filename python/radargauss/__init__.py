# SPDX-License-Identifier: BSD-3-Clause
"""radargauss: 4D radar Gaussian-RCS maps, scan matching and odometry.

    import radargauss as rg
    sequence = rg.simulate(seed=1, scans=50)
    world = rg.build_map(sequence)
    result = rg.match(sequence.scans[10], world, sequence.poses[10], w_rcs=0.25)

Poses are T_world_radar, as 4x4 matrices or [x y z qx qy qz qw]. Every
function's help() lists its arguments; docs/python.md tells the rest.
"""
from ._radargauss import (DataError, GaussianMap, MatchResult, RadarOdometry, Scan, Sequence, build_map, compose,
                          evaluate, initial_errors, match, read_map, read_pcd, read_sequence, read_tum, set_threads,
                          simulate, write_map, write_tum)
from .sweep import Task, plan, run_task, sweep

__all__ = ["DataError", "GaussianMap", "MatchResult", "RadarOdometry", "Scan", "Sequence", "build_map", "compose",
           "evaluate", "initial_errors", "match", "read_map", "read_pcd", "read_sequence", "read_tum",
           "set_threads", "simulate", "write_map", "write_tum", "Task", "plan", "run_task", "sweep"]
