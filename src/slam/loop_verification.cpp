// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/loop_verification.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "radargauss/map/matching_map.hpp"
#include "radargauss/core/voxel_grid.hpp"

namespace radargauss {

const OptionTable<LoopVerificationOptions>& LoopVerificationOptionTable() {
  using O = LoopVerificationOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {
        // At most 1000 cells searched each way: 100 m over cells of 0.1 m.
        RADARGAUSS_OPTION(O, "bev_cell", bev_cell).In(0.1, 10.0).Unit("m").Help("cells of the bird's-eye alignment"),
        RADARGAUSS_OPTION(O, "bev_search", bev_search)
            .In(0.0, 100.0)
            .Unit("m")
            .Help("translations tried around the keyframes' origins"),
        RADARGAUSS_OPTION(O, "min_associated", min_associated)
            .In(0.0, 1.0)
            .Help("share of the query's points within the gate"),
        RADARGAUSS_OPTION(O, "max_cost", max_cost).Above(0.0).Help("eq. 2's f at the end of the match"),
        RADARGAUSS_OPTION(O, "max_translation_std", max_translation_std)
            .Above(0.0)
            .Unit("m")
            .Help("the match's marginal translation std"),
        RADARGAUSS_OPTION(O, "max_rotation_std", max_rotation_std_deg)
            .Above(0.0)
            .Unit("deg")
            .Help("the match's marginal rotation std"),
        RADARGAUSS_OPTION(O, "drift", drift).AtLeast(0.0).Unit("m per m").Help("the loop may move the query this much"),
        RADARGAUSS_OPTION(O, "min_drift", min_drift).AtLeast(0.0).Unit("m").Help("and at least this"),
        RADARGAUSS_OPTION(O, "drift_deg", drift_deg).AtLeast(0.0).Unit("deg per m").Help("and turn it this much"),
        RADARGAUSS_OPTION(O, "min_drift_deg", min_drift_deg).AtLeast(0.0).Unit("deg").Help("and at least this"),
        RADARGAUSS_OPTION(O, "translation_floor_std", translation_floor_std)
            .Above(0.0)
            .Unit("m")
            .Help("added to the match's covariance: what the submaps' own errors leave"),
        RADARGAUSS_OPTION(O, "rotation_floor_std", rotation_floor_std_deg).Above(0.0).Unit("deg").Help("the same"),
        RADARGAUSS_OPTION(O, "kept_targets", kept_targets)
            .In(1, 100000)
            .Help("candidates' verification maps kept, the last verified (each built once while kept)"),
        RADARGAUSS_OPTION(O, "min_overlap", min_overlap)
            .In(0.0, 1.0)
            .Help("a close candidate overlapping less in bird's-eye view is refused before its match"),
        RADARGAUSS_OPTION(O, "budget", budget)
            .In(0, 100000)
            .Help("Gaussian matches per keyframe, the best overlapping candidates first (0: all)"),
        RADARGAUSS_OPTION(O, "start_margin", start_margin)
            .AtLeast(0.0)
            .Unit("m")
            .Help("a start farther from the graph than its bound plus this is refused before its match"),
        RADARGAUSS_OPTION(O, "start_margin_deg", start_margin_deg).AtLeast(0.0).Unit("deg").Help("the same, turned"),
    };
    // The loop's match is geometric: its RCS rows are not options.
    AppendNested(t, MatchOptionTable(), +[](O & o) -> auto& { return o.match; }, "match", "",
                 {"w_rcs", "rcs_loss", "rcs_loss_scale", "rcs_translation"});
    AppendNested(
        t, GaussianMapOptionTable(), +[](O & o) -> auto& { return o.gaussians; }, "gaussians");
    // What an expert of verification changes, whatever the rows are for a scan match or a map.
    for (Option<O>& option : t) option.group = OptionGroup::kTuning;
    return t;
  }();
  return table;
}

void ValidateOptions(const LoopVerificationOptions& o) {
  CheckOptions(LoopVerificationOptionTable(), o);
  if (o.match.matching.w_rcs != 0.0) throw std::invalid_argument("w_rcs: the loop's match is geometric (w_rcs 0)");
}

namespace {

// Fewer points in the query or the candidate: "submap too small".
constexpr std::size_t kMinSubmapPoints = 10;

}  // namespace

