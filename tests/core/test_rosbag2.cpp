// SPDX-License-Identifier: BSD-3-Clause
// ROS 2 bags (docs/design.md, "ROS 2 bags"): CDR against hand-laid bytes
// and in every encoding; MCAP written and read back in each layout, and a
// file laid out by hand that has no summary; sqlite3 bags of schema 1 and 3;
// rosbag2 folders; the rosbag2 project's own test bags; one simulated
// sequence read from its PCD folder and from each kind of bag giving the same
// scans and odometry; and hostile files refused with one DataError.
#include "radargauss/io/rosbag2.hpp"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "radargauss/error.hpp"
#include "radargauss/io/mcap.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/run_mcap.hpp"
#include "radargauss/simulator.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

using Rosbag2Files = testing::TempDirTest;

std::string Bytes(const std::vector<std::uint8_t>& v) { return std::string(v.begin(), v.end()); }
std::vector<std::uint8_t> Vector(const std::string& s) { return std::vector<std::uint8_t>(s.begin(), s.end()); }
std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Little-endian integers appended by hand, for the laid-out cases.
void Put(std::string& s, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) s.push_back(char(std::uint8_t(value >> (8 * i))));
}
void PutString(std::string& s, const std::string& text) {
  Put(s, text.size(), 4);
  s += text;
}
std::string Record(std::uint8_t opcode, const std::string& body) {
  std::string r(1, char(opcode));
  Put(r, body.size(), 8);
  return r + body;
}

// --- CDR ---------------------------------------------------------------

// A sensor_msgs/msg/Imu laid out by hand, XCDR1 little-endian: header
// (stamp 7 s 250 ns, frame "abcdefg"), then doubles aligned to 8 from the
// end of the encapsulation header, so 4 bytes of padding after the frame.
TEST(Cdr, ImuMatchesBytesLaidOutByHand) {
  std::string m = {0x00, 0x01, 0x00, 0x00};
  Put(m, 7, 4);
  Put(m, 250, 4);
  PutString(m, std::string("abcdefg") + '\0');  // offset 8 + 12 = 20
  m += std::string(4, '\0');                    // to 24
  const auto put_double = [&](double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, 8);
    Put(m, bits, 8);
  };
  for (int i = 0; i < 13; ++i) put_double(0.0);  // orientation and its covariance
  for (const double v : {0.1, -0.2, 0.3}) put_double(v);
  for (int i = 0; i < 9; ++i) put_double(0.0);
  for (const double v : {1.0, 2.0, 9.81}) put_double(v);
  for (int i = 0; i < 9; ++i) put_double(0.0);
  ImuSample sample;
  const Ros2Header header = DecodeRos2Imu(reinterpret_cast<const std::uint8_t*>(m.data()), m.size(), "m", sample);
  EXPECT_EQ(header.stamp, JoinStamp(7, 250));
  EXPECT_EQ(header.frame_id, "abcdefg");
  EXPECT_EQ(sample.angular_velocity, Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_EQ(sample.specific_force, Eigen::Vector3d(1.0, 2.0, 9.81));
  // Our encoder writes the same bytes (its covariance marks "no orientation" with -1 first).
  std::vector<std::uint8_t> encoded = EncodeRos2Imu({7.0 + 250e-9, "abcdefg"}, sample);
  ASSERT_EQ(encoded.size(), m.size());
  EXPECT_EQ(Bytes(encoded).substr(0, 24), m.substr(0, 24));
  EXPECT_EQ(Bytes(encoded).substr(24 + 13 * 8), m.substr(24 + 13 * 8));
  // XCDR2 aligns doubles to 4: the same message is 4 bytes shorter.
  const std::vector<std::uint8_t> xcdr2 =
      EncodeRos2Imu({7.0 + 250e-9, "abcdefg"}, sample, CdrEncoding::kXcdr2LittleEndian);
  EXPECT_EQ(xcdr2.size(), m.size() - 4);
  ImuSample again;
  DecodeRos2Imu(xcdr2.data(), xcdr2.size(), "m", again);
  EXPECT_EQ(again.specific_force, sample.specific_force);
}

