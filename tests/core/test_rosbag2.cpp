// SPDX-License-Identifier: BSD-3-Clause
// ROS 2 bags (docs/design/formats.md, "ROS 2 bags"): CDR against hand-laid bytes
// and in every encoding; MCAP written and read back in each layout, and a
// file laid out by hand that has no summary; sqlite3 bags of schema 1 and 3;
// rosbag2 folders; the rosbag2 project's own test bags; one simulated
// sequence read from its PCD folder and from each kind of bag giving the same
// scans and odometry; and hostile files refused with one DataError.
#include "radargauss/io/bag_reader.hpp"
#include "radargauss/io/bag_writer.hpp"

#include <gtest/gtest.h>
#include <lz4frame.h>
#include <sqlite3.h>
#include <sys/resource.h>
#include <zlib.h>
#include <zstd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "radargauss/core/error.hpp"
#include "radargauss/io/mcap.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/experiment/run_mcap.hpp"
#include "radargauss/simulator/simulator.hpp"
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
  // A NUL inside a field's name ("x\0" -> "\0\0"): refused, not read as a name cut short.
  std::vector<std::uint8_t> nul = bytes;
  ASSERT_EQ(nul[fields_count + 4 + 4], 'x');
  nul[fields_count + 4 + 4] = 0;
  try {
    DecodeRos2PointCloud2(nul.data(), nul.size(), "m", cloud);
    FAIL() << "a field name with a NUL read";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("a string holds a NUL byte"), std::string::npos) << e.what();
  }
}

// The topics a bag is written with: names ROS accepts, distinct; refused before the file is begun.
TEST_F(Rosbag2Files, BagTopicsAreNamesAReaderFindsAgain) {
  for (const std::string& good : std::vector<std::string>{"/radar/points", "/a", "/a_1/b2"}) {
    EXPECT_EQ(TopicNameFault(good), "") << good;
  }
  for (const std::string& bad :
       std::vector<std::string>{"", "radar", "/", "/a/", "/a//b", "/1a", "/a b", std::string("/a\0b", 4)}) {
    EXPECT_NE(TopicNameFault(bad), "") << bad;
  }
  RadarScan scan;
  scan.timestamp = 5.0;
  scan.points.push_back({Eigen::Vector3d(1, 2, 3), 0.0, 0.0, {}});
  const std::vector<ImuSample> imu{{4.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.81)}};
  const auto refused = [&](const BagExportOptions& options, const std::vector<RadarScan>& scans,
                           const std::string& fault) {
    const std::string path = Path("topics.mcap");
    try {
      WriteRos2Bag(path, BagFormat::kMcap, scans, imu, nullptr, options);
      ADD_FAILURE() << fault;
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(path));
  };
  BagExportOptions empty;
  empty.scan_topic = "";
  refused(empty, {scan}, "scan topic '' is empty");
  BagExportOptions same;
  same.imu_topic = same.scan_topic;
  refused(same, {scan}, "scan topic and IMU topic are both /radar/points");
  RadarScan before_1970 = scan;
  before_1970.timestamp = -5.0;
  refused({}, {scan, before_1970}, "scan 1: stamp -5.000000 s does not fit ROS's time");
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

// The peak resident memory of this process, in bytes.
std::size_t PeakMemory() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return std::size_t(usage.ru_maxrss) * 1024;
}

// HandMadeMcap's two messages as one chunk whose records are `payload`,
// compressed with `compression`, stating `stated` bytes uncompressed and the
// CRC `crc`; no data-section CRC, so that only the chunk's own checks remain.
std::string McapWithChunk(const std::string& compression, const std::string& payload, std::uint64_t stated,
                          std::uint32_t crc) {
  std::string file = HandMadeMcap();
  const std::size_t first_message = file.find(Record(0x05, std::string(30, '\0')).substr(0, 9));
  std::string chunk;
  Put(chunk, 1000, 8);
  Put(chunk, 1001, 8);
  Put(chunk, stated, 8);
  Put(chunk, crc, 4);
  PutString(chunk, compression);
  Put(chunk, payload.size(), 8);
  chunk += payload;
  const std::size_t data_end = file.find(Record(0x0F, std::string(4, '\0')));
  return file.substr(0, first_message) + Record(0x06, chunk) + file.substr(data_end);
}

