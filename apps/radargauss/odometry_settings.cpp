// SPDX-License-Identifier: BSD-3-Clause
#include "odometry_settings.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>
#include <utility>

#include "radargauss/error.hpp"
#include "radargauss/evaluation.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/names.hpp"
#ifdef RADARGAUSS_HAVE_PCL
#include "radargauss/peers/pcl_peers.hpp"
#endif

namespace radargauss::cli {

namespace {

// The local map's flags (docs/design.md, "Odometry").
void AddLocalMapOptions(CLI::App* app, OdometrySettings& s) {
  OdometryOptions& o = s.odometry;
  app->add_option("--active-radius", o.map.active_radius, "Radius of the active map around the radar (m)")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--azimuth-std", o.map.azimuth_std_deg,
                  "Radar's azimuth noise (deg): map Gaussians at least this angle x range wide")
      ->check(InRange(0.0, kMaxAngularNoiseDeg))
      ->capture_default_str();
  app->add_option("--elevation-std", o.map.elevation_std_deg,
                  "Radar's elevation noise (deg): map Gaussians at least this angle x range high")
      ->check(InRange(0.0, kMaxAngularNoiseDeg))
      ->capture_default_str();
  app->add_option("--region", o.map.region, "Edge of the map regions fitted together (m)")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--region-capacity", o.map.region_capacity,
                  "Points a region keeps (the newest); at least the points a region's first fit needs")
      ->check(InRange(o.map.min_points, std::size_t(1000000)))
      ->capture_default_str();
  app->add_option("--map-estimator", s.map_estimator,
                  "How region Gaussians follow their points: refit (k-means + EM) or incremental")
      ->check(CLI::IsMember(MapEstimatorNames()))
      ->capture_default_str();
  app->add_option("--republish-kl", o.map.republish_kl,
                  "Incremental map: KL (nats) a Gaussian moves before the matching map gets it again")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--refit-growth", o.map.refit_growth, "Refit a region once its new points reach this share")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--points-per-gaussian", o.map.gaussians.points_per_gaussian, "K = round(N_downsampled / this)")
      ->check(InRange(1.0, 1e6))
      ->capture_default_str();
  app->add_option("--min-std", o.map.gaussians.min_std, "Minimum principal std of a Gaussian (m)")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--coarse-levels", s.coarse_levels, "Coarse levels: merged or inflated")
      ->check(CLI::IsMember(CoarseLevelsNames()))
      ->capture_default_str();
  app->add_option("--coarse-sigmas", o.map.matching.inflation,
                  "Blur sigma_k of the coarse levels (m), coarse first; 0: the exact map alone")
      ->expected(1, 8)
      ->check(InRange(0.0, kMaxCoarseSigma))
      ->capture_default_str();
  app->add_option("--index-cell", o.map.matching.index_cell, "Cell of the active map's spatial index (m)")
      ->check(InRange(kMinIndexCell, kMaxIndexCell))
      ->capture_default_str();
}

}  // namespace

// The matcher of a map version: the Gaussian solvers, or a PCL peer over the
// active map's points (RadarOdometry makes one per map version).
MatcherFactory MatcherOf(const std::string& matcher) {
  if (matcher == "gaussians") {
    return [](const LocalMap&, const MatchOptions& match) {
      return std::shared_ptr<const ScanMatcher>(MakeScanMatcher(match));
    };
  }
#ifdef RADARGAUSS_HAVE_PCL
  const PclMethod method = matcher == "pcl-ndt" ? PclMethod::kNdt : PclMethod::kGicp;
  return [method](const LocalMap& map, const MatchOptions&) {
    return std::shared_ptr<const ScanMatcher>(std::make_shared<PclPeerMatcher>(method, map.ActivePoints()));
  };
#else
  throw DataError("--matcher " + matcher + " needs radargauss built with RADARGAUSS_WITH_PCL");
#endif
}