TEST(Cdr, EveryEncodingRoundTrips) {
  RadarScan scan;
  scan.timestamp = 1702450000.123456789;
  scan.has_doppler = scan.has_rcs = true;
  for (int i = 0; i < 5; ++i) scan.points.push_back({Eigen::Vector3d(i, -0.5 * i, 0.1), 0.3 * i, -7.0 + i, {}});
  const SE3d pose(SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.3)), Eigen::Vector3d(1, 2, 3));
  for (const CdrEncoding e : {CdrEncoding::kXcdr1LittleEndian, CdrEncoding::kXcdr1BigEndian,
                              CdrEncoding::kXcdr2LittleEndian, CdrEncoding::kXcdr2BigEndian}) {
    const std::vector<std::uint8_t> bytes =
        EncodeRos2PointCloud2({scan.timestamp, "radar"}, EncodePointCloud2(scan), e);
    PointCloud2Data cloud;
    const Ros2Header header = DecodeRos2PointCloud2(bytes.data(), bytes.size(), "m", cloud);
    EXPECT_EQ(header.frame_id, "radar");
    const RadarScan back = DecodePointCloud2(cloud, header.stamp, {}, "m");
    EXPECT_EQ(back.timestamp, scan.timestamp);
    ASSERT_EQ(back.points.size(), scan.points.size());
    for (std::size_t i = 0; i < scan.points.size(); ++i) {
      EXPECT_EQ(back.points[i].position, scan.points[i].position);
      EXPECT_EQ(back.points[i].doppler, scan.points[i].doppler);
      EXPECT_EQ(back.points[i].rcs, scan.points[i].rcs);
    }
    const std::vector<std::uint8_t> pose_bytes = EncodeRos2PoseStamped({5.5, "world"}, pose, e);
    double stamp = 0.0;
    SE3d decoded;
    ASSERT_TRUE(
        DecodeRos2Pose("geometry_msgs/msg/PoseStamped", pose_bytes.data(), pose_bytes.size(), "m", "", stamp, decoded));
    EXPECT_EQ(stamp, 5.5);
    EXPECT_LT((decoded.translation() - pose.translation()).norm(), 1e-15);
    EXPECT_LT((decoded.rotation().Inverse() * pose.rotation()).Log().norm(), 1e-15);
  }
}

// Every prefix of a valid message, a sequence that claims a billion
// elements and an unknown encapsulation: one DataError each.
TEST(Cdr, LiesAndTruncationsAreRefused) {
  RadarScan scan;
  scan.timestamp = 3.0;
  scan.points.push_back({Eigen::Vector3d(1, 2, 3), 0.0, 0.0, {}});
  const std::vector<std::uint8_t> bytes = EncodeRos2PointCloud2({3.0, "radar"}, EncodePointCloud2(scan));
  PointCloud2Data cloud;
  for (std::size_t n = 0; n < bytes.size() - 1; ++n) {  // the last byte (is_dense) is not read
    EXPECT_THROW(DecodeRos2PointCloud2(bytes.data(), n, "m", cloud), DataError) << n << " bytes";
  }
  std::vector<std::uint8_t> lying = bytes;
  const std::size_t fields_count = 4 + 8 + 4 + 6 + 2 + 8;  // after header, "radar\0", padding, height, width
  ASSERT_EQ(lying[fields_count], 3u);                      // x y z
  lying[fields_count + 3] = 0x40;                          // 3 + 2^30 fields
  try {
    DecodeRos2PointCloud2(lying.data(), lying.size(), "m", cloud);
    FAIL();
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("longer than the message"), std::string::npos) << e.what();
  }
  std::vector<std::uint8_t> parameter_list = bytes;
  parameter_list[1] = 0x03;  // PL_CDR_LE
  EXPECT_THROW(DecodeRos2PointCloud2(parameter_list.data(), parameter_list.size(), "m", cloud), DataError);
}

