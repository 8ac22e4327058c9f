// SPDX-License-Identifier: BSD-3-Clause
// The rig's twist from its radars' Doppler against planted twists: the
// model's row against central differences and a case by hand, exact data
// to 1e-9, the covariance against the spread over noise draws, and what
// one radar and two radars on the vehicle's axis observe.
#include "radargauss/core/rig_twist.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Cholesky>

#include "support/test_util.hpp"

namespace radargauss {
namespace {

SE3d Mounted(double x, double y, double z, double yaw_deg, double pitch_deg = 0.0) {
  const double yaw = yaw_deg * M_PI / 180.0, pitch = pitch_deg * M_PI / 180.0;
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  return SE3d(SO3d::FromMatrix(R), Eigen::Vector3d(x, y, z));
}

// A front long-range radar and four corner radars looking out at 45 deg.
std::vector<SE3d> FiveRadarRig() {
  return {Mounted(3.7, 0.0, 0.5, 0.0), Mounted(3.4, 0.9, 0.5, 45.0), Mounted(3.4, -0.9, 0.5, -45.0),
          Mounted(-0.9, 0.9, 0.6, 135.0), Mounted(-0.9, -0.9, 0.6, -135.0, 3.0)};
}

// Static points in the radar's field of view (+/-60 deg azimuth, +/-15
// elevation) whose Doppler follows the body's twist, with noise; then
// `outliers` points 1 to 10 m/s off it.
RadarScan PlantedRigScan(const SE3d& body_from_radar, const Eigen::Vector3d& v, const Eigen::Vector3d& w, int inliers,
                         int outliers, double noise, std::mt19937& rng) {
  std::uniform_real_distribution<double> azimuth(-1.05, 1.05), elevation(-0.26, 0.26), range(2.0, 80.0);
  std::uniform_real_distribution<double> off(1.0, 10.0), sign(-1.0, 1.0);
  std::normal_distribution<double> normal(0.0, noise);
  RadarScan scan;
  scan.has_doppler = true;
  for (int i = 0; i < inliers + outliers; ++i) {
    const double az = azimuth(rng), el = elevation(rng);
    RadarPoint p;
    p.position = range(rng) * Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    p.doppler = RigDoppler(p.position, body_from_radar, v, w);
    p.doppler += i < inliers ? (noise > 0.0 ? normal(rng) : 0.0) : (sign(rng) > 0.0 ? 1.0 : -1.0) * off(rng);
    scan.points.push_back(p);
  }
  return scan;
}

struct PlantedRig {
  std::vector<RadarScan> scans;
  std::vector<RigScan> rig;
};

PlantedRig Plant(const std::vector<SE3d>& mountings, const Eigen::Vector3d& v, const Eigen::Vector3d& w, int inliers,
                 int outliers, double noise, std::mt19937& rng) {
  PlantedRig planted;
  for (const SE3d& mounting : mountings) {
    planted.scans.push_back(PlantedRigScan(mounting, v, w, inliers, outliers, noise, rng));
  }
  for (std::size_t r = 0; r < mountings.size(); ++r) planted.rig.push_back({&planted.scans[r], mountings[r]});
  return planted;
}

const Eigen::Vector3d kVelocity(12.0, 0.4, -0.1);
const Eigen::Vector3d kAngularVelocity(0.02, -0.03, 0.35);

TEST(RigTwist, TheDopplerRowIsItsDerivativeAndACaseByHand) {
  // By hand: a radar 1 m to the left turning at 1 rad/s about z moves
  // backwards at 1 m/s, so a point straight ahead recedes at 1 m/s.
  const SE3d left(SO3d(), Eigen::Vector3d(0.0, 1.0, 0.0));
  EXPECT_NEAR(RigDoppler(Eigen::Vector3d(10.0, 0.0, 0.0), left, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()), 1.0,
              1e-15);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    const SE3d mounting(SO3d::Exp(uniform(rng) * testing::RandomUnitVector(rng)),
                        Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)));
    const Eigen::Vector3d position = 20.0 * testing::RandomUnitVector(rng);
    Vector6d twist;
    for (int k = 0; k < 6; ++k) twist(k) = uniform(rng);
    const auto doppler = [&](const Vector6d& x) { return RigDoppler(position, mounting, x.head<3>(), x.tail<3>()); };
    const Eigen::Matrix<double, 1, 6> row = RigDopplerJacobian(position, mounting);
    for (int k = 0; k < 6; ++k) {
      const double h = 1e-6;
      Vector6d plus = twist, minus = twist;
      plus(k) += h;
      minus(k) -= h;
      EXPECT_NEAR(row(k), (doppler(plus) - doppler(minus)) / (2.0 * h), 1e-8) << trial << " " << k;
    }
    EXPECT_NEAR(row.dot(twist), doppler(twist), 1e-12);  // linear in the twist
  }
}

