// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/radon_descriptor.hpp"

#include <cmath>
#include <complex>
#include <stdexcept>
#include <unordered_set>

#include "radargauss/core/voxel_grid.hpp"

namespace radargauss {

const OptionTable<RadonOptions>& RadonOptionTable() {
  using O = RadonOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "angles", angles).In(2, 1000).Help("Radon: projection directions over [0, pi)"),
      RADARGAUSS_OPTION(O, "offsets", offsets).In(2, 1000).Help("Radon: bins of a projection"),
      RADARGAUSS_OPTION(O, "cell", cell).Above(0.0).Unit("m").Help("Radon: the bird's-eye grid's cell"),
      RADARGAUSS_OPTION(O, "max_range", max_range).Above(0.0).Unit("m").Help("Radon: cells farther are left out"),
  };
  return table;
}

void ValidateRadonOptions(const RadonOptions& options) { CheckOptions(RadonOptionTable(), options); }

namespace {

// The centres of the occupied bird's-eye cells within max_range.
std::vector<Eigen::Vector2d> OccupiedCells(const std::vector<RadarPoint>& points, const RadonOptions& options) {
  std::unordered_set<std::int64_t> seen;
  std::vector<Eigen::Vector2d> cells;
  for (const RadarPoint& point : points) {
    if (!(point.position.head<2>().norm() < options.max_range)) continue;
    const std::int64_t x = FloorToInt(point.position.x() / options.cell);
    const std::int64_t y = FloorToInt(point.position.y() / options.cell);
    if (seen.insert(PackVoxelKey(x, y, 0)).second) {
      cells.emplace_back((double(x) + 0.5) * options.cell, (double(y) + 0.5) * options.cell);
    }
  }
  return cells;
}

// (1 - cosine) / 2 of the two matrices with the query's rows shifted:
// 0 the same, 1/2 unrelated, 1 opposite; 1 when either is all zero.
double RowDistance(const Eigen::MatrixXd& query, const Eigen::MatrixXd& candidate, int shift) {
  const int rows = int(query.rows());
  const double norms = query.norm() * candidate.norm();
  if (norms <= 0.0) return 1.0;
  double dot = 0.0;
  for (int k = 0; k < rows; ++k) dot += query.row(k).dot(candidate.row((k + shift) % rows));
  return 0.5 * (1.0 - dot / norms);
}

}  // namespace

RadonDescriptor MakeRadonDescriptor(const std::vector<RadarPoint>& points, const RadonOptions& options) {
  ValidateRadonOptions(options);
  const std::vector<Eigen::Vector2d> cells = OccupiedCells(points, options);
  const int bins = options.offsets, frequencies = options.offsets / 2;
  Eigen::MatrixXd sinogram = Eigen::MatrixXd::Zero(options.angles, bins);
  for (int a = 0; a < options.angles; ++a) {
    const double theta = M_PI * a / options.angles;
    const Eigen::Vector2d direction(std::cos(theta), std::sin(theta));
    for (const Eigen::Vector2d& cell : cells) {
      const double s = (cell.dot(direction) + options.max_range) / (2.0 * options.max_range);
      sinogram(a, std::min(bins - 1, std::max(0, int(s * bins)))) += 1.0;
    }
  }
  // The DFT magnitudes of each projection but its mean (the cell count, the
  // same for every direction); a few thousand terms, no FFT needed.
  RadonDescriptor descriptor;
  descriptor.spectra = Eigen::MatrixXd::Zero(options.angles, frequencies);
  for (int k = 1; k <= frequencies; ++k) {
    Eigen::VectorXcd basis(bins);
    for (int s = 0; s < bins; ++s) basis[s] = std::polar(1.0, -2.0 * M_PI * k * s / bins);
    descriptor.spectra.col(k - 1) = (sinogram.cast<std::complex<double>>() * basis).cwiseAbs();
  }
  // The key is the mean over directions; the rows keep what differs between
  // directions (their deviation from that mean), which the yaw aligns.
  descriptor.key = descriptor.spectra.colwise().mean().transpose();
  descriptor.spectra.rowwise() -= descriptor.key.transpose();
  if (descriptor.key.norm() > 0.0) descriptor.key.normalize();
  return descriptor;
}

RadonMatch CompareRadonDescriptors(const RadonDescriptor& query, const RadonDescriptor& candidate,
                                   const RadonOptions& options) {
  ValidateRadonOptions(options);
  const auto same_shape = [&](const Eigen::MatrixXd& m) {
    return m.rows() == options.angles && m.cols() == options.offsets / 2;
  };
  if (!same_shape(query.spectra) || !same_shape(candidate.spectra)) {
    throw std::invalid_argument("radon descriptor: descriptors of another size than the options'");
  }
  RadonMatch best;
  for (int shift = 0; shift < options.angles; ++shift) {
    const double distance = RowDistance(query.spectra, candidate.spectra, shift);
    if (distance < best.distance) {
      best.distance = distance;
      best.shift = shift;
    }
  }
  best.yaw = best.shift * M_PI / options.angles;
  return best;
}

namespace {

struct RadonDescription final : PlaceDescription {
  RadonDescriptor descriptor;
};

}  // namespace

RadonPlaceDescriptor::RadonPlaceDescriptor(const RadonOptions& options, double max_distance)
    : options_(options), max_distance_(max_distance) {
  ValidateRadonOptions(options_);
}

std::shared_ptr<const PlaceDescription> RadonPlaceDescriptor::Describe(const std::vector<RadarPoint>& submap) const {
  auto description = std::make_shared<RadonDescription>();
  description->descriptor = MakeRadonDescriptor(submap, options_);
  description->key = description->descriptor.key;
  return description;
}

PlaceComparison RadonPlaceDescriptor::Compare(const PlaceDescription& query, const PlaceDescription& candidate) const {
  const RadonMatch match =
      CompareRadonDescriptors(dynamic_cast<const RadonDescription&>(query).descriptor,
                              dynamic_cast<const RadonDescription&>(candidate).descriptor, options_);
  return {match.distance, {match.yaw, match.yaw - M_PI}};  // known up to pi
}

}  // namespace radargauss