// --- MCAP --------------------------------------------------------------

// A file laid out by hand from the specification: magic, header, schema,
// channel, two messages, data end, a footer without a summary, magic.
std::string HandMadeMcap() {
  const std::string magic = "\x89MCAP0\r\n";
  std::string header, schema, channel, data_end, footer;
  PutString(header, "ros2");
  PutString(header, "hand");
  Put(schema, 1, 2);
  PutString(schema, "std_msgs/msg/String");
  PutString(schema, "ros2msg");
  PutString(schema, "string data\n");
  Put(channel, 3, 2);
  Put(channel, 1, 2);
  PutString(channel, "/chatter");
  PutString(channel, "cdr");
  Put(channel, 0, 4);
  std::string file = magic + Record(0x01, header) + Record(0x03, schema) + Record(0x04, channel);
  for (int k = 0; k < 2; ++k) {
    std::string message;
    Put(message, 3, 2);
    Put(message, k, 4);
    Put(message, 1000 + k, 8);
    Put(message, 1000 + k, 8);
    message += "payload" + std::to_string(k);
    file += Record(0x05, message);
  }
  Put(data_end, 0, 4);
  file += Record(0x0F, data_end);
  Put(footer, 0, 8);
  Put(footer, 0, 8);
  Put(footer, 0, 4);
  return file + Record(0x02, footer) + magic;
}

TEST_F(Rosbag2Files, McapLaidOutByHandReadsWithoutASummary) {
  const std::string path = WriteFile("hand.mcap", HandMadeMcap());
  McapReader reader(path);
  ASSERT_EQ(reader.channels().size(), 1u);
  EXPECT_EQ(reader.channels()[0].topic, "/chatter");
  EXPECT_EQ(reader.channels()[0].schema_name, "std_msgs/msg/String");
  EXPECT_EQ(reader.channels()[0].message_count, 2u);
  std::vector<std::string> payloads;
  reader.ForEachMessage([&](const McapMessage& m) {
    EXPECT_EQ(m.log_time, 1000u + payloads.size());
    payloads.emplace_back(reinterpret_cast<const char*>(m.data), m.size);
  });
  EXPECT_EQ(payloads, (std::vector<std::string>{"payload0", "payload1"}));
}

// Writes three channels of messages with each layout; reads back the same
// messages in order, and the counts from the summary.
TEST_F(Rosbag2Files, McapEveryLayoutRoundTrips) {
  struct Layout {
    const char* name;
    bool chunked;
    McapCompression compression;
  };
  for (const Layout layout :
       {Layout{"zstd", true, McapCompression::kZstd}, Layout{"lz4", true, McapCompression::kLz4},
        Layout{"none", true, McapCompression::kNone}, Layout{"unchunked", false, McapCompression::kNone}}) {
    const std::string path = Path(std::string(layout.name) + ".mcap");
    {
      std::ofstream out(path, std::ios::binary);
      McapWriterOptions options;
      options.chunked = layout.chunked;
      options.compression = layout.compression;
      options.chunk_bytes = 4096;  // several chunks
      McapWriter writer(out, options);
      const std::uint16_t schema = writer.AddSchema("std_msgs/msg/String", "ros2msg", "string data\n");
      const std::uint16_t a = writer.AddChannel("/a", schema), b = writer.AddChannel("/b", schema);
      writer.AddChannel("/silent", schema);
      for (int k = 0; k < 500; ++k) {
        writer.Write(k % 3 == 0 ? b : a, 10 * k, 10 * k, Vector("message " + std::to_string(k)));
      }
      writer.Finish();
    }
    McapReader reader(path);
    ASSERT_EQ(reader.channels().size(), 3u) << layout.name;
    EXPECT_EQ(reader.channels()[0].message_count, 333u);
    EXPECT_EQ(reader.channels()[1].message_count, 167u);
    EXPECT_EQ(reader.channels()[2].message_count, 0u);
    int k = 0;
    reader.ForEachMessage([&](const McapMessage& m) {
      EXPECT_EQ(m.channel->topic, k % 3 == 0 ? "/b" : "/a");
      EXPECT_EQ(std::string(reinterpret_cast<const char*>(m.data), m.size), "message " + std::to_string(k));
      EXPECT_EQ(m.log_time, 10u * k);
      ++k;
    });
    EXPECT_EQ(k, 500) << layout.name;
  }
}

