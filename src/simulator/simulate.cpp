// SPDX-License-Identifier: BSD-3-Clause
// The simulated drive: per scan, the sensor's state, rays cast through the
// scene until the scan's detection count is reached, then clutter.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "radargauss/simulator/simulator.hpp"
#include "radargauss/simulator/imu_from_reference.hpp"
#include "scene.hpp"

namespace radargauss {

using simulation::kDeg;

double MaterialRcs(const Material& material, double incidence_angle) {
  const double lobe = material.lobe_width_deg * kDeg;
  const double sigma = material.diffuse * std::max(0.0, std::cos(incidence_angle)) +
                       material.specular * std::exp(-std::pow(incidence_angle / lobe, 2));
  return 10.0 * std::log10(std::max(sigma, 1e-6));
}

std::string TimestampStem(double time) {
  long long seconds = static_cast<long long>(std::floor(time));
  long long nanoseconds = std::llround((time - static_cast<double>(seconds)) * 1e9);
  if (nanoseconds >= 1000000000LL) {
    seconds += 1;
    nanoseconds -= 1000000000LL;
  }
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%lld.%09lld", seconds, nanoseconds);
  return buffer;
}

namespace {

using simulation::Box;
using simulation::Hit;
using simulation::Scene;

// The run's random draws, in one order for a seed (every draw goes through here).
struct Draws {
  explicit Draws(std::uint32_t seed) : rng(seed) {}
  double Unit() { return unit(rng); }
  double Normal() { return normal(rng); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * unit(rng); }
  double Gamma(double shape) { return std::gamma_distribution<double>(shape, 1.0 / shape)(rng); }  // mean 1
  std::mt19937 rng;
  std::uniform_real_distribution<double> unit{0.0, 1.0};
  std::normal_distribution<double> normal{0.0, 1.0};
};

// What one scan sees: the sensor's pose and velocity, the moving boxes.
struct ScanState {
  SE3d pose;
  Eigen::Matrix3d R;
  Eigen::Vector3d velocity_radar;
  std::vector<Box> moving;
  MeasurementStd stds;
};

// The point the radar reports for a return along `direction_radar` (at
// azimuth, elevation) at `distance`, moving at `velocity_world`: noise in range, azimuth and
// elevation (biased, growing off boresight), Doppler v_d = u . (v_target -
// v_sensor) (conventions.hpp), RCS with noise, Swerling fluctuation and outliers.
RadarPoint Measure(const SimulationConfig& config, const ScanState& state, double azimuth, double elevation,
                   const Eigen::Vector3d& direction_radar, double distance, const Eigen::Vector3d& velocity_world,
                   double rcs, Draws& draws, DetectionTruth& detection) {
  const double growth = 1.0 + config.elevation_noise_growth * std::pow(azimuth / (config.azimuth_fov_deg * kDeg), 2);
  RadarPoint point;
  const double range = distance + config.range_noise * draws.Normal();
  const double az = azimuth + config.azimuth_noise_deg * kDeg * draws.Normal();
  const double el =
      elevation + config.elevation_bias_deg * kDeg + config.elevation_noise_deg * growth * kDeg * draws.Normal();
  point.position = range * Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  point.doppler = direction_radar.dot(state.R.transpose() * velocity_world - state.velocity_radar) +
                  config.doppler_noise * draws.Normal();
  detection.rcs_noise_free = rcs;
  point.rcs = rcs + config.rcs_noise_db * draws.Normal();
  if (config.rcs_swerling != 0) point.rcs += 10.0 * std::log10(draws.Gamma(config.rcs_swerling == 1 ? 1.0 : 2.0));
  if (draws.Unit() < config.rcs_outlier_fraction) {
    point.rcs += draws.Uniform(-25.0, 25.0);
    detection.rcs_outlier = true;
  }
  point.std_dev = state.stds;
  point.std_dev->elevation = float(config.elevation_noise_deg * growth * kDeg);
  return point;
}

// Whether a return of `rcs` dBsm from `distance` is detected.
bool Detected(const SimulationConfig& config, double rcs, double distance, Draws& draws) {
  const double margin = rcs - 20.0 * std::log10(distance / 10.0) - config.detection_threshold_db;
  return draws.Unit() <= 1.0 / (1.0 + std::exp(-margin / 2.0));
}

// The ray at (azimuth, elevation): the return of the surface it hits, if
// detected, and with multipath_probability when that surface is a wall or
// guardrail, the ghost of what the mirrored ray meets beyond it: seen along
// the ray at the path's length (the target mirrored across the reflector),
// with the mirrored target's velocity (docs/design/simulator.md, "The faults of real
// radars"). Appends to `scan` and `truth`.
void Detect(const SimulationConfig& config, const Scene& scene, const ScanState& state, Draws& draws, RadarScan& scan,
            std::vector<DetectionTruth>& truth) {
  const double azimuth = draws.Uniform(-config.azimuth_fov_deg, config.azimuth_fov_deg) * kDeg;
  const double elevation = draws.Uniform(-config.elevation_fov_deg, config.elevation_fov_deg) * kDeg;
  const Eigen::Vector3d direction_radar(std::cos(elevation) * std::cos(azimuth),
                                        std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  const Eigen::Vector3d direction = state.R * direction_radar;
  const Eigen::Vector3d& origin = state.pose.translation();
  const Hit hit = CastRay(scene, state.moving, origin, direction, config.max_range);
  if (hit.material == nullptr || hit.distance < config.min_range) return;

  const double incidence = std::acos(std::min(1.0, std::abs(direction.dot(hit.normal))));
  const double rcs_true = MaterialRcs(config.materials.at(*hit.material), incidence) + hit.rcs_offset;
  if (Detected(config, rcs_true, hit.distance, draws)) {
    DetectionTruth detection;
    detection.kind = hit.dynamic ? DetectionKind::kDynamic : DetectionKind::kStatic;
    detection.material = *hit.material;
    detection.incidence_angle = incidence;
    detection.position_world = origin + hit.distance * direction;
    detection.target_velocity = hit.velocity;
    scan.points.push_back(Measure(config, state, azimuth, elevation, direction_radar, hit.distance, hit.velocity,
                                  rcs_true, draws, detection));
    truth.push_back(detection);
  }
  const bool reflector = *hit.material == "wall" || *hit.material == "guardrail";
  if (config.multipath_probability <= 0.0 || !reflector || draws.Unit() >= config.multipath_probability) return;
  const Eigen::Vector3d& n = hit.normal;
  const Eigen::Vector3d wall = origin + hit.distance * direction;
  const Eigen::Vector3d mirrored = direction - 2.0 * direction.dot(n) * n;
  const Hit target = CastRay(scene, state.moving, wall + 1e-6 * mirrored, mirrored, config.max_range - hit.distance);
  if (target.material == nullptr || *target.material == "ground") return;
  const double path = hit.distance + 1e-6 + target.distance;
  const double target_incidence = std::acos(std::min(1.0, std::abs(mirrored.dot(target.normal))));
  const double rcs = MaterialRcs(config.materials.at(*target.material), target_incidence) + target.rcs_offset -
                     config.multipath_loss_db;
  if (!Detected(config, rcs, path, draws)) return;
  DetectionTruth ghost;
  ghost.kind = DetectionKind::kGhost;
  ghost.material = *target.material;
  ghost.incidence_angle = target_incidence;
  ghost.position_world = wall + (1e-6 + target.distance) * mirrored;
  ghost.reflector_point = wall;
  ghost.reflector_normal = n;
  ghost.target_velocity = target.velocity;
  const Eigen::Vector3d image_velocity = target.velocity - 2.0 * target.velocity.dot(n) * n;
  scan.points.push_back(
      Measure(config, state, azimuth, elevation, direction_radar, path, image_velocity, rcs, draws, ghost));
  truth.push_back(ghost);
}

// Clutter: uniform directions, ranges, Doppler and RCS.
void AddClutter(const SimulationConfig& config, const ScanState& state, int count, Draws& draws, RadarScan& scan,
                std::vector<DetectionTruth>& truth) {
  for (int c = 0; c < count; ++c) {
    const double azimuth = draws.Uniform(-config.azimuth_fov_deg, config.azimuth_fov_deg) * kDeg;
    const double elevation = draws.Uniform(-config.elevation_fov_deg, config.elevation_fov_deg) * kDeg;
    const double range = draws.Uniform(std::max(1.0, config.min_range), 0.6 * config.max_range);
    RadarPoint point;
    point.position = range * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                             std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    point.doppler = draws.Uniform(-15.0, 15.0);
    point.rcs = draws.Uniform(-20.0, 15.0);
    point.std_dev = state.stds;
    DetectionTruth detection;
    detection.kind = DetectionKind::kClutter;
    detection.position_world = state.pose * point.position;
    detection.rcs_noise_free = point.rcs;
    scan.points.push_back(point);
    truth.push_back(detection);
  }
}

// Scan k's time in integer nanoseconds from the start, so file names are exact.
struct ScanStamp {
  std::string stem;
  double timestamp = 0.0;
  double since_start = 0.0;
};

// On the radar's clock: the true time plus its clock offset.
ScanStamp TimeOfScan(const SimulationConfig& config, int k) {
  const double start = config.start_time + config.clock_offset;
  const long long start_seconds = static_cast<long long>(std::floor(start));
  const long long start_nanoseconds = std::llround((start - static_cast<double>(start_seconds)) * 1e9);
  const long long offset_nanoseconds = std::llround(k * 1e9 / config.rate_hz);
  const long long total = start_nanoseconds + offset_nanoseconds;
  const long long seconds = start_seconds + total / 1000000000LL;
  const long long nanoseconds = total % 1000000000LL;
  char stem[64];
  std::snprintf(stem, sizeof(stem), "%lld.%09lld", seconds, nanoseconds);
  return {stem, static_cast<double>(seconds) + static_cast<double>(nanoseconds) * 1e-9, offset_nanoseconds * 1e-9};
}

}  // namespace

SE3d RadarOnVehicle(const SimulationConfig& config) {
  return SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, config.mounting_yaw_deg * kDeg)) *
                  SO3d::Exp(Eigen::Vector3d(0.0, config.mounting_pitch_deg * kDeg, 0.0)) *
                  SO3d::Exp(Eigen::Vector3d(config.mounting_roll_deg * kDeg, 0.0, 0.0)),
              Eigen::Vector3d(config.mounting_x, config.mounting_y, config.mounting_z));
}

