// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/multi_hypothesis.hpp"

#include <chrono>
#include <stdexcept>
#include <vector>

#include "radargauss/solvers/correspondences.hpp"

namespace radargauss {

std::vector<Eigen::Vector3d> HypothesisOffsets(const MultiHypothesisOptions& o) {
  const double d = o.xy_offset;
  const double a = o.yaw_offset;
  const std::vector<Eigen::Vector3d> pattern = {{0, 0, 0},   {d, 0, 0},  {-d, 0, 0}, {0, d, 0},  {0, -d, 0},
                                                {0, 0, a},   {0, 0, -a}, {d, d, 0},  {d, -d, 0}, {-d, d, 0},
                                                {-d, -d, 0}, {d, 0, a},  {d, 0, -a}};
  if (o.starts < 1 || o.starts > int(pattern.size())) {
    throw std::invalid_argument("multi-hypothesis starts must be in 1..13");
  }
  return std::vector<Eigen::Vector3d>(pattern.begin(), pattern.begin() + o.starts);
}

MultiHypothesisSolver::MultiHypothesisSolver(std::shared_ptr<const ScanMatcher> inner,
                                             const ScanMatchingOptions& options,
                                             const MultiHypothesisOptions& hypotheses)
    : inner_(std::move(inner)), options_(options), hypotheses_(hypotheses) {
  ValidateOptions(options_);
  HypothesisOffsets(hypotheses_);  // validates
}

std::string MultiHypothesisSolver::Name() const {
  return "mh" + std::to_string(hypotheses_.starts) + "-" + inner_->Name();
}

namespace {

double Score(const RadarScan& scan, const MatchingMap& map, const SE3d& pose, double gate) {
  if (scan.points.empty()) return INFINITY;
  std::vector<double> d2;
  const std::vector<int> associations = AssociateScan(scan, map.index(), pose, gate, &d2);
  double sum = 0.0;
  for (std::size_t k = 0; k < associations.size(); ++k) sum += associations[k] < 0 ? gate * gate : d2[k];
  return sum / double(associations.size());
}

}  // namespace

ScanMatchingResult MultiHypothesisSolver::Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                                                const ScanPriors& priors) const {
  const auto start = std::chrono::steady_clock::now();
  ScanMatchingResult best;
  double best_score = INFINITY;
  bool best_converged = false;
  bool have_best = false;
  int total_iterations = 0;
  for (const Eigen::Vector3d& offset : HypothesisOffsets(hypotheses_)) {
    const SE3d perturbation(SO3d::Exp(Eigen::Vector3d(0, 0, offset.z())), Eigen::Vector3d(offset.x(), offset.y(), 0.0));
    ScanMatchingResult candidate = inner_->Match(scan, map, initial * perturbation, priors);
    total_iterations += candidate.iterations;
    const double score = Score(scan, map, candidate.pose, options_.gate);
    const bool better = !have_best || (candidate.converged && !best_converged) ||
                        (candidate.converged == best_converged && score < best_score);
    if (better) {
      have_best = true;
      best = candidate;
      best_score = score;
      best_converged = candidate.converged;
    }
  }
  best.iterations = total_iterations;
  best.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return best;
}

}  // namespace radargauss
