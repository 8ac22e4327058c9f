#include "radargauss/simulator.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <random>
#include <sstream>
#include <variant>

#include "radargauss/atomic_file.hpp"
#include "radargauss/error.hpp"
#include "radargauss/io/pcd.hpp"

namespace radargauss {

namespace {

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
    const Eigen::Vector2d starts[4] = {{radius, 0.0}, {length, radius}, {length - radius, width},
                                       {0.0, width - radius}};
    const Eigen::Vector2d centres[4] = {{length - radius, radius},
                                        {length - radius, width - radius},
                                        {radius, width - radius},
                                        {radius, radius}};
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

  static Eigen::Vector2d Left(double heading) {
    return Eigen::Vector2d(-std::sin(heading), std::cos(heading));
  }
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
  double s0;          // arc length at t = 0
  double lane_offset; // m to the left of the road centre line
  double direction;   // +1 with the loop, -1 against it
  double rcs_offset;
};

struct Hit {
  double distance = INFINITY;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  const std::string* material = nullptr;
  double rcs_offset = 0.0;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  bool dynamic = false;
};

void IntersectBox(const Box& box, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                  Hit& hit) {
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

struct Scene {
  std::vector<Box> static_boxes;
  std::vector<Pole> poles;
  std::vector<MovingCar> moving_cars;
};

const Eigen::Vector3d kCarHalfExtent(2.2, 0.9, 0.75);

Scene BuildScene(const SimulationConfig& config, const LoopPath& path, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> offset(0.0, config.object_rcs_spread_db);
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  Scene scene;
  Eigen::Vector2d p;
  double heading = 0.0;
  bool straight = false;
  // Buildings on both sides of the straights, set back 10 m from the road axis.
  for (const double side : {-1.0, 1.0}) {  // -1 outside (right), +1 inside (left)
    double s = uniform(0.0, 6.0);
    while (s < path.Perimeter()) {
      const double building_length = uniform(10.0, 25.0);
      const double depth = side > 0 ? 8.0 : 10.0;
      bool start_straight = false;
      bool end_straight = false;
      path.At(s, p, heading, start_straight);
      path.At(s + building_length, p, heading, end_straight);
      path.At(s + 0.5 * building_length, p, heading, straight);
      if (start_straight && end_straight && straight) {
        const Eigen::Vector2d centre = p + side * (10.0 + 0.5 * depth) * LoopPath::Left(heading);
        const double height = uniform(6.0, 15.0);
        scene.static_boxes.push_back({Eigen::Vector3d(centre.x(), centre.y(), 0.5 * height),
                                      Eigen::Vector3d(0.5 * building_length, 0.5 * depth,
                                                      0.5 * height),
                                      heading, "wall", offset(rng)});
      }
      s += building_length + uniform(3.0, 8.0);
    }
  }
  for (int i = 0; i < config.poles; ++i) {
    path.At(uniform(0.0, path.Perimeter()), p, heading, straight);
    const double side = unit(rng) < 0.5 ? -1.0 : 1.0;
    scene.poles.push_back({p + side * 5.0 * LoopPath::Left(heading), 0.1, 5.0, offset(rng)});
  }
  for (int i = 0; i < config.parked_cars; ++i) {
    path.At(uniform(0.0, path.Perimeter()), p, heading, straight);
    const double side = unit(rng) < 0.5 ? -1.0 : 1.0;
    const Eigen::Vector2d centre = p + side * 3.3 * LoopPath::Left(heading);
    scene.static_boxes.push_back({Eigen::Vector3d(centre.x(), centre.y(), kCarHalfExtent.z()),
                                  kCarHalfExtent, heading + uniform(-0.1, 0.1), "car",
                                  offset(rng)});
  }
  for (int i = 0; i < config.moving_cars; ++i) {
    // Alternate: oncoming in the left lane, or ahead in the ego lane.
    const bool oncoming = i % 2 == 0;
    scene.moving_cars.push_back({oncoming ? uniform(0.0, path.Perimeter()) : uniform(25.0, 60.0),
                                 oncoming ? 3.5 : 0.0, oncoming ? -1.0 : 1.0, offset(rng)});
  }
  return scene;
}

Box MovingCarBox(const MovingCar& car, const SimulationConfig& config, const LoopPath& path,
                 double time) {
  Eigen::Vector2d p;
  double heading = 0.0;
  bool straight = false;
  path.At(car.s0 + car.direction * config.moving_car_speed * time, p, heading, straight);
  const Eigen::Vector2d centre = p + car.lane_offset * LoopPath::Left(heading);
  const Eigen::Vector2d velocity =
      car.direction * config.moving_car_speed * Eigen::Vector2d(std::cos(heading), std::sin(heading));
  return {Eigen::Vector3d(centre.x(), centre.y(), kCarHalfExtent.z()), kCarHalfExtent, heading,
          "car", car.rcs_offset, Eigen::Vector3d(velocity.x(), velocity.y(), 0.0), true};
}

// Sensor pose and world velocity at a time.
void SensorState(const SimulationConfig& config, const LoopPath& path, double time, SE3d& pose,
                 Eigen::Vector3d& velocity_world) {
  Eigen::Vector2d p;
  double heading = 0.0;
  bool straight = false;
  path.At(5.0 + config.speed * time, p, heading, straight);
  const double roll = config.attitude_wobble_deg * kDeg * std::sin(2.0 * M_PI * 0.5 * time);
  const double pitch = config.attitude_wobble_deg * kDeg * std::sin(2.0 * M_PI * 0.3 * time + 1.0);
  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                       .matrix();
  pose = SE3d(SO3d::FromMatrix(rotation), Eigen::Vector3d(p.x(), p.y(), config.sensor_height));
  velocity_world = config.speed * Eigen::Vector3d(std::cos(heading), std::sin(heading), 0.0);
}

}  // namespace

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

SimulatedSequence Simulate(const SimulationConfig& config) {
  ValidateSimulationConfig(config, "simulation config");
  SimulatedSequence sequence;
  sequence.config = config;
  const LoopPath path{config.loop_length, config.loop_width, config.corner_radius};
  std::mt19937 rng(config.seed);
  const Scene scene = BuildScene(config, path, rng);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  const std::string pole_material = "pole";
  const std::string ground_material = "ground";
  const MeasurementStd stds{float(config.range_noise), float(config.azimuth_noise_deg * kDeg),
                            float(config.elevation_noise_deg * kDeg), float(config.doppler_noise)};

  // Scan times in integer nanoseconds, so that file names are exact.
  const long long start_seconds = static_cast<long long>(std::floor(config.start_time));
  const long long start_nanoseconds =
      std::llround((config.start_time - static_cast<double>(start_seconds)) * 1e9);
  for (int k = 0; k < config.scans; ++k) {
    const long long offset_nanoseconds = std::llround(k * 1e9 / config.rate_hz);
    const long long total = start_nanoseconds + offset_nanoseconds;
    const long long seconds = start_seconds + total / 1000000000LL;
    const long long nanoseconds = total % 1000000000LL;
    char stem[64];
    std::snprintf(stem, sizeof(stem), "%lld.%09lld", seconds, nanoseconds);
    sequence.file_stems.push_back(stem);
    const double time_offset = offset_nanoseconds * 1e-9;
    SE3d pose;
    Eigen::Vector3d velocity_world;
    SensorState(config, path, time_offset, pose, velocity_world);
    const Eigen::Matrix3d R = pose.rotation().Matrix();
    const Eigen::Vector3d velocity_radar = R.transpose() * velocity_world;
    std::vector<Box> moving;
    for (const MovingCar& car : scene.moving_cars) {
      moving.push_back(MovingCarBox(car, config, path, time_offset));
    }

    RadarScan scan;
    scan.timestamp = static_cast<double>(seconds) + static_cast<double>(nanoseconds) * 1e-9;
    scan.has_doppler = true;
    scan.has_rcs = true;
    std::vector<DetectionTruth> truth;
    const int target = config.min_detections +
                       static_cast<int>(unit(rng) * (config.max_detections - config.min_detections + 1));
    const int clutter = static_cast<int>(std::lround(target * config.clutter_fraction));
    const int surface = std::min(target, config.max_detections) - clutter;

    for (int ray = 0; ray < config.max_rays && static_cast<int>(scan.points.size()) < surface;
         ++ray) {
      const double azimuth = uniform(-config.azimuth_fov_deg, config.azimuth_fov_deg) * kDeg;
      const double elevation = uniform(-config.elevation_fov_deg, config.elevation_fov_deg) * kDeg;
      const Eigen::Vector3d direction_radar(std::cos(elevation) * std::cos(azimuth),
                                            std::cos(elevation) * std::sin(azimuth),
                                            std::sin(elevation));
      const Eigen::Vector3d direction = R * direction_radar;
      const Eigen::Vector3d& origin = pose.translation();
      Hit hit;
      hit.distance = config.max_range;
      if (direction.z() < -1e-9) {
        const double t = -origin.z() / direction.z();
        if (t < hit.distance) {
          hit.distance = t;
          hit.normal = Eigen::Vector3d::UnitZ();
          hit.material = &ground_material;
        }
      }
      for (const Box& box : scene.static_boxes) IntersectBox(box, origin, direction, hit);
      for (const Box& box : moving) IntersectBox(box, origin, direction, hit);
      for (const Pole& pole : scene.poles) IntersectPole(pole, pole_material, origin, direction, hit);
      if (hit.material == nullptr || hit.distance < config.min_range) continue;

      const double incidence =
          std::acos(std::min(1.0, std::abs(direction.dot(hit.normal))));
      const double rcs_true = MaterialRcs(config.materials.at(*hit.material), incidence) +
                              hit.rcs_offset;
      const double margin = rcs_true - 20.0 * std::log10(hit.distance / 10.0) -
                            config.detection_threshold_db;
      if (unit(rng) > 1.0 / (1.0 + std::exp(-margin / 2.0))) continue;

      const double range = hit.distance + config.range_noise * normal(rng);
      const double az = azimuth + config.azimuth_noise_deg * kDeg * normal(rng);
      const double el = elevation + config.elevation_noise_deg * kDeg * normal(rng);
      RadarPoint point;
      point.position = range * Eigen::Vector3d(std::cos(el) * std::cos(az),
                                               std::cos(el) * std::sin(az), std::sin(el));
      // v_d = u . (v_target - v_sensor), conventions.hpp.
      point.doppler = direction_radar.dot(R.transpose() * hit.velocity - velocity_radar) +
                      config.doppler_noise * normal(rng);
      DetectionTruth detection;
      detection.kind = hit.dynamic ? DetectionKind::kDynamic : DetectionKind::kStatic;
      detection.material = *hit.material;
      detection.incidence_angle = incidence;
      detection.rcs_noise_free = rcs_true;
      detection.position_world = origin + hit.distance * direction;
      point.rcs = rcs_true + config.rcs_noise_db * normal(rng);
      if (unit(rng) < config.rcs_outlier_fraction) {
        point.rcs += uniform(-25.0, 25.0);
        detection.rcs_outlier = true;
      }
      point.std_dev = stds;
      scan.points.push_back(point);
      truth.push_back(detection);
    }
    for (int c = 0; c < clutter; ++c) {
      const double azimuth = uniform(-config.azimuth_fov_deg, config.azimuth_fov_deg) * kDeg;
      const double elevation = uniform(-config.elevation_fov_deg, config.elevation_fov_deg) * kDeg;
      const double range = uniform(std::max(1.0, config.min_range), 0.6 * config.max_range);
      RadarPoint point;
      point.position = range * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                               std::cos(elevation) * std::sin(azimuth),
                                               std::sin(elevation));
      point.doppler = uniform(-15.0, 15.0);
      point.rcs = uniform(-20.0, 15.0);
      point.std_dev = stds;
      DetectionTruth detection;
      detection.kind = DetectionKind::kClutter;
      detection.position_world = pose * point.position;
      detection.rcs_noise_free = point.rcs;
      scan.points.push_back(point);
      truth.push_back(detection);
    }
    sequence.ground_truth.Append(scan.timestamp, pose);
    sequence.sensor_velocity.push_back(velocity_radar);
    sequence.scans.push_back(std::move(scan));
    sequence.truth.push_back(std::move(truth));
  }
  return sequence;
}