// The IMU on the vehicle along the drive (docs/design/simulator.md, "The
// synthetic world"): the model of SimulateImuAlong on the vehicle's path.
SimulatedImu simulation::VehicleImu(const SimulationConfig& config, std::size_t count) {
  const LoopPath path{config.loop_length, config.loop_width, config.corner_radius};
  const SE3d vehicle_from_imu = ImuOnVehicle(config);
  return SimulateImuAlong(
      [&](double t) {
        SE3d pose;
        Eigen::Vector3d velocity;
        SensorState(config, path, t, pose, velocity);
        return pose * vehicle_from_imu;
      },
      count, config);
}

SimulatedSequence Simulate(const SimulationConfig& config) {
  ValidateSimulationConfig(config, "simulation config");
  SimulatedSequence sequence;
  sequence.config = config;
  const simulation::LoopPath path{config.loop_length, config.loop_width, config.corner_radius};
  Draws draws(config.seed);
  std::mt19937 world_rng(config.world_seed);
  const Scene scene = BuildScene(config, path, config.world_seed == 0 ? draws.rng : world_rng);
  const SE3d mounting = RadarOnVehicle(config);
  const Eigen::Vector3d& lever_arm = mounting.translation();
  const bool mounted = config.mounting_roll_deg != 0.0 || config.mounting_pitch_deg != 0.0 ||
                       config.mounting_yaw_deg != 0.0 || !lever_arm.isZero(0.0);
  ScanState state;
  state.stds = {float(config.range_noise), float(config.azimuth_noise_deg * kDeg),
                float(config.elevation_noise_deg * kDeg), float(config.doppler_noise)};
  for (int k = 0; k < config.scans; ++k) {
    const ScanStamp time = TimeOfScan(config, k);
    sequence.file_stems.push_back(time.stem);
    Eigen::Vector3d velocity_world;
    SensorState(config, path, time.since_start, state.pose, velocity_world);
    if (!lever_arm.isZero(0.0)) {     // the radar's own velocity: the vehicle's plus its turn times the lever arm
      constexpr double kStep = 1e-4;  // s, central differences of the radar's place
      SE3d before, after;
      Eigen::Vector3d unused;
      SensorState(config, path, time.since_start - kStep, before, unused);
      SensorState(config, path, time.since_start + kStep, after, unused);
      velocity_world = (after * lever_arm - before * lever_arm) / (2.0 * kStep);
    }
    if (mounted) state.pose = state.pose * mounting;  // T_world_vehicle T_vehicle_radar
    state.R = state.pose.rotation().Matrix();
    state.velocity_radar = state.R.transpose() * velocity_world;
    state.moving.clear();
    for (const simulation::MovingCar& car : scene.moving_cars) {
      state.moving.push_back(MovingCarBox(car, path, time.since_start, simulation::EgoArc(config, time.since_start)));
    }
    const Scene nearby = Nearby(scene, state.pose.translation(), config.max_range);
    RadarScan scan;
    scan.timestamp = time.timestamp;
    scan.has_doppler = true;
    scan.has_rcs = true;
    std::vector<DetectionTruth> truth;
    const int target =
        config.min_detections + static_cast<int>(draws.Unit() * (config.max_detections - config.min_detections + 1));
    const int clutter = static_cast<int>(std::lround(target * config.clutter_fraction));
    const int surface = std::min(target, config.max_detections) - clutter;
    for (int ray = 0; ray < config.max_rays && static_cast<int>(scan.points.size()) < surface; ++ray) {
      Detect(config, nearby, state, draws, scan, truth);
    }
    AddClutter(config, state, clutter, draws, scan, truth);
    sequence.ground_truth.Append(scan.timestamp, state.pose);
    sequence.sensor_velocity.push_back(state.velocity_radar);
    sequence.scans.push_back(std::move(scan));
    sequence.truth.push_back(std::move(truth));
  }
  // What the simulator writes, its readers accept: a scan they would refuse is
  // a configuration the validation let through, refused here, not written.
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    ValidateScan(sequence.scans[k], "simulation config (scan " + std::to_string(k) + ")");
  }
  if (config.imu_rate_hz > 0.0) {
    SimulatedImu imu = simulation::VehicleImu(config, ImuSampleCount(config));
    sequence.imu = std::move(imu.samples);
    sequence.imu_bias = std::move(imu.bias);
    sequence.radar_from_imu = mounting.Inverse() * ImuOnVehicle(config);
  }
  return sequence;
}

}  // namespace radargauss
