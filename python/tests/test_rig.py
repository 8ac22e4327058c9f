# SPDX-License-Identifier: BSD-3-Clause
"""Radar rigs in Python: the rig's twist from planted Doppler of several
radars, a rig file read back, and odometry and calibration on a simulated
rig (docs/design/rig.md)."""
import os
import subprocess

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


CLI = os.environ.get("RADARGAUSS_CLI")


def simulate_rig(tmp_path, config):
    """`radargauss simulate --rig-config` of the config's text into tmp_path/rig."""
    (tmp_path / "rig_config.yaml").write_text(config)
    subprocess.run([CLI, "simulate", "--rig-config", str(tmp_path / "rig_config.yaml"), "--out",
                    str(tmp_path / "rig")], check=True, stdout=subprocess.DEVNULL)


@pytest.mark.skipif(not CLI, reason="RADARGAUSS_CLI names no command-line tool (it simulates the rig)")
def test_odometry_of_a_simulated_rig_with_an_imu(tmp_path):
    # One IMU on the body, above its origin and turned: rig_odometry with the IMU's samples
    # and T_body_imu gives the command line's --imu --imu-extrinsic run.
    simulate_rig(tmp_path,
        "world: {scans: 40, imu_rate_hz: 200, imu_z: 0.3, imu_yaw_deg: 90}\nradars:\n"
        "  - {name: front, mounting_x: 3.7, mounting_z: 0.5}\n"
        "  - {name: rear, mounting_x: -1.0, mounting_z: 0.6, mounting_yaw_deg: 180, clock_offset: 0.01}\n")
    rig_file = str(tmp_path / "rig" / "rig.yaml")
    imu = np.loadtxt(tmp_path / "rig" / "imu.txt")
    body_from_imu = np.loadtxt(tmp_path / "rig" / "imu_extrinsic.txt")
    assert np.allclose(body_from_imu[:3], [0.0, 0.0, 0.3]) and np.isclose(abs(body_from_imu[5]), np.sqrt(0.5))
    run = rg.rig_odometry(rig_file, imu=imu, body_from_imu=body_from_imu)
    subprocess.run([CLI, "odometry", "--rig", rig_file, "--imu", str(tmp_path / "rig" / "imu.txt"), "--imu-extrinsic",
                    str(tmp_path / "rig" / "imu_extrinsic.txt"), "--out", str(tmp_path / "odometry")], check=True,
                   stdout=subprocess.DEVNULL)
    stamps, poses = run["trajectory"]
    written = np.loadtxt(tmp_path / "odometry" / "body.tum")
    assert np.allclose(stamps, written[:, 0]) and np.allclose(poses, written[:, 1:], atol=1e-6)
    assert run["inertial_state"] is not None and run["inertial_state"]["gyro_bias"].size == 3
    assert "inertial_state" not in rg.rig_odometry(rig_file)
    calibration = rg.calibrate_rig(rig_file, imu=imu, body_from_imu=body_from_imu, rounds=2)
    assert calibration["gyro"] and not rg.calibrate_rig(rig_file, rounds=2)["gyro"]
    with pytest.raises(ValueError, match="body_from_imu needs imu"):
        rg.rig_odometry(rig_file, body_from_imu=body_from_imu)


@pytest.mark.skipif(not CLI, reason="RADARGAUSS_CLI names no command-line tool (it simulates the rig)")
def test_export_of_a_rig_puts_each_radars_scan_where_its_true_pose_does(tmp_path):
    # A run whose poses are the front radar's true ones: export --rig places
    # every point of the rear radar (on its own clock, 20 Hz) where the rear
    # radar's own true pose at its stamp puts it, to the interpolation's error.
    simulate_rig(tmp_path,
        "world: {scans: 12}\nradars:\n  - {name: front, mounting_x: 3.7, mounting_z: 0.5}\n"
        "  - {name: rear, mounting_x: -1.0, mounting_z: 0.6, mounting_yaw_deg: 180, rate_hz: 20, "
        "clock_offset: 0.013}\n")
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "odometry.tum").write_text((tmp_path / "rig" / "front" / "gt_radar_tum.txt").read_text())
    subprocess.run([CLI, "export", str(tmp_path / "run"), "--rig", str(tmp_path / "rig" / "rig.yaml"), "--mcap",
                    str(tmp_path / "run.mcap")], check=True, stdout=subprocess.DEVNULL)
    frames = rg.read_sequence(bag=str(tmp_path / "run.mcap"), topic="/radar/registered").scans
    radars = [rg.read_sequence(path=str(tmp_path / "rig" / name), gt=str(tmp_path / "rig" / name / "gt_radar_tum.txt"))
              for name in ("front", "rear")]
    frame_stamps = np.array([frame.stamp for frame in frames])
    expected = [[] for _ in frames]
    for sequence, offset in zip(radars, (0.0, 0.013)):
        for scan, pose in zip(sequence.scans, sequence.poses_matrix):
            f = np.searchsorted(frame_stamps, scan.stamp - offset - 1e-6)
            if f < len(frames):
                expected[f].append(scan.points @ pose[:3, :3].T + pose[:3, 3])
    assert len(frames) == 12 and sum(len(e) for e in expected) == 12 + 23
    for frame, parts in zip(frames, expected):
        error = np.linalg.norm(frame.points - np.vstack(parts), axis=1)
        assert error.max() < 0.02, error.max()
    assert len(frames[1]) == len(radars[0].scans[1]) + sum(len(radars[1].scans[k]) for k in (1, 2))


