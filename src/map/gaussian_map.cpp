// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/map/gaussian_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <limits>
#include <memory>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/Eigenvalues>

#include "radargauss/core/error.hpp"
#include "radargauss/core/names.hpp"

namespace radargauss {

namespace {

const NamedValue<IncidenceModel> kIncidenceNames[] = {{IncidenceModel::kOffset, "offset"},
                                                      {IncidenceModel::kView, "view"}};

}  // namespace

std::string ToString(IncidenceModel model) { return NameOf(kIncidenceNames, model); }
IncidenceModel IncidenceModelFromString(const std::string& name) {
  return ValueNamed(kIncidenceNames, name, "incidence model");
}
std::vector<std::string> IncidenceModelNames() { return NamesOf(kIncidenceNames); }

void PrincipalAxes(const Eigen::Matrix3d& covariance, Eigen::Vector3d& std_devs, Eigen::Matrix3d& axes) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  std_devs = solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  axes = solver.eigenvectors();
  if (axes.determinant() < 0.0) axes.col(0) = -axes.col(0);
}

Eigen::Matrix3d ClampCovariance(const Eigen::Matrix3d& covariance, double min_std) {
  Eigen::Vector3d std_devs;
  Eigen::Matrix3d axes;
  PrincipalAxes(covariance, std_devs, axes);
  const Eigen::Vector3d variances = std_devs.cwiseMax(min_std).array().square();
  const Eigen::Matrix3d clamped = axes * variances.asDiagonal() * axes.transpose();
  return 0.5 * (clamped + clamped.transpose());  // exactly symmetric
}

