#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Plants one fault at a time in chosen places (a sign, a constant, an
operand), rebuilds the test that guards the place, and expects it to fail:
a check that the tests of the pose graph, place recognition,
relocalisation, the odometry's terms, the IMU's residual, preintegration
and clock offset, the bag readers (the chunk index among them) and writers,
the keyframe graph's local solve, the IMU reader and the
tile index would catch a wrong answer. Every file is restored, whatever happens.

    scripts/mutation_check.py [BUILD_DIR]    (default build/release, configured)

Prints a Markdown table: the fault, the test run, and whether it failed.
Exits non-zero when a planted fault went unnoticed."""
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent

# (what the fault is, file, text, its replacement, test program, gtest filter)
MUTATIONS = [
    ("pose graph: the relative-pose Jacobian of t_i with the wrong sign", "src/residuals/relative_pose_residual.cpp",
     "tangent[1].block<3, 3>(kTranslationOffset, 0) = -Rzi_T;", "tangent[1].block<3, 3>(kTranslationOffset, 0) = Rzi_T;",
     "test_pose_graph", "RelativePoseJacobians.*"),
    ("pose graph: switchable loops report the loss's weight, not their switch", "src/solvers/pose_graph.cpp",
     "LoopRejection::kSwitchable ? switches_[loop] : rho[1];", "LoopRejection::kSwitchable ? rho[1] : rho[1];",
     "test_pose_graph", "PoseGraph.FalseLoopAgainstEachLoopRejection"),
    ("pose graph: graduated non-convexity starts at mu = 1 (no graduation)", "src/solvers/pose_graph.cpp",
     "for (const double s : norms) mu = std::max(mu, 2.0 * s / a2);", "",
     "test_pose_graph", "PoseGraph.FalseLoopAgainstEachLoopRejection"),
    ("place recognition: Scan Context's yaw one sector off", "src/slam/scan_context.cpp",
     "best.yaw = best.shift * sector_width;", "best.yaw = (best.shift + 1) * sector_width;",
     "test_place_recognition", "ScanContext.*"),
    ("place recognition: the Radon yaw one angle step off", "src/slam/radon_descriptor.cpp",
     "best.yaw = best.shift * M_PI / options.angles;", "best.yaw = (best.shift + 1) * M_PI / options.angles;",
     "test_place_recognition", "RadonDescriptor.*"),
    ("loop verification: the bird's-eye search shifts x the wrong way", "src/slam/loop_verification.cpp",
     "count += occupied(c.first + dx, c.second + dy);", "count += occupied(c.first - dx, c.second + dy);",
     "test_place_recognition", "LoopVerification.*"),
    ("relocalisation: the verified match inverted in the fix", "src/slam/relocalization.cpp",
     "map_->places[match.candidate].pose * candidate.check.relative * submap_origin_.Inverse()",
     "map_->places[match.candidate].pose * candidate.check.relative.Inverse() * submap_origin_.Inverse()",
     "test_slam", "Relocalizer.*"),
    ("odometry: the velocity term's analytic twin adds v dt", "include/radargauss/residuals/velocity_residual.hpp",
     "offset_(-(jacobian_ * previous.translation()) - sqrt_information * velocity * dt)",
     "offset_(-(jacobian_ * previous.translation()) + sqrt_information * velocity * dt)",
     "test_velocity_term", "*"),
    ("odometry: the rotation term's analytic Jacobian negated", "include/radargauss/residuals/rotation_residual.hpp",
     "J = 4.0 * prior_.Jacobian(rotation) * P.transpose();", "J = -4.0 * prior_.Jacobian(rotation) * P.transpose();",
     "test_rotation_term", "*"),
    ("odometry: the Doppler RANSAC's residual with the velocity's sign flipped", "src/core/doppler.cpp",
     "residual[k] = std::abs(y0[k] - (hx[k] * v.x() + hy[k] * v.y() + hz[k] * v.z()));",
     "residual[k] = std::abs(y0[k] + (hx[k] * v.x() + hy[k] * v.y() + hz[k] * v.z()));",
     "test_odometry", "RadarOdometry.DriftsLittle*"),
    ("MCAP reader: a chunk's CRC not checked", "src/io/mcap_reader.cpp",
     "if (uncompressed_crc != 0 && Crc(0, records.data(), records.size()) != uncompressed_crc) {",
     "if (false && uncompressed_crc != 0 && Crc(0, records.data(), records.size()) != uncompressed_crc) {",
     "test_rosbag2", "Rosbag2Files.McapChunkSizesAreBoundedByTheirData"),
    ("MCAP reader: a chunk decompressing to less than it states accepted", "src/io/decompress.cpp",
     "if (stated && out.size() != *stated) {", "if (stated && out.size() > *stated) {",
     "test_rosbag2", "Rosbag2Files.McapChunkSizesAreBoundedByTheirData"),
    ("MCAP reader: an lz4 chunk's stated size believed past lz4's ratio", "src/io/decompress.cpp",
     "constexpr std::uint64_t kLz4MaxRatio = 256;", "constexpr std::uint64_t kLz4MaxRatio = 1 << 30;",
     "test_rosbag2", "Rosbag2Files.McapChunkSizesAreBoundedByTheirData"),
    ("MCAP writer: a chunk's CRC computed from the wrong seed", "src/io/mcap_writer.cpp",
     "Put(body, Crc(0, chunk.data(), chunk.size()), 4);", "Put(body, Crc(1, chunk.data(), chunk.size()), 4);",
     "test_rosbag2", "Rosbag2Files.McapEveryLayoutRoundTrips"),
    ("sqlite3 bag writer: messages filed under the next topic", "src/io/rosbag2_writer.cpp",
     "insert_->Bind(1, std::int64_t(topic));", "insert_->Bind(1, std::int64_t(topic) + 1);",
     "test_rosbag2", "Rosbag2Files.OneSequenceFromItsPcdFolderAndEveryBagIsTheSame"),
    ("rosbag2 folder: a file listed twice read twice", "src/io/rosbag2.cpp",
     "if (std::find(seen.begin(), seen.end(), resolved) != seen.end()) {", "if (false) {",
     "test_rosbag2", "Rosbag2Files.FoldersReadTheirFilesInOrderAndRefuseWhatTheyCannot"),
    ("CDR: a string with a NUL inside read as a name cut short", "src/io/ros2_messages.cpp",
     "if (s.find('\\0') != std::string::npos) throw", "if (false && s.find('\\0') != std::string::npos) throw",
     "test_rosbag2", "Cdr.LiesAndTruncationsAreRefused"),
    ("bag writer: two topics of one name written", "src/io/rosbag2_writer.cpp",
     "if (topics[i].second == topics[j].second) {", "if (false) {",
     "test_rosbag2", "Rosbag2Files.BagTopicsAreNamesAReaderFindsAgain"),
    ("MCAP reader: chunks holding none of the topics decompressed", "src/io/mcap_reader.cpp",
     "    if (in_range && has_topic) {", "    if (in_range || has_topic) {",
     "test_rosbag2", "BagReaders.AnMcapReadDecompressesOnlyTheChunksItsFilterAdmits"),
    ("MCAP reader: overlapping chunks delivered unmerged", "src/io/mcap_reader.cpp",
     "    std::stable_sort(messages.begin(), messages.end(),", "    if (false) std::stable_sort(messages.begin(), messages.end(),",
     "test_rosbag2", "BagReaders.OverlappingChunksAreReadInLogTimeOrder"),
    ("keyframe graph: a loop's solve frees the whole graph", "src/slam/keyframe_graph.cpp",
     "    first_free = query;", "    first_free = 1;",
     "test_slam", "KeyframeGraph.*"),
    ("IMU file: a value past any IMU read", "src/io/imu.cpp",
     "if (rate > kMaxPhysicalAngularRate) {", "if (rate > 1e301) {",
     "test_sequence", "ImuFile.*"),
    ("IMU screening: a spike's neighbours need not agree", "src/io/imu.cpp",
     "(after - before).norm() < 0.5 * jump;", "(after - before).norm() < 1e9 * jump;",
     "test_sequence", "ImuScreening.*"),
    ("map tiles: an order run past its tile's count", "src/map/map_tiles.cpp",
     "if (count > index.tile_gaussians[tile] - in_runs[tile]) {", "if (false) {",
     "test_map_file", "MapTiles.*"),
    ("map tiles: a tile listed twice", "src/map/map_tiles.cpp",
     "if (!seen.insert(key).second) throw", "if (!seen.insert(key).second && false) throw",
     "test_map_file", "MapTiles.*"),
    ("IMU residual: the position's Jacobian in the velocity with the wrong sign", "src/residuals/imu_residual.cpp",
     "motion_i.block<3, 3>(kImuPosition, kMotionVelocity) = -Ri_T * dt;",
     "motion_i.block<3, 3>(kImuPosition, kMotionVelocity) = Ri_T * dt;",
     "test_residuals", "ImuResidualJacobians.*"),
    ("preintegration: the gyro's discrete noise halved", "src/residuals/imu_preintegration.cpp",
     "B_g * (gyro_covariance_ / dt) * B_g.transpose()", "B_g * (0.5 * gyro_covariance_ / dt) * B_g.transpose()",
     "test_residuals", "ImuPreintegration.CovarianceMatchesMonteCarlo"),
    ("radar-inertial: the clock offset's sign flipped", "src/residuals/radar_inertial_residuals.cpp",
     "m.d = clock_offset[0] - imu.clock_offset;", "m.d = imu.clock_offset - clock_offset[0];",
     "test_inertial_window", "InertialWindow.CalibratesAPlantedClockOffset"),
    ("radar-inertial: a clock offset left to walk past the IMU's data", "src/solvers/inertial_window.cpp",
     "if (options_.estimate_clock_offset) impl_->HoldClockOffsetFor(stamp);", "",
     "test_inertial_window", "RadarInertialOdometry.AClockOffsetEstimateIsHeldWithinItsBounds"),
    ("evaluation: positions on a line trusted for the rotation", "include/radargauss/experiment/evaluation.hpp",
     "inline constexpr double kThinTrajectory = 0.01;", "inline constexpr double kThinTrajectory = -1.0;",
     "test_evaluation", "Evaluation.*"),
]


def build(build_dir, target):
    result = subprocess.run(["cmake", "--build", str(build_dir), "--target", target, "-j2"], capture_output=True,
                            text=True)
    return result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]


def main():
    build_dir = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "build" / "release").resolve()
    rows, missed = [], 0
    for what, path, text, replacement, program, test_filter in MUTATIONS:
        source = ROOT / path
        original = source.read_text()
        if original.count(text) != 1:
            rows.append((what, program, "not planted: the text is not found once in " + path))
            missed += 1
            continue
        try:
            source.write_text(original.replace(text, replacement))
            built, log = build(build_dir, program)
            if not built:
                verdict = "caught (does not compile)"
            else:
                run = subprocess.run([str(build_dir / "tests" / program), "--gtest_brief=1",
                                      "--gtest_filter=" + test_filter], capture_output=True, text=True, timeout=900)
                failed = [line.split("]", 1)[1].strip() for line in run.stdout.splitlines()
                          if line.startswith("[  FAILED  ]") and "," not in line and "listed below" not in line]
                if run.returncode != 0:
                    verdict = "caught: " + (", ".join(sorted(set(failed))) or "exit %d" % run.returncode)
                else:
                    verdict = "MISSED"
                    missed += 1
        finally:
            source.write_text(original)
        rows.append((what, program + " " + test_filter, verdict))
    for program in sorted({m[4] for m in MUTATIONS}):
        build(build_dir, program)  # back to the sources as they are
    print("| planted fault | test run | result |\n|---|---|---|")
    for what, test, verdict in rows:
        print("| %s | %s | %s |" % (what, test, verdict))
    print("\nmutation check: %d caught, %d missed" % (len(rows) - missed, missed))
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
