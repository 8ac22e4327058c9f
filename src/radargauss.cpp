// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/radargauss.hpp"

#include <utility>

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

}  // namespace radargauss