// ---------------------------------------------------------------------------
// Configuration file.

namespace {

using ConfigValue = std::variant<double*, int*, std::uint32_t*>;

std::vector<std::pair<std::string, ConfigValue>> ConfigFields(SimulationConfig& c) {
  return {{"seed", &c.seed},
          {"scans", &c.scans},
          {"rate_hz", &c.rate_hz},
          {"start_time", &c.start_time},
          {"speed", &c.speed},
          {"loop_length", &c.loop_length},
          {"loop_width", &c.loop_width},
          {"corner_radius", &c.corner_radius},
          {"sensor_height", &c.sensor_height},
          {"attitude_wobble_deg", &c.attitude_wobble_deg},
          {"azimuth_fov_deg", &c.azimuth_fov_deg},
          {"elevation_fov_deg", &c.elevation_fov_deg},
          {"min_range", &c.min_range},
          {"max_range", &c.max_range},
          {"min_detections", &c.min_detections},
          {"max_detections", &c.max_detections},
          {"max_rays", &c.max_rays},
          {"detection_threshold_db", &c.detection_threshold_db},
          {"range_noise", &c.range_noise},
          {"azimuth_noise_deg", &c.azimuth_noise_deg},
          {"elevation_noise_deg", &c.elevation_noise_deg},
          {"doppler_noise", &c.doppler_noise},
          {"rcs_noise_db", &c.rcs_noise_db},
          {"clutter_fraction", &c.clutter_fraction},
          {"rcs_outlier_fraction", &c.rcs_outlier_fraction},
          {"poles", &c.poles},
          {"parked_cars", &c.parked_cars},
          {"moving_cars", &c.moving_cars},
          {"moving_car_speed", &c.moving_car_speed},
          {"object_rcs_spread_db", &c.object_rcs_spread_db}};
}

}  // namespace

