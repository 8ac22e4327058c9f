// SPDX-License-Identifier: BSD-3-Clause
// Synthetic 4D radar world (docs/design/simulator.md, "The synthetic world"): a town block of ground,
// building walls, poles, parked and moving cars, seen by an ARS548-like radar
// driving a loop with turns. Deterministic for a seed.
//
// Detections come from ray casting: rays drawn uniformly in azimuth and
// elevation within the field of view hit the nearest surface; each hit is
// kept with a detection probability (below) until the scan has its drawn
// number of detections. Measurement noise is added in range, azimuth,
// elevation, Doppler and RCS; a share of detections is clutter and a share
// has gross RCS outliers.
//
// RCS law (per material; theta = angle between the reversed ray and the
// surface normal):
//   sigma(theta) = diffuse * cos(theta) + specular * exp(-(theta / lobe)^2)  [m^2]
//   rcs_dBsm     = 10 log10(sigma(theta)) + object_offset + N(0, rcs_noise)
// i.e. a specular lobe around the normal on top of a diffuse floor; each
// object draws a fixed object_offset ~ N(0, object_rcs_spread).
// Detection probability: 1 / (1 + exp(-(rcs_dBsm - 20 log10(range / 10 m)
//   - detection_threshold_db) / 2)).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "radargauss/core/options.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/core/trajectory.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

struct Material {
  double diffuse = 0.1;          // m^2
  double specular = 0.0;         // m^2 at normal incidence
  double lobe_width_deg = 15.0;  // width of the specular lobe
};

// RCS in dBsm of a material at incidence angle theta (radians), noise-free
// and without the object's offset: 10 log10(diffuse cos + specular lobe).
double MaterialRcs(const Material& material, double incidence_angle);

// Every parameter, with its default; a YAML file may set any subset
// (configs/synthetic_world.yaml lists them all with these values).
struct SimulationConfig {
  std::uint32_t seed = 1;
  std::uint32_t world_seed = 0;  // the scene's objects; 0: drawn from seed (another seed, the same world)
  double start_offset = 0.0;     // m along the loop where the drive starts
  // Drive.
  int scans = 300;
  double rate_hz = 10.0;
  double start_time = 1702450000.0;  // s, first scan
  double speed = 6.0;                // m/s along the loop
  double loop_length = 120.0;        // m, rounded-rectangle road loop
  double loop_width = 70.0;          // m
  double corner_radius = 15.0;       // m
  double sensor_height = 0.8;        // m above the ground
  double attitude_wobble_deg = 1.0;  // amplitude of roll/pitch oscillation
  // Sensor (ARS548-like).
  double azimuth_fov_deg = 60.0;    // +/-
  double elevation_fov_deg = 15.0;  // +/-
  double min_range = 0.2;           // m
  double max_range = 100.0;         // m
  int min_detections = 150;         // per scan, drawn uniformly in [min, max]
  int max_detections = 800;
  int max_rays = 60000;  // rays cast per scan at most
  double detection_threshold_db = -5.0;
  double range_noise = 0.05;  // m (std)
  double azimuth_noise_deg = 0.2;
  double elevation_noise_deg = 0.3;
  double doppler_noise = 0.03;  // m/s
  double rcs_noise_db = 1.0;
  double clutter_fraction = 0.05;      // share of detections that are clutter
  double rcs_outlier_fraction = 0.01;  // share with RCS + U(-25, 25) dB
  // The faults of real radars (docs/design/simulator.md, "The faults of real radars"),
  // all off by default.
  double elevation_bias_deg = 0.0;      // added to every elevation
  double elevation_noise_growth = 0.0;  // elevation std x (1 + growth (azimuth / azimuth_fov)^2)
  double mounting_roll_deg = 0.0;       // the radar on the vehicle: T_vehicle_radar = Rz(yaw) Ry(pitch) Rx(roll)
  double mounting_pitch_deg = 0.0;      // positive: the x axis looking down (about the vehicle's y)
  double mounting_yaw_deg = 0.0;
  // Its place on the vehicle (m, from the vehicle's origin on the path: x
  // forward, y left, z up; a lever arm moves it with the turns as well), and
  // its clock: its stamps minus the true time (s).
  double mounting_x = 0.0;
  double mounting_y = 0.0;
  double mounting_z = 0.0;
  double clock_offset = 0.0;
  int rcs_swerling = 0;                // RCS fluctuation per detection: 0 none, 1 Swerling I, 3 Swerling III
  double multipath_probability = 0.0;  // a ray that meets a wall or guardrail also returns a ghost
  double multipath_loss_db = 6.0;      // the ghost's RCS below its target's
  // An IMU on the vehicle (docs/design/simulator.md, "The synthetic world"); none at
  // imu_rate_hz 0. Noise densities and bias random walks as a datasheet
  // gives them (io/imu.hpp's ImuNoise); the turn-on biases drawn per axis.
  double imu_rate_hz = 0.0;
  ImuNoise imu_noise;                // its noise densities and bias random walks (its ranges unused)
  double imu_gyro_bias_std = 0.005;  // rad/s
  double imu_accel_bias_std = 0.05;  // m/s^2
  double imu_roll_deg = 0.0;         // the IMU on the vehicle, as the radar's mounting
  double imu_pitch_deg = 0.0;
  double imu_yaw_deg = 0.0;
  double imu_x = 0.0;  // m: its place on the vehicle (x forward, z up; from the vehicle's origin)
  double imu_y = 0.0;
  double imu_z = 0.0;
  double imu_clock_offset = 0.0;  // s: the IMU's stamps minus the true time (the radar's clock)
  // Scene: "town" (buildings, poles, parked and moving cars along the loop)
  // or "motorway" (guardrails, gantries, three lanes each way of traffic).
  std::string scene = "town";
  double traffic_min_speed = 25.0;  // m/s: the motorway's cars, drawn uniformly
  double traffic_max_speed = 40.0;
  int poles = 24;
  int parked_cars = 14;
  int moving_cars = 4;
  double moving_car_speed = 7.0;  // m/s
  double object_rcs_spread_db = 2.0;
  std::map<std::string, Material> materials = {
      {"ground", {0.02, 0.0, 10.0}}, {"wall", {0.5, 5.0, 15.0}},      {"pole", {1.0, 10.0, 20.0}},
      {"car", {2.0, 30.0, 12.0}},    {"guardrail", {1.0, 20.0, 8.0}},
  };
};

