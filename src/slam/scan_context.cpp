// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/scan_context.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "radargauss/core/names.hpp"

namespace radargauss {

namespace {
constexpr NamedValue<ScanContextChannel> kChannelNames[] = {{ScanContextChannel::kGeometric, "geometric"},
                                                            {ScanContextChannel::kRcs, "rcs"},
                                                            {ScanContextChannel::kBoth, "both"}};
}  // namespace

std::string ToString(ScanContextChannel channel) { return NameOf(kChannelNames, channel); }
ScanContextChannel ScanContextChannelFromString(const std::string& name) {
  return ValueNamed(kChannelNames, name, "Scan Context channel");
}
std::vector<std::string> ScanContextChannelNames() { return NamesOf(kChannelNames); }

const OptionTable<ScanContextOptions>& ScanContextOptionTable() {
  using O = ScanContextOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "rings", rings).In(1, 1000).Help("Scan Context: rings"),
      RADARGAUSS_OPTION(O, "sectors", sectors).In(1, 1000).Help("Scan Context: sectors"),
      RADARGAUSS_OPTION(O, "max_range", max_range)
          .Above(0.0)
          .Unit("m")
          .Help("Scan Context: points beyond are left out"),
      RADARGAUSS_OPTION(O, "rcs_floor", rcs_floor)
          .Unit("dBsm")
          .Help("Scan Context: the RCS channel holds rcs - floor, at least 0"),
  };
  return table;
}

void ValidateScanContextOptions(const ScanContextOptions& options) { CheckOptions(ScanContextOptionTable(), options); }

ScanContext MakeScanContext(const std::vector<RadarPoint>& points, const ScanContextOptions& options) {
  ValidateScanContextOptions(options);
  ScanContext context;
  context.geometric = Eigen::MatrixXd::Zero(options.rings, options.sectors);
  context.rcs = Eigen::MatrixXd::Zero(options.rings, options.sectors);
  context.ring_key = Eigen::VectorXd::Zero(options.rings);
  double lowest = std::numeric_limits<double>::infinity();
  for (const RadarPoint& point : points) {
    if (point.position.head<2>().norm() < options.max_range) lowest = std::min(lowest, point.position.z());
  }
  for (const RadarPoint& point : points) {
    const Eigen::Vector3d& p = point.position;
    const double range = p.head<2>().norm();
    if (!(range < options.max_range)) continue;  // NaN too
    const int ring = std::min(options.rings - 1, int(range / options.max_range * options.rings));
    const double azimuth = std::atan2(p.y(), p.x()) + M_PI;  // [0, 2 pi]
    const int sector = std::min(options.sectors - 1, int(azimuth / (2.0 * M_PI) * options.sectors));
    // 1 m plus the height above the lowest point: every occupied bin counts.
    double& height = context.geometric(ring, sector);
    height = std::max(height, 1.0 + p.z() - lowest);
    double& rcs = context.rcs(ring, sector);
    rcs = std::max(rcs, point.rcs - options.rcs_floor);
  }
  for (int r = 0; r < options.rings; ++r) {
    context.ring_key[r] = double((context.geometric.row(r).array() > 0.0).count()) / options.sectors;
  }
  return context;
}

namespace {

// Mean cosine distance over the columns occupied in either, query column k
// against candidate column k + shift; a column occupied in one only counts 1,
// so that sparse descriptors do not match on the few columns they share.
double ShiftedDistance(const Eigen::MatrixXd& query, const Eigen::MatrixXd& candidate, int shift) {
  const int sectors = int(query.cols());
  double sum = 0.0;
  int count = 0;
  for (int k = 0; k < sectors; ++k) {
    const auto a = query.col(k);
    const auto b = candidate.col((k + shift) % sectors);
    const double na = a.norm(), nb = b.norm();
    if (na <= 0.0 && nb <= 0.0) continue;
    sum += na > 0.0 && nb > 0.0 ? 1.0 - a.dot(b) / (na * nb) : 1.0;
    ++count;
  }
  return count > 0 ? sum / count : 1.0;
}

}  // namespace

ScanContextMatch CompareScanContexts(const ScanContext& query, const ScanContext& candidate,
                                     const ScanContextOptions& options) {
  ValidateScanContextOptions(options);
  const auto same_shape = [&](const Eigen::MatrixXd& m) {
    return m.rows() == options.rings && m.cols() == options.sectors;
  };
  if (!same_shape(query.geometric) || !same_shape(candidate.geometric) || !same_shape(query.rcs) ||
      !same_shape(candidate.rcs)) {
    throw std::invalid_argument("scan context: descriptors of another size than the options'");
  }
  ScanContextMatch best;
  for (int shift = 0; shift < options.sectors; ++shift) {
    double distance = 0.0;
    switch (options.channel) {
      case ScanContextChannel::kGeometric:
        distance = ShiftedDistance(query.geometric, candidate.geometric, shift);
        break;
      case ScanContextChannel::kRcs:
        distance = ShiftedDistance(query.rcs, candidate.rcs, shift);
        break;
      case ScanContextChannel::kBoth:
        distance = 0.5 * (ShiftedDistance(query.geometric, candidate.geometric, shift) +
                          ShiftedDistance(query.rcs, candidate.rcs, shift));
        break;
    }
    if (distance < best.distance) {
      best.distance = distance;
      best.shift = shift;
    }
  }
  const double sector_width = 2.0 * M_PI / options.sectors;
  best.yaw = best.shift * sector_width;
  if (best.yaw > M_PI) best.yaw -= 2.0 * M_PI;
  return best;
}

namespace {

struct ScanContextDescription final : PlaceDescription {
  ScanContext context;
};

}  // namespace

ScanContextDescriptor::ScanContextDescriptor(const ScanContextOptions& options, double max_distance)
    : options_(options), max_distance_(max_distance) {
  ValidateScanContextOptions(options_);
}

std::shared_ptr<const PlaceDescription> ScanContextDescriptor::Describe(const std::vector<RadarPoint>& submap) const {
  auto description = std::make_shared<ScanContextDescription>();
  description->context = MakeScanContext(submap, options_);
  description->key = description->context.ring_key;
  return description;
}

PlaceComparison ScanContextDescriptor::Compare(const PlaceDescription& query, const PlaceDescription& candidate) const {
  const ScanContextMatch match =
      CompareScanContexts(dynamic_cast<const ScanContextDescription&>(query).context,
                          dynamic_cast<const ScanContextDescription&>(candidate).context, options_);
  return {match.distance, {match.yaw}};
}

}  // namespace radargauss