namespace {

// A number in a message, %.3g.
std::string Brief(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

// Whether the cell [lo, hi] may hold a point within `extent` standard
// deviations (Mahalanobis distance) of the Gaussian. false only when a plane
// separates the two: the plane normal to Sigma^-1 (x - mu) at the cell's
// point x of about the smallest Mahalanobis distance (coordinate descent on
// that convex quadratic over the box). Any separating plane proves the cell
// empty, so no query loses a candidate within the gate; the closer x is to
// the minimum, the fewer cells stay that could have gone. The cell and the
// extent are widened by far more than the rounding of a query's voxel key
// and Mahalanobis^2.
bool CellMeetsEllipsoid(Eigen::Vector3d lo, Eigen::Vector3d hi, const Eigen::Vector3d& mean,
                        const Eigen::Matrix3d& covariance, const Eigen::Matrix3d& information, double extent) {
  const double margin = 1e-9 * std::max({1.0, lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff()});
  lo.array() -= margin;
  hi.array() += margin;
  extent *= 1.0 + 1e-6;
  const double extent_sq = extent * extent;
  Eigen::Vector3d x = mean.cwiseMax(lo).cwiseMin(hi);
  for (int sweep = 0; sweep < 6; ++sweep) {
    if ((x - mean).dot(information * (x - mean)) <= extent_sq) return true;  // x itself is within the extent
    for (int i = 0; i < 3; ++i) {
      x[i] = std::clamp(x[i] - information.row(i).dot(x - mean) / information(i, i), lo[i], hi[i]);
    }
  }
  const Eigen::Vector3d n = information * (x - mean);  // the outward normal of the ellipsoid through x
  if ((x - mean).dot(n) <= extent_sq) return true;
  // Along n the ellipsoid reaches n.mu + extent sqrt(n^T Sigma n); the cell starts at its lowest corner.
  double cell_low = 0.0;
  for (int i = 0; i < 3; ++i) cell_low += std::min(n[i] * lo[i], n[i] * hi[i]);
  return cell_low <= n.dot(mean) + extent * std::sqrt(n.dot(covariance * n));
}

// The z-extent of a Gaussian's ellipsoid of `extent` sigmas over a column
// [x0, x0 + w] x [y0, y0 + w]: for fixed (x, y) it spans z_c +- h with
// z_c = mu_z - a . d / A_zz, h^2 = (extent^2 - d^T S d) / A_zz, d the (x, y)
// offset from the mean, A = Sigma^-1, a = A_z,xy and S = Sigma_xy^-1 the
// marginal's information. Bounded by z_c over the corners (it is linear) and
// the largest h (at the smallest d^T S d over the rectangle), both widened as
// CellMeetsEllipsoid widens the cell and the extent: every cell the
// ellipsoid meets lies within the bound.
class ColumnBound {
 public:
  ColumnBound(const Gaussian& g, const Eigen::Matrix3d& information, double extent) : mean_(g.mean) {
    marginal_ = g.covariance.topLeftCorner<2, 2>().inverse();
    a_zz_ = information(2, 2);
    slope_ = Eigen::Vector2d(information(2, 0), information(2, 1)) / a_zz_;
    extent_sq_ = extent * (1.0 + 1e-5) * extent * (1.0 + 1e-5);
  }
  // false: the column misses the ellipsoid.
  bool Bounds(double x0, double y0, double width, double& z_low, double& z_high) const {
    const double margin = 1e-8 * std::max({1.0, std::abs(x0) + width, std::abs(y0) + width});
    const Eigen::Vector2d lo(x0 - margin - mean_.x(), y0 - margin - mean_.y());
    const Eigen::Vector2d hi(x0 + width + margin - mean_.x(), y0 + width + margin - mean_.y());
    const double q = SmallestOverRectangle(lo, hi);
    if (q > extent_sq_) return false;
    const double h = std::sqrt((extent_sq_ - q) / a_zz_);
    double c_low = INFINITY, c_high = -INFINITY;
    for (const double dx : {lo.x(), hi.x()}) {
      for (const double dy : {lo.y(), hi.y()}) {
        const double c = -(slope_.x() * dx + slope_.y() * dy);
        c_low = std::min(c_low, c);
        c_high = std::max(c_high, c);
      }
    }
    const double z_margin = 1e-8 * std::max(1.0, std::abs(mean_.z()) + std::abs(c_low) + std::abs(c_high) + h);
    z_low = mean_.z() + c_low - h - z_margin;
    z_high = mean_.z() + c_high + h + z_margin;
    return true;
  }

 private:
  // min d^T S d over lo <= d <= hi: 0 inside, else on an edge (convex).
  double SmallestOverRectangle(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
    if (lo.x() <= 0.0 && hi.x() >= 0.0 && lo.y() <= 0.0 && hi.y() >= 0.0) return 0.0;
    const Eigen::Matrix2d& S = marginal_;
    const auto value = [&S](double dx, double dy) {
      return S(0, 0) * dx * dx + 2.0 * S(0, 1) * dx * dy + S(1, 1) * dy * dy;
    };
    double best = INFINITY;
    for (const double dx : {lo.x(), hi.x()}) {  // edges of fixed x: the best y, clamped
      best = std::min(best, value(dx, std::clamp(-S(0, 1) * dx / S(1, 1), lo.y(), hi.y())));
    }
    for (const double dy : {lo.y(), hi.y()}) {
      best = std::min(best, value(std::clamp(-S(0, 1) * dy / S(0, 0), lo.x(), hi.x()), dy));
    }
    return best;
  }

  Eigen::Vector3d mean_;
  Eigen::Matrix2d marginal_;
  Eigen::Vector2d slope_;
  double a_zz_ = 1.0;
  double extent_sq_ = 0.0;
};

// Sorts (cell key, id) listings by key, equal keys in the order given (the
// ids come ascending, so this is std::sort's order): an LSD radix sort over
// the keys' span, 11 bits a pass, linear where a comparison sort of a
// map's millions of listings is not.
void SortListingsByKey(std::vector<std::pair<std::int64_t, std::uint32_t>>& listings) {
  // A few thousand listings (a region's fit) sort faster by comparison than
  // by passes over 2^11 buckets each.
  constexpr std::size_t kComparisonSortBelow = 4096;
  if (listings.size() < kComparisonSortBelow) {
    std::sort(listings.begin(), listings.end());
    return;
  }
  std::uint64_t low = ~std::uint64_t(0), high = 0;
  for (const auto& listing : listings) {
    low = std::min(low, std::uint64_t(listing.first));
    high = std::max(high, std::uint64_t(listing.first));
  }
  constexpr int kDigitBits = 11;
  constexpr std::uint64_t kDigitMask = (std::uint64_t(1) << kDigitBits) - 1;
  std::vector<std::pair<std::int64_t, std::uint32_t>> sorted(listings.size());
  std::vector<std::size_t> start(kDigitMask + 2);
  for (int shift = 0; shift < 64 && ((high - low) >> shift) != 0; shift += kDigitBits) {
    std::fill(start.begin(), start.end(), 0);
    const auto digit = [&](std::int64_t key) { return ((std::uint64_t(key) - low) >> shift) & kDigitMask; };
    for (const auto& listing : listings) ++start[digit(listing.first) + 1];
    for (std::size_t d = 1; d < start.size(); ++d) start[d] += start[d - 1];
    for (const auto& listing : listings) sorted[start[digit(listing.first)]++] = listing;
    listings.swap(sorted);
  }
}

}  // namespace

std::int64_t GaussianIndex::Key(const Eigen::Vector3d& p) const {
  // A non-finite point has no voxel: the empty key finds an empty slot (no candidates).
  if (!p.allFinite()) return kEmptyCell;
  const VoxelKey v = VoxelOf(p, cell_size_);
  return PackVoxelKey(v.x, v.y, v.z);
}

std::size_t GaussianIndex::Index(const Gaussian& g, std::uint32_t id, std::vector<std::int64_t>& cell_keys,
                                 const std::vector<VoxelKey>* only) {
  IndexedGaussian& entry = gaussians_[id];
  entry.mean = g.mean;
  const Eigen::Matrix3d information = g.covariance.inverse();
  entry.sqrt_information_t = Eigen::LLT<Eigen::Matrix3d>(information).matrixL().transpose();
  const Eigen::Vector3d half = extent_sigmas_ * g.covariance.diagonal().cwiseSqrt();
  if (!g.mean.allFinite() || !half.allFinite()) {
    throw DataError("Gaussian " + std::to_string(id) + " has a non-finite mean or covariance");
  }
  // The cells as Key finds them (VoxelOf of the box's corners); the box's
  // size in doubles, which saturated corners cannot overflow.
  const VoxelKey lo = VoxelOf(g.mean - half, cell_size_);
  const VoxelKey hi = VoxelOf(g.mean + half, cell_size_);
  const double box =
      (double(hi.x) - double(lo.x) + 1.0) * (double(hi.y) - double(lo.y) + 1.0) * (double(hi.z) - double(lo.z) + 1.0);
  if (!(box <= double(kMaxIndexCellsPerGaussian))) {
    throw DataError("Gaussian " + std::to_string(id) + " spans " + Brief(box) + " index cells of " + Brief(cell_size_) +
                    " m (at most " + std::to_string(kMaxIndexCellsPerGaussian) +
                    "): too large a Gaussian, or too small an index cell (index_cell, --index-cell)");
  }
  // Of the box's cells, those the ellipsoid itself meets: an oblique or
  // round Gaussian leaves many of its box's cells empty (fewer candidates
  // per query, the same answers). Each column of cells is bounded first
  // (ColumnBound), and only the cells within its bound are tested.
  const ColumnBound column(g, information, extent_sigmas_);
  // The cells of column (x, y) within its bound: [first, last].
  const auto column_cells = [&](std::int64_t x, std::int64_t y, std::int64_t& first, std::int64_t& last) {
    double z_low, z_high;
    if (!column.Bounds(double(x) * cell_size_, double(y) * cell_size_, cell_size_, z_low, z_high)) return false;
    first = std::int64_t(std::max(double(lo.z), std::floor(z_low / cell_size_)));
    last = std::int64_t(std::min(double(hi.z), std::floor(z_high / cell_size_)));
    return true;
  };
  const auto meets = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    const Eigen::Vector3d corner = Eigen::Vector3d(double(x), double(y), double(z)) * cell_size_;
    return CellMeetsEllipsoid(corner, corner.array() + cell_size_, g.mean, g.covariance, information, extent_sigmas_);
  };
  if (only != nullptr && double(only->size()) < box) {  // the queries' cells in the box, each tested alike
    for (const VoxelKey& c : *only) {
      if (c.x < lo.x || c.x > hi.x || c.y < lo.y || c.y > hi.y) continue;
      std::int64_t first, last;
      if (column_cells(c.x, c.y, first, last) && c.z >= first && c.z <= last && meets(c.x, c.y, c.z)) {
        cell_keys.push_back(PackVoxelKey(c.x, c.y, c.z));
      }
    }
    return std::size_t(box);
  }
  for (auto x = lo.x; x <= hi.x; ++x) {
    for (auto y = lo.y; y <= hi.y; ++y) {
      std::int64_t first, last;
      if (!column_cells(x, y, first, last)) continue;
      for (auto z = first; z <= last; ++z) {
        if (meets(x, y, z)) cell_keys.push_back(PackVoxelKey(x, y, z));
      }
    }
  }
  return std::size_t(box);
}

