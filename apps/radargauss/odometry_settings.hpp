// SPDX-License-Identifier: BSD-3-Clause
// The flags of odometry, slam and relocalize: the odometry's options, the
// matcher, the IMU, place recognition, and the checks of the reference and
// the gyro against the sequence.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "option_flags.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/core/progress.hpp"
#include "radargauss/core/trajectory.hpp"

namespace radargauss::cli {

struct OdometrySettings {
  SequenceOptions sequence;  // ground_truth: the reference, for evaluation only
  OdometryOptions odometry;
  std::string out;
  std::string imu_topic;
  std::string imu_file;       // a text IMU file (io/imu.hpp), instead of a bag's topic
  std::string imu_extrinsic;  // T_radar_imu file; else --imu-rotation
  std::string imu_stamps = "header";
  std::vector<double> imu_rotation = {0, 0, 0, 1};  // q_radar_imu (x y z w)
  std::size_t first_scan = 0;
  std::size_t max_scans = 0;
  std::string matcher = "gaussians";  // or a PCL peer
  RadarInertialOptions inertial;      // the IMU's motion model (--imu-fusion) and the window's
  std::string mcap;                   // --mcap: the run for a viewer (run_mcap.hpp)
  std::string rig;                    // --rig: a rig file's radars instead of one sequence
  const CLI::App* app = nullptr;      // the command's, to tell a flag given from its default
};

// The matcher of a map version: the Gaussian solvers, or a PCL peer.
MatcherFactory MatcherOf(const std::string& matcher);
// R_radar_imu from --imu-rotation, checked whether or not an IMU is read.
Eigen::Matrix3d ImuRotation(const std::vector<double>& xyzw);
// The IMU's samples (the bag's topic or the IMU file) and T_radar_imu
// (--imu-extrinsic, else --imu-rotation); none without an IMU.
// With an --imu-extrinsic file that states its accuracy, `inertial` is the
// settings' with each calibration estimated where the file says it is
// rough (its std above the window's observed_*_std) and not where exact,
// unless its --estimate-* flag was given, and the stated stds as the
// window's priors (docs/design/odometry.md, "Radar-inertial odometry").
struct ImuInput {
  std::vector<ImuSample> samples;
  SE3d radar_from_imu;
  RadarInertialOptions inertial;
};
ImuInput ImuOf(const OdometrySettings& s);
// A rig's IMU: --imu FILE, or --imu-topic of the bag that holds the rig's
// radars; its --imu-extrinsic (or --imu-rotation) is T_body_imu, and the
// window's clock offset the IMU's stamps minus the body's clock
// (docs/design/rig.md, "An IMU on a rig").
ImuInput RigImuOf(const OdometrySettings& s, const Rig& rig);
// IMU samples that cover none of the scans' time span are a clock mismatch
// (`hint`: what to try, appended to the message).
void CheckOverlap(const std::vector<ImuSample>& imu, const Sequence& sequence, const std::string& hint);
// Throws FileError when fewer than 3 scans lie in the reference's time span.
void CheckReferenceCovers(const Trajectory& reference, const Sequence& sequence, const std::string& path);
// What odometry, slam and relocalize run on: every scan of the sequence (not
// only those the reference covers) from --first-scan, at most --max-scans,
// refused when none is left or when `w_rcs` needs RCS they lack; and with
// --gt the reference, read and checked before the run, so that a bad one
// fails early and leaves nothing behind.
// With `hold_points` false the scans keep their stamps and fields but not
// their points: the checks see the whole run, and the run reads the points
// again with StreamScans (memory bounded by a scan, not the drive).
struct RunInputs {
  Sequence sequence;
  std::optional<Trajectory> reference;
};
RunInputs LoadRunInputs(const OdometrySettings& s, double w_rcs, bool hold_points = true);

// The scans of LoadRunInputs(s, ...) read again one at a time, passed in
// order to register_scan with a progress bar named `stage` (`total`: their
// count); a DataError names the scan's file.
void StreamScans(const OdometrySettings& s, const char* stage, std::size_t total,
                 const std::function<void(const RadarScan&)>& register_scan);

// The sequence as messages name it: its folder, or its bag and topic.
std::string SequenceName(const SequenceOptions& sequence);

// The results folder --out of a run on the sequence: refused when it is the
// sequence's own folder; `outputs` (the command's files) and the evaluation's
// are never kept from an earlier run (StagedFolder).
StagedFolder RunFolder(const OdometrySettings& s, std::vector<std::string> outputs);

// Calls register_scan on every scan in order with a progress bar named
// `stage`; a DataError names the scan's file.
template <typename RegisterScan>
void RegisterScans(const Sequence& sequence, const char* stage, RegisterScan&& register_scan) {
  ProgressBar bar;
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    try {
      register_scan(sequence.scans[k]);
    } catch (const DataError& e) {
      throw DataError(sequence.scan_sources[k] + ": " + e.what());
    }
    if (k % 16 == 0) bar.Update(stage, k, sequence.scans.size());
  }
  bar.Update(stage, sequence.scans.size(), sequence.scans.size());
  bar.Finish();
}
// Every flag of OdometrySettings: the odometry's from its option table.
void AddOdometryOptions(CLI::App* app, OdometrySettings& s);
// The IMU's: its file or bag topic, stamps and rotation into the radar frame.
void AddImuOptions(CLI::App* app, OdometrySettings& s);
// What slam and relocalize read but leave to `odometry --help-all`: the
// front end's tuning, and the loop verification's match rows equal to it.
ListedElsewhere OdometryListedElsewhere();
// The run's own: the scans to run on (slam and relocalize take the
// odometry's options from their own tables).
void AddRunOptions(CLI::App* app, OdometrySettings& s);

}  // namespace radargauss::cli