TEST(RigTwist, ExactDopplerGivesThePlantedTwistAmongOutliers) {
  std::mt19937 rng(11);
  for (const int outliers : {0, 25}) {
    const PlantedRig planted = Plant(FiveRadarRig(), kVelocity, kAngularVelocity, 60, outliers, 0.0, rng);
    const RigTwist twist = EstimateRigTwist(planted.rig);
    ASSERT_TRUE(twist.success) << twist.reason;
    EXPECT_EQ(twist.rank, 6);
    EXPECT_LT((twist.velocity - kVelocity).norm(), 1e-9) << outliers;
    EXPECT_LT((twist.angular_velocity - kAngularVelocity).norm(), 1e-9) << outliers;
    EXPECT_LT((twist.observed - Matrix6d::Identity()).norm(), 1e-9);
    for (std::size_t r = 0; r < planted.scans.size(); ++r) {
      for (std::size_t i = 0; i < planted.scans[r].points.size(); ++i) {
        EXPECT_EQ(twist.inlier[r][i], i < 60u) << r << " " << i;
      }
    }
  }
}

// A close car fills the rear-left radar's view (300 returns moving with it,
// 30 static): each radar votes with the share of its points a twist
// explains, so the car cannot outvote the four radars that see the world
// (by points it would: 300 against 190).
TEST(RigTwist, ACarFillingOneRadarsViewDoesNotOutvoteTheRig) {
  std::mt19937 rng(29);
  PlantedRig planted = Plant(FiveRadarRig(), kVelocity, kAngularVelocity, 40, 0, 0.0, rng);
  const Eigen::Vector3d car_velocity(-8.0, 1.5, 0.0);  // the rig's twist as the car's returns show it
  RadarScan& filled = planted.scans[3];
  filled = PlantedRigScan(FiveRadarRig()[3], kVelocity, kAngularVelocity, 30, 0, 0.0, rng);
  const RadarScan car = PlantedRigScan(FiveRadarRig()[3], car_velocity, Eigen::Vector3d::Zero(), 300, 0, 0.0, rng);
  filled.points.insert(filled.points.end(), car.points.begin(), car.points.end());
  const RigTwist twist = EstimateRigTwist(planted.rig);
  ASSERT_TRUE(twist.success) << twist.reason;
  // The world's twist, up to the few car returns whose Doppler happens to
  // fall within the threshold of it (directions across the two motions).
  EXPECT_LT((twist.velocity - kVelocity).norm(), 0.02);
  EXPECT_LT((twist.angular_velocity - kAngularVelocity).norm(), 0.01);
  const auto kept = std::count(twist.inlier[3].begin(), twist.inlier[3].end(), true);
  EXPECT_GE(kept, 30);
  EXPECT_LT(kept, 60);
}

// Two radars whose views a car's returns fill (the car's returns follow a
// twist of their own) give the car's twist without a gate. The odometry's
// gates bring back the world's: around the predicted velocity when the car's
// velocity is off it, around the last rotation rate when only the rate is.
TEST(RigTwist, TheGatesKeepACarThatFillsTheViewsOut) {
  // The body's origin at the front radar, as the rig's odometry puts it: the
  // velocity there is observed though the rotation about the radars' line is not.
  const SE3d origin = FiveRadarRig()[0];
  const std::vector<SE3d> mountings = {SE3d(), origin.Inverse() * FiveRadarRig()[1]};
  const auto plant = [&](const Eigen::Vector3d& car_v, const Eigen::Vector3d& car_w, std::mt19937& rng) {
    PlantedRig planted;
    for (std::size_t r = 0; r < 2; ++r) {
      RadarScan scan = PlantedRigScan(mountings[r], kVelocity, kAngularVelocity, r == 0 ? 60 : 15, 0, 0.0, rng);
      const RadarScan car = PlantedRigScan(mountings[r], car_v, car_w, r == 0 ? 30 : 50, 0, 0.0, rng);
      scan.points.insert(scan.points.end(), car.points.begin(), car.points.end());
      planted.scans.push_back(scan);
    }
    for (std::size_t r = 0; r < 2; ++r) planted.rig.push_back({&planted.scans[r], mountings[r]});
    return planted;
  };
  std::mt19937 rng(41);
  const PlantedRig faster = plant(Eigen::Vector3d(20.0, -1.0, 0.0), kAngularVelocity, rng);
  const PlantedRig turning = plant(kVelocity, Eigen::Vector3d(0.0, 0.0, 2.5), rng);
  RigTwistOptions options;
  options.doppler.outlier_probability = 0.7;  // draws enough to find the world among the car's returns
  for (const PlantedRig* planted : {&faster, &turning}) {
    const RigTwist ungated = EstimateRigTwist(planted->rig, options);
    ASSERT_TRUE(ungated.success) << ungated.reason;
    EXPECT_GT((ungated.velocity - kVelocity).norm() + (ungated.angular_velocity - kAngularVelocity).norm(), 1.0);
  }
  options.gate = VelocityGate{kVelocity + Eigen::Vector3d(0.3, -0.2, 0.0), 1.0};
  options.angular_gate = VelocityGate{Eigen::Vector3d(0.0, 0.0, 0.3), 0.5};
  for (const PlantedRig* planted : {&faster, &turning}) {
    SCOPED_TRACE(planted == &faster ? "the faster car" : "the turning car");
    const RigTwist gated = EstimateRigTwist(planted->rig, options);
    ASSERT_TRUE(gated.success) << gated.reason;
    // The world's twist, up to the few car returns whose Doppler falls within
    // the threshold of it; rank 5: the rotation about the radars' line is unobserved.
    EXPECT_LT((gated.velocity - kVelocity).norm(), 0.02);
    EXPECT_LT((gated.observed *
               (Vector6d() << gated.velocity - kVelocity, gated.angular_velocity - kAngularVelocity).finished())
                  .norm(),
              0.03);
  }
  // A gate that holds no twist the points agree on fails, saying so.
  options.gate = VelocityGate{Eigen::Vector3d(-30.0, 0.0, 0.0), 0.5};
  const RigTwist none = EstimateRigTwist(faster.rig, options);
  EXPECT_FALSE(none.success);
  EXPECT_FALSE(none.reason.empty());
}