void ValidateSimulationConfig(const SimulationConfig& c, const std::string& source) {
  const auto require = [&](bool ok, const std::string& what) {
    if (!ok) throw FileError(source, what);
  };
  require(c.scans >= 1, "scans must be >= 1");
  require(c.rate_hz > 0.0, "rate_hz must be > 0");
  require(std::isfinite(c.start_time) && c.start_time >= 0.0, "start_time must be >= 0");
  require(c.speed >= 0.0, "speed must be >= 0");
  require(c.corner_radius > 0.0 && c.loop_length > 2.0 * c.corner_radius &&
              c.loop_width > 2.0 * c.corner_radius,
          "loop_length and loop_width must exceed 2 x corner_radius > 0");
  require(c.sensor_height > 0.0, "sensor_height must be > 0");
  require(c.azimuth_fov_deg > 0.0 && c.azimuth_fov_deg <= 90.0, "azimuth_fov_deg must be in (0, 90]");
  require(c.elevation_fov_deg > 0.0 && c.elevation_fov_deg < 90.0,
          "elevation_fov_deg must be in (0, 90)");
  require(c.min_range >= 0.0 && c.max_range > c.min_range, "need 0 <= min_range < max_range");
  require(c.min_detections >= 1 && c.max_detections >= c.min_detections,
          "need 1 <= min_detections <= max_detections");
  require(c.max_rays >= 1, "max_rays must be >= 1");
  for (const double noise : {c.range_noise, c.azimuth_noise_deg, c.elevation_noise_deg,
                             c.doppler_noise, c.rcs_noise_db, c.object_rcs_spread_db}) {
    require(noise >= 0.0 && std::isfinite(noise), "noise levels must be finite and >= 0");
  }
  require(c.clutter_fraction >= 0.0 && c.clutter_fraction < 1.0, "clutter_fraction must be in [0, 1)");
  require(c.rcs_outlier_fraction >= 0.0 && c.rcs_outlier_fraction <= 1.0,
          "rcs_outlier_fraction must be in [0, 1]");
  require(c.poles >= 0 && c.parked_cars >= 0 && c.moving_cars >= 0, "object counts must be >= 0");
  for (const char* name : {"ground", "wall", "pole", "car"}) {
    const auto it = c.materials.find(name);
    require(it != c.materials.end(), std::string("material '") + name + "' missing");
    require(it->second.diffuse >= 0.0 && it->second.specular >= 0.0 &&
                it->second.lobe_width_deg > 0.0 &&
                it->second.diffuse + it->second.specular > 0.0,
            std::string("material '") + name + "' needs diffuse, specular >= 0 (not both 0) and lobe_width_deg > 0");
  }
}

