// SPDX-License-Identifier: BSD-3-Clause
// The Gaussian-RCS map (paper section III-A, docs/design/map.md, "Building the map"): 3D
// Gaussians in the world frame, each with an optional RCS model, and the
// spatial index used to associate points with them.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/core/linear_probing_table.hpp"
#include "radargauss/core/sh.hpp"
#include "radargauss/core/types.hpp"
#include "radargauss/core/voxel_grid.hpp"

namespace radargauss {

// How the incidence vector d of a member point is formed (docs/design/map.md,
// "RCS models"), in the radar frame of the point's scan, mu_r = R^T (mu - t):
//   kOffset (the paper's): d = normalize(p_r - mu_r)
//   kView (radar-to-centre ray): d = normalize(-mu_r)
// In both, d is flipped when d.x > 0 so that it faces the radar.
enum class IncidenceModel : std::uint8_t { kOffset = 0, kView = 1 };

std::string ToString(IncidenceModel model);
IncidenceModel IncidenceModelFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> IncidenceModelNames();

// Per-Gaussian RCS model: y = (rcs - median) / scale in [-1, 1] is
// predicted as c . Y(d) with real SH up to `degree` (sh.hpp).
struct RcsModel {
  int degree = -1;      // -1: no model (too few members or scale 0)
  double median = 0.0;  // dBsm
  double scale = 0.0;   // dBsm
  std::array<double, ShCoefficientCount(kMaxShDegree)> coefficients{};
  double fit_rmse = 0.0;  // normalised units, over the inliers
  std::uint32_t inliers = 0;
  // The fit's statistics over its inliers (docs/design/map.md, "RCS confidence"):
  // the residuals' std in dB with the fitted coefficients' degrees of freedom
  // taken out; the share of the RCS variance the view explains (adjusted
  // R^2, in [0, 1]); and the dB from the model's value to the members'
  // linear mean, which the Swerling likelihoods take as the mean.
  double spread_db = 0.0;
  double explained = 1.0;
  double mean_offset_db = 0.0;

  bool valid() const { return degree >= 0; }
  // The normalised measurement of a raw RCS value.
  double Normalise(double rcs) const { return (rcs - median) / scale; }
};

struct Gaussian {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();            // world frame, m
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // m^2, symmetric positive definite
  std::uint32_t point_count = 0;                             // member points
  RcsModel rcs;
};

// A keyframe of the run that built the map (SLAM): where it was and the
// static points it saw, so that a later run can describe its own submaps and
// relocalise against the map (docs/design/slam.md, "Relocalisation").
struct MapPlace {
  SE3d pose;                       // T_world_keyframe
  std::vector<RadarPoint> points;  // its submap in its frame (position and RCS)
};

struct GaussianMap {
  std::vector<Gaussian> gaussians;
  IncidenceModel incidence = IncidenceModel::kOffset;  // how the RCS models were fitted
  std::vector<MapPlace> places;                        // empty unless SLAM built the map
};

// The ellipsoid of a covariance: std devs (ascending) and the rotation whose
// columns are the principal axes (det +1). Sigma = R diag(std^2) R^T.
void PrincipalAxes(const Eigen::Matrix3d& covariance, Eigen::Vector3d& std_devs, Eigen::Matrix3d& axes);

// Clamps every principal std to at least `min_std` (docs/design/map.md, "Building the map").
Eigen::Matrix3d ClampCovariance(const Eigen::Matrix3d& covariance, double min_std);

// The upper triangle (00 01 02 11 12 22) of Sigma^-1 = L L^T from that of the
// upper-triangular L^T, for one Gaussian (T = double) or one per SIMD lane
// (T = Eigen::Array2d): 10 products over the symmetric triangle.
template <typename T>
void InformationFromSqrtInformationT(const T u[6], T information[6]) {
  information[0] = u[0] * u[0];
  information[1] = u[0] * u[1];
  information[2] = u[0] * u[2];
  information[3] = u[1] * u[1] + u[3] * u[3];
  information[4] = u[1] * u[2] + u[3] * u[4];
  information[5] = u[2] * u[2] + u[4] * u[4] + u[5] * u[5];
}

// Spatial index: a voxel hash listing each Gaussian in the cells its
// ellipsoid of `extent_sigmas` standard deviations (Mahalanobis distance)
// meets, so a query point has a few candidates; association is the candidate
// of smallest Mahalanobis^2, gated by tau^2 (complete for tau <= extent).
// Bounds on the work of indexing (docs/design/formats.md, "Bounds on input"): the
// cells of the box around one Gaussian's ellipsoid (each is tested; 2^24 take
// about half a second), and those of all Gaussians of a static index.
inline constexpr std::size_t kMaxIndexCellsPerGaussian = std::size_t(1) << 24;
inline constexpr std::size_t kMaxIndexCells = std::size_t(1) << 30;

class GaussianIndex {
 public:
  GaussianIndex() = default;
  // Throws DataError when a Gaussian, or all of them, span more cells than
  // the bounds above.
  // A Gaussian is listed in the cells its ellipsoid of this many standard deviations meets.
  static constexpr double kExtentSigmas = 3.0;
  GaussianIndex(const std::vector<Gaussian>& gaussians, double cell_size = 1.0, double extent_sigmas = kExtentSigmas);
  // An index that answers only for points in `only` (sorted cells, CellsOf),
  // as the full index answers there, listing each Gaussian in those cells
  // alone: a fit's E steps on a region's few hundred points index a few
  // dozen cells rather than every cell each Gaussian meets.
  GaussianIndex(const std::vector<Gaussian>& gaussians, double cell_size, double extent_sigmas,
                const std::vector<VoxelKey>* only);
  // The cells (of `cell_size`) of the finite `points`, each once, sorted by
  // packed key; none when one lies beyond the packing's +-2^20 cells.
  static std::vector<VoxelKey> CellsOf(const std::vector<Eigen::Vector3d>& points, double cell_size);

