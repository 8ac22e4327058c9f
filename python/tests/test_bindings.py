# SPDX-License-Identifier: BSD-3-Clause
"""The Python module against independent references: arrays equal the bytes
of the files they came from, match equals the command-line tool, bad
arguments raise ValueError with the library's message."""
import os
import re
import struct
import subprocess
import sys
import time

import numpy as np
import pytest

import radargauss as rg


def test_scan_arrays_round_trip_exactly():
    rng = np.random.default_rng(1)
    points, doppler, rcs = rng.normal(size=(50, 3)) * 30, rng.normal(size=50), rng.normal(size=50) * 10
    scan = rg.Scan(points, doppler=doppler, rcs=rcs, stamp=12.5)
    assert np.array_equal(scan.points, points) and np.array_equal(scan.doppler, doppler)
    assert np.array_equal(scan.rcs, rcs) and scan.stamp == 12.5 and scan.has_rcs and len(scan) == 50
    assert not rg.Scan(points).has_doppler


def test_read_pcd_gives_the_files_floats(tmp_path):
    values = np.random.default_rng(2).normal(size=(7, 5)).astype(np.float32)
    header = ("VERSION 0.7\nFIELDS x y z rcs doppler\nSIZE 4 4 4 4 4\nTYPE F F F F F\nCOUNT 1 1 1 1 1\n"
              "WIDTH 7\nHEIGHT 1\nPOINTS 7\nDATA binary\n")
    path = tmp_path / "1702450000.250000000.pcd"
    path.write_bytes(header.encode() + values.tobytes())
    scan = rg.read_pcd(str(path))
    assert np.array_equal(scan.points, values[:, :3].astype(np.float64))
    assert np.array_equal(scan.rcs, values[:, 3]) and np.array_equal(scan.doppler, values[:, 4])
    assert scan.stamp == pytest.approx(1702450000.25, abs=1e-6)