std::vector<VoxelKey> GaussianIndex::CellsOf(const std::vector<Eigen::Vector3d>& points, double cell_size) {
  // Sorted as packed keys (integers sort fast) and unpacked; cells beyond
  // the packing's range (+-2^20 cells) would wrap, so none are given then.
  constexpr std::int64_t kReach = (std::int64_t(1) << 20) - 1;
  constexpr std::int64_t kMask = (std::int64_t(1) << 21) - 1;
  std::vector<std::int64_t> keys;
  keys.reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    const VoxelKey v = VoxelOf(p, cell_size);
    if (std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}) > kReach) return {};
    keys.push_back(PackVoxelKey(v));
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<VoxelKey> cells(keys.size());
  const auto axis = [](std::int64_t key, int shift) { return ((key >> shift) & kMask) - (kReach + 1); };
  for (std::size_t k = 0; k < keys.size(); ++k) cells[k] = {axis(keys[k], 0), axis(keys[k], 21), axis(keys[k], 42)};
  return cells;
}

GaussianIndex::GaussianIndex(const std::vector<Gaussian>& gaussians, double cell_size, double extent_sigmas)
    : GaussianIndex(gaussians, cell_size, extent_sigmas, nullptr) {}

GaussianIndex::GaussianIndex(const std::vector<Gaussian>& gaussians, double cell_size, double extent_sigmas,
                             const std::vector<VoxelKey>* only)
    : cell_size_(cell_size), extent_sigmas_(extent_sigmas) {
  if (!(cell_size > 0.0)) throw std::invalid_argument("index cell size must be > 0");
  if (!(extent_sigmas > 0.0)) throw std::invalid_argument("index extent must be > 0 standard deviations");
  const std::size_t n = gaussians.size();
  gaussians_.resize(n);
  std::vector<std::pair<std::int64_t, std::uint32_t>> entries;
  std::vector<std::int64_t> cell_keys;
  std::size_t box_cells = 0;
  for (std::size_t i = 0; i < n; ++i) {
    cell_keys.clear();
    box_cells += Index(gaussians[i], std::uint32_t(i), cell_keys, only);
    if (box_cells > kMaxIndexCells) {
      throw DataError("the map spans more than " + std::to_string(kMaxIndexCells) + " index cells of " +
                      Brief(cell_size_) + " m: too many large Gaussians, or too small an index cell");
    }
    for (const std::int64_t key : cell_keys) entries.emplace_back(key, static_cast<std::uint32_t>(i));
  }
  SortListingsByKey(entries);
  cell_entries_.resize(entries.size());
  std::size_t cell_count = 0;
  for (std::size_t k = 0; k < entries.size(); ++k) cell_count += k == 0 || entries[k].first != entries[k - 1].first;
  cells_.Reset(cell_count, Cell());
  for (std::size_t begin = 0; begin < entries.size();) {
    std::size_t end = begin;
    while (end < entries.size() && entries[end].first == entries[begin].first) {
      cell_entries_[end] = entries[end].second;
      ++end;
    }
    Cell& cell = cells_[Slot(entries[begin].first)];
    cell.key = entries[begin].first;
    cell.begin = std::uint32_t(begin);
    cell.end = std::uint32_t(end);
    begin = end;
  }
}