@pytest.mark.skipif(not CLI, reason="RADARGAUSS_CLI names no command-line tool (it simulates the rig)")
def test_odometry_and_calibration_of_a_simulated_rig(tmp_path):
    # A front radar and a front corner at twice its rate on its own clock:
    # the body's odometry equals the command line's, and the calibration
    # from the truth stays near it (0.3 deg, 3 cm, 6 ms: the test of the C++
    # calibration, RigCalibration.*).
    simulate_rig(tmp_path,
        "world: {scans: 120}\nradars:\n  - {name: front, mounting_x: 3.7, mounting_z: 0.5}\n"
        "  - {name: front_left, mounting_x: 3.4, mounting_y: 0.9, mounting_z: 0.5, mounting_yaw_deg: 45, "
        "azimuth_fov_deg: 75, max_range: 80, min_detections: 80, max_detections: 200, rate_hz: 20, "
        "clock_offset: 0.012}\n")
    rig_file = str(tmp_path / "rig" / "rig.yaml")
    run = rg.rig_odometry(rig_file)
    subprocess.run([CLI, "odometry", "--rig", rig_file, "--out", str(tmp_path / "odometry")], check=True,
                   stdout=subprocess.DEVNULL)
    stamps, poses = run["trajectory"]
    written = np.loadtxt(tmp_path / "odometry" / "body.tum")
    assert np.allclose(stamps, written[:, 0]) and np.allclose(poses, written[:, 1:], atol=1e-6)
    assert run["frame_radars"][5] == [1, 0, 1] and run["rig_velocity_measured"] >= 100
    with pytest.raises(TypeError, match="unknown keyword"):
        rg.rig_odometry(rig_file, rig_speed=1.0)
    calibration = rg.calibrate_rig(rig_file, rounds=4)
    truth = rg.read_rig(rig_file)[1]
    corner = calibration["radars"][1]
    assert corner["name"] == "front_left" and corner["map_points"] > 1000
    error = np.linalg.inv(truth["body_from_radar"]) @ corner["body_from_radar"]
    assert np.degrees(np.arccos(np.clip((np.trace(error[:3, :3]) - 1) / 2, -1, 1))) < 0.3
    assert np.linalg.norm(error[:3, 3]) < 0.03 and abs(corner["clock_offset"] - 0.012) < 0.006
    assert np.all(np.isfinite(corner["rotation_std"])) and calibration["rig"][1]["clock_offset"] == corner["clock_offset"]
    with pytest.raises(ValueError, match="rounds"):
        rg.calibrate_rig(rig_file, rounds=0)
    # The online calibration (rig_calibrate): the rig it returns is the one the
    # command line writes. From the truth, over these 12 s, the corner's
    # rotation and clock stay near it (its translation moves up to 18 cm:
    # docs/design/rig.md, "Online calibration").
    online = rg.rig_odometry(rig_file, rig_calibrate=True)
    subprocess.run([CLI, "odometry", "--rig", rig_file, "--rig-calibrate", "--out", str(tmp_path / "online")],
                   check=True, stdout=subprocess.DEVNULL)
    written = rg.read_rig(str(tmp_path / "online" / "rig.yaml"))[1]
    assert np.allclose(written["body_from_radar"], online["rig"][1]["body_from_radar"], atol=1e-6)
    assert abs(written["clock_offset"] - online["rig"][1]["clock_offset"]) < 1e-9
    assert online["calibration_windows"] >= 4
    stds = np.array(online["calibration_std"])
    assert stds.shape == (2, 7) and np.all(stds[0] == 0) and np.all(np.isfinite(stds[1])) and np.all(stds[1] > 0)
    error = np.linalg.inv(truth["body_from_radar"]) @ online["rig"][1]["body_from_radar"]
    assert np.degrees(np.arccos(np.clip((np.trace(error[:3, :3]) - 1) / 2, -1, 1))) < 0.6
    assert abs(online["rig"][1]["clock_offset"] - 0.012) < 0.005
    assert "rig" not in run
    with pytest.raises(ValueError, match="rig_calibration_window"):
        rg.rig_odometry(rig_file, rig_calibrate=True, rig_calibration_window=0.0)
