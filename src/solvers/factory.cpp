// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/factory.hpp"

#include <stdexcept>
#include <utility>

#include "radargauss/core/names.hpp"
#include "radargauss/solvers/ceres_solver.hpp"
#include "radargauss/solvers/gauss_newton.hpp"
#include "radargauss/solvers/multi_hypothesis.hpp"

namespace radargauss {

namespace {

const NamedValue<SolverKind> kSolverNames[] = {
    {SolverKind::kGaussNewton, "gn"},        {SolverKind::kGaussNewtonAutoDiff, "gn-autodiff"},
    {SolverKind::kCeres, "ceres"},           {SolverKind::kCeresDogleg, "ceres-dogleg"},
    {SolverKind::kMultiHypothesis, "mh-gn"},
};

const NamedValue<CeresBlocks> kBlocksNames[] = {
    {CeresBlocks::kPerTerm, "per-term"}, {CeresBlocks::kShared, "shared"}, {CeresBlocks::kSquareRoot, "square-root"}};

}  // namespace

std::string ToString(CeresBlocks blocks) { return NameOf(kBlocksNames, blocks); }
CeresBlocks CeresBlocksFromString(const std::string& name) { return ValueNamed(kBlocksNames, name, "Ceres blocks"); }
std::vector<std::string> CeresBlocksNames() { return NamesOf(kBlocksNames); }

std::string ToString(SolverKind kind) { return NameOf(kSolverNames, kind); }
SolverKind SolverKindFromString(const std::string& name) { return ValueNamed(kSolverNames, name, "solver"); }

const std::vector<std::string>& ScanMatcherNames() {
  static const std::vector<std::string> names = NamesOf(kSolverNames);
  return names;
}

const OptionTable<MatchOptions>& MatchOptionTable() {
  using O = MatchOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {RADARGAUSS_CHOICE(O, "solver", solver, ScanMatcherNames(), SolverKindFromString)
                            .Sensor()
                            .Help("the scan matcher: gn (own Gauss-Newton), gn-autodiff, ceres, ceres-dogleg, mh-gn")};
    AppendNested(
        t, ScanMatchingOptionTable(), +[](O & o) -> auto& { return o.matching; }, "matching");
    for (Option<O> option : OptionTable<O>{
             RADARGAUSS_OPTION(O, "gn_max_step_halvings", gauss_newton.max_step_halvings)
                 .In(0, 64)
                 .Help("Gauss-Newton: halvings of a step that raises eq. 2 (0: plain steps)"),
             RADARGAUSS_OPTION(O, "gn_loss_curvature", gauss_newton.loss_curvature)
                 .Help("Gauss-Newton: the losses' curvature in the Hessian (else IRLS)"),
             RADARGAUSS_OPTION(O, "ceres_dogleg", ceres.dogleg).Help("Ceres: dogleg instead of Levenberg-Marquardt"),
             RADARGAUSS_OPTION(O, "ceres_max_inner_iterations", ceres.max_inner_iterations)
                 .AtLeast(1)
                 .Help("Ceres: iterations per solve in the stages that steer"),
             RADARGAUSS_OPTION(O, "ceres_max_exact_inner_iterations", ceres.max_exact_inner_iterations)
                 .AtLeast(1)
                 .Help("Ceres: iterations per solve in the last stage"),
             RADARGAUSS_CHOICE(O, "ceres_blocks", ceres.blocks, CeresBlocksNames(), CeresBlocksFromString)
                 .Help("Ceres: how analytic terms enter the problem"),
             RADARGAUSS_OPTION(O, "ceres_threads", ceres.threads).In(1, 1024).Help("Ceres: threads"),
             RADARGAUSS_OPTION(O, "ceres_function_tolerance", ceres.function_tolerance)
                 .Above(0.0)
                 .Help("Ceres: per solve"),
             RADARGAUSS_OPTION(O, "ceres_gradient_tolerance", ceres.gradient_tolerance)
                 .Above(0.0)
                 .Help("Ceres: per solve"),
             RADARGAUSS_OPTION(O, "ceres_parameter_tolerance", ceres.parameter_tolerance)
                 .Above(0.0)
                 .Help("Ceres: per solve"),
             RADARGAUSS_OPTION(O, "mh_starts", hypotheses.starts).In(1, 13).Help("multi-hypothesis: starts"),
             RADARGAUSS_OPTION(O, "mh_xy_offset", hypotheses.xy_offset)
                 .AtLeast(0.0)
                 .Unit("m")
                 .Help("multi-hypothesis: x/y offset of the starts"),
             RADARGAUSS_OPTION(O, "mh_yaw_offset", hypotheses.yaw_offset)
                 .AtLeast(0.0)
                 .Unit("rad")
                 .Help("multi-hypothesis: yaw offset of the starts"),
         }) {
      t.push_back(std::move(option));
    }
    return t;
  }();
  return table;
}

std::unique_ptr<ScanMatcher> MakeScanMatcher(const MatchOptions& options) {
  CheckOptions(MatchOptionTable(), options);
  ScanMatchingOptions matching = options.matching;
  CeresSolverOptions ceres = options.ceres;
  switch (options.solver) {
    case SolverKind::kGaussNewton:
      return std::make_unique<GaussNewtonSolver>(matching, options.gauss_newton);
    case SolverKind::kGaussNewtonAutoDiff:
      matching.jacobians = JacobianMode::kAutoDiff;
      return std::make_unique<GaussNewtonSolver>(matching, options.gauss_newton);
    case SolverKind::kCeres:
      return std::make_unique<CeresSolver>(matching, ceres);
    case SolverKind::kCeresDogleg:
      ceres.dogleg = true;
      return std::make_unique<CeresSolver>(matching, ceres);
    case SolverKind::kMultiHypothesis:
      return std::make_unique<MultiHypothesisSolver>(
          std::make_shared<GaussNewtonSolver>(matching, options.gauss_newton), matching, options.hypotheses);
  }
  throw std::invalid_argument("unknown solver kind");
}

std::unique_ptr<ScanMatcher> MakeScanMatcher(const std::string& name, const ScanMatchingOptions& options) {
  MatchOptions match;
  match.solver = SolverKindFromString(name);
  match.matching = options;
  return MakeScanMatcher(match);
}

}  // namespace radargauss