namespace {

// A dense occupancy grid over a submap's extent is at most this many cells
// (4 MB); points spread wider (a hostile map's far points) use a sorted list.
constexpr std::int64_t kMaxDenseBirdsEyeCells = std::int64_t(1) << 22;

using Cell = std::pair<std::int64_t, std::int64_t>;  // (x, y) in cells, 64-bit: no coordinate overflows it

Cell CellOf(const Eigen::Vector3d& p, double cell) { return {FloorToInt(p.x() / cell), FloorToInt(p.y() / cell)}; }

// The candidate's occupied cells, asked one cell at a time.
class BirdsEyeOccupancy {
 public:
  explicit BirdsEyeOccupancy(std::vector<Cell> cells) {
    low_ = high_ = cells.front();
    for (const Cell& c : cells) {
      low_ = {std::min(low_.first, c.first), std::min(low_.second, c.second)};
      high_ = {std::max(high_.first, c.first), std::max(high_.second, c.second)};
    }
    // The extent in double: the span of two far cells overflows no integer.
    const double area =
        (double(high_.first) - double(low_.first) + 1.0) * (double(high_.second) - double(low_.second) + 1.0);
    if (area <= double(kMaxDenseBirdsEyeCells)) {
      width_ = high_.first - low_.first + 1;
      dense_.assign(std::size_t(area), 0);
      for (const Cell& c : cells) dense_[std::size_t((c.second - low_.second) * width_ + c.first - low_.first)] = 1;
    } else {
      std::sort(cells.begin(), cells.end());
      cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
      sparse_ = std::move(cells);
    }
  }

  int operator()(std::int64_t x, std::int64_t y) const {
    if (x < low_.first || y < low_.second || x > high_.first || y > high_.second) return 0;
    if (!dense_.empty()) return dense_[std::size_t((y - low_.second) * width_ + x - low_.first)];
    return std::binary_search(sparse_.begin(), sparse_.end(), Cell(x, y)) ? 1 : 0;
  }

 private:
  Cell low_, high_;
  std::int64_t width_ = 0;
  std::vector<char> dense_;
  std::vector<Cell> sparse_;
};

}  // namespace

std::pair<Eigen::Vector2d, double> AlignBirdsEye(const std::vector<Eigen::Vector3d>& query,
                                                 const std::vector<Eigen::Vector3d>& candidate, double cell,
                                                 double search) {
  // The query as unique cells, the candidate's occupancy as a grid to look them up in.
  std::vector<Cell> query_cells;
  for (const Eigen::Vector3d& p : query) query_cells.push_back(CellOf(p, cell));
  std::sort(query_cells.begin(), query_cells.end());
  query_cells.erase(std::unique(query_cells.begin(), query_cells.end()), query_cells.end());
  if (query_cells.empty() || candidate.empty()) return {Eigen::Vector2d::Zero(), 0.0};
  std::vector<Cell> candidate_cells;
  for (const Eigen::Vector3d& p : candidate) candidate_cells.push_back(CellOf(p, cell));
  const BirdsEyeOccupancy occupied(std::move(candidate_cells));
  const int reach = int(std::floor(search / cell));
  int best_count = -1;
  Eigen::Vector2i best(0, 0);
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      int count = 0;
      for (const Cell& c : query_cells) count += occupied(c.first + dx, c.second + dy);
      // Ties go to the smaller shift: the keyframes' origins are the prior.
      if (count > best_count || (count == best_count && dx * dx + dy * dy < best.squaredNorm())) {
        best_count = count;
        best = {dx, dy};
      }
    }
  }
  return {best.cast<double>() * cell, double(best_count) / query_cells.size()};
}