SimulationConfig LoadSimulationConfig(const std::string& path) {
  SimulationConfig config;
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw FileError(path, "cannot open simulation config");
  } catch (const YAML::Exception& e) {
    throw FileError(path, std::string("YAML: ") + e.what());
  }
  if (root.IsNull()) return config;
  if (!root.IsMap()) throw FileError(path, "expected a map of parameters");
  auto fields = ConfigFields(config);
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    try {
      if (key == "materials") {
        if (!entry.second.IsMap()) throw FileError(path, "materials must be a map");
        for (const auto& material : entry.second) {
          const std::string name = material.first.as<std::string>();
          if (!config.materials.count(name)) {
            throw FileError(path, "unknown material '" + name + "' (ground, wall, pole, car)");
          }
          Material& m = config.materials[name];
          for (const auto& property : material.second) {
            const std::string property_name = property.first.as<std::string>();
            if (property_name == "diffuse") m.diffuse = property.second.as<double>();
            else if (property_name == "specular") m.specular = property.second.as<double>();
            else if (property_name == "lobe_width_deg") m.lobe_width_deg = property.second.as<double>();
            else throw FileError(path, "unknown material property '" + property_name + "'");
          }
        }
        continue;
      }
      const auto it = std::find_if(fields.begin(), fields.end(),
                                   [&](const auto& field) { return field.first == key; });
      if (it == fields.end()) throw FileError(path, "unknown parameter '" + key + "'");
      std::visit([&](auto* target) { *target = entry.second.as<std::remove_pointer_t<decltype(target)>>(); },
                 it->second);
    } catch (const YAML::Exception&) {
      throw FileError(path, "parameter '" + key + "' has the wrong type");
    }
  }
  ValidateSimulationConfig(config, path);
  return config;
}

