// SPDX-License-Identifier: BSD-3-Clause
// The ceres::Problem of a scan match (docs/design.md, "Ceres"): the pose
// blocks and the terms of the current association, with eq. 2's weights.
#pragma once

#include <ceres/problem.h>

#include <memory>

#include "radargauss/solvers/scan_matcher.hpp"

namespace radargauss {

// How analytic terms enter the ceres::Problem (CeresScanProblem); autodiff
// terms always take a residual block each.
enum class CeresBlocks {
  kPerTerm,     // a residual block per term under ScaledLoss(its loss): Ceres's own loss handling
  kShared,      // blocks of CeresScanProblem::kTermsPerBlock terms, each term's loss in its residual
  kSquareRoot,  // shared blocks, each handed to Ceres in its square-root form (default)
};

// The ceres::Problem of one match, kept across associations: the pose blocks
// (rotation with SO3Manifold, translation) and the terms of the current
// association, with eq. 2's weights as ScaledLoss.
//
// Shared blocks (analytic terms, CeresBlocks::kShared): kTermsPerBlock terms of a
// kind per residual block, so that Ceres's per-block work (evaluator loop,
// manifold product, loss correction, checks, preprocessing) is paid per
// block of terms. Ceres applies a block's loss to the block's squared norm,
// so each term's robust loss rho goes into its own residual instead:
// r -> sqrt(rho(s)/s) r with s = |r|^2, whose squared norm is rho(s), and that
// residual's exact Jacobian. Cost and gradient are eq. 2's, as with a block
// per term; the Gauss-Newton model is that of the rescaled residual, where
// Ceres's loss correction would take sqrt(rho') J (IRLS, for every loss here).
//
// Square-root blocks (the default for analytic terms): the terms of a kind
// share `threads` blocks (so that Ceres can evaluate them in parallel), and
// each block hands Ceres, instead of its rows r (loss applied as above) and
// their Jacobian J on the tangent space, the residuals [z; sqrt(|r|^2 -
// |z|^2)] with the Jacobian [R; 0], where R^T R = J^T J (Cholesky; on a
// rank-deficient block R = Lambda^1/2 V^T from J^T J's eigenvectors) and
// R^T z = J^T r. The cost |r|^2, the gradient J^T r and the Gauss-Newton
// matrix J^T J, all that Levenberg-Marquardt and dogleg use (step, jacobi
// scaling, model cost change, tolerances), are those of the shared rows, so
// Ceres takes the same steps; it handles 7 (geometric) or 4 (rotation-only
// RCS) rows per block instead of 3 per geometric and 1 per RCS term, which
// saves it its per-row work (Jacobian writing, manifold products, normal
// equations, scaling). A Jacobian from Problem::Evaluate is then R's, not
// the terms' (use kShared to read theirs). With residuals only (the cost of
// a candidate step) a block returns [|r|; 0].
//
// Otherwise (autodiff terms, or kPerTerm) a block per term under
// ScaledLoss(its loss); Update re-targets the blocks it keeps at the new
// terms and adds or removes blocks only for the change in count, so Ceres's
// per-block set-up is paid about once per match instead of once per
// association.
class CeresScanProblem {
 public:
  static constexpr std::size_t kTermsPerBlock = 64;  // kShared

  // `rotation` (quaternion x y z w) and `translation` are the parameter
  // blocks; they must outlive the problem. `threads`: square-root blocks
  // per kind of term.
  CeresScanProblem(const ScanMatchingOptions& options, double* rotation, double* translation,
                   CeresBlocks blocks = CeresBlocks::kSquareRoot, int threads = 1);
  ~CeresScanProblem();
  CeresScanProblem(const CeresScanProblem&) = delete;
  CeresScanProblem& operator=(const CeresScanProblem&) = delete;

  // Makes the problem hold exactly the terms of `correspondences` weighted
  // for `w_rcs` (the geometric terms when w_rcs < 1, the RCS terms when > 0).
  void Update(const Correspondences& correspondences, double w_rcs);
  ceres::Problem& problem();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace radargauss
