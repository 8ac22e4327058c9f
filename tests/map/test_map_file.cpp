// SPDX-License-Identifier: BSD-3-Clause
// Map files: bit-exact round trips, corrupt files, the 3DGS-layout PLY.

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include "radargauss/core/error.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/temp_dir.hpp"
#include "support/map_fixtures.hpp"

namespace radargauss {
namespace {

using testing::RandomUnitVector;
using MapFiles = testing::TempDirTest;

// ---------------------------------------------------------------------------
// Map files.

GaussianMap ExampleMap() {
  const Planted planted = PlantGaussians(1, 5);
  GaussianMap map;
  map.incidence = IncidenceModel::kView;
  map.gaussians = planted.gaussians;
  std::mt19937 rng(6);
  std::normal_distribution<double> normal;
  for (std::size_t i = 0; i < map.gaussians.size(); ++i) {
    Gaussian& g = map.gaussians[i];
    g.point_count = std::uint32_t(10 + i);
    if (i % 3 == 0) continue;  // no model
    g.rcs.degree = int(i % 4);
    g.rcs.median = normal(rng);
    g.rcs.scale = 1.0 + std::abs(normal(rng));
    g.rcs.fit_rmse = 0.1;
    g.rcs.inliers = 9;
    g.rcs.spread_db = 0.5 + std::abs(normal(rng));
    g.rcs.explained = 0.1 * double(i % 10);
    g.rcs.mean_offset_db = normal(rng);
    for (int j = 0; j < ShCoefficientCount(g.rcs.degree); ++j) g.rcs.coefficients[j] = normal(rng);
  }
  return map;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void AppendCrc(std::string& bytes) {
  const std::uint32_t crc =
      std::uint32_t(crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), uInt(bytes.size())));
  bytes.append(reinterpret_cast<const char*>(&crc), 4);
}

// The bytes of an older version of a current file, laid out by hand from
// map_file.hpp: version 2 without the fit statistics (24 bytes at the end of
// each Gaussian), version 1 without the places section either.
std::string OlderVersion(const std::string& current, int version) {
  constexpr std::size_t kHeader = 24, kGaussianV2 = 236, kStatistics = 24;
  std::uint64_t count;
  std::memcpy(&count, current.data() + 16, 8);
  std::string out = current.substr(0, kHeader);
  out[8] = char(version);
  for (std::uint64_t k = 0; k < count; ++k)
    out += current.substr(kHeader + k * (kGaussianV2 + kStatistics), kGaussianV2);
  if (version == 2) {
    const std::size_t places = kHeader + count * (kGaussianV2 + kStatistics);
    out += current.substr(places, current.size() - 4 - places);
  }
  AppendCrc(out);
  return out;
}

TEST_F(MapFiles, RoundTripIsBitExact) {
  const GaussianMap map = ExampleMap();
  WriteMap(Path("a.rgm"), map);
  const GaussianMap read = ReadMap(Path("a.rgm"));
  EXPECT_EQ(read.incidence, map.incidence);
  ASSERT_EQ(read.gaussians.size(), map.gaussians.size());
  for (std::size_t i = 0; i < map.gaussians.size(); ++i) {
    EXPECT_EQ(read.gaussians[i].mean, map.gaussians[i].mean);
    EXPECT_EQ(read.gaussians[i].covariance, map.gaussians[i].covariance);
    EXPECT_EQ(read.gaussians[i].rcs.coefficients, map.gaussians[i].rcs.coefficients);
    EXPECT_EQ(read.gaussians[i].rcs.degree, map.gaussians[i].rcs.degree);
    EXPECT_EQ(read.gaussians[i].rcs.spread_db, map.gaussians[i].rcs.spread_db);
    EXPECT_EQ(read.gaussians[i].rcs.explained, map.gaussians[i].rcs.explained);
    EXPECT_EQ(read.gaussians[i].rcs.mean_offset_db, map.gaussians[i].rcs.mean_offset_db);
  }
  WriteMap(Path("b.rgm"), read);
  EXPECT_EQ(ReadBytes(Path("a.rgm")), ReadBytes(Path("b.rgm")));
}

TEST_F(MapFiles, CorruptFilesGiveClearErrors) {
  WriteMap(Path("good.rgm"), ExampleMap());
  const std::string good = ReadBytes(Path("good.rgm"));
  const auto expect_error = [&](const std::string& bytes, const std::string& fault) {
    const std::string path = WriteFile("bad.rgm", bytes);
    try {
      ReadMap(path);
      ADD_FAILURE() << "accepted a map with " << fault;
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u) << e.what();
    }
  };
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  expect_error(flipped, "CRC32 mismatch");
  expect_error(good.substr(0, good.size() - 100), "truncated");
  expect_error(good.substr(0, 10), "too short");
  std::string version = good;
  version[8] = 7;
  expect_error(version, "map version 7, this build reads versions 1 to 3");
  GaussianMap unexplained = ExampleMap();
  unexplained.gaussians[1].rcs.explained = 1.5;
  WriteMap(Path("unexplained.rgm"), unexplained);
  expect_error(ReadBytes(Path("unexplained.rgm")), "Gaussian 1: RCS fit statistics out of range");
  expect_error("PLY?" + good, "bad magic");
  EXPECT_THROW(ReadMap(Path("absent.rgm")), DataError);
}

