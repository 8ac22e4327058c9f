// SPDX-License-Identifier: BSD-3-Clause
// One reader per bag format (docs/design/formats.md, "One reader per
// format"): a filtered read delivers exactly what a whole pass filtered by
// hand delivers, in log-time order; an MCAP read decompresses only the
// chunks its filter admits; chunk indexes that lie are refused.
#include "radargauss/io/bag_reader.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "radargauss/core/error.hpp"
#include "radargauss/io/bag_writer.hpp"
#include "radargauss/io/mcap.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

using BagReaders = testing::TempDirTest;

std::vector<std::uint8_t> Text(const std::string& s) { return std::vector<std::uint8_t>(s.begin(), s.end()); }

struct Seen {
  std::string topic;
  std::uint64_t log_time;
  std::string payload;
  bool operator==(const Seen& o) const { return topic == o.topic && log_time == o.log_time && payload == o.payload; }
};

// An MCAP writer of std_msgs/String messages into `out`, a chunk closing
// past `chunk_bytes`; `schema` for its channels.
struct StringMcap {
  StringMcap(std::ostream& out, std::size_t chunk_bytes) : writer(out, Options(chunk_bytes)) {}
  static McapWriterOptions Options(std::size_t chunk_bytes) {
    McapWriterOptions options;
    options.chunk_bytes = chunk_bytes;
    return options;
  }
  McapWriter writer;
  const std::uint16_t schema = writer.AddSchema("std_msgs/msg/String", "ros2msg", "string data\n");
};

// An MCAP file of small chunks: 300 messages on /radar (t = 0..299 us),
// then 300 on /imu, then 300 on /radar again, so that most chunks hold one
// topic; `interleave` writes them alternating instead.
std::string WriteSegments(const std::string& path, bool interleave = false) {
  std::ofstream out(path, std::ios::binary);
  StringMcap mcap(out, 2048);
  McapWriter& writer = mcap.writer;
  const std::uint16_t schema = mcap.schema;
  const std::uint16_t radar = writer.AddChannel("/radar", schema), imu = writer.AddChannel("/imu", schema);
  for (int k = 0; k < 900; ++k) {
    const bool on_imu = interleave ? k % 2 == 1 : (k >= 300 && k < 600);
    writer.Write(on_imu ? imu : radar, 1000u * k, 1000u * k, Text("message " + std::to_string(k)));
  }
  writer.Finish();
  return path;
}

std::vector<Seen> WholePass(const std::string& path) {
  McapReader reader(path);
  std::vector<Seen> seen;
  reader.ForEachMessage([&](const McapMessage& m) {
    seen.push_back({m.channel->topic, m.log_time, std::string(reinterpret_cast<const char*>(m.data), m.size)});
  });
  return seen;
}

std::vector<Seen> Filtered(const std::vector<Seen>& all, const std::string& topic, std::uint64_t start,
                           std::uint64_t end) {
  std::vector<Seen> kept;
  for (const Seen& s : all) {
    if ((topic.empty() || s.topic == topic) && s.log_time >= start && s.log_time <= end) kept.push_back(s);
  }
  return kept;
}

