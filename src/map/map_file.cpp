// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/map/map_file.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/Geometry>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"

namespace radargauss {

namespace {

constexpr char kMagic[8] = {'R', 'G', 'A', 'U', 'S', 'M', 'A', 'P'};
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8;
constexpr std::size_t kGaussianBytesV2 = 3 * 8 + 6 * 8 + 4 + 4 + 3 * 8 + 4 + 16 * 8;
constexpr std::size_t kGaussianBytes = kGaussianBytesV2 + 3 * 8;  // and the fit's statistics

template <typename T>
void Put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

class Reader {
 public:
  explicit Reader(const std::string& bytes) : bytes_(bytes) {}
  std::size_t position() const { return position_; }
  template <typename T>
  T Get() {
    T value;
    std::memcpy(&value, bytes_.data() + position_, sizeof(T));
    position_ += sizeof(T);
    return value;
  }

 private:
  const std::string& bytes_;
  std::size_t position_ = 0;
};

std::uint32_t Crc32(const char* data, std::size_t size) {
  uLong crc = crc32(0L, Z_NULL, 0);
  // zlib takes uInt lengths: feed large buffers in pieces.
  while (size > 0) {
    const uInt piece = static_cast<uInt>(std::min<std::size_t>(size, 1u << 30));
    crc = crc32(crc, reinterpret_cast<const Bytef*>(data), piece);
    data += piece;
    size -= piece;
  }
  return static_cast<std::uint32_t>(crc);
}

}  // namespace

void WriteMap(const std::string& path, const GaussianMap& map) {
  std::string bytes;
  bytes.reserve(kHeaderBytes + map.gaussians.size() * kGaussianBytes + 4);
  bytes.append(kMagic, 8);
  Put<std::uint32_t>(bytes, kMapFileVersion);
  Put<std::uint8_t>(bytes, static_cast<std::uint8_t>(map.incidence));
  bytes.append(3, '\0');
  Put<std::uint64_t>(bytes, map.gaussians.size());
  for (const Gaussian& g : map.gaussians) {
    for (int i = 0; i < 3; ++i) Put<double>(bytes, g.mean[i]);
    for (int r = 0; r < 3; ++r) {
      for (int c = r; c < 3; ++c) Put<double>(bytes, g.covariance(r, c));
    }
    Put<std::uint32_t>(bytes, g.point_count);
    Put<std::int32_t>(bytes, g.rcs.degree);
    Put<double>(bytes, g.rcs.median);
    Put<double>(bytes, g.rcs.scale);
    Put<double>(bytes, g.rcs.fit_rmse);
    Put<std::uint32_t>(bytes, g.rcs.inliers);
    for (const double c : g.rcs.coefficients) Put<double>(bytes, c);
    Put<double>(bytes, g.rcs.spread_db);
    Put<double>(bytes, g.rcs.explained);
    Put<double>(bytes, g.rcs.mean_offset_db);
  }
  Put<std::uint64_t>(bytes, map.places.size());
  for (const MapPlace& place : map.places) {
    for (const double q : place.pose.rotation().quaternion().coeffs()) Put<double>(bytes, q);
    for (int i = 0; i < 3; ++i) Put<double>(bytes, place.pose.translation()[i]);
    Put<std::uint64_t>(bytes, place.points.size());
    for (const RadarPoint& point : place.points) {
      for (int i = 0; i < 3; ++i) Put<float>(bytes, float(point.position[i]));
      Put<float>(bytes, float(point.rcs));
    }
  }
  Put<std::uint32_t>(bytes, Crc32(bytes.data(), bytes.size()));
  WriteFileAtomically(
      path, [&](std::ostream& out) { out.write(bytes.data(), std::streamsize(bytes.size())); },
      /*binary=*/true);
}

namespace {

// The bounds of map_file.hpp; `fail` makes the error naming the Gaussian.
template <typename Fail>
void ValidateGaussian(const Gaussian& g, const Fail& fail) {
  if (!g.mean.allFinite() || !g.covariance.allFinite()) throw fail("non-finite mean or covariance");
  if (g.mean.cwiseAbs().maxCoeff() > kMaxMapCoordinate) {
    throw fail("mean beyond " + std::to_string(int(kMaxMapCoordinate)) + " m of the origin");
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(g.covariance, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d variances = solver.eigenvalues();
  if (!(variances.minCoeff() >= kMinMapStd * kMinMapStd) || !(variances.maxCoeff() <= kMaxMapStd * kMaxMapStd)) {
    throw fail("covariance with principal stds outside [1e-4, 100] m (or not positive definite)");
  }
  if (g.rcs.degree < -1 || g.rcs.degree > kMaxShDegree) throw fail("SH degree out of range");
  const bool rcs_finite =
      std::isfinite(g.rcs.median) && std::isfinite(g.rcs.scale) && std::isfinite(g.rcs.fit_rmse) &&
      std::isfinite(g.rcs.spread_db) && std::isfinite(g.rcs.mean_offset_db) &&
      std::all_of(g.rcs.coefficients.begin(), g.rcs.coefficients.end(), [](double c) { return std::isfinite(c); });
  if (!rcs_finite) throw fail("non-finite RCS model");
  if (g.rcs.degree >= 0 && !(g.rcs.scale > 0.0)) throw fail("RCS model with scale <= 0");
  if (!(g.rcs.spread_db >= 0.0) || !(g.rcs.explained >= 0.0 && g.rcs.explained <= 1.0)) {
    throw fail("RCS fit statistics out of range (spread < 0 dB or explained share outside [0, 1])");
  }
}

// The places section, which must end at `end` (the CRC).
std::vector<MapPlace> ReadPlaces(Reader& reader, std::size_t end, const std::string& path) {
  constexpr std::size_t kPoseBytes = 7 * 8 + 8, kPointBytes = 4 * 4;
  const std::uint64_t count = reader.Get<std::uint64_t>();
  if (count > (end - reader.position()) / kPoseBytes) throw FileError(path, "truncated places section");
  std::vector<MapPlace> places(count);
  for (std::uint64_t k = 0; k < count; ++k) {
    if (end - reader.position() < kPoseBytes) throw FileError(path, "truncated places section");
    double q[4], t[3];
    for (double& v : q) v = reader.Get<double>();
    for (double& v : t) v = reader.Get<double>();
    const std::uint64_t points = reader.Get<std::uint64_t>();
    const Eigen::Quaterniond quaternion(q[3], q[0], q[1], q[2]);
    const auto fail = [&](const std::string& what) {
      return FileError(path, "place " + std::to_string(k) + ": " + what);
    };
    if (!quaternion.coeffs().allFinite() || std::abs(quaternion.norm() - 1.0) > 1e-6 ||
        !Eigen::Vector3d(t[0], t[1], t[2]).allFinite()) {
      throw fail("non-finite or non-unit pose");
    }
    if (Eigen::Vector3d(t[0], t[1], t[2]).cwiseAbs().maxCoeff() > kMaxMapCoordinate) {
      throw fail("position beyond " + std::to_string(int(kMaxMapCoordinate)) + " m of the origin");
    }
    if (points > (end - reader.position()) / kPointBytes) throw FileError(path, "truncated places section");
    places[k].pose = SE3d(SO3d(quaternion), Eigen::Vector3d(t[0], t[1], t[2]));
    places[k].points.resize(points);
    for (RadarPoint& point : places[k].points) {
      float v[4];
      for (float& x : v) x = reader.Get<float>();
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]) || !std::isfinite(v[3])) {
        throw fail("non-finite point");
      }
      if (std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])}) > kMaxPlaceRadius) {
        throw fail("point beyond " + std::to_string(int(kMaxPlaceRadius)) + " m of its place");
      }
      point.position = Eigen::Vector3d(v[0], v[1], v[2]);
      point.rcs = v[3];
    }
  }
  if (reader.position() != end) throw FileError(path, "trailing bytes after the places section");
  return places;
}

}  // namespace

