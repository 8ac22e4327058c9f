// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/imu_health.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace radargauss {

namespace {

constexpr double kDeg = 180.0 / M_PI;

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

std::string Format(const char* format, double a, double b = 0.0) {
  char line[256];
  std::snprintf(line, sizeof line, format, a, b);
  return line;
}

}  // namespace

ImuHealth::ImuHealth(const std::vector<ImuSample>& imu, const SO3d& radar_from_imu, double clock_offset)
    : clock_offset_(clock_offset) {
  if (imu.empty()) return;
  double integral = 0.0;
  std::vector<GyroSample> rates;
  for (std::size_t k = 0; k < imu.size(); ++k) {
    rates.push_back({imu[k].stamp - clock_offset, radar_from_imu * imu[k].angular_velocity});
    if (k > 0) integral += imu[k - 1].angular_velocity.norm() * (imu[k].stamp - imu[k - 1].stamp);
    stamps_.push_back(imu[k].stamp);
    rate_integral_.push_back(integral);
  }
  rates_.Add(rates);
  // Over the first second the mean specific force is gravity's reaction
  // (a car's acceleration tilts it a few degrees at most).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int n = 0;
  for (const ImuSample& sample : imu) {
    if (sample.stamp > imu.front().stamp + 1.0) break;
    mean += sample.specific_force;
    ++n;
  }
  mean /= n;
  const double magnitude = mean.norm();
  if (magnitude > 0.5 && magnitude < 1.5) {
    fault_ =
        ImuFault{imu.front().stamp - clock_offset,
                 Format("the accelerometer reads %.2f against gravity's 9.81: it reads in g, not m/s^2", magnitude)};
  } else if (std::abs(magnitude - kGravity) > kGravityTolerance) {
    fault_ = ImuFault{imu.front().stamp - clock_offset,
                      Format("the accelerometer reads %.2f m/s^2 at rest against gravity's 9.81", magnitude)};
  } else {
    const double up = std::acos(std::clamp((radar_from_imu * mean).normalized().z(), -1.0, 1.0)) * kDeg;
    if (up > kMaxUpAngleDeg) {
      fault_ = ImuFault{imu.front().stamp - clock_offset,
                        Format("gravity's reaction points %.0f deg from the radar's up: the accelerometer's sign or "
                               "axes, or the extrinsic rotation, are wrong",
                               up)};
    }
  }
}

void ImuHealth::AddScan(double stamp, const SE3d& matched) {
  if (fault_ || confirmed_at_) return;
  if (!first_scan_) first_scan_ = stamp;
  CheckRotations(stamp, matched);
  if (!fault_ && !clock_checked_) {
    history_.push_back({stamp, matched.rotation()});
    CheckClock(stamp);
  }
  if (fault_) return;
  verified_ = clock_checked_ && int(axis_angles_.size()) >= kMinTurns;
  if (verified_ || stamp - *first_scan_ > kMaxProbation) confirmed_at_ = stamp;
}

// The radar's rotation over the last span against the gyro's, on spans that
// turn (a straight drive shows neither the axes nor the scale). The gyro's
// raw rates: a bias the window estimated could hide a wrong axis.
void ImuHealth::CheckRotations(double stamp, const SE3d& matched) {
  recent_.push_back({stamp, matched.rotation()});
  while (recent_.size() > 2 && recent_[1].stamp <= stamp - kSpan) recent_.pop_front();
  const Scan& old = recent_.front();
  if (stamp - old.stamp < kSpan || old.stamp < last_compared_) return;
  const Eigen::Vector3d radar = (old.rotation.Inverse() * matched.rotation()).Log();
  if (radar.norm() * kDeg < kMinTurnDeg) return;
  const std::optional<SO3d> gyro_rotation = rates_.Rotation(old.stamp, stamp);
  if (!gyro_rotation) return;
  const Eigen::Vector3d gyro = gyro_rotation->Log();
  last_compared_ = stamp;
  const double cosine = gyro.norm() > 0.0 ? radar.dot(gyro) / (radar.norm() * gyro.norm()) : -1.0;
  axis_angles_.push_back(std::acos(std::clamp(cosine, -1.0, 1.0)) * kDeg);
  rate_ratios_.push_back(gyro.norm() / radar.norm());
  if (int(axis_angles_.size()) < kMinTurns) return;
  const double axis = Median(axis_angles_), ratio = Median(rate_ratios_);
  if (axis > kMaxAxisAngleDeg) {
    fault_ = ImuFault{stamp, Format("the gyro turns about an axis %.0f deg from the radar's: its axes are swapped "
                                    "or the extrinsic rotation is wrong",
                                    axis)};
  } else if (ratio > kMaxRateRatio || ratio < 1.0 / kMaxRateRatio) {
    fault_ = ImuFault{stamp, Format("the gyro turns %.2f times as far as the radar: its unit (rad/s) is wrong", ratio)};
  }
}