// Its options (options.hpp): the YAML keys of a simulation config, each
// bounded at both ends (what has no meaning below, what no road radar sees
// or what overflows a draw above), in the order simulation.yaml writes them.
const OptionTable<SimulationConfig>& SimulationOptionTable();

// Reads a YAML file over the defaults. Throws DataError naming the file for a
// parse error, an unknown key, a wrong type or an invalid value.
SimulationConfig LoadSimulationConfig(const std::string& path);
// Throws DataError (source named) if a value is out of its row's range or
// breaks a rule between keys (the loop's corners, the detections' bounds).
void ValidateSimulationConfig(const SimulationConfig& config, const std::string& source);
// The configuration as YAML (every key), as written next to a simulation.
std::string SimulationConfigToYaml(const SimulationConfig& config);

// kGhost: a multipath image of a target seen by way of a wall or guardrail.
enum class DetectionKind { kStatic, kDynamic, kClutter, kGhost };

// What the simulator knows about a detection and a test may check.
struct DetectionTruth {
  DetectionKind kind = DetectionKind::kStatic;
  std::string material;          // empty for clutter
  double incidence_angle = 0.0;  // rad
  double rcs_noise_free = 0.0;   // dBsm incl. object offset, before noise/outlier
  bool rcs_outlier = false;
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();  // noise-free hit (a ghost's: its target's)
  // A ghost's reflector: a point of its plane and the plane's normal (world).
  Eigen::Vector3d reflector_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d reflector_normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_velocity = Eigen::Vector3d::Zero();  // world, m/s
};

struct SimulatedSequence {
  SimulationConfig config;
  std::vector<RadarScan> scans;
  std::vector<std::vector<DetectionTruth>> truth;  // per scan, per detection
  std::vector<Eigen::Vector3d> sensor_velocity;    // per scan, radar frame, m/s
  Trajectory ground_truth;                         // T_world_radar per scan time
  std::vector<std::string> file_stems;             // "<secs>.<nsecs>" per scan, exact
  // The IMU's samples (stamped on its clock) and true biases, and T_radar_imu; empty without an IMU.
  std::vector<ImuSample> imu;
  std::vector<ImuBias> imu_bias;
  SE3d radar_from_imu;
};