// The records of HandMadeMcap's two messages, as a chunk holds them.
std::string MessageRecords() {
  const std::string file = HandMadeMcap();
  const std::size_t first_message = file.find(Record(0x05, std::string(30, '\0')).substr(0, 9));
  const std::size_t data_end = file.find(Record(0x0F, std::string(4, '\0')));
  return file.substr(first_message, data_end - first_message);
}

std::vector<std::string> Payloads(const std::string& path) {
  McapReader reader(path);
  std::vector<std::string> payloads;
  reader.ForEachMessage(
      [&](const McapMessage& m) { payloads.emplace_back(reinterpret_cast<const char*>(m.data), m.size); });
  return payloads;
}

// A chunk's stated size is believed only as far as its data goes: an lz4
// chunk of a few bytes stating 1 GiB is refused by lz4's ratio before
// anything is decompressed, a zstd frame that leaves its size out is
// streamed, and neither costs memory for the size it states. Compressed
// chunks laid out by hand read back; a flipped byte in an uncompressed
// chunk is caught by the chunk's CRC alone.
TEST_F(Rosbag2Files, McapChunkSizesAreBoundedByTheirData) {
  const std::string records = MessageRecords();
  const std::vector<std::string> expected{"payload0", "payload1"};
  std::string lz4(LZ4F_compressFrameBound(records.size(), nullptr), '\0');
  lz4.resize(LZ4F_compressFrame(lz4.data(), lz4.size(), records.data(), records.size(), nullptr));
  ZSTD_CCtx* context = ZSTD_createCCtx();
  ZSTD_CCtx_setParameter(context, ZSTD_c_contentSizeFlag, 0);  // a frame that does not state its size
  std::string zstd(ZSTD_compressBound(records.size()), '\0');
  zstd.resize(ZSTD_compress2(context, zstd.data(), zstd.size(), records.data(), records.size()));
  ZSTD_freeCCtx(context);
  ASSERT_EQ(ZSTD_getFrameContentSize(zstd.data(), zstd.size()), ZSTD_CONTENTSIZE_UNKNOWN);
  EXPECT_EQ(Payloads(WriteFile("lz4.mcap", McapWithChunk("lz4", lz4, records.size(), 0))), expected);
  EXPECT_EQ(Payloads(WriteFile("zstd.mcap", McapWithChunk("zstd", zstd, records.size(), 0))), expected);
  EXPECT_EQ(Payloads(WriteFile("none.mcap", McapWithChunk("", records, records.size(), 0))), expected);

  const auto refused = [&](const std::string& name, const std::string& bytes, const std::string& fault) {
    const std::size_t before = PeakMemory();
    try {
      Payloads(WriteFile(name, bytes));
      ADD_FAILURE() << name << " read";
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
    }
    EXPECT_LT(PeakMemory(), before + (std::size_t(64) << 20)) << name;
  };
  constexpr std::uint64_t kGiB = std::uint64_t(1) << 30;
  refused("lz4_gib.mcap", McapWithChunk("lz4", lz4, kGiB, 0), "lz4 expands at most 256-fold");
  refused("zstd_gib.mcap", McapWithChunk("zstd", zstd, kGiB, 0), "not its stated 1073741824");
  refused("zstd_short.mcap", McapWithChunk("zstd", zstd, records.size() - 1, 0), "decompresses past its stated");
  refused("lz4_short.mcap", McapWithChunk("lz4", lz4, records.size() - 1, 0), "decompresses past its stated");
  refused("lz4_cut.mcap", McapWithChunk("lz4", lz4.substr(0, lz4.size() - 5), records.size(), 0), "lz4");
  refused("zstd_cut.mcap", McapWithChunk("zstd", zstd.substr(0, zstd.size() - 3), records.size(), 0), "zstd");
  std::string flipped = records;
  flipped[flipped.size() - 3] ^= 0x01;  // inside "payload1"
  const std::uint32_t crc = std::uint32_t(crc32(0, reinterpret_cast<const Bytef*>(records.data()), records.size()));
  EXPECT_EQ(Payloads(WriteFile("crc.mcap", McapWithChunk("", records, records.size(), crc))), expected);
  refused("flipped.mcap", McapWithChunk("", flipped, records.size(), crc), "a chunk's CRC does not match");
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
  const auto refused = [&](const std::string& files, const std::string& fault) {
    WriteFile("bag/metadata.yaml", "rosbag2_bagfile_information:\n  relative_file_paths: " + files + "\n");
    try {
      ReadBagScans(Path("bag"), "/radar/points");
      ADD_FAILURE() << files;
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
    }
  };
  // A name with two dots is a name; a link out of the folder is outside it; a file listed twice is refused.
  std::filesystem::rename(Path("bag/part_1.db3"), Path("bag/b..0.db3"));
  WriteFile("bag/metadata.yaml", "rosbag2_bagfile_information:\n  relative_file_paths: [part_0.mcap, b..0.db3]\n");
  EXPECT_EQ(ReadBagScans(Path("bag"), "/radar/points").size(), 6u);
  std::filesystem::rename(Path("bag/b..0.db3"), Path("outside.db3"));
  std::filesystem::create_symlink(Path("outside.db3"), Path("bag/link.db3"));
  refused("[part_0.mcap, link.db3]", "'link.db3' is not inside the bag's folder");
  refused("[part_0.mcap, part_0.mcap]", "'part_0.mcap' is listed twice");
  refused("[part_0.mcap, ./part_0.mcap]", "'./part_0.mcap' is listed twice");
  refused("[.]", "is not inside");
  // One message compressed on its own: a 13-byte zstd frame stating 1 GiB (one
  // RLE block of 100 bytes) is refused without the GiB being allocated.
  const std::string db3 = Path("bag/compressed.db3");
  Sql(db3,
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, serialization_format TEXT "
      "NOT NULL);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data "
      "BLOB NOT NULL);"
      "INSERT INTO topics VALUES(1, '/radar/points', 'sensor_msgs/msg/PointCloud2', 'cdr');"
      "INSERT INTO messages VALUES(1, 1, 1, X'28B52FFDA00000004023030007');");
  WriteFile("bag/metadata.yaml",
            "rosbag2_bagfile_information:\n  compression_format: zstd\n  compression_mode: MESSAGE\n"
            "  relative_file_paths: [compressed.db3]\n");
  const std::size_t before = PeakMemory();
  try {
    ReadBagScans(Path("bag"), "/radar/points");
    ADD_FAILURE() << "a 13-byte message stating 1 GiB read";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("a zstd message"), std::string::npos) << e.what();
  }
  EXPECT_LT(PeakMemory(), before + (std::size_t(64) << 20));
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