// A SLAM map's places: poses bit-exact, points in float32; version-1 (no
// places section) and version-2 (no fit statistics) files still read; a
// truncated places section is an error.
TEST_F(MapFiles, PlacesRoundTripAndVersionsOneAndTwoStillRead) {
  GaussianMap map = ExampleMap();
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  for (int k = 0; k < 3; ++k) {
    MapPlace place;
    place.pose = SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 10 * normal(rng), normal(rng), 0.1 * normal(rng),
                            0.1 * normal(rng), 0.1 * normal(rng), normal(rng))
                               .finished());
    for (int i = 0; i < 5 + k; ++i) {
      RadarPoint point;
      point.position = 20.0 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
      point.rcs = 5.0 * normal(rng);
      place.points.push_back(point);
    }
    map.places.push_back(place);
  }
  WriteMap(Path("places.rgm"), map);
  const GaussianMap read = ReadMap(Path("places.rgm"));
  ASSERT_EQ(read.places.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(read.places[k].pose.translation(), map.places[k].pose.translation());
    // Renormalised on reading: equal to the last bit or two.
    EXPECT_LT(
        (read.places[k].pose.rotation().quaternion().coeffs() - map.places[k].pose.rotation().quaternion().coeffs())
            .norm(),
        1e-15);
    ASSERT_EQ(read.places[k].points.size(), map.places[k].points.size());
    for (std::size_t i = 0; i < map.places[k].points.size(); ++i) {
      EXPECT_EQ(read.places[k].points[i].position, map.places[k].points[i].position.cast<float>().cast<double>());
      EXPECT_EQ(read.places[k].points[i].rcs, double(float(map.places[k].points[i].rcs)));
    }
  }
  // Versions 1 and 2: the same Gaussians and places (version 2), and for
  // the fit statistics the fit's rmse in dB, explained 1 and offset 0.
  for (const int version : {1, 2}) {
    const GaussianMap old = ReadMap(WriteFile("old.rgm", OlderVersion(ReadBytes(Path("places.rgm")), version)));
    ASSERT_EQ(old.gaussians.size(), map.gaussians.size());
    EXPECT_EQ(old.places.size(), version == 1 ? 0u : 3u);
    for (std::size_t i = 0; i < map.gaussians.size(); ++i) {
      const RcsModel& a = old.gaussians[i].rcs;
      const RcsModel& b = map.gaussians[i].rcs;
      EXPECT_EQ(old.gaussians[i].mean, map.gaussians[i].mean);
      EXPECT_EQ(a.coefficients, b.coefficients);
      EXPECT_EQ(a.inliers, b.inliers);
      EXPECT_EQ(a.spread_db, b.fit_rmse * b.scale);
      EXPECT_EQ(a.explained, 1.0);
      EXPECT_EQ(a.mean_offset_db, 0.0);
    }
  }
  // The places file cut inside its last point, with a CRC that matches the cut.
  std::string cut = ReadBytes(Path("places.rgm"));
  cut.erase(cut.size() - 4 - 8);
  AppendCrc(cut);
  try {
    ReadMap(WriteFile("cut.rgm", cut));
    ADD_FAILURE() << "accepted a truncated places section";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("places section"), std::string::npos) << e.what();
  }
}