// Over 200 draws of noise (0.05 m/s) with a fifth of the points moving,
// the error's Mahalanobis distance under the stated covariance is
// chi-square with 6 degrees of freedom: its mean near 6, 97 % or more
// within the 99.7 % bound, and each component within 3 sigma as often.
TEST(RigTwist, TheCovarianceHoldsTheSpreadOverNoiseDraws) {
  std::mt19937 rng(5);
  const int draws = 200;
  double nees_sum = 0.0;
  int within_bound = 0;
  std::vector<int> within_3_sigma(6, 0);
  for (int d = 0; d < draws; ++d) {
    const PlantedRig planted = Plant(FiveRadarRig(), kVelocity, kAngularVelocity, 40, 10, 0.05, rng);
    RigTwistOptions options;
    options.doppler.seed = std::uint32_t(d + 1);
    const RigTwist twist = EstimateRigTwist(planted.rig, options);
    ASSERT_TRUE(twist.success) << twist.reason;
    ASSERT_EQ(twist.rank, 6);
    Vector6d error;
    error << twist.velocity - kVelocity, twist.angular_velocity - kAngularVelocity;
    const double nees = error.dot(twist.covariance.ldlt().solve(error));
    nees_sum += nees;
    within_bound += nees < 20.06;  // chi-square, 6 dof, 99.73 %
    for (int k = 0; k < 6; ++k) within_3_sigma[k] += std::abs(error(k)) < 3.0 * std::sqrt(twist.covariance(k, k));
  }
  EXPECT_NEAR(nees_sum / draws, 6.0, 1.0);
  EXPECT_GE(within_bound, int(0.97 * draws));
  for (int k = 0; k < 6; ++k) EXPECT_GE(within_3_sigma[k], int(0.97 * draws)) << k;
}

// Two radars on the vehicle's axis (front and rear, both at y = 0, z = 0.5):
// a roll rate moves both sideways alike, so it cannot be told from a
// lateral velocity; the yaw rate and the forward velocity are observed
// exactly, the rest is the planted twist without its unobserved direction.
TEST(RigTwist, TwoRadarsOnTheAxisGiveTheYawRateButNotTheRoll) {
  const std::vector<SE3d> pair = {Mounted(3.7, 0.0, 0.5, 0.0), Mounted(-1.0, 0.0, 0.5, 180.0)};
  std::mt19937 rng(17);
  const PlantedRig planted = Plant(pair, kVelocity, kAngularVelocity, 80, 20, 0.0, rng);
  const RigTwist twist = EstimateRigTwist(planted.rig);
  ASSERT_TRUE(twist.success) << twist.reason;
  EXPECT_EQ(twist.rank, 5);
  EXPECT_NEAR(twist.angular_velocity.z(), kAngularVelocity.z(), 1e-9);
  EXPECT_NEAR(twist.velocity.x(), kVelocity.x(), 1e-9);
  Vector6d unobserved;  // a roll rate and the lateral velocity that cancels it at both radars
  unobserved << 0.0, 0.5, 0.0, 1.0, 0.0, 0.0;
  unobserved.normalize();
  EXPECT_LT((twist.observed * unobserved).norm(), 1e-9);
  EXPECT_LT((twist.covariance * unobserved).norm(), 1e-12);
  Vector6d planted_twist, estimated;
  planted_twist << kVelocity, kAngularVelocity;
  estimated << twist.velocity, twist.angular_velocity;
  EXPECT_LT((estimated - (planted_twist - unobserved * unobserved.dot(planted_twist))).norm(), 1e-9);
  // With noise the yaw rate stays within 3 sigma of its stated std.
  int within = 0;
  for (int d = 0; d < 200; ++d) {
    const PlantedRig noisy = Plant(pair, kVelocity, kAngularVelocity, 80, 20, 0.05, rng);
    const RigTwist t = EstimateRigTwist(noisy.rig);
    ASSERT_TRUE(t.success);
    within += std::abs(t.angular_velocity.z() - kAngularVelocity.z()) < 3.0 * std::sqrt(t.covariance(5, 5));
  }
  EXPECT_GE(within, 194);
}

