// Scan matching against a Gaussian-RCS map (paper section III-B, DESIGN.md
// section 5): the options, the result and the interface every solver
// implements, and the pieces they share (association, the cost of eq. 2).
//
// The cost (eq. 2):
//   f = (1 - w)/N_geo * sum rho_geo(||r_geo||^2) + w/N_rcs * sum rho_rcs(r_rcs^2),
// N counting the residuals that contributed; RCS residuals only for points
// whose normalised RCS is in [-1, 1] and whose Gaussian has a model.
// Pose: rotation quaternion + translation; updates [dt (world); dphi (radar)].
#pragma once

#include <string>
#include <vector>

#include "radargauss/lie/se3.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/types.hpp"
#include "residuals/loss.hpp"
#include "residuals/rcs_residual.hpp"

namespace radargauss {

// How the RCS term treats translation: the paper's rotation-only, or full.
enum class RcsTranslation { kRotationOnly, kFull };
// Which Jacobians a solver uses: closed form, or Jets through the functors.
enum class JacobianMode { kAnalytic, kAutoDiff };

struct ScanMatchingOptions {
  double w_rcs = 0.0;  // eq. 2's w, in [0, 1]
  LossConfig geometric_loss{LossType::kTrivial, 1.0};
  LossConfig rcs_loss{LossType::kCauchy, 1.0};  // the paper: Cauchy
  RcsTranslation rcs_translation = RcsTranslation::kRotationOnly;
  JacobianMode jacobians = JacobianMode::kAnalytic;
  double gate = 3.0;          // tau: association gate (Mahalanobis distance)
  int max_iterations = 30;    // outer iterations (association + update)
  bool reassociate = true;    // false: associate once at the initial pose
  double translation_tolerance = 1e-4;  // m: stop when the update is smaller ...
  double rotation_tolerance = 1e-5;     // rad ... in both parts
};

// Throws std::invalid_argument naming the bad option.
void ValidateOptions(const ScanMatchingOptions& options);

struct ScanMatchingResult {
  SE3d pose;
  int iterations = 0;
  double final_cost = 0.0;  // f of eq. 2 at the final pose and association
  std::size_t n_geo = 0;
  std::size_t n_rcs = 0;
  bool converged = false;
  std::string reason;       // why it did not converge; empty when it did
  double time_ms = 0.0;
};

// The map as the solvers use it: the Gaussians and their spatial index.
class MatchingMap {
 public:
  explicit MatchingMap(const GaussianMap& map, double index_cell = 1.0)
      : map_(map), index_(map.gaussians, index_cell) {}
  const GaussianMap& map() const { return map_; }
  const GaussianIndex& index() const { return index_; }

 private:
  const GaussianMap& map_;
  GaussianIndex index_;
};

struct GeometricTerm {
  Eigen::Vector3d point_radar;
  std::uint32_t gaussian = 0;
};

struct Correspondences {
  std::vector<GeometricTerm> geometric;
  std::vector<RcsTerm> rcs;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // of the pose they were made at
};

// Associates every point at `pose` (smallest Mahalanobis^2 within the gate);
// RCS terms too when `with_rcs` (and the scan has RCS).
Correspondences FindCorrespondences(const RadarScan& scan, const MatchingMap& map, const SE3d& pose,
                                    double gate, bool with_rcs);

// f of eq. 2 for fixed correspondences at `pose`. RCS residuals take the
// translation of the correspondences when rotation-only.
double EvaluateCost(const Correspondences& correspondences, const MatchingMap& map,
                    const SE3d& pose, const ScanMatchingOptions& options);

// Checks the inputs every solver shares; false with a reason for an empty
// scan or a term that has no residuals although its weight is not zero.
bool CheckCorrespondences(const RadarScan& scan, const Correspondences& correspondences,
                          const ScanMatchingOptions& options, std::string& reason);

class ScanMatcher {
 public:
  virtual ~ScanMatcher() = default;
  virtual std::string Name() const = 0;
  virtual ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map,
                                   const SE3d& initial) const = 0;
};

}  // namespace radargauss