GaussianMap ReadMap(const std::string& path) {
  const std::string bytes = ReadFileBytes(path, "map");
  if (bytes.size() < kHeaderBytes + 4 || std::memcmp(bytes.data(), kMagic, 8) != 0) {
    throw FileError(path, "not a radargauss map (bad magic or too short)");
  }
  Reader reader(bytes);
  reader.Get<std::uint64_t>();  // magic
  const std::uint32_t version = reader.Get<std::uint32_t>();
  if (version < 1 || version > kMapFileVersion) {
    throw FileError(path, "map version " + std::to_string(version) + ", this build reads versions 1 to " +
                              std::to_string(kMapFileVersion) + " (rebuild the map)");
  }
  const std::uint8_t incidence = reader.Get<std::uint8_t>();
  reader.Get<std::uint8_t>();
  reader.Get<std::uint16_t>();
  const std::uint64_t count = reader.Get<std::uint64_t>();
  const std::size_t places_bytes = version == 1 ? 0 : 8;  // at least the place count
  const std::size_t gaussian_bytes = version < 3 ? kGaussianBytesV2 : kGaussianBytes;
  if (count > (bytes.size() - kHeaderBytes) / gaussian_bytes ||
      (version == 1 && bytes.size() != kHeaderBytes + count * gaussian_bytes + 4) ||
      bytes.size() < kHeaderBytes + count * gaussian_bytes + places_bytes + 4) {
    throw FileError(path, "truncated or oversized: " + std::to_string(bytes.size()) + " bytes for " +
                              std::to_string(count) + " Gaussians");
  }
  std::uint32_t stored_crc;
  std::memcpy(&stored_crc, bytes.data() + bytes.size() - 4, 4);
  if (stored_crc != Crc32(bytes.data(), bytes.size() - 4)) {
    throw FileError(path, "CRC32 mismatch: the map file is corrupt");
  }
  if (incidence > 1) throw FileError(path, "unknown incidence model " + std::to_string(incidence));
  GaussianMap map;
  map.incidence = static_cast<IncidenceModel>(incidence);
  map.gaussians.resize(count);
  for (std::uint64_t k = 0; k < count; ++k) {
    Gaussian& g = map.gaussians[k];
    for (int i = 0; i < 3; ++i) g.mean[i] = reader.Get<double>();
    for (int r = 0; r < 3; ++r) {
      for (int c = r; c < 3; ++c) g.covariance(r, c) = g.covariance(c, r) = reader.Get<double>();
    }
    g.point_count = reader.Get<std::uint32_t>();
    g.rcs.degree = reader.Get<std::int32_t>();
    g.rcs.median = reader.Get<double>();
    g.rcs.scale = reader.Get<double>();
    g.rcs.fit_rmse = reader.Get<double>();
    g.rcs.inliers = reader.Get<std::uint32_t>();
    for (double& c : g.rcs.coefficients) c = reader.Get<double>();
    if (version >= 3) {
      g.rcs.spread_db = reader.Get<double>();
      g.rcs.explained = reader.Get<double>();
      g.rcs.mean_offset_db = reader.Get<double>();
    } else {  // no statistics: the fit's rmse in dB, view-dependent (docs/design/map.md, "RCS confidence")
      g.rcs.spread_db = g.rcs.fit_rmse * g.rcs.scale;
    }
    const auto fail = [&](const std::string& what) {
      return FileError(path, "Gaussian " + std::to_string(k) + ": " + what);
    };
    ValidateGaussian(g, fail);
  }
  if (version > 1) map.places = ReadPlaces(reader, bytes.size() - 4, path);
  return map;
}

