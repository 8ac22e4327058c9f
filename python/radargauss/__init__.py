# SPDX-License-Identifier: BSD-3-Clause
"""radargauss: 4D radar Gaussian-RCS maps, scan matching, odometry and SLAM.

    import radargauss as rg
    sequence = rg.simulate(seed=1, scans=50)
    world = rg.build_map(sequence)
    result = rg.match(sequence.scans[10], world, sequence.poses[10], w_rcs=0.25)

Poses are T_world_radar, as 4x4 matrices or [x y z qx qy qz qw]
(Sequence.poses_matrix and pose_matrices give the 4x4 form). match and
RadarOdometry, RadarInertialOdometry (with read_imu's samples), RadarSlam
and Relocalizer take every option as a keyword
(option_fields lists them; match_options, odometry_options, slam_options
and relocalization_options read them back).
Every function's help() lists its arguments; docs/python.md tells the rest.
"""
from ._radargauss import (DataError, GaussianMap, MatchResult, RadarInertialOdometry, RadarOdometry, RadarSlam,
                          Relocalizer, Scan, Sequence, build_map, calibrate_rig, compose, estimate_rig_twist,
                          evaluate, initial_errors, match, match_options, odometry_options, option_fields,
                          pose_matrices, pose_matrix, read_bag_poses, read_bag_topics, read_imu, read_map, read_pcd,
                          read_rig, read_sequence, read_tum, relocalization_options, rig_odometry, set_threads,
                          simulate, slam_options, write_map, write_run_mcap, write_tum)
from .sweep import Task, plan, run_task, sweep

__all__ = ["DataError", "GaussianMap", "MatchResult", "RadarInertialOdometry", "RadarOdometry", "RadarSlam", "Relocalizer", "Scan", "Sequence", "build_map", "calibrate_rig", "compose",
           "estimate_rig_twist", "evaluate", "initial_errors", "match", "match_options", "odometry_options", "option_fields",
           "pose_matrices", "pose_matrix", "read_bag_poses", "read_bag_topics", "read_imu", "read_map", "read_pcd",
           "read_rig", "read_sequence", "read_tum", "relocalization_options", "rig_odometry", "set_threads", "simulate",
           "slam_options",
           "write_map", "write_run_mcap", "write_tum", "Task", "plan", "run_task", "sweep"]
