// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/types.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "radargauss/core/error.hpp"

namespace radargauss {
namespace {

RadarScan GoodScan() {
  RadarScan scan;
  scan.timestamp = 1.0;
  for (int i = 0; i < 3; ++i) {
    RadarPoint p;
    p.position = Eigen::Vector3d(10.0 + i, 1.0, 0.5);
    p.doppler = -3.0;
    p.rcs = 5.0;
    p.std_dev = MeasurementStd{0.1f, 0.01f, 0.02f, 0.05f};
    scan.points.push_back(p);
  }
  return scan;
}

TEST(ValidateScan, AcceptsGoodAndEmptyScans) {
  EXPECT_NO_THROW(ValidateScan(GoodScan(), "scan.pcd"));
  EXPECT_NO_THROW(ValidateScan(RadarScan{}, "empty.pcd"));
}

TEST(ValidateScan, RejectsNonFiniteValuesNamingSourceAndPoint) {
  const auto expect_rejected = [](RadarScan scan, const std::string& fault) {
    try {
      ValidateScan(scan, "scan.pcd");
      FAIL() << "accepted a scan with " << fault;
    } catch (const DataError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("scan.pcd: point 1: ", 0), 0u) << message;
      EXPECT_NE(message.find(fault), std::string::npos) << message;
    }
  };
  RadarScan scan = GoodScan();
  scan.points[1].position.y() = NAN;
  expect_rejected(scan, "position");
  scan = GoodScan();
  scan.points[1].doppler = INFINITY;
  expect_rejected(scan, "Doppler");
  scan = GoodScan();
  scan.points[1].rcs = -INFINITY;
  expect_rejected(scan, "RCS");
  scan = GoodScan();
  scan.points[1].std_dev->range = -1.0f;
  expect_rejected(scan, "standard deviation");
}

}  // namespace
}  // namespace radargauss
