// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/types.hpp"

#include <cmath>

#include "radargauss/core/error.hpp"

namespace radargauss {

void ValidateScan(const RadarScan& scan, const std::string& source) {
  if (!std::isfinite(scan.timestamp)) throw FileError(source, "non-finite scan timestamp");
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const RadarPoint& p = scan.points[i];
    const auto fail = [&](const std::string& what) {
      return FileError(source, "point " + std::to_string(i) + ": " + what);
    };
    if (!p.position.allFinite()) throw fail("non-finite position");
    if (!std::isfinite(p.doppler)) throw fail("non-finite Doppler");
    if (!std::isfinite(p.rcs)) throw fail("non-finite RCS");
    if (p.std_dev) {
      const MeasurementStd& s = *p.std_dev;
      for (const float v : {s.range, s.azimuth, s.elevation, s.doppler}) {
        if (!std::isfinite(v) || v < 0.0f) throw fail("standard deviation not finite and >= 0");
      }
    }
  }
}

void LowerElevations(RadarScan& scan, double angle) {
  const double cos_a = std::cos(angle), sin_a = std::sin(angle);
  for (RadarPoint& point : scan.points) {
    // (cos el, sin el) turned by -angle in the point's vertical plane.
    const Eigen::Vector3d& p = point.position;
    const double horizontal = p.head<2>().norm();
    const double lowered = horizontal * cos_a + p.z() * sin_a;
    const double z = p.z() * cos_a - horizontal * sin_a;
    const double scale = horizontal > 0.0 ? lowered / horizontal : 0.0;
    point.position = Eigen::Vector3d(p.x() * scale, p.y() * scale, z);
  }
}

}  // namespace radargauss
