// SPDX-License-Identifier: BSD-3-Clause
#include "scene.hpp"

#include <algorithm>

#include <Eigen/Geometry>

namespace radargauss::simulation {

namespace {

const std::string kPoleMaterial = "pole";
const std::string kGroundMaterial = "ground";
const Eigen::Vector3d kCarHalfExtent(2.2, 0.9, 0.75);

// False when the ray cannot reach the box closer than hit.distance: it misses
// the box's bounding sphere or meets it only beyond the nearest hit so far. A
// millimetre of margin keeps the test conservative, so it changes no hit.
bool MayHitBox(const Box& box, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, const Hit& hit) {
  const double radius = box.half_extent.norm() + 1e-3;
  const Eigen::Vector3d to_centre = box.centre - origin;
  const double squared_length = direction.squaredNorm();
  const double along = to_centre.dot(direction);  // the centre's ray parameter times squared_length
  const double reach = radius * std::sqrt(squared_length);
  if (along + reach <= 0.0 || along - reach >= hit.distance * squared_length) return false;
  return to_centre.squaredNorm() - along * along / squared_length <= radius * radius;
}

void IntersectBox(const Box& box, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, Hit& hit) {
  if (!MayHitBox(box, origin, direction, hit)) return;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(box.yaw, Eigen::Vector3d::UnitZ()).matrix();
  const Eigen::Vector3d o = rotation.transpose() * (origin - box.centre);
  const Eigen::Vector3d d = rotation.transpose() * direction;
  double t_near = -INFINITY;
  double t_far = INFINITY;
  int near_axis = -1;
  for (int axis = 0; axis < 3; ++axis) {
    const double h = box.half_extent[axis];
    if (std::abs(d[axis]) < 1e-12) {
      if (std::abs(o[axis]) > h) return;
      continue;
    }
    double t1 = (-h - o[axis]) / d[axis];
    double t2 = (h - o[axis]) / d[axis];
    if (t1 > t2) std::swap(t1, t2);
    if (t1 > t_near) {
      t_near = t1;
      near_axis = axis;
    }
    t_far = std::min(t_far, t2);
  }
  if (near_axis < 0 || t_near > t_far || t_near <= 0.0 || t_near >= hit.distance) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  normal[near_axis] = d[near_axis] > 0.0 ? -1.0 : 1.0;
  hit.distance = t_near;
  hit.normal = rotation * normal;
  hit.material = &box.material;
  hit.rcs_offset = box.rcs_offset;
  hit.velocity = box.velocity;
  hit.dynamic = box.dynamic;
}

void IntersectPole(const Pole& pole, const std::string& material, const Eigen::Vector3d& origin,
                   const Eigen::Vector3d& direction, Hit& hit) {
  const Eigen::Vector2d o = origin.head<2>() - pole.xy;
  const Eigen::Vector2d d = direction.head<2>();
  const double a = d.squaredNorm();
  if (a < 1e-12) return;
  const double b = 2.0 * o.dot(d);
  const double c = o.squaredNorm() - pole.radius * pole.radius;
  const double discriminant = b * b - 4.0 * a * c;
  if (discriminant < 0.0) return;
  const double t = (-b - std::sqrt(discriminant)) / (2.0 * a);
  if (t <= 0.0 || t >= hit.distance) return;
  const double z = origin.z() + t * direction.z();
  if (z < 0.0 || z > pole.height) return;
  const Eigen::Vector2d radial = (o + t * d) / pole.radius;
  hit.distance = t;
  hit.normal = Eigen::Vector3d(radial.x(), radial.y(), 0.0);
  hit.material = &material;
  hit.rcs_offset = pole.rcs_offset;
  hit.velocity.setZero();
  hit.dynamic = false;
}

// The scene's random draws from the run's scene generator, in one order.
struct SceneDraws {
  SceneDraws(const SimulationConfig& config, std::mt19937& rng) : rng(rng), offset(0.0, config.object_rcs_spread_db) {}
  double Unit() { return unit(rng); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * unit(rng); }
  double Offset() { return offset(rng); }  // an object's RCS offset, dB
  std::mt19937& rng;
  std::uniform_real_distribution<double> unit{0.0, 1.0};
  std::normal_distribution<double> offset;
};

// The motorway: the ego in the middle of three lanes (offsets -3.5, 0, 3.5
// m), a guardrail on the right shoulder and in the median, the oncoming
// carriageway's three lanes beyond it and its outer guardrail; gantries
// across both every 400 m; poles on the right verge; traffic both ways.
Scene BuildMotorway(const SimulationConfig& config, const LoopPath& path, std::mt19937& rng) {
  SceneDraws draws(config, rng);
  Scene scene;
  Eigen::Vector2d p;
  double heading = 0.0;
  bool straight = false;
  const double segment = 4.0;  // m of guardrail per box (corners: chords)
  for (double s = 0.0; s < path.Perimeter(); s += segment) {
    path.At(s + 0.5 * segment, p, heading, straight);
    for (const double lateral : {-5.75, 5.75, 18.25}) {
      const Eigen::Vector2d centre = p + lateral * LoopPath::Left(heading);
      scene.static_boxes.push_back({Eigen::Vector3d(centre.x(), centre.y(), 0.55),
                                    Eigen::Vector3d(0.5 * segment, 0.05, 0.2), heading, "guardrail", draws.Offset()});
    }
  }
  for (double s = draws.Uniform(0.0, 400.0); s < path.Perimeter(); s += 400.0) {
    path.At(s, p, heading, straight);
    const Eigen::Vector2d centre = p + 6.0 * LoopPath::Left(heading);
    scene.static_boxes.push_back({Eigen::Vector3d(centre.x(), centre.y(), 6.5), Eigen::Vector3d(0.4, 13.5, 0.6),
                                  heading, "wall", draws.Offset()});
    for (const double lateral : {-7.0, 19.5}) {
      scene.poles.push_back({p + lateral * LoopPath::Left(heading), 0.25, 7.0, draws.Offset()});
    }
  }
  for (int i = 0; i < config.poles; ++i) {
    path.At(draws.Uniform(0.0, path.Perimeter()), p, heading, straight);
    scene.poles.push_back({p - 8.0 * LoopPath::Left(heading), 0.1, 5.0, draws.Offset()});
  }
  const double ego = 5.0 + config.start_offset;
  for (int i = 0; i < config.moving_cars; ++i) {
    // Alternately with the ego (right or left lane, near it) and oncoming.
    const bool oncoming = i % 2 == 1;
    const double lane = oncoming ? 9.25 + 3.5 * std::floor(draws.Uniform(0.0, 3.0)) : (draws.Unit() < 0.5 ? -3.5 : 3.5);
    const double s0 = ego + (oncoming ? draws.Uniform(0.0, 2500.0) : draws.Uniform(-100.0, 300.0));  // met within ~30 s
    const double speed = draws.Uniform(config.traffic_min_speed, config.traffic_max_speed);
    scene.moving_cars.push_back({s0, lane, oncoming ? -1.0 : 1.0, draws.Offset(), speed});
  }
  return scene;
}

Scene BuildTown(const SimulationConfig& config, const LoopPath& path, std::mt19937& rng) {
  SceneDraws draws(config, rng);
  Scene scene;
  Eigen::Vector2d p;
  double heading = 0.0;
  bool straight = false;
  // Buildings on both sides of the straights, set back 10 m from the road axis.
  for (const double side : {-1.0, 1.0}) {  // -1 outside (right), +1 inside (left)
    double s = draws.Uniform(0.0, 6.0);
    while (s < path.Perimeter()) {
      const double building_length = draws.Uniform(10.0, 25.0);
      const double depth = side > 0 ? 8.0 : 10.0;
      bool start_straight = false;
      bool end_straight = false;
      path.At(s, p, heading, start_straight);
      path.At(s + building_length, p, heading, end_straight);
      path.At(s + 0.5 * building_length, p, heading, straight);
      if (start_straight && end_straight && straight) {
        const Eigen::Vector2d centre = p + side * (10.0 + 0.5 * depth) * LoopPath::Left(heading);
        const double height = draws.Uniform(6.0, 15.0);
        scene.static_boxes.push_back({Eigen::Vector3d(centre.x(), centre.y(), 0.5 * height),
                                      Eigen::Vector3d(0.5 * building_length, 0.5 * depth, 0.5 * height), heading,
                                      "wall", draws.Offset()});
      }
      s += building_length + draws.Uniform(3.0, 8.0);
    }
  }
  for (int i = 0; i < config.poles; ++i) {
    path.At(draws.Uniform(0.0, path.Perimeter()), p, heading, straight);
    const double side = draws.Unit() < 0.5 ? -1.0 : 1.0;
    scene.poles.push_back({p + side * 5.0 * LoopPath::Left(heading), 0.1, 5.0, draws.Offset()});
  }
  for (int i = 0; i < config.parked_cars; ++i) {
    path.At(draws.Uniform(0.0, path.Perimeter()), p, heading, straight);
    const double side = draws.Unit() < 0.5 ? -1.0 : 1.0;
    const Eigen::Vector2d centre = p + side * 3.3 * LoopPath::Left(heading);
    scene.static_boxes.push_back({Eigen::Vector3d(centre.x(), centre.y(), kCarHalfExtent.z()), kCarHalfExtent,
                                  heading + draws.Uniform(-0.1, 0.1), "car", draws.Offset()});
  }
  for (int i = 0; i < config.moving_cars; ++i) {
    // Alternate: oncoming in the left lane, or ahead in the ego lane.
    const bool oncoming = i % 2 == 0;
    scene.moving_cars.push_back({oncoming ? draws.Uniform(0.0, path.Perimeter()) : draws.Uniform(25.0, 60.0),
                                 oncoming ? 3.5 : 0.0, oncoming ? -1.0 : 1.0, draws.Offset(), config.moving_car_speed});
  }
  return scene;
}

}  // namespace

Scene BuildScene(const SimulationConfig& config, const LoopPath& path, std::mt19937& rng) {
  return config.scene == "motorway" ? BuildMotorway(config, path, rng) : BuildTown(config, path, rng);
}

Scene Nearby(const Scene& scene, const Eigen::Vector3d& position, double range) {
  Scene nearby;
  for (const Box& box : scene.static_boxes) {
    if ((box.centre - position).norm() <= range + box.half_extent.norm() + 1e-3) nearby.static_boxes.push_back(box);
  }
  for (const Pole& pole : scene.poles) {
    if ((pole.xy - position.head<2>()).norm() <= range + pole.radius + 1e-3) nearby.poles.push_back(pole);
  }
  nearby.moving_cars = scene.moving_cars;
  return nearby;
}

Box MovingCarBox(const MovingCar& car, const LoopPath& path, double time, double ego_arc) {
  Eigen::Vector2d p;
  double heading = 0.0;
  bool straight = false;
  const double arc = car.s0 + car.direction * car.speed * time;
  path.At(arc, p, heading, straight);
  double lane = car.lane_offset;
  if (car.lane_offset == 0.0 && car.direction > 0.0) {
    // Within 15 m of the ego (along the path, either side) in the next lane, beyond 23 m in the ego's.
    constexpr double kPassingLane = 3.5, kReach = 15.0, kRamp = 8.0;
    const double apart = std::abs(std::remainder(arc - ego_arc, path.Perimeter()));
    lane = kPassingLane * std::clamp((kReach + kRamp - apart) / kRamp, 0.0, 1.0);
  }
  const Eigen::Vector2d centre = p + lane * LoopPath::Left(heading);
  const Eigen::Vector2d velocity = car.direction * car.speed * Eigen::Vector2d(std::cos(heading), std::sin(heading));
  return {Eigen::Vector3d(centre.x(), centre.y(), kCarHalfExtent.z()),
          kCarHalfExtent,
          heading,
          "car",
          car.rcs_offset,
          Eigen::Vector3d(velocity.x(), velocity.y(), 0.0),
          true};
}

double EgoArc(const SimulationConfig& config, double time) { return 5.0 + config.start_offset + config.speed * time; }

// Sensor pose and world velocity at a time.
void SensorState(const SimulationConfig& config, const LoopPath& path, double time, SE3d& pose,
                 Eigen::Vector3d& velocity_world) {
  Eigen::Vector2d p;
  double heading = 0.0;
  bool straight = false;
  path.At(EgoArc(config, time), p, heading, straight);
  const double roll = config.attitude_wobble_deg * kDeg * std::sin(2.0 * M_PI * 0.5 * time);
  const double pitch = config.attitude_wobble_deg * kDeg * std::sin(2.0 * M_PI * 0.3 * time + 1.0);
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
          .matrix();
  pose = SE3d(SO3d::FromMatrix(rotation), Eigen::Vector3d(p.x(), p.y(), config.sensor_height));
  velocity_world = config.speed * Eigen::Vector3d(std::cos(heading), std::sin(heading), 0.0);
}

Hit CastRay(const Scene& scene, const std::vector<Box>& moving, const Eigen::Vector3d& origin,
            const Eigen::Vector3d& direction, double max_range) {
  Hit hit;
  hit.distance = max_range;
  if (direction.z() < -1e-9) {
    const double t = -origin.z() / direction.z();
    if (t < hit.distance) {
      hit.distance = t;
      hit.normal = Eigen::Vector3d::UnitZ();
      hit.material = &kGroundMaterial;
    }
  }
  for (const Box& box : scene.static_boxes) IntersectBox(box, origin, direction, hit);
  for (const Box& box : moving) IntersectBox(box, origin, direction, hit);
  for (const Pole& pole : scene.poles) IntersectPole(pole, kPoleMaterial, origin, direction, hit);
  return hit;
}

}  // namespace radargauss::simulation