namespace {

std::vector<Eigen::Vector3d> Positions(const std::vector<RadarPoint>& points) {
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(points.size());
  for (const RadarPoint& p : points) positions.push_back(p.position);
  return positions;
}

// The match's covariance over [dt (candidate frame); dphi (query frame)], in
// the relative-pose residual's [t_E; Log R_E] (t_E is in the query frame):
// rotated by R^T, then the floors added; false when the information is singular.
bool FillInformation(const ScanMatchingResult& match, const LoopVerificationOptions& options, LoopCheck& check) {
  const Eigen::Matrix<double, 6, 6> information = match.information * double(match.n_geo);
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(information);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return false;
  const Eigen::Matrix<double, 6, 6> covariance = ldlt.solve(Eigen::Matrix<double, 6, 6>::Identity());
  check.translation_std = std::sqrt(std::max(
      0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance.topLeftCorner<3, 3>()).eigenvalues().maxCoeff()));
  check.rotation_std_deg =
      std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance.bottomRightCorner<3, 3>())
                                  .eigenvalues()
                                  .maxCoeff())) *
      180.0 / M_PI;
  Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Identity();
  J.topLeftCorner<3, 3>() = match.pose.rotation().Matrix().transpose();
  Eigen::Matrix<double, 6, 6> residual_covariance = J * covariance * J.transpose();
  const double rotation_floor = options.rotation_floor_std_deg * M_PI / 180.0;
  residual_covariance.diagonal() +=
      (Eigen::Matrix<double, 6, 1>() << Eigen::Vector3d::Constant(options.translation_floor_std),
       Eigen::Vector3d::Constant(rotation_floor))
          .finished()
          .cwiseAbs2();
  const Eigen::Matrix<double, 6, 6> residual_information =
      residual_covariance.ldlt().solve(Eigen::Matrix<double, 6, 6>::Identity());
  check.sqrt_information = Eigen::LLT<Eigen::Matrix<double, 6, 6>>(residual_information).matrixU();
  return true;
}

}  // namespace

VerificationTarget::VerificationTarget(const std::vector<RadarPoint>& candidate, const LoopVerificationOptions& options)
    : points_(Positions(candidate)), matcher_(MakeScanMatcher(options.match)) {
  ValidateOptions(options);
  if (points_.size() >= kMinSubmapPoints) {
    GaussianMap map;
    map.gaussians = BuildGaussians(points_, options.gaussians);
    map_ = std::make_unique<const MatchingMap>(std::move(map));
  }
}

std::shared_ptr<const VerificationTarget> VerificationTargets::Get(int index, const std::vector<RadarPoint>& points,
                                                                   const LoopVerificationOptions& options) {
  for (auto kept = kept_.begin(); kept != kept_.end(); ++kept) {
    if (kept->first != index) continue;
    kept_.splice(kept_.begin(), kept_, kept);  // the most recent first
    return kept_.front().second;
  }
  auto target = std::make_shared<const VerificationTarget>(points, options);
  ++built_;
  kept_.emplace_front(index, target);
  if (kept_.size() > capacity_) kept_.pop_back();
  return target;
}

SE3d BirdsEyeStart::pose() const {
  return SE3d(SO3d(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()))),
              Eigen::Vector3d(shift.x(), shift.y(), 0.0));
}

namespace {

// The start at one yaw: the query turned (once, not per point) and aligned to the target's cells.
BirdsEyeStart StartAt(const std::vector<RadarPoint>& query, const std::vector<Eigen::Vector3d>& target, double yaw,
                      const LoopVerificationOptions& options) {
  BirdsEyeStart start;
  start.yaw = yaw;
  const SO3d rotation = start.pose().rotation();
  std::vector<Eigen::Vector3d> turned = Positions(query);
  for (Eigen::Vector3d& p : turned) p = rotation * p;
  std::tie(start.shift, start.overlap) = AlignBirdsEye(turned, target, options.bev_cell, options.bev_search);
  return start;
}

}  // namespace

std::vector<BirdsEyeStart> BirdsEyeStarts(const std::vector<RadarPoint>& query,
                                          const std::vector<RadarPoint>& candidate, const std::vector<double>& yaws,
                                          const LoopVerificationOptions& options) {
  std::vector<BirdsEyeStart> starts(yaws.size());
  for (std::size_t i = 0; i < yaws.size(); ++i) starts[i].yaw = yaws[i];
  if (query.size() < kMinSubmapPoints || candidate.size() < kMinSubmapPoints) return starts;
  const std::vector<Eigen::Vector3d> target = Positions(candidate);
  for (BirdsEyeStart& start : starts) start = StartAt(query, target, start.yaw, options);
  return starts;
}

