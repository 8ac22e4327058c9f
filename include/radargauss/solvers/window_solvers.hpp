// SPDX-License-Identifier: BSD-3-Clause
// The solvers of the sliding window's problem (docs/design/solvers.md, "The sliding
// window"), on the same terms: Ceres's Levenberg-Marquardt or dogleg, or the
// own Gauss-Newton on the tangent Jacobians Ceres evaluates. The problem
// holds the window's blocks and terms; `blocks` are the ones that move.
#pragma once

#include <vector>

#include <ceres/problem.h>

#include "radargauss/solvers/inertial_window.hpp"

namespace radargauss {

WindowSolveSummary SolveWithGaussNewton(ceres::Problem& problem, const std::vector<double*>& blocks,
                                        int max_iterations);
WindowSolveSummary SolveWithCeres(ceres::Problem& problem, const InertialWindowOptions& options);

}  // namespace radargauss
