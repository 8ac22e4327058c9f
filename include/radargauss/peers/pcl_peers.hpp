// SPDX-License-Identifier: BSD-3-Clause
// PCL peers on the experiment's protocol (optional, RADARGAUSS_WITH_PCL):
// NDT and GICP match each scan against the merged map cloud (the static
// points the Gaussian map was built from), from the same initial poses, and
// report through the same ScanMatcher interface, so that they appear as rows
// of the same table. Match uses neither the MatchingMap nor the priors.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/solvers/scan_matcher.hpp"

namespace radargauss {

enum class PclMethod { kNdt, kGicp };

struct PclPeerOptions {
  double ndt_resolution = 1.0;           // m, NDT voxel
  double ndt_step_size = 0.1;            // m
  double gicp_max_correspondence = 2.5;  // m (covers the 2 m initial errors)
  // GICP's target per scan: the map cloud voxel-downsampled (as the Gaussian
  // builder's input), within gicp_crop_radius of the initial position, in a
  // frame whose origin is there: GICP turns about the target's origin, which
  // for a whole map is 50-220 m from the vehicle. false: the whole map in
  // the world frame.
  bool gicp_local_target = true;
  double gicp_crop_radius = 80.0;   // m
  double gicp_target_voxel = 0.25;  // m; 0: every point
  int max_iterations = 50;
  double transformation_epsilon = 1e-6;
};

class PclPeerMatcher final : public ScanMatcher {
 public:
  // The target is copied into PCL form once; each worker thread builds its
  // own registration object over it the first time it matches.
  PclPeerMatcher(PclMethod method, const std::vector<Eigen::Vector3d>& map_cloud, const PclPeerOptions& options = {});
  ~PclPeerMatcher() override;
  std::string Name() const override;
  using ScanMatcher::Match;
  ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                           const ScanPriors& priors) const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace radargauss
