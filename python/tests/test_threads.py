# SPDX-License-Identifier: BSD-3-Clause
"""Objects with mutable state shared by Python threads (docs/python.md,
"Threads"): calls on one object take turns under its own lock, so two to
eight threads registering and reading at once neither crash the process
(pytest's faulthandler prints the stack of a crash) nor leave a state that
one thread alone could not have made."""
import threading

import numpy as np
import pytest

import radargauss as rg


@pytest.fixture(scope="module")
def drive():
    return rg.simulate(seed=2, scans=30)


def hammer(threads, register, read, scans):
    """`threads` threads take the scans in turn and register them while one
    more reads; returns the registered stamps and the errors raised."""
    order = iter(scans)
    take = threading.Lock()
    registered, errors = [], []

    def writer():
        while True:
            with take:
                scan = next(order, None)
            if scan is None:
                return
            try:
                register(scan)
                registered.append(scan.stamp)
            except ValueError as error:  # a later scan overtook this one
                errors.append(str(error))

    done = threading.Event()

    def reader():
        while not done.is_set():
            read()

    workers = [threading.Thread(target=writer) for _ in range(threads)]
    watcher = threading.Thread(target=reader)
    watcher.start()
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join()
    done.set()
    watcher.join()
    return sorted(registered), errors


def check_turns(stamps, errors, trajectory_stamps, scans):
    # Every scan either registered or refused for its stamp, never both or neither.
    assert len(stamps) + len(errors) == len(scans)
    assert all("stamp" in error for error in errors), errors
    assert np.array_equal(trajectory_stamps, stamps)
    assert np.all(np.diff(trajectory_stamps) > 0)


@pytest.mark.parametrize("threads", [2, 8])
def test_odometry_shared_by_threads(drive, threads):
    odometry = rg.RadarOdometry()
    stamps, errors = hammer(threads, odometry.register, lambda: (odometry.trajectory(), len(odometry)),
                            drive.scans)
    check_turns(stamps, errors, odometry.trajectory()[0], drive.scans)
    assert len(odometry) == len(stamps) and len(odometry.map()) > 0


@pytest.mark.parametrize("threads", [2, 8])
def test_slam_shared_by_threads(drive, threads):
    slam = rg.RadarSlam(descriptor="radon", submap_distance=2.0, min_loop_path=5.0)
    stamps, errors = hammer(threads, slam.register,
                            lambda: (slam.trajectory(), slam.loops(), slam.keyframes, slam.odometry_trajectory()),
                            drive.scans)
    slam.finish()
    check_turns(stamps, errors, slam.odometry_trajectory()[0], drive.scans)
    assert slam.keyframes > 0


def test_a_single_thread_and_shared_objects_agree(drive):
    # Registering in order from one thread while others only read gives the
    # trajectory of a run with no other thread: the readers change nothing.
    alone = rg.RadarOdometry()
    for scan in drive.scans:
        alone.register(scan)
    shared = rg.RadarOdometry()
    stamps, errors = hammer(1, shared.register, lambda: (shared.trajectory(), shared.options()), drive.scans)
    assert not errors
    assert np.array_equal(shared.trajectory()[1], alone.trajectory()[1])


@pytest.mark.parametrize("threads", [2, 4])
def test_relocalizer_shared_by_threads(drive, threads):
    slam = rg.RadarSlam(descriptor="radon", submap_distance=2.0)
    for scan in drive.scans:
        slam.register(scan)
    slam.finish()
    place_map = slam.place_map(drive.scans)
    relocalizer = rg.Relocalizer(place_map, descriptor="radon", submap_distance=2.0)
    fixes = []
    stamps, errors = hammer(threads, lambda scan: fixes.append(relocalizer.register(scan)),
                            lambda: relocalizer.first_fix, drive.scans)
    assert len(stamps) + len(errors) == len(drive.scans)
    assert all("stamp" in error for error in errors), errors
    assert sorted(fix["stamp"] for fix in fixes) == stamps


def test_place_map_names_what_it_needs(drive):
    slam = rg.RadarSlam()
    for scan in drive.scans:
        slam.register(scan)
    with pytest.raises(ValueError, match="needs the 30 registered scans in order, not 10"):
        slam.place_map(drive.scans[:10])