OdometryOptions Resolved(const OdometrySettings& s) {
  OdometryOptions o = s.odometry;
  o.match.solver = SolverKindFromString(s.solver);
  o.match.matching.geometric_loss.type = LossTypeFromString(s.loss);
  o.map.rcs.incidence = IncidenceModelFromString(s.incidence);
  o.map.matching.coarse = CoarseLevelsFromString(s.coarse_levels);
  o.map.estimator = MapEstimatorFromString(s.map_estimator);
  o.rotation_rate_std_deg = Eigen::Vector3d(s.rotation_rate_std[0], s.rotation_rate_std[1], s.rotation_rate_std[2]);
  o.mounting_deg = Eigen::Vector3d(s.mounting[0], s.mounting[1], s.mounting[2]);
  if (o.map.matching.inflation == std::vector<double>{0.0}) o.map.matching.inflation.clear();  // the exact map alone
  return o;
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

// The bag's gyro rates turned into the radar frame by q_radar_imu.
std::vector<GyroSample> GyroOf(const OdometrySettings& s) {
  if (s.sequence.bag.empty()) throw DataError("--imu-topic needs --bag");
  const Eigen::Matrix3d R = ImuRotation(s.imu_rotation);
  std::vector<GyroSample> samples;
  for (const ImuSample& imu : ReadBagImu(s.sequence.bag, s.imu_topic, s.imu_stamps == "record")) {
    samples.push_back({imu.stamp, R * imu.angular_velocity});
  }
  return samples;
}

// Gyro samples that cover none of the scans' time span are a clock mismatch, not data.
void CheckOverlap(const std::vector<GyroSample>& gyro, const Sequence& sequence) {
  const double first = sequence.scans.front().timestamp, last = sequence.scans.back().timestamp;
  if (gyro.back().stamp < first || gyro.front().stamp > last) {
    throw DataError("the IMU's stamps (" + std::to_string(gyro.front().stamp) + " to " +
                    std::to_string(gyro.back().stamp) + " s) do not overlap the scans' (" + std::to_string(first) +
                    " to " + std::to_string(last) + " s); try --imu-stamps record");
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
  OdometryOptions& o = s.odometry;
  app->add_option("--solver", s.solver, "Scan matcher: gn (own Gauss-Newton), gn-autodiff, ceres, ceres-dogleg, mh-gn")
      ->check(CLI::IsMember(ScanMatcherNames()))
      ->capture_default_str();
  app->add_option("--matcher", s.matcher,
                  "gaussians (the Gaussian-RCS map and --solver), or pcl-ndt / pcl-gicp on the active map's points "
                  "(no w_rcs, no velocity term; needs PCL)")
      ->check(CLI::IsMember({"gaussians", "pcl-ndt", "pcl-gicp"}))
      ->capture_default_str();
  app->add_option("--w-rcs", o.match.matching.w_rcs, "Weight w_rcs of eq. 2 (0..1)")
      ->check(InRange(0.0, 1.0))
      ->capture_default_str();
  app->add_option("--loss", s.loss, "Geometric robust loss")->check(CLI::IsMember(LossNames()))->capture_default_str();
  app->add_option("--loss-scale", o.match.matching.geometric_loss.scale, "Scale of the geometric loss")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--incidence", s.incidence, "Incidence vector of the RCS models: offset or view")
      ->check(CLI::IsMember(IncidenceModelNames()))
      ->capture_default_str();
  app->add_option("--degree", o.map.rcs.max_degree, "SH degree of the RCS models (0..3)")
      ->check(InRange(0, kMaxShDegree))
      ->capture_default_str();
  app->add_option("--velocity-weight", o.velocity_weight, "Weight of the Doppler velocity term (0: off)")
      ->check(NonNegative())
      ->capture_default_str();
  app->add_option("--velocity-floor", o.velocity_floor, "Std of the velocity term's floor Q (m)")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--velocity-vertical-floor", o.velocity_vertical_floor,
                  "Its floor along the radar's z (m; 0: --velocity-floor); larger leaves the vertical to the map")
      ->check(NonNegative())
      ->capture_default_str();
  app->add_option("--rotation-weight", o.rotation_weight, "Weight of the rotation term (0: off)")
      ->check(NonNegative())
      ->capture_default_str();
  app->add_option("--mounting", s.mounting,
                  "The radar on the vehicle: roll pitch yaw (deg; positive pitch looks down; odometry prints an "
                  "estimate)")
      ->expected(3)
      ->check(InRange(-45.0, 45.0))
      ->capture_default_str();
  app->add_flag("--estimate-elevation-bias", o.elevation_bias.estimate,
                "Estimate the elevation bias (beyond --elevation-bias) from the Doppler velocity (needs --mounting)");
  app->add_option("--rotation-rate-std", s.rotation_rate_std,
                  "Rotation term: change of the rate between scans about x y z (roll pitch yaw, deg/s)")
      ->expected(3)
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--gate-sigmas", o.gate_sigmas, "Doppler gate around the predicted velocity (sigmas)")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--acceleration-std", o.acceleration_std, "Process noise of the velocity (m/s^2)")
      ->check(NonNegative())
      ->capture_default_str();
  app->add_option("--min-gate", o.min_gate, "Smallest Doppler gate (m/s)")->check(Positive())->capture_default_str();
  app->add_option("--keyframe-distance", o.keyframe_distance, "A scan enters the map after this distance (m) ...")
      ->check(NonNegative())
      ->capture_default_str();
  app->add_option("--keyframe-angle", o.keyframe_angle_deg, "... or this rotation (deg) since the last keyframe")
      ->check(NonNegative())
      ->capture_default_str();
  AddLocalMapOptions(app, s);
  app->add_option("--seed", o.ego_velocity.seed, "Seed of the Doppler RANSAC")->capture_default_str();
  CLI::Option* imu_topic =
      app->add_option("--imu-topic", s.imu_topic, "sensor_msgs/Imu topic of --bag: gyro rates for the prediction");
  // The IMU's settings without its topic would be read by nothing: refused.
  app->add_option("--imu-stamps", s.imu_stamps, "Stamp the IMU by its header or by the bag's record time")
      ->check(CLI::IsMember({"header", "record"}))
      ->needs(imu_topic)
      ->capture_default_str();
  app->add_option("--imu-rotation", s.imu_rotation, "q_radar_imu as x y z w (rotates gyro rates into the radar frame)")
      ->expected(4)
      ->needs(imu_topic)
      ->capture_default_str();
  app->add_option("--first-scan", s.first_scan, "Skip the scans before this one (0: none)")->capture_default_str();
  app->add_option("--max-scans", s.max_scans, "Only the first N scans from --first-scan (0: all)")
      ->capture_default_str();
}