// One radar observes its own velocity alone: the rank is 3, and that
// velocity is the single-radar estimate's.
TEST(RigTwist, OneRadarObservesItsOwnVelocityAsTheSingleRadarEstimate) {
  const SE3d corner = Mounted(3.4, 0.9, 0.5, 45.0);
  std::mt19937 rng(23);
  const PlantedRig planted = Plant({corner}, kVelocity, kAngularVelocity, 80, 0, 0.0, rng);
  const RigTwist twist = EstimateRigTwist(planted.rig);
  ASSERT_TRUE(twist.success) << twist.reason;
  EXPECT_EQ(twist.rank, 3);
  const Eigen::Vector3d radar_velocity =
      corner.rotation().Inverse() * (twist.velocity + twist.angular_velocity.cross(corner.translation()));
  const EgoVelocityResult single = EstimateEgoVelocity(planted.scans[0]);
  ASSERT_TRUE(single.success);
  EXPECT_LT((radar_velocity - single.velocity).norm(), 1e-9);
  EXPECT_LT((radar_velocity - corner.rotation().Inverse() * (kVelocity + kAngularVelocity.cross(corner.translation())))
                .norm(),
            1e-9);
}

TEST(RigTwist, TheLeverArmsTellWhichRotationsNoDopplerObserves) {
  EXPECT_EQ(UnobservedRotations({Mounted(1.0, 2.0, 0.5, 30.0)}).cols(), 3);
  EXPECT_EQ(UnobservedRotations({Mounted(1.0, 2.0, 0.5, 30.0), Mounted(1.0, 2.0, 0.5, -30.0)}).cols(), 3);
  const Eigen::Matrix3Xd axis = UnobservedRotations({Mounted(3.7, 0.0, 0.5, 0.0), Mounted(-1.0, 0.0, 0.5, 180.0)});
  ASSERT_EQ(axis.cols(), 1);
  EXPECT_NEAR(std::abs(axis.col(0).x()), 1.0, 1e-12);
  const Eigen::Matrix3Xd diagonal =
      UnobservedRotations({Mounted(0, 0, 0, 0), Mounted(1, 1, 1, 90), Mounted(2, 2, 2, 180)});
  ASSERT_EQ(diagonal.cols(), 1);
  EXPECT_NEAR(std::abs(diagonal.col(0).dot(Eigen::Vector3d(1, 1, 1).normalized())), 1.0, 1e-12);
  EXPECT_EQ(UnobservedRotations(FiveRadarRig()).cols(), 0);
}

TEST(RigTwist, SaysWhyItFails) {
  EXPECT_THROW(EstimateRigTwist({{nullptr, SE3d()}}), std::invalid_argument);
  RadarScan silent;
  silent.points.resize(10);
  for (RadarPoint& p : silent.points) p.position = Eigen::Vector3d(10.0, 1.0, 0.0);
  const RigTwist no_doppler = EstimateRigTwist({{&silent, SE3d()}});
  EXPECT_FALSE(no_doppler.success);
  EXPECT_NE(no_doppler.reason.find("no radar point with Doppler"), std::string::npos) << no_doppler.reason;
  std::mt19937 rng(2);
  const PlantedRig few = Plant(FiveRadarRig(), kVelocity, kAngularVelocity, 1, 0, 0.0, rng);
  const RigTwist too_few = EstimateRigTwist(few.rig);
  EXPECT_FALSE(too_few.success);
  EXPECT_NE(too_few.reason.find("fewer Doppler points"), std::string::npos) << too_few.reason;
}

}  // namespace
}  // namespace radargauss
