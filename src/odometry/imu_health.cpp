// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/imu_health.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "radargauss/core/conventions.hpp"
#include "radargauss/core/stats.hpp"

namespace radargauss {

namespace {

std::string HealthCause(const char* format, double a, double b = 0.0) {
  char line[256];
  std::snprintf(line, sizeof line, format, a, b);
  return line;
}

}  // namespace

ImuHealth::ImuHealth(const std::vector<ImuSample>& imu, const SO3d& radar_from_imu, double clock_offset)
    : clock_offset_(clock_offset) {
  if (imu.empty()) return;
  double integral = 0.0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  std::vector<GyroSample> rates;
  for (std::size_t k = 0; k < imu.size(); ++k) {
    rates.push_back({imu[k].stamp - clock_offset, radar_from_imu * imu[k].angular_velocity});
    if (k > 0) integral += imu[k - 1].angular_velocity.norm() * (imu[k].stamp - imu[k - 1].stamp);
    if (k > 0) force += radar_from_imu * imu[k - 1].specific_force * (imu[k].stamp - imu[k - 1].stamp);
    stamps_.push_back(imu[k].stamp);
    rate_integral_.push_back(integral);
    force_integral_.push_back(force);
  }
  rates_.Add(rates);
  // Over the first second the mean specific force is gravity's reaction
  // (a car's acceleration tilts it a few degrees at most). Which way is up
  // the radar cannot say (it may hang upside down): the accelerometer's
  // sign and axes are checked in the turns.
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
    fault_ = ImuFault{
        imu.front().stamp - clock_offset,
        HealthCause("the accelerometer reads %.2f against gravity's 9.81: it reads in g, not m/s^2", magnitude)};
  } else if (std::abs(magnitude - kGravity) > kGravityTolerance) {
    fault_ = ImuFault{imu.front().stamp - clock_offset,
                      HealthCause("the accelerometer reads %.2f m/s^2 at rest against gravity's 9.81", magnitude)};
  }
}

void ImuHealth::AddScan(double stamp, const SE3d& pose, bool matched) {
  if (fault_ || confirmed_at_) return;
  if (!probation_start_) probation_start_ = stamp;
  if (!matched) {
    recent_.clear();  // a span must be matched throughout
  } else {
    CheckTurns(stamp, pose);
    if (!fault_) {
      history_.push_back({stamp, pose});  // kept for the turns' check to name a clock
      if (!clock_checked_) CheckClock(stamp);
    }
  }
  if (fault_) return;
  verified_ = clock_checked_ && turns_ >= kMinTurns && int(force_cosines_.size()) >= kMinTurns;
  if (verified_ || stamp - *probation_start_ > kMaxProbation) confirmed_at_ = stamp;
}

// The IMU's mean specific force over [a, b] on the radar's clock, in the radar's frame.
std::optional<Eigen::Vector3d> ImuHealth::MeanForce(double a, double b) const {
  a += clock_offset_;
  b += clock_offset_;
  if (stamps_.empty() || a < stamps_.front() || b > stamps_.back() || !(b > a)) return std::nullopt;
  const auto at = [&](double t) -> Eigen::Vector3d {
    const std::size_t k = std::upper_bound(stamps_.begin(), stamps_.end(), t) - stamps_.begin() - 1;
    if (k + 1 >= stamps_.size()) return force_integral_[k];
    const double share = (t - stamps_[k]) / (stamps_[k + 1] - stamps_[k]);
    return force_integral_[k] + share * (force_integral_[k + 1] - force_integral_[k]);
  };
  return Eigen::Vector3d((at(b) - at(a)) / (b - a));
}