std::string SimulationConfigToYaml(const SimulationConfig& config) {
  SimulationConfig copy = config;
  std::ostringstream out;
  out.precision(17);
  for (const auto& [key, value] : ConfigFields(copy)) {
    out << key << ": ";
    std::visit([&](auto* target) { out << *target; }, value);
    out << "\n";
  }
  out << "materials:\n";
  for (const auto& [name, m] : config.materials) {
    out << "  " << name << ": {diffuse: " << m.diffuse << ", specular: " << m.specular
        << ", lobe_width_deg: " << m.lobe_width_deg << "}\n";
  }
  return out.str();
}

Sequence AsSequence(const SimulatedSequence& simulated) {
  Sequence sequence;
  sequence.layout = "simulated";
  sequence.scans = simulated.scans;
  sequence.total_scans = simulated.scans.size();
  sequence.trajectory = simulated.ground_truth;
  for (const StampedPose& sample : simulated.ground_truth) sequence.poses.push_back(sample.pose);
  return sequence;
}

void WriteSimulatedSequence(const std::string& dir, const SimulatedSequence& sequence) {
  namespace fs = std::filesystem;
  const fs::path points = fs::path(dir) / "ars548" / "points";
  std::error_code error;
  fs::create_directories(points, error);
  if (error) throw FileError(points.string(), "cannot create directory: " + error.message());
  std::string times;
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    const std::string& stem = sequence.file_stems[k];
    WritePcdScan((points / (stem + ".pcd")).string(), sequence.scans[k], PcdFormat::kBinary);
    times += stem + "\n";
  }
  WriteFileAtomically((points / "times.txt").string(), [&](std::ostream& out) { out << times; });
  WriteTum((fs::path(dir) / "gt_radar_tum.txt").string(), sequence.ground_truth);
  WriteFileAtomically((fs::path(dir) / "simulation.yaml").string(), [&](std::ostream& out) {
    out << "# radargauss simulate: the configuration that produced this sequence\n"
        << SimulationConfigToYaml(sequence.config);
  });
}

}  // namespace radargauss