// Each a one-line DataError: truncation at many lengths, a flipped byte in a
// chunk (its CRC), a chunk claiming 10 GB, a record longer than the file,
// a footer pointing past the end, a file of another kind.
TEST_F(Rosbag2Files, HostileMcapFilesAreRefused) {
  std::ostringstream written;
  {
    McapWriter writer(written, {});
    const std::uint16_t schema = writer.AddSchema("std_msgs/msg/String", "ros2msg", "string data\n");
    const std::uint16_t channel = writer.AddChannel("/a", schema);
    for (int k = 0; k < 50; ++k) writer.Write(channel, k, k, Vector(std::string(100, char('a' + k % 26))));
    writer.Finish();
  }
  const std::string good = written.str();
  const auto refused = [&](const std::string& bytes, const std::string& expected) {
    const std::string path = WriteFile("bad.mcap", bytes);
    try {
      McapReader reader(path);
      reader.ForEachMessage([](const McapMessage&) {});
      ADD_FAILURE() << "read: " << expected;
    } catch (const DataError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos);
      if (!expected.empty()) EXPECT_NE(what.find(expected), std::string::npos) << what;
    }
  };
  for (std::size_t n = 0; n < good.size(); n += 37) refused(good.substr(0, n), "");
  // The chunk follows the magic and the header record ("ros2", "radargauss").
  const std::size_t chunk = 8 + 9 + 4 + 4 + 4 + 10;
  ASSERT_EQ(good[chunk], '\x06');
  std::string flipped = good;
  flipped[chunk + 9 + 8 + 8 + 8 + 4 + 4 + 4 + 8 + 30] ^= 0x10;  // inside the zstd payload
  refused(flipped, "");
  std::string huge = good;
  for (int i = 0; i < 8; ++i) huge[chunk + 9 + 16 + i] = char(std::uint8_t((10ull << 30) >> (8 * i)));
  refused(huge, "limit");
  std::string long_record = good;
  long_record[chunk + 8] = 0x7f;  // the chunk's length's top byte
  refused(long_record, "past the end");
  std::string footer = good;
  footer[good.size() - 8 - 20 + 7] = 0x7f;  // summary_start's top byte
  refused(footer, "outside the file");
  refused("SQLite format 3" + std::string(200, '\0'), "not an MCAP file");
}

// --- sqlite3 and folders -------------------------------------------------