// A run folder's CSVs read back into columns: five million keyframes (20 MB)
// cost their numbers, not a map per row; a loop's keyframe found by its
// stamp; a cell that is not a number named by file, line and column.
TEST_F(Rosbag2Files, ARunsCsvsAreReadIntoColumns) {
  std::filesystem::create_directories(Path("run"));
  WriteFile("run/odometry.tum", "0 0 0 0 0 0 0 1\n10 10 0 0 0 0 0 1\n");
  {
    std::ofstream keyframes(Path("run/keyframes.csv"));
    keyframes << "index,stamp\n";
    for (int k = 0; k < 5000000; ++k) keyframes << k << "," << (k == 1 ? 5 : 0) << "\n";
  }
  WriteFile("run/loops.csv", "query,candidate,accepted\n1,0,1\n0,1,0\n");
  const std::size_t before = PeakMemory();
  const RunForViewer run = ReadRunFolder(Path("run"));
  EXPECT_LT(PeakMemory(), before + (std::size_t(300) << 20));
  ASSERT_EQ(run.loops.size(), 1u);
  EXPECT_LT((run.loops[0].first - Eigen::Vector3d(5, 0, 0)).norm(), 1e-12);  // keyframe 1 at 5 s
  WriteFile("run/loops.csv", "query,candidate,accepted\n1,x,1\n");
  try {
    ReadRunFolder(Path("run"));
    FAIL() << "a loop naming keyframe 'x' read";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("loops.csv:2: column 'candidate' holds 'x', not a number"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace radargauss
