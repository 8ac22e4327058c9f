// SPDX-License-Identifier: BSD-3-Clause
// Rig files: a round trip, the scans of two radars in one time order on the
// body's clock, and every bad rig refused in one line naming what is wrong.
#include "radargauss/io/rig.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <utility>
#include <string>
#include <vector>

#include "radargauss/core/error.hpp"
#include "radargauss/io/mcap.hpp"
#include "radargauss/io/pcd.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/io/rosbag.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

class RigFile : public testing::TempDirTest {
 protected:
  // A folder of scans at the given times (one point each), named by time.
  std::string ScanFolder(const std::string& name, const std::vector<double>& stamps) const {
    const std::string dir = Path(name);
    std::filesystem::create_directories(dir);
    for (const double stamp : stamps) {
      RadarScan scan;
      scan.timestamp = stamp;
      scan.has_doppler = true;
      RadarPoint point;
      point.position = Eigen::Vector3d(10.0, 0.0, 0.0);
      scan.points.push_back(point);
      char file[64];
      std::snprintf(file, sizeof(file), "/%.6f.pcd", stamp);
      WritePcdScan(dir + file, scan);
    }
    return dir;
  }

  // The one-line error of reading `text` as a rig.
  std::string ErrorOf(const std::string& text) const {
    const std::string path = WriteFile("bad.yaml", text);
    try {
      ReadRig(path);
    } catch (const DataError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      EXPECT_NE(message.find(path), std::string::npos) << message;
      return message;
    }
    ADD_FAILURE() << "read without an error:\n" << text;
    return "";
  }
};

TEST_F(RigFile, WrittenAndReadBackIsTheSameRig) {
  Rig rig;
  RigRadar front;
  front.name = "front";
  front.scans.sequence_dir = Path("front");
  front.body_from_radar = SE3d(SO3d::Exp(Eigen::Vector3d(0.01, -0.02, 0.3)), Eigen::Vector3d(3.7, 0.1, 0.5));
  front.clock_offset = 0.012;
  RigRadar rear = front;
  rear.name = "rear left";
  rear.scans.sequence_dir = Path("rear");
  rear.body_from_radar = SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, 2.4)), Eigen::Vector3d(-0.9, 0.9, 0.6));
  rear.clock_offset = -0.03;
  rig.radars = {front, rear};
  WriteRig(Path("rig.yaml"), rig);
  const Rig read = ReadRig(Path("rig.yaml"));
  ASSERT_EQ(read.radars.size(), 2u);
  for (std::size_t r = 0; r < 2; ++r) {
    const RigRadar &a = rig.radars[r], &b = read.radars[r];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.scans.sequence_dir, b.scans.sequence_dir);
    EXPECT_DOUBLE_EQ(a.clock_offset, b.clock_offset);
    EXPECT_LT((a.body_from_radar.translation() - b.body_from_radar.translation()).norm(), 1e-15);
    EXPECT_LT((a.body_from_radar.rotation().Inverse() * b.body_from_radar.rotation()).Log().norm(), 1e-15);
  }
}