// A place lies within the map's coordinates and its points within a submap's
// reach of it (WriteMap writes what it is given, as a hostile file would be).
TEST_F(MapFiles, PlacesOutsideTheirBoundsAreRefused) {
  const auto error_of = [&](const Eigen::Vector3d& position, const Eigen::Vector3d& point) -> std::string {
    GaussianMap map = ExampleMap();
    MapPlace place;
    place.pose = SE3d(SO3d(), Eigen::Vector3d(1.0, 2.0, 0.0));
    for (int k = 0; k < 4; ++k) place.points.push_back(RadarPoint{});
    map.places.push_back(place);
    place.pose = SE3d(SO3d(), position);
    place.points[2].position = point;
    map.places.push_back(place);
    WriteMap(Path("p.rgm"), map);
    try {
      return std::to_string(ReadMap(Path("p.rgm")).places.size());
    } catch (const DataError& e) {
      return e.what();
    }
  };
  const std::string path = Path("p.rgm");
  EXPECT_EQ(error_of(Eigen::Vector3d(5e6, -5e6, 0.0), Eigen::Vector3d(2e4, -2e4, 5.0)), "2");
  EXPECT_EQ(error_of(Eigen::Vector3d(1e300, 0.0, 0.0), Eigen::Vector3d::Zero()),
            path + ": place 1: position beyond 10000000 m of the origin");
  EXPECT_EQ(error_of(Eigen::Vector3d(0.0, 0.0, -2e7), Eigen::Vector3d::Zero()),
            path + ": place 1: position beyond 10000000 m of the origin");
  EXPECT_EQ(error_of(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 2e5, 0.0)),
            path + ": place 1: point beyond 100000 m of its place");
  EXPECT_EQ(error_of(Eigen::Vector3d::Zero(), Eigen::Vector3d(-3e9, 0.0, 0.0)),
            path + ": place 1: point beyond 100000 m of its place");
}

TEST_F(MapFiles, PlyHasThe3dgsLayout) {
  const GaussianMap map = ExampleMap();
  ExportPly(Path("map.ply"), map);
  const std::string bytes = ReadBytes(Path("map.ply"));
  const std::size_t end = bytes.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  const std::string header = bytes.substr(0, end);
  std::size_t properties = 0;
  for (std::size_t at = header.find("property float"); at != std::string::npos;
       at = header.find("property float", at + 1)) {
    ++properties;
  }
  EXPECT_EQ(properties, 62u);
  for (const char* name : {"f_dc_0", "f_rest_44", "opacity", "scale_2", "rot_3", "nz"}) {
    EXPECT_NE(header.find(std::string("property float ") + name + "\n"), std::string::npos) << name;
  }
  const std::size_t data = end + std::string("end_header\n").size();
  ASSERT_EQ(bytes.size() - data, map.gaussians.size() * 62 * sizeof(float));
  // Vertex 1: position, grey level 0.5 c_0, scales = log principal stds, and
  // rotation * diag(exp(2 scale)) * rotation^T = covariance.
  float v[62];
  std::memcpy(v, bytes.data() + data + 62 * sizeof(float), sizeof(v));
  const Gaussian& g = map.gaussians[1];
  EXPECT_NEAR(v[0], g.mean.x(), 1e-5);
  EXPECT_NEAR(v[6], 0.5 * g.rcs.coefficients[0], 1e-6);
  EXPECT_EQ(v[6], v[8]);
  const Eigen::Quaterniond q(v[58], v[59], v[60], v[61]);
  const Eigen::Vector3d variances(std::exp(2 * v[55]), std::exp(2 * v[56]), std::exp(2 * v[57]));
  const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
  EXPECT_LT((R * variances.asDiagonal() * R.transpose() - g.covariance).norm(), 1e-5);
}

}  // namespace
}  // namespace radargauss