PlaceRecognitionOptions PlaceRecognitionSettings::Resolved() const {
  PlaceRecognitionOptions o = options;
  o.descriptor = PlaceDescriptorKindFromString(descriptor);
  o.scan_context.channel = channel == "geometric" ? ScanContextChannel::kGeometric
                           : channel == "rcs"     ? ScanContextChannel::kRcs
                                                  : ScanContextChannel::kBoth;
  return o;
}

void AddPlaceRecognitionOptions(CLI::App* app, PlaceRecognitionSettings& s) {
  PlaceRecognitionOptions& o = s.options;
  app->add_option("--descriptor", s.descriptor, "Place descriptor: scan-context or radon")
      ->check(CLI::IsMember(PlaceDescriptorKindNames()))
      ->capture_default_str();
  app->add_option("--channel", s.channel, "Scan Context channels: geometric, rcs or both")
      ->check(CLI::IsMember({"geometric", "rcs", "both"}))
      ->capture_default_str();
  app->add_option("--candidates", o.candidates, "Places compared per submap (nearest keys)")
      ->check(InRange(1, 100000))
      ->capture_default_str();
  app->add_option("--max-scan-context-distance", o.max_scan_context_distance,
                  "Places farther by Scan Context are not verified")
      ->check(InRange(0.0, 1.0))
      ->capture_default_str();
  app->add_option("--max-radon-distance", o.max_radon_distance,
                  "Places farther by the Radon descriptor are not verified")
      ->check(InRange(0.0, 1.0))
      ->capture_default_str();
}

std::string SequenceName(const SequenceOptions& sequence) {
  return sequence.bag.empty() ? sequence.sequence_dir : sequence.bag + " (topic " + sequence.topic + ")";
}

RunInputs LoadRunInputs(const OdometrySettings& s, double w_rcs) {
  SequenceOptions sequence_options = s.sequence;
  sequence_options.ground_truth.clear();
  RunInputs inputs{LoadSequence(sequence_options), std::nullopt};
  std::vector<RadarScan>& scans = inputs.sequence.scans;
  std::vector<std::string>& sources = inputs.sequence.scan_sources;
  const std::size_t first = std::min(s.first_scan, scans.size());
  scans.erase(scans.begin(), scans.begin() + std::ptrdiff_t(first));
  sources.erase(sources.begin(), sources.begin() + std::ptrdiff_t(std::min(first, sources.size())));
  if (s.max_scans > 0 && scans.size() > s.max_scans) scans.resize(s.max_scans);
  const std::string name = SequenceName(s.sequence);
  if (scans.empty()) {
    throw DataError(first > 0 ? "--first-scan " + std::to_string(s.first_scan) + " skips every one of the " +
                                    std::to_string(first) + " scans of " + name
                              : name + ": the sequence has no scans");
  }
  if (std::all_of(scans.begin(), scans.end(), [](const RadarScan& scan) { return scan.points.empty(); })) {
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

StagedFolder RunFolder(const OdometrySettings& s, std::vector<std::string> outputs) {
  std::error_code error;
  if (!s.sequence.sequence_dir.empty() && std::filesystem::equivalent(s.out, s.sequence.sequence_dir, error)) {
    throw FileError(s.out, "is the sequence's own folder; refused as an output folder");
  }
  outputs.insert(outputs.end(), {"evaluation.json", "evaluation.md"});
  return StagedFolder(s.out, std::move(outputs));
}

}  // namespace radargauss::cli