TEST_F(BagReaders, AnMcapReadDecompressesOnlyTheChunksItsFilterAdmits) {
  const std::string path = WriteSegments(Path("segments.mcap"));
  const std::vector<Seen> all = WholePass(path);
  ASSERT_EQ(all.size(), 900u);
  McapReader counter(path);
  const std::size_t chunks = counter.chunk_indexes().size();
  ASSERT_GT(chunks, 10u);

  // IMU alone: the chunks of the middle third and the two it shares with /radar.
  McapReader reader(path);
  std::vector<Seen> imu;
  reader.Read({{"/imu"}}, [&](const McapMessage& m) {
    imu.push_back({m.channel->topic, m.log_time, std::string(reinterpret_cast<const char*>(m.data), m.size)});
  });
  EXPECT_EQ(imu, Filtered(all, "/imu", 0, ~0ull));
  EXPECT_EQ(reader.chunks_read() + reader.chunks_skipped(), chunks);
  EXPECT_LE(reader.chunks_read(), chunks / 3 + 2);
  EXPECT_GE(reader.chunks_read(), chunks / 3 - 1);

  // A time range inside the first third: only its chunks.
  McapReader ranged(path);
  std::vector<Seen> window;
  ranged.Read({{}, 50000, 80000}, [&](const McapMessage& m) {
    window.push_back({m.channel->topic, m.log_time, std::string(reinterpret_cast<const char*>(m.data), m.size)});
  });
  EXPECT_EQ(window, Filtered(all, "", 50000, 80000));
  EXPECT_LE(ranged.chunks_read(), 3u);

  // Everything: every chunk once, in the whole pass's order.
  McapReader everything(path);
  std::vector<Seen> read;
  everything.Read({}, [&](const McapMessage& m) {
    read.push_back({m.channel->topic, m.log_time, std::string(reinterpret_cast<const char*>(m.data), m.size)});
  });
  EXPECT_EQ(read, all);
  EXPECT_EQ(everything.chunks_read(), chunks);
  EXPECT_EQ(everything.chunks_skipped(), 0u);
}

// Chunks whose times overlap (written out of order) are merged: the read is
// in log-time order, a whole pass in file order.
TEST_F(BagReaders, OverlappingChunksAreReadInLogTimeOrder) {
  const std::string path = Path("overlap.mcap");
  {
    std::ofstream out(path, std::ios::binary);
    StringMcap mcap(out, 1024);
    McapWriter& writer = mcap.writer;
    const std::uint16_t schema = mcap.schema;
    const std::uint16_t a = writer.AddChannel("/a", schema), b = writer.AddChannel("/b", schema);
    for (int k = 0; k < 200; ++k) writer.Write(a, 10u * k, 0, Text("a" + std::to_string(k)));
    for (int k = 0; k < 200; ++k) writer.Write(b, 5u * k + 3, 0, Text("b" + std::to_string(k)));
    writer.Write(b, 1000, 0, Text("b tie"));  // the time of /a 100, later in the file: after it
    writer.Finish();
  }
  const std::vector<Seen> all = WholePass(path);
  McapReader reader(path);
  std::vector<Seen> read;
  reader.Read({}, [&](const McapMessage& m) {
    read.push_back({m.channel->topic, m.log_time, std::string(reinterpret_cast<const char*>(m.data), m.size)});
  });
  ASSERT_EQ(read.size(), all.size());
  std::vector<Seen> expected = all;
  std::stable_sort(expected.begin(), expected.end(),
                   [](const Seen& x, const Seen& y) { return x.log_time < y.log_time; });
  EXPECT_EQ(read, expected);
  EXPECT_NE(all, expected);  // the file itself is out of order
}