const std::uint32_t* GaussianIndex::Candidates(const Eigen::Vector3d& point, std::size_t& count) const {
  if (cells_.empty()) {  // a default-constructed index
    count = 0;
    return nullptr;
  }
  const Cell& cell = cells_[Slot(Key(point))];
  count = cell.end - cell.begin;  // 0 for an empty slot
  return cell_entries_.data() + cell.begin;
}

double GaussianIndex::GateBound(double gate_sq) {
  return std::nextafter(gate_sq, std::numeric_limits<double>::infinity());
}

int GaussianIndex::Nearest(const Eigen::Vector3d& point, const std::uint32_t* candidates, std::size_t count,
                           double bound, double* mahalanobis_sq) const {
  // A candidate wins when strictly closer than the best so far, so ties go to
  // the smallest id (candidates come sorted by id); the bound starts one ulp
  // above the gate (GateBound), so that a candidate on the gate itself is
  // taken. Without a branch (the winner is unpredictable): the select
  // compiles to moves.
  int best = -1;
  double best_d2 = bound;
  for (std::size_t k = 0; k < count; ++k) {
    const std::uint32_t i = candidates[k];
    const double d2 = MahalanobisSq(i, point - gaussians_[i].mean);
    const bool closer = d2 < best_d2;
    best_d2 = closer ? d2 : best_d2;
    best = closer ? static_cast<int>(i) : best;
  }
  if (mahalanobis_sq && best >= 0) *mahalanobis_sq = best_d2;
  return best;
}

