// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/scan_matcher.hpp"

#include <cmath>
#include <stdexcept>

#include "radargauss/core/names.hpp"

namespace radargauss {

namespace {

const NamedValue<RcsTranslation> kRcsTranslationNames[] = {{RcsTranslation::kRotationOnly, "rotation-only"},
                                                           {RcsTranslation::kFull, "full"}};
const NamedValue<JacobianMode> kJacobianNames[] = {{JacobianMode::kAnalytic, "analytic"},
                                                   {JacobianMode::kAutoDiff, "autodiff"}};

}  // namespace

std::string ToString(RcsTranslation mode) { return NameOf(kRcsTranslationNames, mode); }
RcsTranslation RcsTranslationFromString(const std::string& name) {
  return ValueNamed(kRcsTranslationNames, name, "RCS translation");
}
std::vector<std::string> RcsTranslationNames() { return NamesOf(kRcsTranslationNames); }

std::string ToString(JacobianMode mode) { return NameOf(kJacobianNames, mode); }
JacobianMode JacobianModeFromString(const std::string& name) { return ValueNamed(kJacobianNames, name, "Jacobians"); }
std::vector<std::string> JacobianModeNames() { return NamesOf(kJacobianNames); }

const OptionTable<ScanMatchingOptions>& ScanMatchingOptionTable() {
  using O = ScanMatchingOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "w_rcs", w_rcs).In(0.0, 1.0).Sensor().Help("eq. 2's RCS weight w"),
      RADARGAUSS_CHOICE(O, "loss", geometric_loss.type, LossNames(), LossTypeFromString)
          .Sensor()
          .Help("robust loss of the geometric term"),
      RADARGAUSS_OPTION(O, "loss_scale", geometric_loss.scale).Above(0.0).Help("its scale a"),
      RADARGAUSS_CHOICE(O, "rcs_loss", rcs_loss.type, LossNames(), LossTypeFromString)
          .Help("robust loss of the RCS term (the paper: cauchy)"),
      RADARGAUSS_OPTION(O, "rcs_loss_scale", rcs_loss.scale).Above(0.0).Help("its scale a"),
      RADARGAUSS_CHOICE(O, "rcs_likelihood", rcs_terms.likelihood, RcsLikelihoodNames(), RcsLikelihoodFromString)
          .Help("the RCS residual: decibel (the paper), swerling1 or swerling3 (fluctuating RCS)"),
      RADARGAUSS_OPTION(O, "rcs_confidence", rcs_terms.confidence)
          .Help("weigh each RCS term by its Gaussian's fit (spread and members)"),
      RADARGAUSS_OPTION(O, "rcs_expected_spread", rcs_terms.expected_spread_db)
          .AtLeast(0.0)
          .Unit("dB")
          .Help("the spread the confidence expects (0: the likelihood's own)"),
      RADARGAUSS_CHOICE(O, "rcs_translation", rcs_translation, RcsTranslationNames(), RcsTranslationFromString)
          .Help("the RCS term on the rotation alone (the paper) or on the full pose"),
      RADARGAUSS_CHOICE(O, "jacobians", jacobians, JacobianModeNames(), JacobianModeFromString)
          .Help("closed-form Jacobians or Jets through the Ceres functors"),
      RADARGAUSS_OPTION(O, "gate", gate).Above(0.0).Help("association gate tau (Mahalanobis distance)"),
      RADARGAUSS_OPTION(O, "max_iterations", max_iterations).In(1, 10000).Help("outer iterations on the exact map"),
      RADARGAUSS_OPTION(O, "coarse_iterations", coarse_iterations)
          .In(1, 10000)
          .Help("outer iterations per coarse level"),
      RADARGAUSS_OPTION(O, "coarse_voxel_per_sigma", coarse_voxel_per_sigma)
          .AtLeast(0.0)
          .Help("coarse levels match voxel centroids of this many sigma_k (0: the points)"),
      RADARGAUSS_OPTION(O, "coarse_points", coarse_points).Help("at most this many points per coarse level (0: all)"),
      RADARGAUSS_OPTION(O, "geometric_first", geometric_first)
          .Help("with 0 < w < 1, the geometric term alone first on the exact map"),
      RADARGAUSS_OPTION(O, "reassociate", reassociate).Help("false: associate once at the initial pose"),
      RADARGAUSS_OPTION(O, "reassociation_translation", reassociation_translation)
          .AtLeast(0.0)
          .Unit("m")
          .Help("re-associate on the exact map once the pose moved this far"),
      RADARGAUSS_OPTION(O, "reassociation_rotation", reassociation_rotation)
          .AtLeast(0.0)
          .Unit("rad")
          .Help("or turned this far"),
      RADARGAUSS_OPTION(O, "translation_tolerance", translation_tolerance)
          .Above(0.0)
          .Unit("m")
          .Help("converged when a step on the exact map is smaller"),
      RADARGAUSS_OPTION(O, "rotation_tolerance", rotation_tolerance)
          .Above(0.0)
          .Unit("rad")
          .Help("and its rotation smaller"),
      RADARGAUSS_OPTION(O, "coarse_translation_tolerance", coarse_translation_tolerance)
          .Above(0.0)
          .Unit("m")
          .Help("the same on coarse levels"),
      RADARGAUSS_OPTION(O, "coarse_rotation_tolerance", coarse_rotation_tolerance)
          .Above(0.0)
          .Unit("rad")
          .Help("the same on coarse levels"),
      RADARGAUSS_OPTION(O, "pose_covariance", pose_covariance)
          .Help("also state the pose's covariance from the residuals' own spread"),
  };
  return table;
}

void ValidateOptions(const ScanMatchingOptions& o) { CheckOptions(ScanMatchingOptionTable(), o); }

}  // namespace radargauss