void Sql(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

// A schema-1 bag (topics without QoS, no schema table), made with SQL.
TEST_F(Rosbag2Files, SqliteSchemaOneReads) {
  const std::string path = Path("v1.db3");
  RadarScan scan;
  scan.timestamp = 12.5;
  scan.points.push_back({Eigen::Vector3d(4, 5, 6), 0.0, 0.0, {}});
  std::string hex;
  for (const std::uint8_t byte : EncodeRos2PointCloud2({12.5, "r"}, EncodePointCloud2(scan))) {
    static const char kHex[] = "0123456789abcdef";
    hex += {kHex[byte >> 4], kHex[byte & 15]};
  }
  Sql(path,
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, serialization_format TEXT "
      "NOT NULL);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data "
      "BLOB NOT NULL);"
      "INSERT INTO topics VALUES(1, '/radar', 'sensor_msgs/msg/PointCloud2', 'cdr');"
      "INSERT INTO messages VALUES(1, 1, 12500000000, X'" +
          hex + "');");
  EXPECT_EQ(DetectBagFormat(path), BagFormat::kSqlite3);
  const std::vector<RadarScan> scans = ReadBagScans(path, "/radar");
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(scans[0].timestamp, 12.5);
  EXPECT_EQ(scans[0].points[0].position, Eigen::Vector3d(4, 5, 6));
  const std::vector<BagTopic> topics = ListBagTopics(path);
  ASSERT_EQ(topics.size(), 1u);
  EXPECT_EQ(topics[0].messages, 1u);
  // A sqlite file that is not a bag; a topic of another type.
  const std::string other = Path("other.db3");
  Sql(other, "CREATE TABLE notes(text TEXT);");
  EXPECT_THROW(ListBagTopics(other), DataError);
  EXPECT_THROW(ReadBagImu(path, "/radar"), DataError);
  EXPECT_THROW(ReadBagScans(path, "/absent"), DataError);
}

TEST_F(Rosbag2Files, FoldersReadTheirFilesInOrderAndRefuseWhatTheyCannot) {
  SimulationConfig config;
  config.scans = 6;
  const Sequence sequence = AsSequence(Simulate(config));
  const std::vector<RadarScan> first(sequence.scans.begin(), sequence.scans.begin() + 3);
  const std::vector<RadarScan> second(sequence.scans.begin() + 3, sequence.scans.end());
  std::filesystem::create_directories(Path("bag"));
  WriteRos2Bag(Path("bag/part_0.mcap"), BagFormat::kMcap, first, {}, nullptr);
  WriteRos2Bag(Path("bag/part_1.db3"), BagFormat::kSqlite3, second, {}, nullptr);
  const std::string metadata =
      "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  compression_format: ''\n"
      "  compression_mode: ''\n  relative_file_paths:\n    - part_0.mcap\n    - part_1.db3\n";
  WriteFile("bag/metadata.yaml", metadata);
  const std::vector<RadarScan> scans = ReadBagScans(Path("bag"), "/radar/points");
  ASSERT_EQ(scans.size(), 6u);
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(scans[k].timestamp, sequence.scans[k].timestamp);
  WriteFile("bag/metadata.yaml", metadata + "  compression_format: zstd\n");
  EXPECT_THROW(ReadBagScans(Path("bag"), "/radar/points"), DataError);  // a key twice
  WriteFile("bag/metadata.yaml",
            "rosbag2_bagfile_information:\n  compression_format: zstd\n  compression_mode: FILE\n"
            "  relative_file_paths: [part_0.mcap.zstd]\n");
  EXPECT_THROW(ReadBagScans(Path("bag"), "/radar/points"), DataError);
  WriteFile("bag/metadata.yaml", "rosbag2_bagfile_information:\n  relative_file_paths: [../../etc/passwd]\n");
  EXPECT_THROW(ReadBagScans(Path("bag"), "/radar/points"), DataError);
  std::filesystem::create_directories(Path("empty"));
  EXPECT_THROW(ReadBagScans(Path("empty"), "/radar/points"), DataError);
}

// The rosbag2 project's own test bags (tests/data/rosbag2: ros2/rosbag2,
// Apache-2.0): the topics and counts its metadata states (talker), the same
// from the .db3 and the .mcap recording of the same run.
TEST(Rosbag2TestBags, ListTheirTopics) {
  const std::string data = std::string(RADARGAUSS_SOURCE_DIR) + "/tests/data/rosbag2/";
  const std::vector<BagTopic> talker = ListBagTopics(data + "talker");
  ASSERT_EQ(talker.size(), 3u);
  EXPECT_EQ(talker[0].name, "/parameter_events");
  EXPECT_EQ(talker[0].messages, 0u);
  EXPECT_EQ(talker[1].name, "/rosout");
  EXPECT_EQ(talker[1].type, "rcl_interfaces/msg/Log");
  EXPECT_EQ(talker[1].messages, 10u);
  EXPECT_EQ(talker[2].name, "/topic");
  EXPECT_EQ(talker[2].type, "std_msgs/msg/String");
  EXPECT_EQ(talker[2].messages, 10u);
  const std::vector<BagTopic> db3 = ListBagTopics(data + "topics_and_services.db3");
  const std::vector<BagTopic> mcap = ListBagTopics(data + "topics_and_services.mcap");
  ASSERT_EQ(db3.size(), 5u);
  ASSERT_EQ(mcap.size(), db3.size());
  for (std::size_t i = 0; i < db3.size(); ++i) {
    EXPECT_EQ(db3[i].name, mcap[i].name);
    EXPECT_EQ(db3[i].type, mcap[i].type);
    EXPECT_EQ(db3[i].messages, mcap[i].messages) << db3[i].name;
  }
  EXPECT_EQ(db3[0].name, "/add_two_ints/_service_event");
  EXPECT_EQ(db3[0].messages, 6u);
  EXPECT_EQ(db3[3].name, "/parameter_events");
  EXPECT_EQ(db3[3].messages, 7u);
}

// --- one sequence, every container -------------------------------------

void ExpectSameScans(const std::vector<RadarScan>& a, const std::vector<RadarScan>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].timestamp, b[k].timestamp) << what << " scan " << k;
    ASSERT_EQ(a[k].has_doppler, b[k].has_doppler);
    ASSERT_EQ(a[k].has_rcs, b[k].has_rcs);
    ASSERT_EQ(a[k].points.size(), b[k].points.size()) << what << " scan " << k;
    for (std::size_t i = 0; i < a[k].points.size(); ++i) {
      ASSERT_EQ(a[k].points[i].position, b[k].points[i].position) << what << " scan " << k;
      ASSERT_EQ(a[k].points[i].doppler, b[k].points[i].doppler);
      ASSERT_EQ(a[k].points[i].rcs, b[k].points[i].rcs);
    }
  }
}

