// SPDX-License-Identifier: BSD-3-Clause
// Joint refinement (docs/design/solvers.md, "Joint refinement"): the poses of many scans and every
// Gaussian's SH coefficients in one sparse Ceres problem. Geometric residuals
// tie a pose to the map; RCS residuals tie a rotation block (and, with kFull,
// a translation block) to the SH block of their Gaussian. Each scan's terms
// carry eq. 2's weights. The first pose is fixed; optional priors hold
// consecutive relative poses and the coefficients near their initial values.
// Solved with SPARSE_SCHUR (SH blocks eliminated first) or
// SPARSE_NORMAL_CHOLESKY (SuiteSparse); associations are redone between rounds.
// The RCS blocks are RcsCoefficientCostFunction (analytic) or
// RcsCoefficientResidual's Jets, as matching.jacobians says.
#pragma once

#include <string>
#include <vector>

#include "radargauss/core/options.hpp"
#include "radargauss/solvers/scan_matcher.hpp"

namespace radargauss {

struct JointRefinementOptions {
  ScanMatchingOptions matching;       // w_rcs, losses, gate, RCS translation mode, Jacobians
  int rounds = 3;                     // association rounds
  int max_iterations_per_round = 20;  // Ceres iterations per round
  double relative_pose_prior = 0.0;   // weight of Log(dT0^-1 dT) between consecutive scans; 0: off
  double coefficient_prior = 0.0;     // weight of (c - c0); 0: off
  bool schur = true;                  // SPARSE_SCHUR, else SPARSE_NORMAL_CHOLESKY
  int threads = 1;
  // Fewer of the scans' points within the gate of a Gaussian at the initial
  // poses than this share is a map of another place (or poses in another
  // frame): refused before any work (0: never).
  double min_associated_share = 0.1;
};

// Its options (options.hpp): its own, then the rows of ScanMatchingOptions
// the joint problem reads (the weight, the losses, the RCS terms, the gate).
const OptionTable<JointRefinementOptions>& JointRefinementOptionTable();

struct JointRefinementResult {
  std::vector<SE3d> poses;
  GaussianMap map;            // with the refined SH coefficients
  double initial_cost = 0.0;  // Ceres cost before / after
  double final_cost = 0.0;
  int iterations = 0;
  bool converged = false;
  std::string reason;
  double time_ms = 0.0;
};

// Throws std::invalid_argument for mismatched sizes or bad options, and
// DataError when the map does not cover the scans (min_associated_share).
JointRefinementResult RefineJointly(const std::vector<RadarScan>& scans, const std::vector<SE3d>& initial_poses,
                                    const GaussianMap& map, const JointRefinementOptions& options);

// RMS of the RCS residuals (normalised units) of the scans at `poses` against
// `map`: the quality measure the refinement should lower.
double RcsResidualRms(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses, const GaussianMap& map,
                      double gate);

}  // namespace radargauss
