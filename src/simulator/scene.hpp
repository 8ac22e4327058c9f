// SPDX-License-Identifier: BSD-3-Clause
// The simulator's loop (docs/design/simulator.md, "The synthetic world"): the road,
// the town's buildings, poles and cars or the motorway's guardrails,
// gantries and traffic along it, and ray casting through them. Internal to
// src/simulator/.
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/simulator/imu_from_reference.hpp"
#include "radargauss/simulator/simulator.hpp"

namespace radargauss::simulation {

constexpr double kDeg = M_PI / 180.0;

// The road: a rounded rectangle driven counter-clockwise, so "left" is inward.
struct LoopPath {
  double length;
  double width;
  double radius;

  double StraightX() const { return length - 2.0 * radius; }
  double StraightY() const { return width - 2.0 * radius; }
  double CornerLength() const { return 0.5 * M_PI * radius; }
  double Perimeter() const { return 2.0 * (StraightX() + StraightY()) + 4.0 * CornerLength(); }

  // Position, heading and whether s lies on a straight segment.
  void At(double s, Eigen::Vector2d& position, double& heading, bool& straight) const {
    s = std::fmod(s, Perimeter());
    if (s < 0.0) s += Perimeter();
    const double straights[4] = {StraightX(), StraightY(), StraightX(), StraightY()};
    const Eigen::Vector2d starts[4] = {
        {radius, 0.0}, {length, radius}, {length - radius, width}, {0.0, width - radius}};
    const Eigen::Vector2d centres[4] = {
        {length - radius, radius}, {length - radius, width - radius}, {radius, width - radius}, {radius, radius}};
    for (int side = 0; side < 4; ++side) {
      const double side_heading = side * 0.5 * M_PI;
      if (s <= straights[side]) {
        position = starts[side] + s * Eigen::Vector2d(std::cos(side_heading), std::sin(side_heading));
        heading = side_heading;
        straight = true;
        return;
      }
      s -= straights[side];
      if (s <= CornerLength() || side == 3) {
        const double alpha = side_heading - 0.5 * M_PI + s / radius;
        position = centres[side] + radius * Eigen::Vector2d(std::cos(alpha), std::sin(alpha));
        heading = alpha + 0.5 * M_PI;
        straight = false;
        return;
      }
      s -= CornerLength();
    }
  }

  static Eigen::Vector2d Left(double heading) { return Eigen::Vector2d(-std::sin(heading), std::cos(heading)); }
};

struct Box {
  Eigen::Vector3d centre;
  Eigen::Vector3d half_extent;
  double yaw = 0.0;
  std::string material;
  double rcs_offset = 0.0;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // world frame
  bool dynamic = false;
};

struct Pole {
  Eigen::Vector2d xy;
  double radius = 0.1;
  double height = 5.0;
  double rcs_offset = 0.0;
};

struct MovingCar {
  double s0;           // arc length at t = 0
  double lane_offset;  // m to the left of the road centre line
  double direction;    // +1 with the loop, -1 against it
  double rcs_offset;
  double speed;  // m/s
};

struct Hit {
  double distance = INFINITY;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  const std::string* material = nullptr;
  double rcs_offset = 0.0;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  bool dynamic = false;
};

struct Scene {
  std::vector<Box> static_boxes;
  std::vector<Pole> poles;
  std::vector<MovingCar> moving_cars;
};

// The scene of a run, drawn from `rng` (the same for a seed): the town or
// the motorway of config.scene.
Scene BuildScene(const SimulationConfig& config, const LoopPath& path, std::mt19937& rng);

// The scene's objects that a ray from `position` can meet within `range`
// (the rest cannot change a hit): ray casting's cost follows the
// neighbourhood, not the length of the loop.
Scene Nearby(const Scene& scene, const Eigen::Vector3d& position, double range);

// A moving car's box at `time` (s since the start), the ego at `ego_arc`
// metres along the path: a car in the ego's lane that comes within reach of
// it (a faster car lapping the ego on a long drive) passes in the next lane.
Box MovingCarBox(const MovingCar& car, const LoopPath& path, double time, double ego_arc);

// The ego's metres along the path at `time`.
double EgoArc(const SimulationConfig& config, double time);

// Sensor pose and world velocity at `time`.
void SensorState(const SimulationConfig& config, const LoopPath& path, double time, SE3d& pose,
                 Eigen::Vector3d& velocity_world);

// The IMU on the vehicle (ImuOnVehicle) along the drive: `count` samples from
// config.start_time on the true clock (SimulateImuAlong's model and draws).
SimulatedImu VehicleImu(const SimulationConfig& config, std::size_t count);

// The nearest surface along a ray within max_range: the ground, the scene's
// static boxes, the moving boxes and the poles (hit.material null: none).
Hit CastRay(const Scene& scene, const std::vector<Box>& moving, const Eigen::Vector3d& origin,
            const Eigen::Vector3d& direction, double max_range);

}  // namespace radargauss::simulation
