# SPDX-License-Identifier: BSD-3-Clause
"""Radar rigs in Python: the rig's twist from planted Doppler of several
radars, and a rig file read back (docs/design/rig.md)."""
import numpy as np
import pytest

import radargauss as rg


def test_rig_twist_from_planted_doppler_and_the_rig_file(tmp_path):
    # Three radars on a car (front and two rear corners): the body's twist
    # from their exact Doppler, v_d = -u . R^T (v + w x t), is the planted one.
    rng = np.random.default_rng(4)
    v, w = np.array([12.0, 0.4, -0.1]), np.array([0.02, -0.03, 0.35])
    mountings = [(np.array([3.7, 0.0, 0.5]), 0.0), (np.array([-0.9, 0.9, 0.6]), 2.356),
                 (np.array([-0.9, -0.9, 0.6]), -2.356)]
    scans, poses = [], []
    for t, yaw in mountings:
        R = np.array([[np.cos(yaw), -np.sin(yaw), 0.0], [np.sin(yaw), np.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
        az, el = rng.uniform(-1.0, 1.0, 80), rng.uniform(-0.25, 0.25, 80)
        u = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
        points = u * rng.uniform(3.0, 70.0, (80, 1))
        doppler = -u @ (R.T @ (v + np.cross(w, t)))
        scans.append(rg.Scan(points, doppler=doppler))
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = R, t
        poses.append(pose)
    twist = rg.estimate_rig_twist(scans, poses)
    assert twist["success"] and twist["rank"] == 6
    assert np.allclose(twist["velocity"].ravel(), v, atol=1e-9)
    assert np.allclose(twist["angular_velocity"].ravel(), w, atol=1e-9)
    single = rg.estimate_rig_twist(scans[:1], poses[:1], ego_inlier_threshold=0.1)
    assert single["rank"] == 3
    with pytest.raises(TypeError, match="unknown keyword"):
        rg.estimate_rig_twist(scans, poses, inlier_threshold=0.1)
    with pytest.raises(ValueError, match="one body_from_radar per scan"):
        rg.estimate_rig_twist(scans, poses[:2])
    (tmp_path / "rig.yaml").write_text(
        "radars:\n  - {name: front, sequence: front, extrinsic: [3.7, 0, 0.5, 0, 0, 0, 1], clock_offset: 0.01}\n")
    (radar,) = rg.read_rig(str(tmp_path / "rig.yaml"))
    assert radar["name"] == "front" and radar["sequence"] == str(tmp_path / "front")
    assert radar["clock_offset"] == 0.01 and np.allclose(radar["body_from_radar"][:3, 3], [3.7, 0, 0.5])