// The turn rates' magnitudes (blind to the axes and the extrinsic) cross-
// correlated over lags: the best lag is the IMU's clock offset as the data
// show it.
void ImuHealth::CheckClock(double stamp) {
  if (history_.size() < 3 || stamp - history_.front().stamp < kMinHistory) return;
  std::vector<double> radar;
  for (std::size_t k = 1; k < history_.size(); ++k) {
    radar.push_back((history_[k - 1].rotation.Inverse() * history_[k].rotation).Log().norm() /
                    (history_[k].stamp - history_[k - 1].stamp));
  }
  const auto mean_of = [](const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return sum / double(v.size());
  };
  const double radar_mean = mean_of(radar);
  double radar_var = 0.0;
  for (double x : radar) radar_var += (x - radar_mean) * (x - radar_mean);
  if (radar_var / double(radar.size()) < 0.02 * 0.02) return;  // an even drive shows no lag
  clock_checked_ = true;
  // The gyro's mean |w| over [a, b] on its own clock, from the integral; none outside its samples.
  const auto gyro_rate = [&](double a, double b) -> std::optional<double> {
    if (a < stamps_.front() || b > stamps_.back()) return std::nullopt;
    const auto at = [&](double t) {
      const std::size_t k = std::upper_bound(stamps_.begin(), stamps_.end(), t) - stamps_.begin() - 1;
      const double next = k + 1 < stamps_.size() ? rate_integral_[k + 1] : rate_integral_[k];
      const double span = k + 1 < stamps_.size() ? stamps_[k + 1] - stamps_[k] : 1.0;
      return rate_integral_[k] + (next - rate_integral_[k]) * (t - stamps_[k]) / span;
    };
    return (at(b) - at(a)) / (b - a);
  };
  double best_lag = 0.0, best = -2.0, at_given = -2.0;
  for (double lag = -kLagSearch; lag <= kLagSearch + 1e-9; lag += 0.005) {
    std::vector<double> r, g;
    for (std::size_t k = 1; k < history_.size(); ++k) {
      const std::optional<double> rate = gyro_rate(history_[k - 1].stamp + lag, history_[k].stamp + lag);
      if (!rate) continue;
      r.push_back(radar[k - 1]);
      g.push_back(*rate);
    }
    if (r.size() < radar.size() / 2) continue;
    const double rm = mean_of(r), gm = mean_of(g);
    double rg = 0.0, rr = 0.0, gg = 0.0;
    for (std::size_t k = 0; k < r.size(); ++k) {
      rg += (r[k] - rm) * (g[k] - gm);
      rr += (r[k] - rm) * (r[k] - rm);
      gg += (g[k] - gm) * (g[k] - gm);
    }
    const double correlation = rr > 0.0 && gg > 0.0 ? rg / std::sqrt(rr * gg) : -1.0;
    if (std::abs(lag - clock_offset_) < 0.0025) at_given = correlation;
    if (correlation > best) {
      best = correlation;
      best_lag = lag;
    }
  }
  history_.clear();
  // A clear peak elsewhere: a noisy drive's correlation is flat, and no proof.
  if (best > 0.7 && best - at_given > 0.25 && std::abs(best_lag - clock_offset_) > kClockTolerance) {
    fault_ = ImuFault{stamp, Format("the IMU's clock is %.2f s off the radar's (given %.3f s): more than the window "
                                    "estimates",
                                    best_lag, clock_offset_)};
  }
}

}  // namespace radargauss