// On spans that turn (a straight drive shows neither axes nor scale): the
// radar's rotation between its poses against the gyro's raw rates (a bias
// the window estimated could hide a wrong axis), and the radar's
// acceleration against what the specific force gained over its mean.
void ImuHealth::CheckTurns(double stamp, const SE3d& pose) {
  if (!first_matched_) first_matched_ = stamp;
  recent_.push_back({stamp, pose});
  while (recent_.size() > 2 && recent_[1].stamp <= stamp - kSpan) recent_.pop_front();
  const Scan& old = recent_.front();
  if (stamp - old.stamp < kSpan || old.stamp < last_compared_) return;
  const Eigen::Vector3d radar = (old.pose.rotation().Inverse() * pose.rotation()).Log();
  if (radar.norm() * kDegreesPerRadian < kMinTurnDeg) return;
  const std::optional<SO3d> gyro_rotation = rates_.Rotation(old.stamp, stamp);
  if (!gyro_rotation) return;
  last_compared_ = stamp;
  ++turns_;
  disagreement_ += (gyro_rotation->Log() - radar).norm();
  turned_ += radar.norm();
  // The turn's acceleration in the radar's frame (its velocity over each
  // half of the span) against the specific force's gain over its mean since
  // the first scan (gravity's reaction, near constant on a ground vehicle).
  const Scan& middle = *std::min_element(recent_.begin(), recent_.end(), [&](const Scan& a, const Scan& b) {
    return std::abs(a.stamp - 0.5 * (old.stamp + stamp)) < std::abs(b.stamp - 0.5 * (old.stamp + stamp));
  });
  const std::optional<Eigen::Vector3d> span_force = MeanForce(old.stamp, stamp);
  const std::optional<Eigen::Vector3d> all_force = MeanForce(*first_matched_, stamp);
  if (middle.stamp > old.stamp && middle.stamp < stamp && span_force && all_force) {
    const Eigen::Vector3d v1 = (middle.pose.translation() - old.pose.translation()) / (middle.stamp - old.stamp);
    const Eigen::Vector3d v2 = (pose.translation() - middle.pose.translation()) / (stamp - middle.stamp);
    const Eigen::Vector3d turn = middle.pose.rotation().Inverse() * ((v2 - v1) / (0.5 * (stamp - old.stamp)));
    const Eigen::Vector3d gained = *span_force - *all_force;
    if (turn.norm() > kMinTurnAcceleration && gained.norm() > 0.0) {
      force_cosines_.push_back(turn.dot(gained) / (turn.norm() * gained.norm()));
    }
  }
  if (turns_ < kMinTurns) return;
  const double disagreement = disagreement_ / turned_;
  if (disagreement > kMaxDisagreement) {
    // Turns that disagree may be a clock off. The rates' magnitudes are blind
    // to axes and extrinsic: when they agree best at another lag, the clock is named.
    const std::optional<ClockCorrelation> clock = CorrelateClocks();
    if (clock && clock->best > 0.5 && clock->best > clock->at_given + 0.05 &&
        std::abs(clock->lag - clock_offset_) > kClockTolerance) {
      fault_ = ImuFault{stamp, clock->Cause(clock_offset_)};
      return;
    }
    fault_ = ImuFault{stamp, HealthCause("the gyro's turns differ from the radar's by %.2f of their angle: its axes, "
                                         "its unit or the extrinsic rotation are wrong",
                                         disagreement)};
  } else if (int(force_cosines_.size()) >= kMinTurns && Median(force_cosines_) < 0.0) {
    fault_ =
        ImuFault{stamp, HealthCause("the accelerometer's sign or axes are wrong: in the turns it reads against the "
                                    "radar's acceleration (median cosine %.2f)",
                                    Median(force_cosines_))};
  }
}

// The turn rates' magnitudes (blind to the axes and the extrinsic) cross-
// correlated over lags: the best lag is the IMU's clock offset as the data
// show it.
void ImuHealth::CheckClock(double stamp) {
  if (history_.size() < 3 || stamp - history_.front().stamp < kMinHistory) return;
  const std::optional<ClockCorrelation> c = CorrelateClocks();
  if (!c) return;  // an even drive shows no lag
  clock_checked_ = true;
  if (c->Off(clock_offset_)) fault_ = ImuFault{stamp, c->Cause(clock_offset_)};
}

// A clear peak elsewhere: a noisy drive's correlation is flat, and no proof.
bool ImuHealth::ClockCorrelation::Off(double given) const {
  return best > 0.7 && best - at_given > 0.25 && std::abs(lag - given) > kClockTolerance;
}

std::string ImuHealth::ClockCorrelation::Cause(double given) const {
  return HealthCause("the IMU's clock is %.2f s off the radar's (given %.3f s): more than the window estimates", lag,
                     given);
}

std::optional<ImuHealth::ClockCorrelation> ImuHealth::CorrelateClocks() const {
  if (history_.size() < 3) return std::nullopt;
  std::vector<double> radar;
  for (std::size_t k = 1; k < history_.size(); ++k) {
    radar.push_back((history_[k - 1].pose.rotation().Inverse() * history_[k].pose.rotation()).Log().norm() /
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
  if (radar_var / double(radar.size()) < 0.02 * 0.02) return std::nullopt;
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
  ClockCorrelation result;
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
    if (std::abs(lag - clock_offset_) < 0.0025) result.at_given = correlation;
    if (correlation > result.best) {
      result.best = correlation;
      result.lag = lag;
    }
  }
  return result;
}

}  // namespace radargauss