// Every reader answers a filtered read as a whole read filtered by hand.
TEST_F(BagReaders, EveryFormatFiltersByTopicAndTime) {
  SimulationConfig config;
  config.scans = 30;
  config.imu_rate_hz = 100.0;
  const SimulatedSequence simulated = Simulate(config);
  std::filesystem::create_directories(Path("folder"));
  BagExportOptions small_chunks;
  small_chunks.mcap.chunk_bytes = 1 << 14;
  WriteRos2Bag(Path("bag.mcap"), BagFormat::kMcap, simulated.scans, simulated.imu, &simulated.ground_truth,
               small_chunks);
  WriteRos2Bag(Path("bag.db3"), BagFormat::kSqlite3, simulated.scans, simulated.imu, &simulated.ground_truth);
  WriteRos2Bag(Path("folder/part_0.mcap"), BagFormat::kMcap, simulated.scans, {}, nullptr, small_chunks);
  std::ofstream(Path("folder/metadata.yaml")) << "rosbag2_bagfile_information:\n  relative_file_paths:\n"
                                                 "    - part_0.mcap\n";
  for (const std::string name : {"bag.mcap", "bag.db3", "folder"}) {
    const std::unique_ptr<BagReader> bag = OpenBag(Path(name));
    std::vector<std::pair<std::string, std::int64_t>> all, some;
    bag->Read({}, [&](const BagMessage& m) { all.emplace_back(*m.topic, m.log_time); });
    ASSERT_GE(all.size(), 30u) << name;
    const std::int64_t start = all[all.size() / 4].second, end = all[all.size() / 2].second;
    bag->Read({{"/radar/points"}, start, end}, [&](const BagMessage& m) {
      EXPECT_EQ(m.codec, &CdrCodec());
      some.emplace_back(*m.topic, m.log_time);
    });
    std::vector<std::pair<std::string, std::int64_t>> expected;
    for (const auto& m : all) {
      if (m.first == "/radar/points" && m.second >= start && m.second <= end) expected.push_back(m);
    }
    EXPECT_FALSE(expected.empty()) << name;
    EXPECT_EQ(some, expected) << name;
    for (std::size_t k = 1; k < all.size(); ++k) EXPECT_LE(all[k - 1].second, all[k].second) << name;
  }
  // What the readers list agrees across formats.
  const std::vector<BagTopic> mcap = OpenBag(Path("bag.mcap"))->Topics(), db3 = OpenBag(Path("bag.db3"))->Topics();
  ASSERT_EQ(mcap.size(), db3.size());
  for (std::size_t k = 0; k < mcap.size(); ++k) {
    EXPECT_EQ(mcap[k].name, db3[k].name);
    EXPECT_EQ(mcap[k].messages, db3[k].messages);
  }
  EXPECT_THROW(OpenBag(Path("absent.mcap")), DataError);
}

// The byte offsets of the summary's chunk index records, read from the footer.
std::vector<std::size_t> ChunkIndexOffsets(const std::string& file) {
  const auto u64 = [&](std::size_t at) {
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= std::uint64_t(std::uint8_t(file[at + i])) << (8 * i);
    return v;
  };
  const std::size_t footer = file.size() - 8 - 29;
  std::size_t at = std::size_t(u64(footer + 9));
  std::vector<std::size_t> found;
  while (at < footer) {
    if (file[at] == '\x08') found.push_back(at);
    at += 9 + std::size_t(u64(at + 1));
  }
  return found;
}

TEST_F(BagReaders, ChunkIndexesThatLieAreRefused) {
  std::ostringstream written;
  {
    StringMcap mcap(written, 512);
    McapWriter& writer = mcap.writer;
    const std::uint16_t schema = mcap.schema;
    const std::uint16_t a = writer.AddChannel("/a", schema);
    for (int k = 0; k < 100; ++k) writer.Write(a, k, k, Text(std::string(40, char('a' + k % 26))));
    writer.Finish();
  }
  std::string good = written.str();
  good.replace(good.size() - 8 - 4, 4, std::string(4, '\0'));  // no summary CRC: the lie is the index's alone
  const std::vector<std::size_t> indexes = ChunkIndexOffsets(good);
  ASSERT_GT(indexes.size(), 2u);
  const auto read_all = [&](const std::string& bytes) {
    const std::string path = Path("lie.mcap");
    std::ofstream(path, std::ios::binary) << bytes;
    McapReader reader(path);
    std::size_t n = 0;
    reader.Read({}, [&](const McapMessage&) { ++n; });
    return n;
  };
  EXPECT_EQ(read_all(good), 100u);
  const auto refused = [&](std::string bytes, std::size_t field, std::uint64_t value, const std::string& fault) {
    for (int i = 0; i < 8; ++i) bytes[indexes[1] + 9 + field + i] = char(std::uint8_t(value >> (8 * i)));
    try {
      read_all(bytes);
      ADD_FAILURE() << fault;
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
    }
  };
  refused(good, 16, good.size() * 2, "outside the data section");  // the chunk's offset
  refused(good, 16, 8, "points to no chunk");                      // the header record's offset
  refused(good, 24, 1ull << 40, "outside the data section");       // its length
  refused(good, 0, ~0ull, "ends before it starts");                // its start time
}

}  // namespace
}  // namespace radargauss