  // An empty index that Update can change (docs/design/odometry.md, "Odometry"): it
  // also keeps the cells each Gaussian is listed in.
  static GaussianIndex Updatable(double cell_size = 1.0, double extent_sigmas = kExtentSigmas);
  // Lists gaussians[id] anew for every id of `changed` (ids may grow the
  // index) and takes every id of `removed` out of all cells: then the index
  // answers as one built from the listed Gaussians would. Only the cells of
  // those Gaussians are touched; the cell lists are compacted when stale
  // entries outnumber live ones. Throws std::logic_error on a static index.
  void Update(const std::vector<Gaussian>& gaussians, const std::vector<std::uint32_t>& changed,
              const std::vector<std::uint32_t>& removed);
  bool updatable() const { return updatable_; }

  // Index of the associated Gaussian, or -1 if no candidate has
  // Mahalanobis^2 <= gate_sq (or the point is not finite). Writes the
  // Mahalanobis^2 when asked.
  int Associate(const Eigen::Vector3d& point, double gate_sq, double* mahalanobis_sq = nullptr) const;

  // Associate for points[0, count), written to associations[0, count) (and
  // the Mahalanobis^2 of the associated ones to mahalanobis_sq[0, count) when
  // asked): the same answers, with the memory of later points (their cell,
  // its list, their candidates) fetched while earlier ones are scored. A
  // query is bound by cache misses on maps larger than the cache; this
  // overlaps them.
  void AssociateAll(const Eigen::Vector3d* points, std::size_t count, double gate_sq, int* associations,
                    double* mahalanobis_sq = nullptr) const;

  // The Gaussians whose ellipsoid of extent_sigmas meets the cell of `point`.
  const std::uint32_t* Candidates(const Eigen::Vector3d& point, std::size_t& count) const;