int GaussianIndex::Associate(const Eigen::Vector3d& point, double gate_sq, double* mahalanobis_sq) const {
  std::size_t count = 0;
  const std::uint32_t* candidates = Candidates(point, count);
  return Nearest(point, candidates, count, GateBound(gate_sq), mahalanobis_sq);
}

void GaussianIndex::AssociateAll(const Eigen::Vector3d* points, std::size_t count, double gate_sq, int* associations,
                                 double* mahalanobis_sq) const {
  if (cells_.empty()) {  // a default-constructed index
    std::fill(associations, associations + count, -1);
    return;
  }
  // Four stages kAhead points apart: fetch the cell's home slot; find the
  // cell and fetch its list of candidates; fetch the candidates' entries; score.
  constexpr std::size_t kAhead = 8;
  const double bound = GateBound(gate_sq);
  // Written by the stages ahead before they are read: not value-initialised.
  const std::unique_ptr<std::int64_t[]> keys(new std::int64_t[count]);
  const std::unique_ptr<const Cell*[]> cells(new const Cell*[count]);
  const auto fetch_cell = [&](std::size_t k) {
    keys[k] = Key(points[k]);
    __builtin_prefetch(&cells_[cells_.HomeSlot(std::uint64_t(keys[k]))]);
  };
  const auto fetch_list = [&](std::size_t k) {
    cells[k] = &cells_[Slot(keys[k])];
    __builtin_prefetch(cell_entries_.data() + cells[k]->begin);
  };
  const auto fetch_candidates = [&](std::size_t k) {
    for (std::uint32_t e = cells[k]->begin; e < cells[k]->end; ++e) {
      const char* entry = reinterpret_cast<const char*>(&gaussians_[cell_entries_[e]]);
      __builtin_prefetch(entry);  // mean and L^T: the entry's first two cache lines
      __builtin_prefetch(entry + 64);
    }
  };
  for (std::size_t k = 0; k < std::min(count, 3 * kAhead); ++k) fetch_cell(k);
  for (std::size_t k = 0; k < std::min(count, 2 * kAhead); ++k) fetch_list(k);
  for (std::size_t k = 0; k < std::min(count, kAhead); ++k) fetch_candidates(k);
  for (std::size_t k = 0; k < count; ++k) {
    if (k + 3 * kAhead < count) fetch_cell(k + 3 * kAhead);
    if (k + 2 * kAhead < count) fetch_list(k + 2 * kAhead);
    if (k + kAhead < count) fetch_candidates(k + kAhead);
    const Cell& cell = *cells[k];
    associations[k] = Nearest(points[k], cell_entries_.data() + cell.begin, cell.end - cell.begin, bound,
                              mahalanobis_sq ? mahalanobis_sq + k : nullptr);
  }
}

std::size_t GaussianIndex::MemoryBytes() const {
  std::size_t listed = listed_cells_.size() * sizeof(std::vector<std::int64_t>);
  for (const std::vector<std::int64_t>& keys : listed_cells_) listed += keys.capacity() * sizeof(std::int64_t);
  return gaussians_.size() * sizeof(IndexedGaussian) + cell_entries_.size() * sizeof(std::uint32_t) +
         cells_.size() * sizeof(Cell) + listed;
}

}  // namespace radargauss
