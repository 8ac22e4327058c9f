// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/simulator/imu_from_reference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/conventions.hpp"
#include "radargauss/core/error.hpp"

namespace radargauss {

namespace {

// The uniform cubic B-spline's four weights at s in [0, 1] of an interval.
Eigen::Vector4d CubicWeights(double s) {
  const double s2 = s * s, s3 = s2 * s;
  return Eigen::Vector4d((1.0 - s) * (1.0 - s) * (1.0 - s), 3.0 * s3 - 6.0 * s2 + 4.0,
                         -3.0 * s3 + 3.0 * s2 + 3.0 * s + 1.0, s3) /
         6.0;
}

// Roll, pitch, yaw of R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector3d RollPitchYaw(const Eigen::Matrix3d& R) {
  return Eigen::Vector3d(std::atan2(R(2, 1), R(2, 2)), std::asin(std::clamp(-R(2, 0), -1.0, 1.0)),
                         std::atan2(R(1, 0), R(0, 0)));
}

// The angle closest to `previous` among angle + 2 pi k.
double Unwrapped(double angle, double previous) {
  return angle + 2.0 * M_PI * std::round((previous - angle) / (2.0 * M_PI));
}

}  // namespace

SE3d ImuOnVehicle(const SimulationConfig& config) {
  return SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, config.imu_yaw_deg * kRadiansPerDegree)) *
                  SO3d::Exp(Eigen::Vector3d(0.0, config.imu_pitch_deg * kRadiansPerDegree, 0.0)) *
                  SO3d::Exp(Eigen::Vector3d(config.imu_roll_deg * kRadiansPerDegree, 0.0, 0.0)),
              Eigen::Vector3d(config.imu_x, config.imu_y, config.imu_z));
}

// The IMU frame's mean rate and specific force over the interval from each
// sample to the next (delta angle and delta velocity over dt), plus turn-on
// biases, their random walks and white noise, drawn from a generator of
// their own so that the scans are the same with an IMU or without.
SimulatedImu SimulateImuAlong(const std::function<SE3d(double)>& world_from_imu, std::size_t count,
                              const SimulationConfig& config) {
  std::mt19937 rng(config.seed ^ 0x9e3779b9u);
  std::normal_distribution<double> normal;
  const auto draw = [&](double std) -> Eigen::Vector3d {
    return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * std;
  };
  ImuBias bias{draw(config.imu_gyro_bias_std), draw(config.imu_accel_bias_std)};
  const double dt = 1.0 / config.imu_rate_hz;
  const double h = 1e-3;
  const Eigen::Vector3d gravity(0.0, 0.0, -kGravity);
  // The IMU frame's velocity by central differences (h).
  const auto velocity = [&](double t) -> Eigen::Vector3d {
    return (world_from_imu(t + h).translation() - world_from_imu(t - h).translation()) / (2.0 * h);
  };
  SimulatedImu imu;
  imu.samples.reserve(count);
  imu.bias.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    const double t = double(k) * dt;
    const SE3d at = world_from_imu(t), next = world_from_imu(t + dt);
    const Eigen::Vector3d rate = (at.rotation().Inverse() * next.rotation()).Log() / dt;
    const Eigen::Vector3d acceleration = (velocity(t + dt) - velocity(t)) / dt;
    ImuSample sample;
    sample.stamp = config.start_time + t + config.imu_clock_offset;
    sample.angular_velocity = rate + bias.gyro + draw(config.imu_noise.gyro_noise_density / std::sqrt(dt));
    sample.specific_force = at.rotation().Inverse() * (acceleration - gravity) + bias.accel +
                            draw(config.imu_noise.accel_noise_density / std::sqrt(dt));
    imu.samples.push_back(sample);
    imu.bias.push_back(bias);
    bias.gyro += draw(config.imu_noise.gyro_bias_random_walk * std::sqrt(dt));
    bias.accel += draw(config.imu_noise.accel_bias_random_walk * std::sqrt(dt));
  }
  return imu;
}

void WriteImuFiles(const std::string& dir, const SimulatedImu& imu, const SE3d& radar_from_imu,
                   const std::string& host) {
  namespace fs = std::filesystem;
  WriteFileAtomically((fs::path(dir) / "imu.txt").string(), [&](std::ostream& out) {
    out << "# stamp wx wy wz ax ay az (s, rad/s, m/s^2; the IMU's frame)\n";
    char line[256];
    for (const ImuSample& s : imu.samples) {
      std::snprintf(line, sizeof(line), "%.9f %.17g %.17g %.17g %.17g %.17g %.17g\n", s.stamp, s.angular_velocity.x(),
                    s.angular_velocity.y(), s.angular_velocity.z(), s.specific_force.x(), s.specific_force.y(),
                    s.specific_force.z());
      out << line;
    }
  });
  WriteFileAtomically((fs::path(dir) / "imu_extrinsic.txt").string(), [&](std::ostream& out) {
    const Eigen::Vector3d& t = radar_from_imu.translation();
    const Eigen::Quaterniond& q = radar_from_imu.rotation().quaternion();
    char line[256];
    std::snprintf(line, sizeof(line), "%.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", t.x(), t.y(), t.z(), q.x(), q.y(),
                  q.z(), q.w());
    out << "# x y z qx qy qz qw: T_" << host << "_imu\n" << line;
  });
  WriteFileAtomically((fs::path(dir) / "imu_biases.txt").string(), [&](std::ostream& out) {
    out << "# stamp bgx bgy bgz bax bay baz: the true biases (rad/s, m/s^2), for evaluation only\n";
    char line[256];
    for (std::size_t k = 0; k < imu.samples.size(); ++k) {
      const ImuBias& b = imu.bias[k];
      std::snprintf(line, sizeof(line), "%.9f %.9g %.9g %.9g %.9g %.9g %.9g\n", imu.samples[k].stamp, b.gyro.x(),
                    b.gyro.y(), b.gyro.z(), b.accel.x(), b.accel.y(), b.accel.z());
      out << line;
    }
  });
}