  // L^T with Sigma^-1 = L L^T (Cholesky), so ||L^T (x - mu)||^2 is the Mahalanobis^2.
  const Eigen::Matrix3d& SqrtInformationT(std::size_t i) const { return gaussians_[i].sqrt_information_t; }
  // Sigma^-1 = L L^T, formed from the upper-triangular L^T (the index keeps
  // only the factor: a query reads two cache lines per candidate).
  Eigen::Matrix3d Information(std::size_t i) const {
    const Eigen::Matrix3d& U = gaussians_[i].sqrt_information_t;
    const double u[6] = {U(0, 0), U(0, 1), U(0, 2), U(1, 1), U(1, 2), U(2, 2)};
    double m[6];
    InformationFromSqrtInformationT(u, m);
    return (Eigen::Matrix3d() << m[0], m[1], m[2], m[1], m[3], m[4], m[2], m[4], m[5]).finished();
  }
  // The Mahalanobis^2 of x - mu = e, |L^T e|^2: 9 products with the triangle
  // (e^T Sigma^-1 e takes 12).
  double MahalanobisSq(std::size_t i, const Eigen::Vector3d& e) const {
    const Eigen::Matrix3d& U = gaussians_[i].sqrt_information_t;
    const double y0 = U(0, 0) * e.x() + U(0, 1) * e.y() + U(0, 2) * e.z();
    const double y1 = U(1, 1) * e.y() + U(1, 2) * e.z();
    const double y2 = U(2, 2) * e.z();
    return y0 * y0 + y1 * y1 + y2 * y2;
  }
  const Eigen::Vector3d& Mean(std::size_t i) const { return gaussians_[i].mean; }
  std::size_t size() const { return gaussians_.size(); }
  double cell_size() const { return cell_size_; }
  std::size_t MemoryBytes() const;

 private:
  std::int64_t Key(const Eigen::Vector3d& p) const;
  // The entry of `g` (mean, L^T) and the keys of the cells its ellipsoid of
  // extent_sigmas_ meets, in key order of the box's cells. Returns the
  // number of the box's cells; throws DataError beyond kMaxIndexCellsPerGaussian.
  // With `only`, the cells of `only` among them (the same test, cell by cell).
  std::size_t Index(const Gaussian& g, std::uint32_t id, std::vector<std::int64_t>& cell_keys,
                    const std::vector<VoxelKey>* only = nullptr);
  // Rebuilds the cell lists without stale entries or empty cells, with room
  // for `extra_cells` more.
  void Compact(std::size_t extra_cells);
  // An update's listings, (cell key, id): those that go (removed Gaussians,
  // cells a changed one has left) and those that come, each sorted.
  using Listing = std::pair<std::int64_t, std::uint32_t>;
  void ListingChanges(const std::vector<Gaussian>& gaussians, const std::vector<std::uint32_t>& changed,
                      const std::vector<std::uint32_t>& removed, std::vector<Listing>& leaving,
                      std::vector<Listing>& joining);

  double cell_size_ = 1.0;
  double extent_sigmas_ = kExtentSigmas;
  bool updatable_ = false;
  std::vector<std::vector<std::int64_t>> listed_cells_;  // updatable: the cells of each Gaussian
  std::size_t cell_count_ = 0;                           // occupied slots of cells_ (updatable)
  std::size_t stale_entries_ = 0;                        // entries of cell_entries_ no cell points to (updatable)
  // What a query reads per candidate, side by side in one entry; aligned so
  // that the mean and L^T a query scores fill two cache lines.
  struct alignas(64) IndexedGaussian {
    Eigen::Vector3d mean;
    Eigen::Matrix3d sqrt_information_t;
  };
  std::vector<IndexedGaussian> gaussians_;
  std::vector<std::uint32_t> cell_entries_;  // Gaussian ids grouped by cell
  // The cells: an open-addressing hash table (linear probing, power-of-two
  // size, at most half full), so that a query reads one or two adjacent
  // slots instead of chasing a node-based map's pointers.
  struct Cell {
    std::int64_t key = kEmptyCell;
    std::uint32_t begin = 0, end = 0;  // [begin, end) in cell_entries_
  };
  static constexpr std::int64_t kEmptyCell = -1;  // packed keys are >= 0
  LinearProbingTable<Cell> cells_;
  // The slot holding `key`, or the empty slot where it would go.
  std::size_t Slot(std::int64_t key) const {
    return cells_.Probe(std::uint64_t(key),
                        [key](const Cell& cell) { return cell.key == key || cell.key == kEmptyCell; });
  }
  // The smallest Mahalanobis^2 a candidate must beat: one ulp above gate_sq.
  static double GateBound(double gate_sq);
  // The best candidate of `point` among `count` (-1 if none within the gate
  // GateBound made `bound` from).
  int Nearest(const Eigen::Vector3d& point, const std::uint32_t* candidates, std::size_t count, double bound,
              double* mahalanobis_sq) const;
};

}  // namespace radargauss
