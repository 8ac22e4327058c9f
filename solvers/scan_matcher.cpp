// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/scan_matcher.hpp"

#include <cmath>
#include <stdexcept>

#include "radargauss/names.hpp"

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

void ValidateOptions(const ScanMatchingOptions& o) {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(what);
  };
  require(o.w_rcs >= 0.0 && o.w_rcs <= 1.0, "w_rcs must be in [0, 1]");
  require(o.geometric_loss.scale > 0.0 && o.rcs_loss.scale > 0.0, "loss scales must be > 0");
  require(o.gate > 0.0, "association gate must be > 0");
  require(o.max_iterations >= 1 && o.coarse_iterations >= 1, "iteration limits must be >= 1");
  require(o.coarse_voxel_per_sigma >= 0.0 && std::isfinite(o.coarse_voxel_per_sigma),
          "coarse voxel per sigma must be >= 0 and finite");
  require(o.translation_tolerance > 0.0 && o.rotation_tolerance > 0.0 && o.coarse_translation_tolerance > 0.0 &&
              o.coarse_rotation_tolerance > 0.0,
          "tolerances must be > 0");
  require(o.reassociation_translation >= 0.0 && o.reassociation_rotation >= 0.0,
          "re-association thresholds must be >= 0");
}

}  // namespace radargauss