def parse_map(path):
    """Means, covariances and SH coefficients of a .rgm, read with struct
    (the layout of include/radargauss/map/map_file.hpp)."""
    data = open(path, "rb").read()
    count = struct.unpack_from("<Q", data, 16)[0]
    means, covariances, coefficients, statistics = [], [], [], []
    for k in range(count):
        record = struct.unpack_from("<3d6dIiddd I16d3d", data, 24 + k * 260)
        means.append(record[0:3])
        xx, xy, xz, yy, yz, zz = record[3:9]
        covariances.append([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        coefficients.append(record[15:31])
        statistics.append(record[31:33])
    return np.array(means), np.array(covariances), np.array(coefficients), np.array(statistics)


def test_rcs_weight_from_the_map_by_numpy(written):
    """The map's own w_rcs, recomputed from its arrays as docs/design.md
    states it: 1.5 x the mean over the models of confidence x (p - 1) / 15,
    confidence min(1, s_e^2 / (spread^2 (1 + p / n))), at most 0.75."""
    world = rg.read_map(written["map"])
    models = world.rcs_degrees >= 0
    p = (world.rcs_degrees[models] + 1) ** 2
    n = world.rcs_inliers[models]
    spread = world.rcs_spreads[models]
    for likelihood, expected in (("decibel", 2.0), ("swerling1", 10 / np.log(10) * np.pi / np.sqrt(6))):
        predictive = spread ** 2 * (1 + p / n)
        confidence = np.where(predictive <= expected ** 2, 1.0, expected ** 2 / predictive)
        information = np.mean(confidence * (p - 1) / 15)
        assert world.rcs_weight(likelihood) == pytest.approx(min(0.75, 1.5 * information), rel=1e-12)
    assert 0 < world.rcs_weight("decibel") < world.rcs_weight("swerling1") <= 0.75
    with pytest.raises(ValueError):
        world.rcs_weight("swerling2")


def test_map_arrays_equal_the_file(written, tmp_path):
    world = rg.read_map(written["map"])
    means, covariances, coefficients, statistics = parse_map(written["map"])
    assert len(world) == len(means) > 100
    assert np.array_equal(world.means, means) and np.array_equal(world.covariances, covariances)
    assert np.array_equal(world.rcs_coefficients, coefficients)
    assert np.array_equal(world.rcs_spreads, statistics[:, 0]) and np.array_equal(world.rcs_explained, statistics[:, 1])
    assert world.rcs_spreads.max() > 0 and 0 <= world.rcs_explained.min() <= world.rcs_explained.max() <= 1
    copy = str(tmp_path / "copy.rgm")
    rg.write_map(copy, world)
    assert open(copy, "rb").read() == open(written["map"], "rb").read()


def test_tum_round_trip_is_byte_exact(written, tmp_path):
    stamps, poses = rg.read_tum(written["gt"])
    assert poses.shape == (len(stamps), 7)
    copy = str(tmp_path / "gt.txt")
    rg.write_tum(copy, stamps, poses)
    assert open(copy).read() == open(written["gt"]).read()


@pytest.mark.parametrize("suffix", [".mcap", ".db3"])
def test_read_sequence_from_a_ros2_bag_equals_the_folder(cli, written, tmp_path, suffix):
    bag = str(tmp_path / ("seq" + suffix))
    subprocess.run([cli, "convert", "--sequence", written["sequence"], "--out", bag], check=True,
                   stdout=subprocess.DEVNULL)
    folder = rg.read_sequence(written["sequence"])
    from_bag = rg.read_sequence(bag=bag, topic="/radar/points")
    assert len(from_bag.scans) == len(folder.scans) == 20
    for a, b in zip(folder.scans, from_bag.scans):
        assert a.stamp == b.stamp
        assert np.array_equal(a.points, b.points) and np.array_equal(a.doppler, b.doppler)
        assert np.array_equal(a.rcs, b.rcs)
    with pytest.raises(ValueError, match="no messages on topic"):
        rg.read_sequence(bag=bag, topic="/absent")


def test_a_run_written_for_a_viewer_reads_back(written, tmp_path):
    sequence = rg.read_sequence(written["sequence"], gt=written["gt"])
    stamps = np.array([scan.stamp for scan in sequence.scans])
    poses = np.array(sequence.poses)
    path = str(tmp_path / "run.mcap")
    rg.write_run_mcap(path, stamps, poses, map=rg.read_map(written["map"]), scans=sequence.scans)
    topics = {t["name"]: t for t in rg.read_bag_topics(path)}
    assert topics["/radar/pose"]["messages"] == len(stamps)
    assert topics["/radar/registered"]["type"] == "sensor_msgs/msg/PointCloud2"
    assert topics["/map/ellipsoids"]["messages"] == 1
    read_stamps, read_poses = rg.read_bag_poses(path, "/radar/pose")
    assert np.array_equal(read_stamps, stamps)
    assert np.allclose(read_poses[:, :3], poses[:, :3], atol=1e-12)
    path_stamps, path_poses = rg.read_bag_poses(path, "/trajectory")  # the nav_msgs/Path
    assert np.array_equal(path_stamps, stamps)
    tf_stamps, _ = rg.read_bag_poses(path, "/tf", child_frame="radar")
    assert np.array_equal(tf_stamps, stamps)
    with pytest.raises(ValueError, match="fewer than 2 poses"):
        rg.read_bag_poses(path, "/tf", child_frame="absent")


def test_build_map_in_python_equals_build_map_of_the_cli(written):
    sequence = rg.read_sequence(written["sequence"], gt=written["gt"])
    built, read = rg.build_map(sequence), rg.read_map(written["map"])
    assert np.array_equal(built.means, read.means) and np.array_equal(built.rcs_medians, read.rcs_medians)


def test_match_equals_localize_of_the_cli(cli, written):
    out = str(written["root"] / "localize")
    subprocess.run([cli, "localize", "--sequence", written["sequence"], "--gt", written["gt"], "--map",
                    written["map"], "--w-rcs", "0.25", "--out", out], check=True, stdout=subprocess.DEVNULL)
    _, expected = rg.read_tum(os.path.join(out, "trajectories", "gn-w0.25-trivial-offset-L3.tum"))
    sequence, world = rg.read_sequence(written["sequence"], gt=written["gt"]), rg.read_map(written["map"])
    errors = rg.initial_errors(len(sequence))  # localize's defaults: 2 m, 5 deg, seed 42
    for i, scan in enumerate(sequence.scans):
        result = rg.match(scan, world, rg.compose(sequence.poses[i], errors[i]), w_rcs=0.25)
        assert np.max(np.abs(result.pose_tum - expected[i])) < 1e-12, i


def test_odometry_and_evaluate():
    sequence = rg.simulate(seed=1, scans=60)
    odometry = rg.RadarOdometry(w_rcs=0.25)
    steps = [odometry.register(scan) for scan in sequence.scans]
    assert len(odometry) == 60 and sum(step["matched"] for step in steps) > 50
    assert all(np.isfinite(step["pose"]).all() for step in steps)
    # A keyframe's dict has its map update's time and the map after it, whether
    # the update ran on the scan's path or behind it.
    keyframes = [step for step in steps if step["keyframe"]]
    assert len(keyframes) > 10 and all(step["map_update_ms"] > 0 for step in keyframes)
    assert all(step["active_gaussians"] > 0 for step in keyframes[1:])
    assert all(step["map_update_ms"] == 0 for step in steps if not step["keyframe"])
    evaluation = rg.evaluate(odometry.trajectory(), (sequence.stamps, sequence.poses))
    assert evaluation["matched"] == 60 and evaluation["rpe"]["horizontal_percent"] < 2.0
    perfect = rg.evaluate((sequence.stamps, sequence.poses), (sequence.stamps, sequence.poses))
    assert perfect["ate_translation_m"]["rmse"] < 1e-9
    assert len(odometry.map()) > 100


def test_errors_carry_the_library_message(tmp_path):
    missing = str(tmp_path / "absent.rgm")
    with pytest.raises(rg.DataError, match="absent.rgm: cannot open map"):
        rg.read_map(missing)
    assert issubclass(rg.DataError, ValueError)
    bad = tmp_path / "bad.txt"
    bad.write_text("1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n")
    with pytest.raises(rg.DataError, match="bad.txt:2: time does not increase"):
        rg.read_tum(str(bad))


def test_readers_refuse_special_files_by_type(tmp_path):
    with pytest.raises(rg.DataError, match="^/dev/zero: is a character device, not a map$"):
        rg.read_map("/dev/zero")
    with pytest.raises(rg.DataError, match="^/dev/zero: is a character device, not a TUM trajectory$"):
        rg.read_tum("/dev/zero")
    fifo = tmp_path / "scan.pcd"
    os.mkfifo(fifo)
    with pytest.raises(rg.DataError, match="scan.pcd: is a FIFO, not a PCD file"):
        rg.read_pcd(str(fifo))


# A conversion that numpy cannot allocate: MemoryError, not a crash. In a
# child whose address space is capped just above what it holds, the float32
# array fits and its float64 copy (twice the bytes) does not.
CAPPED_CONVERSION = """
import resource, numpy as np, radargauss as rg
held = int(open('/proc/self/statm').read().split()[0]) * resource.getpagesize()
points = np.ones((50_000_000, 3), np.float32)
resource.setrlimit(resource.RLIMIT_AS, (held + 1_000_000_000, resource.RLIM_INFINITY))
try:
    rg.Scan(points)
    print("converted")
except MemoryError:
    print("MemoryError")
"""


def test_a_conversion_too_large_raises_memory_error():
    done = subprocess.run([sys.executable, "-c", CAPPED_CONVERSION], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["MemoryError"], done.stdout + done.stderr[-2000:]


@pytest.mark.parametrize("call, message", [
    (lambda s, m: rg.match(s, m, np.eye(3)), r"must have shape \(4, 4\), not \(3, 3\)"),
    (lambda s, m: rg.match(s, m, np.eye(4).astype(np.int64)), "must be float64"),
    (lambda s, m: rg.match(s, m, np.full((4, 4), np.nan)), "not finite"),
    (lambda s, m: rg.match(s, m, np.diag([2.0, 1, 1, 1])), "not a rigid transform"),
    (lambda s, m: rg.match(s, m, np.eye(4), solver="newton"), "solver = newton is not one of {gn,"),
    (lambda s, m: rg.match(s, m, np.eye(4), loss="l3"), "l3"),
    (lambda s, m: rg.match(s, m, np.eye(4), w_rcs=float("nan")), "w_rcs = nan is not a finite number"),
    (lambda s, m: rg.match(s, m, np.eye(4), w_rcs=2.0), r"w_rcs = 2 is not in \[0, 1\]"),
    (lambda s, m: rg.Scan(np.zeros((4, 2))), r"points must have shape \(N, 3\)"),
    (lambda s, m: rg.Scan(np.zeros((4, 3)), doppler=np.zeros(3)), r"doppler must have shape \(4,\)"),
    (lambda s, m: rg.Scan("points"), "points must be an array"),
])
def test_bad_arguments_raise_value_error(call, message):
    sequence = rg.simulate(seed=2, scans=3)
    world = rg.build_map(sequence)
    with pytest.raises(ValueError, match=message):
        call(sequence.scans[0], world)


def test_every_solver_and_loss_of_the_docstring_matches():
    sequence = rg.simulate(seed=2, scans=3)
    world = rg.build_map(sequence)
    doc = rg.match.__doc__
    for keyword in ("solver", "loss"):
        for name in re.search(keyword + r" : \{([^}]*)\}", doc).group(1).replace("'", "").split(", "):
            result = rg.match(sequence.scans[0], world, sequence.poses[0], **{keyword: name})
            assert result.converged, (keyword, name, result.reason)


def test_help_explains_the_arguments():
    assert "initial" in rg.match.__doc__ and "w_rcs" in rg.match.__doc__ and "solver" in rg.match.__doc__


def aligned_first_pose(drive, stamps, poses):
    """T_world_map: the SE(3) alignment of SLAM's trajectory to the drive's
    truth, found as rg.evaluate finds it (Umeyama on the paired positions)."""
    truth = dict(zip(drive.stamps, drive.poses[:, :3]))
    p = np.array(poses[:, :3])
    q = np.array([truth[t] for t in stamps])
    p_mean, q_mean = p.mean(axis=0), q.mean(axis=0)
    u, _, vt = np.linalg.svd((q - q_mean).T @ (p - p_mean))
    d = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    rotation = u @ d @ vt
    pose = np.eye(4)
    pose[:3, :3] = rotation
    pose[:3, 3] = q_mean - rotation @ p_mean
    return pose


def test_slam_closes_the_yard_and_relocalizes_a_second_run(tmp_path):
    yard = ("loop_length: 60\nloop_width: 30\ncorner_radius: 8\npoles: 12\nparked_cars: 8\nmoving_cars: 1\n"
            "min_detections: 150\nmax_detections: 300\nmax_range: 60\n")
    (tmp_path / "yard.yaml").write_text(yard)
    (tmp_path / "second.yaml").write_text(yard + "world_seed: 1\nstart_offset: 70\n")
    drive = rg.simulate(seed=1, scans=500, config=str(tmp_path / "yard.yaml"))
    slam = rg.RadarSlam(descriptor="radon", min_loop_path=100.0, candidates=20, active_radius=30.0)
    for scan in drive.scans:
        slam.register(scan)
    slam.finish()
    loops = [loop for loop in slam.loops() if loop["accepted"]]
    assert slam.keyframes == 30 and len(loops) >= 5
    corrected = rg.evaluate(slam.trajectory(), (drive.stamps, drive.poses))
    odometry = rg.evaluate(slam.odometry_trajectory(), (drive.stamps, drive.poses))
    assert corrected["ate_translation_m"]["rmse"] < odometry["ate_translation_m"]["rmse"]
    place_map = slam.place_map(drive.scans)
    # The points the SLAM held give the same map (no revisit merged by default).
    held = slam.place_map()
    assert slam.place_map_bytes > 0 and np.array_equal(held.means, place_map.means)
    second = rg.simulate(seed=7, scans=120, config=str(tmp_path / "second.yaml"))
    relocalizer = rg.Relocalizer(place_map, descriptor="radon", candidates=20)
    steps = [relocalizer.register(scan) for scan in second.scans]
    assert relocalizer.first_fix is not None and relocalizer.first_fix < 60
    assert all(step["pose"] is None for step in steps[:relocalizer.first_fix])
    assert steps[relocalizer.first_fix]["fixed"] and steps[relocalizer.first_fix]["pose"].shape == (4, 4)
    # Against the truth: the map's frame is SLAM's, T_world_map the alignment of
    # its trajectory to the first drive's truth (as tests/test_slam.cpp); every
    # reported pose within 1 m, the first fix within 0.5 m and 2.5 deg.
    stamps, poses = slam.trajectory()
    map_in_world = rg.pose_matrix(aligned_first_pose(drive, stamps, poses))
    truth = dict(zip(second.stamps, second.poses_matrix))
    for k, step in enumerate(steps):
        if not step["fixed"]:
            continue
        error = np.linalg.inv(map_in_world @ step["pose"]) @ truth[step["stamp"]]
        limit = 0.5 if k == relocalizer.first_fix else 1.0
        assert np.linalg.norm(error[:3, 3]) < limit, (k, error[:3, 3])
        if k == relocalizer.first_fix:
            angle = np.degrees(np.arccos(np.clip((np.trace(error[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)))
            assert angle < 2.5, angle
    with pytest.raises(ValueError, match="descriptor = sift is not one of {scan-context,radon}"):
        rg.RadarSlam(descriptor="sift")
    with pytest.raises(ValueError, match="graph_initialization = odometry is not one of"):
        rg.RadarSlam(graph_initialization="odometry")


def test_radar_inertial_odometry(cli, tmp_path):
    """An IMU file read and fused: the drift below the radar's alone, the biases near the truth."""
    config = tmp_path / "world.yaml"
    config.write_text("scans: 120\nimu_rate_hz: 200\n")
    sequence_dir = str(tmp_path / "seq")
    subprocess.run([cli, "simulate", "--config", str(config), "--out", sequence_dir], check=True,
                   stdout=subprocess.DEVNULL)
    sequence = rg.read_sequence(sequence_dir, gt=os.path.join(sequence_dir, "gt_radar_tum.txt"), extrinsic="identity")
    imu = rg.read_imu(os.path.join(sequence_dir, "imu.txt"))
    assert imu.shape[1] == 7 and imu.shape[0] > 2000
    extrinsic = np.loadtxt(os.path.join(sequence_dir, "imu_extrinsic.txt"))
    inertial = rg.RadarInertialOdometry(imu, radar_from_imu=extrinsic, window_size=5, w_rcs=0.0)
    radar = rg.RadarOdometry()
    for scan in sequence.scans:
        step = inertial.register(scan)
        radar.register(scan)
    assert step["inertial"] is not None and np.isfinite(step["inertial"]["velocity"]).all()
    reference = (sequence.stamps, sequence.poses)
    fused = rg.evaluate(inertial.trajectory(), reference)["rpe"]["translation_percent"]
    alone = rg.evaluate(radar.trajectory(), reference)["rpe"]["translation_percent"]
    assert fused < 0.6 * alone, (fused, alone)
    truth = np.loadtxt(os.path.join(sequence_dir, "imu_biases.txt"))[-1]
    assert np.linalg.norm(step["inertial"]["gyro_bias"].ravel() - truth[1:4]) < 1e-3
    calibration = inertial.calibration()
    assert np.all(calibration["gyro_bias_std"] > 0) and calibration["tilt"].size == 2
    assert inertial.imu_dropped() == {"beyond_range": 0, "spikes": 0}
    glitched = imu.copy()
    glitched[500, 4] = 1e5  # one accelerometer sample of 1e5 m/s^2
    assert rg.RadarInertialOdometry(glitched, radar_from_imu=extrinsic).imu_dropped() == {"beyond_range": 1,
                                                                                          "spikes": 0}
    # The gyro's model by name: the rates turn the prediction, no window.
    gyro = rg.RadarInertialOdometry(imu, radar_from_imu=extrinsic, imu_fusion="gyro", w_rcs=0.0)
    steps = [gyro.register(scan) for scan in sequence.scans[:20]]
    assert len(gyro) == 20 and all(step["inertial"] is None for step in steps)
    with pytest.raises(ValueError, match="no window"):
        gyro.calibration()
    with pytest.raises(ValueError, match="imu_fusion"):
        rg.RadarInertialOdometry(imu, imu_fusion="kalman")
    with pytest.raises(TypeError, match="unknown keyword 'window_sise'"):
        rg.RadarInertialOdometry(imu, window_sise=5)
    with pytest.raises(ValueError, match="window_size"):
        rg.RadarInertialOdometry(imu, window_size=1)
    with pytest.raises(ValueError, match="imu"):
        rg.RadarInertialOdometry(imu[:, :6])


def test_hostile_arguments_are_refused_as_the_cli_refuses_them(written, tmp_path):
    """The values the command line refuses are refused here too, at once and naming the argument."""
    sequence = rg.read_sequence(written["sequence"], gt=written["gt"])
    stamps = np.array([scan.stamp for scan in sequence.scans])
    poses = np.array(sequence.poses)
    world = rg.read_map(written["map"])
    path = str(tmp_path / "run.mcap")
    for sigma in (float("nan"), -1.0, 0.0, float("inf"), 11.0):
        with pytest.raises(ValueError, match="ellipsoid_sigma"):
            rg.write_run_mcap(path, stamps, poses, map=world, ellipsoid_sigma=sigma)
    with pytest.raises(TypeError, match="map must be a GaussianMap or None, not str"):
        rg.write_run_mcap(path, stamps, poses, map="not a map")
    assert not os.path.exists(path)
    for spread in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="expected_spread"):
            world.rcs_weight("decibel", spread)
    with pytest.raises(ValueError, match="has no sample"):
        rg.RadarInertialOdometry(np.zeros((0, 7)))
    started = time.monotonic()
    with pytest.raises(ValueError, match="past 10000000"):
        rg.initial_errors(10 ** 12)
    assert time.monotonic() - started < 5.0

