// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/radargauss.hpp"

#include <utility>

#include "radargauss/core/error.hpp"

namespace radargauss {

GaussianMap BuildMap(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses, const MapOptions& options) {
  MapGeometry geometry = BuildMapGeometry(scans, poses, options);
  FitRcsModels(geometry.map, geometry.cloud, geometry.association, options.rcs);
  return std::move(geometry.map);
}

GaussianMap BuildMap(const Sequence& sequence, const MapOptions& options) {
  return BuildMap(sequence.scans, sequence.poses, options);
}

ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                         const MatchOptions& options) {
  return MakeScanMatcher(options)->Match(scan, map, initial);
}

RadarOdometry Odometry(const Sequence& sequence, const OdometryOptions& options) {
  RadarOdometry odometry(options);
  for (const RadarScan& scan : sequence.scans) odometry.Register(scan);
  return odometry;
}

RadarOdometry InertialOdometry(const Sequence& sequence, std::vector<ImuSample> imu, const SE3d& radar_from_imu,
                               const OdometryOptions& odometry, const RadarInertialOptions& options) {
  if (imu.empty()) throw DataError("the IMU has no sample");
  RadarOdometry run(odometry, MakeMotionModel(options, radar_from_imu, std::move(imu)));
  for (const RadarScan& scan : sequence.scans) run.Register(scan);
  return run;
}

std::unique_ptr<RadarSlam> Slam(const Sequence& sequence, const SlamOptions& options) {
  auto slam = std::make_unique<RadarSlam>(options);
  for (const RadarScan& scan : sequence.scans) slam->Register(scan);
  slam->Finish();
  return slam;
}

}  // namespace radargauss
