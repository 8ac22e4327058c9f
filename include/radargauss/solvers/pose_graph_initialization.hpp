// SPDX-License-Identifier: BSD-3-Clause
// A pose graph's initial estimate from its edges alone (docs/design/solvers.md, "The
// pose graph"): rotations by the chordal relaxation, then translations by
// linear least squares given them (Carlone et al. 2015, "Initialization
// techniques for 3D SLAM"). From this start Levenberg-Marquardt needs a few
// iterations where a drifted odometry start needs tens.
#pragma once

#include <vector>

#include "radargauss/solvers/pose_graph.hpp"

namespace radargauss {

// Poses that satisfy the edges in the least-squares sense, keyframe `fixed`
// kept where it is. Each edge counts with the mean of its rotational
// (translational) information's diagonal. Keyframes that no chain of edges
// links to the fixed one keep their poses, as do all when a system is
// singular. Throws std::invalid_argument on an unknown keyframe.
std::vector<SE3d> ChordalInitialization(const std::vector<SE3d>& poses, const std::vector<PoseGraphEdge>& edges,
                                        int fixed = 0);

}  // namespace radargauss
