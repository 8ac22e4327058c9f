// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/rosbag.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>

#include "radargauss/core/error.hpp"
#include "radargauss/io/sequence.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

using testing::SharedData;
using RosbagRealDataFiles = testing::TempDirTest;  // cases on the real bag
constexpr const char* kBag = "ti_mmwave_demo/demo_ti_mmwave_rospkg_format.bag";
constexpr const char* kTopic = "/ti_mmwave/radar_scan_pcl";

// A PointCloud2 with x y z (float32), rcs (uint16), velocity (float64),
// point_step padding and row_step padding, in either byte order.
PointCloud2Data MakeCloud(bool big_endian) {
  PointCloud2Data cloud;
  cloud.height = 2;
  cloud.width = 2;
  cloud.fields = {{"x", 0, 7, 1}, {"y", 4, 7, 1}, {"z", 8, 7, 1}, {"rcs", 12, 4, 1}, {"velocity", 16, 8, 1}};
  cloud.is_bigendian = big_endian;
  cloud.point_step = 28;
  cloud.row_step = 60;
  cloud.data.assign(cloud.row_step * cloud.height, 0xAB);
  const auto put = [&](std::size_t offset, const void* value, int size) {
    const auto* bytes = static_cast<const std::uint8_t*>(value);
    for (int i = 0; i < size; ++i) {
      cloud.data[offset + i] = big_endian ? bytes[size - 1 - i] : bytes[i];
    }
  };
  for (std::uint32_t row = 0; row < 2; ++row) {
    for (std::uint32_t column = 0; column < 2; ++column) {
      const std::size_t base = row * cloud.row_step + column * cloud.point_step;
      const float xyz[3] = {float(row * 10 + column), -1.5f, 0.25f};
      for (int k = 0; k < 3; ++k) put(base + 4 * k, &xyz[k], 4);
      const std::uint16_t rcs = std::uint16_t(300 + row);
      put(base + 12, &rcs, 2);
      const double velocity = -2.5 * (column + 1);
      put(base + 16, &velocity, 8);
    }
  }
  return cloud;
}

TEST(PointCloud2, DecodesBothByteOrdersWithPadding) {
  for (const bool big_endian : {false, true}) {
    const RadarScan scan = DecodePointCloud2(MakeCloud(big_endian), 3.0, {}, "msg");
    ASSERT_EQ(scan.points.size(), 4u);
    EXPECT_EQ(scan.points[3].position, Eigen::Vector3d(11, -1.5, 0.25));
    EXPECT_EQ(scan.points[2].rcs, 301.0);
    EXPECT_EQ(scan.points[1].doppler, -5.0);
    EXPECT_EQ(scan.timestamp, 3.0);
  }
}

TEST(PointCloud2, RejectsInconsistentMessages) {
  PointCloud2Data cloud = MakeCloud(false);
  cloud.data.resize(100);
  EXPECT_THROW(DecodePointCloud2(cloud, 0.0, {}, "msg"), DataError);
  cloud = MakeCloud(false);
  cloud.row_step = 40;
  EXPECT_THROW(DecodePointCloud2(cloud, 0.0, {}, "msg"), DataError);
  cloud = MakeCloud(false);
  cloud.fields[4].offset = 24;  // float64 at 24 runs past point_step 28
  EXPECT_THROW(DecodePointCloud2(cloud, 0.0, {}, "msg"), DataError);
  cloud = MakeCloud(false);
  cloud.fields[3].datatype = 9;
  EXPECT_THROW(DecodePointCloud2(cloud, 0.0, {}, "msg"), DataError);
  cloud = MakeCloud(false);
  cloud.fields.erase(cloud.fields.begin() + 1);
  EXPECT_THROW(DecodePointCloud2(cloud, 0.0, {}, "msg"), DataError);
  cloud = MakeCloud(false);
  const float nan = NAN;
  std::memcpy(cloud.data.data() + 4, &nan, 4);
  EXPECT_THROW(DecodePointCloud2(cloud, 0.0, {}, "msg"), DataError);
}

TEST(RosbagRealData, TiMmwaveDemoBag) {
  if (!RosbagSupported()) GTEST_SKIP() << "built without ROS1 bag support";
  const std::string bag = SharedData(kBag);
  if (bag.empty()) GTEST_SKIP() << "shared data not found";
  const std::vector<BagTopic> topics = ListBagTopics(bag);
  ASSERT_EQ(topics.size(), 4u);
  const auto radar = std::find_if(topics.begin(), topics.end(), [](const BagTopic& t) { return t.name == kTopic; });
  ASSERT_NE(radar, topics.end());
  EXPECT_EQ(radar->type, "sensor_msgs/PointCloud2");
  EXPECT_EQ(radar->messages, 412u);

  const std::vector<RadarScan> scans = ReadBagScans(bag, kTopic);
  ASSERT_EQ(scans.size(), 412u);
  std::vector<std::size_t> counts;
  std::size_t total = 0;
  for (const RadarScan& scan : scans) {
    counts.push_back(scan.points.size());
    total += scan.points.size();
    EXPECT_TRUE(scan.has_doppler);
  }
  std::sort(counts.begin(), counts.end());
  EXPECT_EQ(total, 17872u);
  EXPECT_EQ(counts.front(), 19u);
  EXPECT_EQ(counts[counts.size() / 2], 41u);
  EXPECT_EQ(counts.back(), 87u);
  // header.stamp is zero in this bag: the record time is used (2021-09-21).
  EXPECT_NEAR(scans.front().timestamp, 1632233878.9, 0.1);
  EXPECT_NEAR(scans.back().timestamp - scans.front().timestamp, 40.15, 0.05);

  SequenceOptions options;
  options.bag = bag;
  options.topic = kTopic;
  EXPECT_EQ(LoadSequence(options).scans.size(), 412u);
}

TEST_F(RosbagRealDataFiles, BadBagsAndTopicsGiveErrors) {
  if (!RosbagSupported()) GTEST_SKIP() << "built without ROS1 bag support";
  const std::string bag = SharedData(kBag);
  if (bag.empty()) GTEST_SKIP() << "shared data not found";
  EXPECT_THROW(ReadBagScans(bag, "/no/such/topic"), DataError);
  EXPECT_THROW(ReadBagScans(bag, "/sensor_platform/imu"), DataError);  // not a PointCloud2
  EXPECT_THROW(ReadBagScans(Path("absent.bag"), kTopic), DataError);
  EXPECT_THROW(ReadBagScans(WriteFile("text.bag", "not a bag at all\n"), kTopic), DataError);

  std::ifstream in(bag, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // A broken bag header record (its length field), and a truncated bag.
  std::string bad_header = bytes;
  for (std::size_t i = 13; i < 17; ++i) bad_header[i] = char(0xFF);
  EXPECT_THROW(ReadBagScans(WriteFile("bad_header.bag", bad_header), kTopic), DataError);
  EXPECT_THROW(ReadBagScans(WriteFile("truncated.bag", bytes.substr(0, 5000)), kTopic), DataError);
}

}  // namespace
}  // namespace radargauss