TEST_F(Rosbag2Files, OneSequenceFromItsPcdFolderAndEveryBagIsTheSame) {
  SimulationConfig config;
  config.scans = 80;
  config.imu_rate_hz = 100.0;
  const SimulatedSequence simulated = Simulate(config);
  WriteSimulatedSequence(Path("pcd"), simulated);
  SequenceOptions options;
  options.sequence_dir = Path("pcd");
  const Sequence pcd = LoadSequence(options);
  RadarOdometry reference;
  for (const RadarScan& scan : pcd.scans) reference.Register(scan);
  struct Container {
    const char* name;
    BagFormat format;
    bool chunked;
    McapCompression compression;
  };
  for (const Container c : {Container{"zstd.mcap", BagFormat::kMcap, true, McapCompression::kZstd},
                            Container{"lz4.mcap", BagFormat::kMcap, true, McapCompression::kLz4},
                            Container{"unchunked.mcap", BagFormat::kMcap, false, McapCompression::kNone},
                            Container{"bag.db3", BagFormat::kSqlite3, true, McapCompression::kZstd}}) {
    BagExportOptions bag;
    bag.mcap.chunked = c.chunked;
    bag.mcap.compression = c.compression;
    bag.mcap.chunk_bytes = 1 << 16;
    WriteRos2Bag(Path(c.name), c.format, pcd.scans, simulated.imu, &simulated.ground_truth, bag);
    ExpectSameScans(pcd.scans, ReadBagScans(Path(c.name), "/radar/points"), c.name);
    const std::vector<ImuSample> imu = ReadBagImu(Path(c.name), "/imu/data");
    ASSERT_EQ(imu.size(), simulated.imu.size());
    for (std::size_t i = 0; i < imu.size(); ++i) {
      ASSERT_EQ(imu[i].angular_velocity, simulated.imu[i].angular_velocity);
      ASSERT_EQ(imu[i].specific_force, simulated.imu[i].specific_force);
    }
    RadarOdometry odometry;
    for (const RadarScan& scan : ReadBagScans(Path(c.name), "/radar/points")) odometry.Register(scan);
    for (std::size_t k = 0; k < reference.steps().size(); ++k) {
      ASSERT_EQ(odometry.steps()[k].pose.translation(), reference.steps()[k].pose.translation()) << c.name;
      ASSERT_EQ(odometry.steps()[k].pose.rotation().quaternion().coeffs(),
                reference.steps()[k].pose.rotation().quaternion().coeffs());
    }
  }
}

