// SPDX-License-Identifier: BSD-3-Clause
#include "odometry_settings.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <system_error>
#include <utility>

#include "radargauss/core/error.hpp"
#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/core/names.hpp"
#ifdef RADARGAUSS_HAVE_PCL
#include "radargauss/peers/pcl_peers.hpp"
#endif

namespace radargauss::cli {

// The matcher of a map version: the Gaussian solvers, or a PCL peer over the
// active map's points (RadarOdometry makes one per map version).
MatcherFactory MatcherOf(const std::string& matcher) {
  if (matcher == "gaussians") return GaussianMatcherFactory();
#ifdef RADARGAUSS_HAVE_PCL
  const PclMethod method = matcher == "pcl-ndt" ? PclMethod::kNdt : PclMethod::kGicp;
  return [method](const LocalMap& map, const MatchOptions&) {
    return std::shared_ptr<const ScanMatcher>(std::make_shared<PclPeerMatcher>(method, map.ActivePoints()));
  };
#else
  throw DataError("--matcher " + matcher + " needs radargauss built with RADARGAUSS_WITH_PCL");
#endif
}

// R_radar_imu from --imu-rotation, checked whether or not an IMU is read.
Eigen::Matrix3d ImuRotation(const std::vector<double>& xyzw) {
  const Eigen::Quaterniond q(xyzw[3], xyzw[0], xyzw[1], xyzw[2]);
  if (!(std::abs(q.norm() - 1.0) < kTumQuaternionNormTolerance)) {
    char norm[32];
    std::snprintf(norm, sizeof(norm), "%g", q.norm());
    throw DataError(std::string("--imu-rotation: not a unit quaternion (x y z w), its norm is ") + norm);
  }
  return q.normalized().toRotationMatrix();
}

namespace {

// An extrinsic file's stated accuracy: each calibration estimated where it
// is rough and held where exact (unless its flag was given), its std the prior.
void ApplyStatedAccuracy(const ExtrinsicAccuracy& accuracy, const OdometrySettings& s, InertialWindowOptions& window) {
  const auto decide = [&](const char* flag, double stated, double observed, bool& estimate, double& prior) {
    if (stated > 0.0) prior = stated;
    if (s.app == nullptr || s.app->count(flag) == 0) estimate = stated > observed;
  };
  decide("--estimate-extrinsic-rotation", accuracy.rotation_deg, window.observed_rotation_std_deg,
         window.estimate_extrinsic_rotation, window.extrinsic_rotation_prior_deg);
  decide("--estimate-extrinsic-translation", accuracy.translation, window.observed_translation_std,
         window.estimate_extrinsic_translation, window.extrinsic_translation_prior);
  decide("--estimate-clock-offset", accuracy.clock_offset, window.observed_clock_std, window.estimate_clock_offset,
         window.clock_offset_prior);
  std::printf(
      "imu extrinsic: stated to %g deg, %g m and %g s; estimating the rotation %s, the translation %s, "
      "the clock offset %s\n",
      accuracy.rotation_deg, accuracy.translation, accuracy.clock_offset,
      window.estimate_extrinsic_rotation ? "yes" : "no", window.estimate_extrinsic_translation ? "yes" : "no",
      window.estimate_clock_offset ? "yes" : "no");
}

}  // namespace

// The IMU's samples (the bag's topic or the IMU file) and T_radar_imu
// (--imu-extrinsic, else the rotation of --imu-rotation); none without an IMU.
ImuInput ImuOf(const OdometrySettings& s) {
  if (s.imu_topic.empty() && s.imu_file.empty()) {
    if (!s.imu_extrinsic.empty()) throw DataError("--imu-extrinsic needs an IMU (--imu or --imu-topic)");
    return {};
  }
  if (!s.imu_topic.empty() && s.sequence.bag.empty()) throw DataError("--imu-topic needs --bag");
  if (!s.imu_topic.empty() && !s.imu_file.empty()) throw DataError("--imu and --imu-topic: one IMU at a time");
  if (!s.imu_extrinsic.empty() && s.imu_rotation != std::vector<double>{0, 0, 0, 1}) {
    throw DataError("--imu-extrinsic and --imu-rotation: the IMU's rotation once");
  }
  ImuInput input;
  input.inertial = s.inertial;
  if (s.imu_extrinsic.empty()) {
    input.radar_from_imu = SE3d(SO3d::FromMatrix(ImuRotation(s.imu_rotation)), Eigen::Vector3d::Zero());
  } else {
    const StatedExtrinsic stated = ReadStatedExtrinsicFile(s.imu_extrinsic);
    input.radar_from_imu = stated.pose;
    if (stated.accuracy) ApplyStatedAccuracy(*stated.accuracy, s, input.inertial.window);
  }
  input.samples =
      s.imu_file.empty() ? ReadBagImu(s.sequence.bag, s.imu_topic, s.imu_stamps == "record") : ReadImuFile(s.imu_file);
  return input;
}

// A rig's IMU (docs/design/rig.md, "An IMU on a rig"): --imu FILE, or
// --imu-topic of the bag that holds the rig's radars; its --imu-extrinsic
// (or --imu-rotation) is T_body_imu, its clock offset the IMU's stamps
// minus the body's clock.
ImuInput RigImuOf(const OdometrySettings& s, const Rig& rig) {
  OdometrySettings on_rig = s;
  if (!s.imu_topic.empty()) {
    const std::string& bag = rig.radars.front().scans.bag;
    const bool one_bag = std::all_of(rig.radars.begin(), rig.radars.end(),
                                     [&](const RigRadar& radar) { return radar.scans.bag == bag; });
    if (bag.empty() || !one_bag) {
      throw DataError("--imu-topic on a rig needs the radars in one bag (bag: in the rig file); else --imu FILE");
    }
    on_rig.sequence.bag = bag;
  }
  return ImuOf(on_rig);
}

// IMU samples that cover none of the scans' time span are a clock mismatch, not data.
void CheckOverlap(const std::vector<ImuSample>& gyro, const Sequence& sequence, const std::string& hint) {
  const double first = sequence.scans.front().timestamp, last = sequence.scans.back().timestamp;
  if (gyro.back().stamp < first || gyro.front().stamp > last) {
    throw DataError("the IMU's stamps (" + std::to_string(gyro.front().stamp) + " to " +
                    std::to_string(gyro.back().stamp) + " s) do not overlap the scans' (" + std::to_string(first) +
                    " to " + std::to_string(last) + " s)" + hint);
  }
}

// The evaluation pairs scans with reference poses by time: a reference of
// another run or clock pairs with none, which is said before the run.
void CheckReferenceCovers(const Trajectory& reference, const Sequence& sequence, const std::string& path) {
  const double tolerance = EvaluationOptions().time_tolerance;
  std::size_t covered = 0;
  for (const RadarScan& scan : sequence.scans) {
    covered += scan.timestamp >= reference.StartTime() - tolerance && scan.timestamp <= reference.EndTime() + tolerance;
  }
  if (covered < 3) {
    char spans[120];
    std::snprintf(spans, sizeof(spans), "%.3f to %.3f s; the scans': %.3f to %.3f s", reference.StartTime(),
                  reference.EndTime(), sequence.scans.front().timestamp, sequence.scans.back().timestamp);
    throw FileError(path, "--gt: " + std::to_string(covered) + " of the " + std::to_string(sequence.scans.size()) +
                              " scans lie in the reference's time span (" + spans + ")");
  }
}

void AddOdometryOptions(CLI::App* app, OdometrySettings& s) {
  app->add_option("--matcher", s.matcher,
                  "gaussians (the Gaussian-RCS map and --solver), or pcl-ndt / pcl-gicp on the active map's points "
                  "(no w_rcs, no velocity term; needs PCL)")
      ->check(CLI::IsMember({"gaussians", "pcl-ndt", "pcl-gicp"}))
      ->capture_default_str();
  AddTableOptions(app, OdometryOptionTable(), s.odometry);
  AddImuOptions(app, s);
  AddTableOptions(app, RadarInertialOptionTable(), s.inertial);
  AddRunOptions(app, s);
  s.app = app;
}

ListedElsewhere OdometryListedElsewhere() {
  return {"odometry", "verify_",
          "The front end reads every option of `radargauss odometry` (its --help-all lists them; the sensor group "
          "is listed here too), and --verify-X sets the loop verification's match and map as --X does the "
          "odometry's: those listed here are the ones whose defaults differ."};
}

void AddImuOptions(CLI::App* app, OdometrySettings& s) {
  CLI::Option* imu_topic =
      app->add_option("--imu-topic", s.imu_topic,
                      "sensor_msgs/Imu topic of --bag (with --rig, of the rig's bag): the IMU (--imu-fusion)");
  app->add_option("--imu", s.imu_file,
                  "IMU file of lines 'stamp wx wy wz ax ay az' (s, rad/s, m/s^2; the IMU's frame)");
  app->add_option("--imu-extrinsic", s.imu_extrinsic,
                  "T_radar_imu (with --rig, T_body_imu): a file 'x y z qx qy qz qw' (the IMU's frame in the radar's)");
  // The IMU's settings without its topic would be read by nothing: refused.
  app->add_option("--imu-stamps", s.imu_stamps, "Stamp the IMU by its header or by the bag's record time")
      ->check(CLI::IsMember({"header", "record"}))
      ->needs(imu_topic)
      ->capture_default_str()
      ->group(HelpGroup(OptionGroup::kTuning));  // a bag's IMU details: --help-all
  app->add_option("--imu-rotation", s.imu_rotation,
                  "q_radar_imu (with --rig, q_body_imu) as x y z w (rotates gyro rates into the radar frame)")
      ->expected(4)
      ->needs(imu_topic)
      ->capture_default_str()
      ->group(HelpGroup(OptionGroup::kTuning));
}

void AddRunOptions(CLI::App* app, OdometrySettings& s) {
  app->add_option("--first-scan", s.first_scan, "Skip the scans before this one (0: none)")->capture_default_str();
  app->add_option("--max-scans", s.max_scans, "Only the first N scans from --first-scan (0: all)")
      ->capture_default_str();
  app->add_option("--mcap", s.mcap, "Also write the run as an MCAP file a robotics viewer opens (as export does)");
}

std::string SequenceName(const SequenceOptions& sequence) {
  return sequence.bag.empty() ? sequence.sequence_dir : sequence.bag + " (topic " + sequence.topic + ")";
}

RunInputs LoadRunInputs(const OdometrySettings& s, double w_rcs, bool hold_points) {
  SequenceOptions sequence_options = s.sequence;
  sequence_options.ground_truth.clear();
  RunInputs inputs;
  std::vector<bool> has_points;  // per scan
  if (hold_points) {
    inputs.sequence = LoadSequence(sequence_options);
    for (const RadarScan& scan : inputs.sequence.scans) has_points.push_back(!scan.points.empty());
  } else {
    Sequence& sequence = inputs.sequence;
    sequence.layout = ForEachScan(sequence_options, [&](RadarScan& scan, const std::string& source) {
      has_points.push_back(!scan.points.empty());
      std::vector<RadarPoint>().swap(scan.points);  // its memory too, not only its size
      sequence.scans.push_back(std::move(scan));
      sequence.scan_sources.push_back(source);
      return true;
    });
    sequence.total_scans = sequence.scans.size();
    if (sequence.scans.empty()) throw DataError("sequence has no scans");
    ResolveExtrinsic(sequence_options.extrinsic, "");  // as LoadSequence: a file given is checked
  }
  std::vector<RadarScan>& scans = inputs.sequence.scans;
  std::vector<std::string>& sources = inputs.sequence.scan_sources;
  const std::size_t first = std::min(s.first_scan, scans.size());
  scans.erase(scans.begin(), scans.begin() + std::ptrdiff_t(first));
  sources.erase(sources.begin(), sources.begin() + std::ptrdiff_t(std::min(first, sources.size())));
  has_points.erase(has_points.begin(), has_points.begin() + std::ptrdiff_t(first));
  if (s.max_scans > 0 && scans.size() > s.max_scans) {
    scans.resize(s.max_scans);
    has_points.resize(s.max_scans);
  }
  const std::string name = SequenceName(s.sequence);
  if (scans.empty()) {
    throw DataError(first > 0 ? "--first-scan " + std::to_string(s.first_scan) + " skips every one of the " +
                                    std::to_string(first) + " scans of " + name
                              : name + ": the sequence has no scans");
  }
  if (std::none_of(has_points.begin(), has_points.end(), [](bool points) { return points; })) {
    throw DataError(name + ": every one of the " + std::to_string(scans.size()) + " scans has no points");
  }
  CheckRcsWeights(inputs.sequence, {w_rcs});
  if (!s.sequence.ground_truth.empty()) {
    inputs.reference =
        ReadRadarTrajectory(s.sequence.ground_truth, ResolveExtrinsic(s.sequence.extrinsic, s.sequence.ground_truth));
    CheckReferenceCovers(*inputs.reference, inputs.sequence, s.sequence.ground_truth);
  }
  return inputs;
}

void StreamScans(const OdometrySettings& s, const char* stage, std::size_t total,
                 const std::function<void(const RadarScan&)>& register_scan) {
  SequenceOptions sequence_options = s.sequence;
  sequence_options.ground_truth.clear();
  ProgressBar bar;
  std::size_t read = 0, done = 0;
  ForEachScan(sequence_options, [&](RadarScan& scan, const std::string& source) {
    if (read++ < s.first_scan) return true;
    try {
      register_scan(scan);
    } catch (const DataError& e) {
      throw DataError(source + ": " + e.what());
    }
    if (++done % 16 == 0) bar.Update(stage, done, total);
    return done < total;
  });
  if (done != total) {
    throw DataError(SequenceName(s.sequence) + " changed while it was read: " + std::to_string(done) + " scans of " +
                    std::to_string(total));
  }
  bar.Update(stage, total, total);
  bar.Finish();
}

StagedFolder RunFolder(const OdometrySettings& s, std::vector<std::string> outputs) {
  outputs.insert(outputs.end(), {"evaluation.json", "evaluation.md"});
  return StagedFolder(s.out, std::move(outputs));
}

}  // namespace radargauss::cli