SimulatedSequence Simulate(const SimulationConfig& config);
// The radar on the vehicle, T_vehicle_radar = Rz(yaw) Ry(pitch) Rx(roll) at
// (mounting_x, mounting_y, mounting_z): its mounting keys.
SE3d RadarOnVehicle(const SimulationConfig& config);

// The IMU's samples over the drive, every 1 / imu_rate_hz from the first
// scan's time to the last's (0 without an IMU); at most kMaxImuSamples.
std::size_t ImuSampleCount(const SimulationConfig& config);

// The simulated scans as a Sequence matched to their ground-truth poses (what
// LoadSequence gives for the written files, without the float32 rounding).
Sequence AsSequence(const SimulatedSequence& simulated);

// Writes the Snail-Radar layout: <dir>/ars548/points/<secs>.<nsecs>.pcd (the
// nine float32 fields), <dir>/ars548/points/times.txt, the radar ground truth
// <dir>/gt_radar_tum.txt (TUM) and the configuration <dir>/simulation.yaml;
// with an IMU, <dir>/imu.txt and <dir>/imu_extrinsic.txt (io/imu.hpp's
// formats) and the true biases <dir>/imu_biases.txt (stamp bg bg bg ba ba ba).
void WriteSimulatedSequence(const std::string& dir, const SimulatedSequence& sequence);

// A rig of radars on one vehicle (docs/design/rig.md, "A simulated rig"):
// every radar is a simulation of the same drive through the same world with
// its own settings (mounting and lever arm, field of view, range, rate,
// clock offset, faults, noise seed). `world` holds what they share and each
// radar's defaults; a radar's map holds its own keys.
struct RigSimulationConfig {
  SimulationConfig world;
  std::vector<std::pair<std::string, SimulationConfig>> radars;  // name, settings
};
// The keys a radar may not set: the drive, the world and the IMU are the rig's.
const std::vector<std::string>& RigSharedSimulationKeys();
// A YAML file `world: {keys}` and `radars: [{name: ..., keys}]`. Throws
// DataError naming the file for a radar without a name or with the rig's
// keys, a name given twice, an IMU (not simulated on a rig), and what
// LoadSimulationConfig refuses.
RigSimulationConfig LoadRigSimulationConfig(const std::string& path);

struct SimulatedRig {
  std::vector<std::string> names;
  std::vector<SimulatedSequence> radars;  // each on its own clock, its ground truth T_world_radar
  std::vector<SE3d> body_from_radar;      // T_body_radar of each
  Trajectory body;                        // T_world_body on the true clock, at the first radar's scans
  // The body's true twist at the same times: velocity and angular velocity
  // in the body frame (central differences of its pose over 1e-4 s).
  std::vector<Eigen::Vector3d> body_velocity, body_angular_velocity;
  // The body's IMU (the world's imu_* keys; empty at imu_rate_hz 0): its
  // samples on its clock, its true biases and T_body_imu.
  std::vector<ImuSample> imu;
  std::vector<ImuBias> imu_bias;
  SE3d body_from_imu;
};
// Each radar simulated over the world's drive: its scans number its rate
// times the drive's duration (world.scans / world.rate_hz), its noise seed
// is world.seed plus its index unless it sets one, and the world's objects
// are one for all (world_seed, or world.seed when that is 0). With the
// world's imu_rate_hz, one IMU on the body over the whole drive, its draws
// seeded by world.seed plus the number of radars.
SimulatedRig SimulateRig(const RigSimulationConfig& config);
// <dir>/<name>/ per radar (WriteSimulatedSequence), <dir>/rig.yaml (io/rig.hpp:
// the folders, mountings and clock offsets), <dir>/gt_body_tum.txt and
// <dir>/twist_body.txt (lines "t vx vy vz wx wy wz", body frame); with an
// IMU, <dir>/imu.txt, imu_extrinsic.txt (T_body_imu) and imu_biases.txt.
void WriteSimulatedRig(const std::string& dir, const SimulatedRig& rig);

// "<secs>.<nsecs>" with nine decimals: the Snail-Radar file stem of a time,
// to the nearest nanosecond of the double (whose own resolution near 1.7e9 s
// is about 0.24 us; the simulator builds its stems from integers instead).
std::string TimestampStem(double time);

}  // namespace radargauss