void ExportPly(const std::string& path, const GaussianMap& map) {
  constexpr int kRest = 45;
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\n"
         << "comment radargauss Gaussian-RCS map: grey level = 0.5 + 0.5 * normalised RCS\n"
         << "element vertex " << map.gaussians.size() << "\n";
  for (const char* name : {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"}) {
    header << "property float " << name << "\n";
  }
  for (int i = 0; i < kRest; ++i) header << "property float f_rest_" << i << "\n";
  for (const char* name : {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"}) {
    header << "property float " << name << "\n";
  }
  header << "end_header\n";
  const float opacity_logit = std::log(0.8f / 0.2f);
  WriteFileAtomically(
      path,
      [&](std::ostream& out) {
        out << header.str();
        std::vector<float> row;
        for (const Gaussian& g : map.gaussians) {
          Eigen::Vector3d std_devs;
          Eigen::Matrix3d axes;
          PrincipalAxes(g.covariance, std_devs, axes);
          const Eigen::Quaterniond rotation(axes);
          float dc = 0.0f;
          float rest[15] = {};
          if (g.rcs.valid()) {
            dc = float(0.5 * g.rcs.coefficients[0]);
            for (int j = 1; j < ShCoefficientCount(g.rcs.degree); ++j) {
              rest[j - 1] = float(0.5 * g.rcs.coefficients[j]);
            }
          }
          row.assign({float(g.mean.x()), float(g.mean.y()), float(g.mean.z()), 0.0f, 0.0f, 0.0f, dc, dc, dc});
          for (int channel = 0; channel < 3; ++channel) row.insert(row.end(), rest, rest + 15);
          row.push_back(opacity_logit);
          for (int i = 0; i < 3; ++i) row.push_back(float(std::log(std::max(std_devs[i], 1e-9))));
          row.insert(row.end(), {float(rotation.w()), float(rotation.x()), float(rotation.y()), float(rotation.z())});
          out.write(reinterpret_cast<const char*>(row.data()), std::streamsize(row.size() * sizeof(float)));
        }
      },
      /*binary=*/true);
}

}  // namespace radargauss