TEST_F(RigFile, AMatrixMountingAndPathsBesideTheFile) {
  std::filesystem::create_directories(Path("rig"));
  const std::string path = WriteFile("rig/rig.yaml",
                                     "radars:\n"
                                     "  - name: left\n"
                                     "    sequence: scans/left\n"
                                     "    rotation: [[0, -1, 0], [1, 0, 0], [0, 0, 1]]\n"
                                     "    translation: [1, 2, 3]\n");
  const Rig rig = ReadRig(path);
  ASSERT_EQ(rig.radars.size(), 1u);
  EXPECT_EQ(rig.radars[0].scans.sequence_dir, Path("rig/scans/left"));
  EXPECT_LT((rig.radars[0].body_from_radar.rotation().Matrix().col(0) - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  EXPECT_EQ(rig.radars[0].body_from_radar.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(rig.radars[0].clock_offset, 0.0);
}

// Two radars, the second's clock 0.25 s behind the body's (offset -0.25):
// its scans come at their stamps plus 0.25, interleaved with the first's; a tie goes to
// the radar listed first (times exact in binary, so ties are ties).
TEST_F(RigFile, TheRadarsScansComeInOneTimeOrderOnTheBodysClock) {
  ScanFolder("a", {10.0, 10.5, 11.0, 11.5});
  ScanFolder("b", {9.875, 10.125, 10.75, 11.25});
  const std::string path = WriteFile("rig.yaml",
                                     "radars:\n"
                                     "  - {name: a, sequence: a, extrinsic: [0, 0, 0, 0, 0, 0, 1]}\n"
                                     "  - {name: b, sequence: b, extrinsic: [0, 0, 0, 0, 0, 0, 1], clock_offset: "
                                     "-0.25}\n");
  std::vector<std::pair<std::size_t, double>> order;
  ForEachRigScan(ReadRig(path), [&](std::size_t radar, RadarScan& scan, const std::string& source) {
    EXPECT_NE(source.find(radar == 0 ? "/a/" : "/b/"), std::string::npos) << source;
    order.emplace_back(radar, scan.timestamp);
  });
  const std::vector<std::pair<std::size_t, double>> expected = {{0, 10.0}, {1, 10.125}, {1, 10.375}, {0, 10.5},
                                                                {0, 11.0}, {1, 11.0},   {0, 11.5},   {1, 11.5}};
  ASSERT_EQ(order.size(), expected.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    EXPECT_EQ(order[k].first, expected[k].first) << k;
    EXPECT_EQ(order[k].second, expected[k].second) << k;
  }
  const std::string missing = WriteFile("missing.yaml",
                                        "radars:\n"
                                        "  - {name: a, sequence: a, extrinsic: [0, 0, 0, 0, 0, 0, 1]}\n"
                                        "  - {name: gone, sequence: nowhere, extrinsic: [0, 0, 0, 0, 0, 0, 1]}\n");
  try {
    ForEachRigScan(ReadRig(missing), [](std::size_t, RadarScan&, const std::string&) {});
    ADD_FAILURE() << "a radar without its folder was read";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("radar 'gone'"), std::string::npos) << e.what();
  }
}

// A rig whose radars are two PointCloud2 topics of one MCAP file: the
// scans come from their topics, in one order on the body's clock.
TEST_F(RigFile, TheRadarsOfOneBagAreItsTopics) {
  const std::string bag = Path("drive.mcap");
  {
    std::ofstream out(bag, std::ios::binary);
    McapWriter writer(out);
    const std::uint16_t schema = writer.AddSchema("sensor_msgs/msg/PointCloud2", "ros2msg", "");
    const std::uint16_t front = writer.AddChannel("/front/points", schema);
    const std::uint16_t rear = writer.AddChannel("/rear/points", schema);
    for (int k = 0; k < 4; ++k) {
      for (const auto& [channel, stamp] : {std::pair{front, 100.0 + 0.1 * k}, std::pair{rear, 100.04 + 0.1 * k}}) {
        RadarScan scan;
        scan.timestamp = stamp;
        scan.has_doppler = true;
        RadarPoint point;
        point.position = Eigen::Vector3d(5.0, channel == front ? 1.0 : -1.0, 0.0);
        scan.points.push_back(point);
        const std::uint64_t log_time = std::uint64_t(std::llround(stamp * 1e9));
        writer.Write(channel, log_time, log_time, EncodeRos2PointCloud2({stamp, "radar"}, EncodePointCloud2(scan)));
      }
    }
    writer.Finish();
  }
  const std::string path = WriteFile("rig.yaml",
                                     "bag: drive.mcap\n"
                                     "radars:\n"
                                     "  - {name: front, topic: /front/points, extrinsic: [3.7, 0, 0.5, 0, 0, 0, 1]}\n"
                                     "  - {name: rear, topic: /rear/points, extrinsic: [-1, 0, 0.5, 0, 0, 1, 0], "
                                     "clock_offset: 0.08}\n");
  const Rig rig = ReadRig(path);
  EXPECT_EQ(rig.radars[1].scans.bag, bag);
  std::vector<std::size_t> radars;
  std::vector<double> stamps;
  ForEachRigScan(rig, [&](std::size_t radar, RadarScan& scan, const std::string& source) {
    EXPECT_NE(source.find(radar == 0 ? ":/front/points#" : ":/rear/points#"), std::string::npos) << source;
    EXPECT_EQ(scan.points.front().position.y(), radar == 0 ? 1.0 : -1.0);
    radars.push_back(radar);
    stamps.push_back(scan.timestamp);
  });
  // The rear radar's stamps run 0.08 s ahead of the body's clock: 100.04 is 99.96 on it.
  EXPECT_EQ(radars, (std::vector<std::size_t>{1, 0, 1, 0, 1, 0, 1, 0}));
  ASSERT_EQ(stamps.size(), 8u);
  EXPECT_NEAR(stamps[0], 99.96, 1e-9);
  EXPECT_TRUE(std::is_sorted(stamps.begin(), stamps.end()));
}

TEST_F(RigFile, EveryBadRigIsRefusedInOneLine) {
  const std::string pose = "extrinsic: [0, 0, 0, 0, 0, 0, 1]";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"radars: []\n", "no radars"},
      {"bag: x.mcap\n", "no radars"},
      {"radars:\n  - {name: a, " + pose + "}\n", "radar 'a' has no scans"},
      {"radars:\n  - {name: a, sequence: s, topic: /t, " + pose + "}\n", "two sources of scans"},
      {"radars:\n  - {name: a, topic: /t, " + pose + "}\n", "needs the rig's bag"},
      {"bag: x.mcap\nradars:\n  - {name: a, topic: /t, " + pose + "}\n  - {name: b, topic: /t, " + pose + "}\n",
       "reads the topic /t of another radar"},
      {"radars:\n  - {name: a, sequence: s, " + pose + "}\n  - {name: a, sequence: t, " + pose + "}\n",
       "two radars are named 'a'"},
      {"radars:\n  - {sequence: s, " + pose + "}\n", "radar 1 has no name"},
      {"radars:\n  - {name: a, sequence: s, extrinsic: [0, 0, 0, 0, 0, 0.1, 1]}\n", "not a rotation"},
      {"radars:\n  - {name: a, sequence: s, rotation: [[1, 0, 0], [0, 1, 0], [0, 0.1, 1]], translation: [0, 0, 0]}\n",
       "not a rotation"},
      {"radars:\n  - {name: a, sequence: s, rotation: [[1, 0, 0], [0, 1, 0], [0, 0, -1]], translation: [0, 0, 0]}\n",
       "a reflection"},
      {"radars:\n  - {name: a, sequence: s}\n", "give its mounting once"},
      {"radars:\n  - {name: a, sequence: s, " + pose + ", rotation: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}\n",
       "give its mounting once"},
      {"radars:\n  - {name: a, sequence: s, extrinsic: [0, 0, 0, 0, 0, 1]}\n", "a list of 7 numbers"},
      {"radars:\n  - {name: a, sequence: s, extrinsic: [0, 0, .nan, 0, 0, 0, 1]}\n", "not finite"},
      {"radars:\n  - {name: a, sequence: s, extrinsic: [5000, 0, 0, 0, 0, 0, 1]}\n", "from the body's origin"},
      {"radars:\n  - {name: a, sequence: s, " + pose + ", clock_offset: 2}\n", "past +/-"},
      {"radars:\n  - {name: a, sequence: s, " + pose + ", clock_offset: soon}\n", "not a number"},
      {"radars:\n  - {name: a, sequence: s, " + pose + ", mounting: front}\n", "unknown key 'mounting'"},
      {"radar: []\n", "unknown key 'radar'"},
      {"- just a list\n", "a rig file is a map"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string message = ErrorOf(text);
    EXPECT_NE(message.find(expected), std::string::npos) << "for\n" << text << "got: " << message;
  }
}

}  // namespace
}  // namespace radargauss