TEST_F(Rosbag2Files, NothingIsLeftBehindWhenAWriteFails) {
  const std::string path = Path("out.mcap");
  {
    Ros2BagWriter writer(path, BagFormat::kMcap);
    writer.AddTopic("/a", "sensor_msgs/msg/Imu");
    EXPECT_THROW(writer.AddTopic("/b", "std_msgs/msg/Unknown"), DataError);
  }  // not finished: nothing at `path`, no temporary beside it
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_), std::filesystem::directory_iterator()), 0);
}

// A run written for a viewer and read back by the MCAP reader: one pose, tf
// and registered scan per scan, the path equal to the poses, the map's
// means and one ellipsoid per Gaussian, the loops as one line list.
TEST_F(Rosbag2Files, ARunForAViewerReadsBack) {
  SimulationConfig config;
  config.scans = 30;
  const Sequence sequence = AsSequence(Simulate(config));
  RunForViewer run;
  for (const RadarScan& scan : sequence.scans) run.stamps.push_back(scan.timestamp);
  run.poses = sequence.poses;
  run.scans = sequence.scans;
  for (int i = 0; i < 4; ++i) {
    Gaussian g;
    g.mean = Eigen::Vector3d(i, 2.0 * i, 0.5);
    g.covariance = Eigen::Vector3d(0.5, 0.2, 0.1 + i).asDiagonal();
    g.point_count = 10 + i;
    run.map.gaussians.push_back(g);
  }
  run.loops.push_back({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 0)});
  WriteRunMcap(Path("run.mcap"), run);
  McapReader reader(Path("run.mcap"));
  std::map<std::string, std::size_t> counts;
  for (const McapChannel& c : reader.channels()) counts[c.topic] = c.message_count;
  EXPECT_EQ(counts["/radar/pose"], 30u);
  EXPECT_EQ(counts["/tf"], 30u);
  EXPECT_EQ(counts["/radar/registered"], 30u);
  EXPECT_EQ(counts["/trajectory"], 1u);
  EXPECT_EQ(counts["/map/ellipsoids"], 1u);
  std::size_t scan = 0;
  reader.ForEachMessage([&](const McapMessage& m) {
    const std::string& topic = m.channel->topic;
    if (topic == "/radar/pose") {
      double stamp;
      SE3d pose;
      ASSERT_TRUE(DecodeRos2Pose(m.channel->schema_name, m.data, m.size, "m", "", stamp, pose));
      EXPECT_EQ(stamp, run.stamps[scan]);
      EXPECT_LT((pose.translation() - run.poses[scan].translation()).norm(), 1e-12);
    } else if (topic == "/tf") {
      double stamp;
      SE3d pose;
      ASSERT_TRUE(DecodeRos2Pose(m.channel->schema_name, m.data, m.size, "m", "radar", stamp, pose));
      EXPECT_LT((pose.translation() - run.poses[scan].translation()).norm(), 1e-12);
    } else if (topic == "/radar/registered") {
      PointCloud2Data cloud;
      const Ros2Header header = DecodeRos2PointCloud2(m.data, m.size, "m", cloud);
      EXPECT_EQ(header.frame_id, "map");
      const RadarScan registered = DecodePointCloud2(cloud, header.stamp, {}, "m");
      ASSERT_EQ(registered.points.size(), run.scans[scan].points.size());
      const Eigen::Vector3d expected = run.poses[scan] * run.scans[scan].points[0].position;
      EXPECT_LT((registered.points[0].position - expected).norm(), 1e-12);
      ++scan;
    } else if (topic == "/map/gaussians") {
      PointCloud2Data cloud;
      DecodeRos2PointCloud2(m.data, m.size, "m", cloud);
      EXPECT_EQ(cloud.width, 4u);
    }
  });
  EXPECT_EQ(scan, 30u);
}

}  // namespace
}  // namespace radargauss