SmoothTrajectory::SmoothTrajectory(const Trajectory& reference, double knot_spacing, double smoothing) {
  if (!(knot_spacing > 0.0) || !std::isfinite(knot_spacing)) {
    throw DataError("the knot spacing must be above zero (got " + std::to_string(knot_spacing) + " s)");
  }
  if (!(smoothing >= 0.0) || !std::isfinite(smoothing)) throw DataError("the smoothing must be zero or above");
  if (reference.size() < 4 || reference.EndTime() - reference.StartTime() < 2.0 * knot_spacing) {
    throw DataError("the reference holds " + std::to_string(reference.size()) +
                    " poses: a smooth motion needs four and two knot spacings of time");
  }
  start_ = reference.StartTime();
  end_ = reference.EndTime();
  spacing_ = knot_spacing;
  const int intervals = int(std::ceil((end_ - start_) / spacing_));
  const int n = intervals + 3;
  // Least squares over the control points (a banded normal matrix), the
  // channels of each pose with roll and yaw unwrapped along the drive.
  std::vector<Eigen::Triplet<double>> normal;
  Eigen::MatrixXd AtY = Eigen::MatrixXd::Zero(n, 6);
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < reference.size(); ++k) {
    const Eigen::Matrix3d R = reference[k].pose.rotation().Matrix();
    if (std::abs(R(2, 0)) > std::sin(89.0 * kRadiansPerDegree)) {
      throw DataError("the reference pitches to 90 deg at " + std::to_string(reference[k].time) +
                      " s, where roll and yaw are one");
    }
    Eigen::Vector3d angles = RollPitchYaw(R);
    if (k > 0) {
      angles(0) = Unwrapped(angles(0), previous(0));
      angles(2) = Unwrapped(angles(2), previous(2));
    }
    previous = angles;
    Eigen::Matrix<double, 6, 1> y;
    y << reference[k].pose.translation(), angles;
    const double u = (reference[k].time - start_) / spacing_;
    const int i = std::clamp(int(std::floor(u)), 0, intervals - 1);
    const Eigen::Vector4d w = CubicWeights(u - i);
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) normal.emplace_back(i + a, i + b, w(a) * w(b));
    }
    AtY.middleRows<4>(i) += w * y.transpose();
  }
  // Second differences of the control points: the smoothing, and a floor
  // that keeps the points of an interval without poses determined.
  const double lambda = std::max(smoothing, 1e-6);
  const Eigen::Vector3d d(1.0, -2.0, 1.0);
  for (int j = 1; j + 1 < n; ++j) {
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) normal.emplace_back(j - 1 + a, j - 1 + b, lambda * d(a) * d(b));
    }
  }
  Eigen::SparseMatrix<double> AtA(n, n);
  AtA.setFromTriplets(normal.begin(), normal.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor(AtA);
  if (factor.info() != Eigen::Success) throw DataError("the reference's smooth motion could not be fitted");
  control_ = factor.solve(AtY);
  double position = 0.0, rotation = 0.0;
  for (const StampedPose& sample : reference) {
    const SE3d fitted = Pose(Channels(sample.time));
    position += (fitted.translation() - sample.pose.translation()).squaredNorm();
    rotation += (sample.pose.rotation().Inverse() * fitted.rotation()).Log().squaredNorm();
  }
  position_rms_ = std::sqrt(position / double(reference.size()));
  rotation_rms_ = std::sqrt(rotation / double(reference.size()));
}

Eigen::Matrix<double, 6, 1> SmoothTrajectory::Channels(double time) const {
  const int intervals = int(control_.rows()) - 3;
  const double u = (std::clamp(time, start_, end_) - start_) / spacing_;
  const int i = std::clamp(int(std::floor(u)), 0, intervals - 1);
  const Eigen::Vector4d w = CubicWeights(u - i);
  return control_.middleRows<4>(i).transpose() * w;
}

SE3d SmoothTrajectory::Pose(const Eigen::Matrix<double, 6, 1>& c) const {
  const SO3d R = SO3d::Exp(Eigen::Vector3d(0.0, 0.0, c(5))) * SO3d::Exp(Eigen::Vector3d(0.0, c(4), 0.0)) *
                 SO3d::Exp(Eigen::Vector3d(c(3), 0.0, 0.0));
  return SE3d(R, c.head<3>());
}

SE3d SmoothTrajectory::operator()(double time) const {
  if (time >= start_ && time <= end_) return Pose(Channels(time));
  // Beyond an end: on at the end's velocity and rate (differences over 1 ms inside).
  constexpr double kStep = 1e-3;
  const bool before = time < start_;
  const double edge = before ? start_ : end_, inside = before ? start_ + kStep : end_ - kStep;
  const SE3d at = Pose(Channels(edge)), near = Pose(Channels(inside));
  const double span = (edge - inside);
  const Eigen::Vector3d velocity = (at.translation() - near.translation()) / span;
  const Eigen::Vector3d rate = (near.rotation().Inverse() * at.rotation()).Log() / span;
  const double beyond = time - edge;
  return SE3d(at.rotation() * SO3d::Exp(rate * beyond), at.translation() + velocity * beyond);
}

}  // namespace radargauss