GraphCorrection CorrectGraph(const SE3d& relative, const GraphPrior& prior, const LoopVerificationOptions& options,
                             double margin, double margin_deg) {
  const SE3d correction = prior.expected.Inverse() * relative;
  GraphCorrection c;
  c.translation = correction.translation().norm();
  c.rotation_deg = correction.rotation().Log().norm() * 180.0 / M_PI;
  c.consistent = c.translation <= std::max(options.min_drift, options.drift * prior.path) + margin &&
                 c.rotation_deg <= std::max(options.min_drift_deg, options.drift_deg * prior.path) + margin_deg;
  return c;
}

std::vector<std::shared_ptr<const VerificationTarget>> VerificationTargets::GetAll(
    const std::vector<int>& indices, const std::vector<const std::vector<RadarPoint>*>& points,
    const LoopVerificationOptions& options) {
  std::vector<std::shared_ptr<const VerificationTarget>> built(indices.size());
  std::vector<std::size_t> missing;
  for (std::size_t i = 0; i < indices.size(); ++i) {
    const bool kept = std::any_of(kept_.begin(), kept_.end(), [&](const auto& k) { return k.first == indices[i]; });
    if (!kept) missing.push_back(i);
  }
  tbb::parallel_for(std::size_t(0), missing.size(), [&](std::size_t m) {
    built[missing[m]] = std::make_shared<const VerificationTarget>(*points[missing[m]], options);
  });
  std::vector<std::shared_ptr<const VerificationTarget>> targets;
  for (std::size_t i = 0; i < indices.size(); ++i) {
    auto kept = std::find_if(kept_.begin(), kept_.end(), [&](const auto& k) { return k.first == indices[i]; });
    if (kept != kept_.end()) {
      kept_.splice(kept_.begin(), kept_, kept);
    } else {
      kept_.emplace_front(indices[i],
                          built[i] ? built[i] : std::make_shared<const VerificationTarget>(*points[i], options));
      ++built_;
      if (kept_.size() > capacity_) kept_.pop_back();
    }
    targets.push_back(kept_.front().second);
  }
  return targets;
}

LoopCheck VerifyLoop(const std::vector<RadarPoint>& query, const std::vector<RadarPoint>& candidate, double yaw,
                     const std::optional<GraphPrior>& prior, const LoopVerificationOptions& options) {
  return VerifyLoop(query, VerificationTarget(candidate, options), yaw, prior, options);
}

LoopCheck VerifyLoop(const std::vector<RadarPoint>& query, const VerificationTarget& candidate, double yaw,
                     const std::optional<GraphPrior>& prior, const LoopVerificationOptions& options) {
  ValidateOptions(options);
  LoopCheck check;
  if (query.size() < kMinSubmapPoints || !candidate.map()) {
    check.reason = "submap too small";
    return check;
  }
  const BirdsEyeStart start = StartAt(query, candidate.points(), yaw, options);
  check.overlap = start.overlap;
  const SE3d initial = start.pose();

  RadarScan scan;
  scan.points = query;
  const ScanMatchingResult match = candidate.matcher().Match(scan, *candidate.map(), initial);
  check.relative = match.pose;
  check.associated = double(match.n_geo) / query.size();
  check.cost = match.final_cost;
  GraphCorrection correction;
  if (prior) {
    correction = CorrectGraph(match.pose, *prior, options);
    check.correction = correction.translation;
    check.correction_deg = correction.rotation_deg;
  }
  char detail[96];
  if (!match.converged) {
    check.reason = "match did not converge: " + match.reason;
  } else if (check.associated < options.min_associated) {
    std::snprintf(detail, sizeof(detail), "%.2f of the points associated", check.associated);
    check.reason = detail;
  } else if (check.cost > options.max_cost) {
    std::snprintf(detail, sizeof(detail), "cost %.2f", check.cost);
    check.reason = detail;
  } else if (!FillInformation(match, options, check) || check.translation_std > options.max_translation_std ||
             check.rotation_std_deg > options.max_rotation_std_deg) {
    std::snprintf(detail, sizeof(detail), "degenerate: std %.3f m, %.3f deg", check.translation_std,
                  check.rotation_std_deg);
    check.reason = detail;
  } else if (prior && !correction.consistent) {
    std::snprintf(detail, sizeof(detail), "inconsistent with the graph: %.1f m, %.1f deg", check.correction,
                  check.correction_deg);
    check.reason = detail;
  } else {
    check.accepted = true;
  }
  return check;
}

}  // namespace radargauss
