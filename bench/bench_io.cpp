// SPDX-License-Identifier: BSD-3-Clause
// Data in: load throughput (points/s) per format, and Doppler ego velocity
// per 800-point scan.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "radargauss/core/doppler.hpp"
#include "radargauss/io/kitti_bin.hpp"
#include "radargauss/io/pcd.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/io/bag_reader.hpp"
#include "radargauss/io/bag_writer.hpp"
#include "radargauss/simulator/simulator.hpp"

namespace radargauss {
namespace {

namespace fs = std::filesystem;

// One simulated scan of about 800 points (the ARS548 maximum) with every field.
const RadarScan& BenchmarkScan() {
  static const RadarScan scan = [] {
    SimulationConfig config;
    config.scans = 1;
    config.min_detections = config.max_detections = 800;
    return Simulate(config).scans.front();
  }();
  return scan;
}

std::string BenchmarkFile(const std::string& name) {
  static const fs::path dir = fs::temp_directory_path() / "radargauss_bench_io";
  fs::create_directories(dir);
  return (dir / name).string();
}

void BM_ReadPcd(benchmark::State& state, PcdFormat format, const char* name) {
  const std::string path = BenchmarkFile(name);
  WritePcdScan(path, BenchmarkScan(), format);
  std::size_t points = 0;
  for (auto _ : state) {
    const RadarScan scan = ReadPcdScan(path);
    points += scan.points.size();
    benchmark::DoNotOptimize(scan.points.data());
  }
  state.counters["points/s"] = benchmark::Counter(double(points), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(BM_ReadPcd, ascii, PcdFormat::kAscii, "scan_ascii.pcd");
BENCHMARK_CAPTURE(BM_ReadPcd, binary, PcdFormat::kBinary, "scan_binary.pcd");
BENCHMARK_CAPTURE(BM_ReadPcd, binary_compressed, PcdFormat::kBinaryCompressed, "scan_compressed.pcd");

void BM_ReadKittiBin(benchmark::State& state) {
  const std::string path = BenchmarkFile("scan.bin");
  {
    std::ofstream out(path, std::ios::binary);
    for (const RadarPoint& p : BenchmarkScan().points) {
      const float record[7] = {float(p.position.x()),
                               float(p.position.y()),
                               float(p.position.z()),
                               float(p.rcs),
                               float(p.doppler),
                               0.0f,
                               0.0f};
      out.write(reinterpret_cast<const char*>(record), sizeof(record));
    }
  }
  const std::vector<std::string> layout = ParseBinLayout("vod");
  std::size_t points = 0;
  for (auto _ : state) {
    const RadarScan scan = ReadKittiBin(path, layout);
    points += scan.points.size();
    benchmark::DoNotOptimize(scan.points.data());
  }
  state.counters["points/s"] = benchmark::Counter(double(points), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ReadKittiBin);

// The whole TI mmWave demo bag (412 messages, 17,872 points), when present.
void BM_ReadBag(benchmark::State& state) {
  const std::string bag = std::string(RADARGAUSS_SHARED_DATA_DIR) + "/ti_mmwave_demo/demo_ti_mmwave_rospkg_format.bag";
  if (!RosbagSupported() || !fs::exists(bag)) {
    state.SkipWithError("no ROS1 bag support or no shared data");
    return;
  }
  std::size_t points = 0;
  for (auto _ : state) {
    for (const RadarScan& scan : ReadBagScans(bag, "/ti_mmwave/radar_scan_pcl")) {
      points += scan.points.size();
    }
  }
  state.counters["points/s"] = benchmark::Counter(double(points), benchmark::Counter::kIsRate);
  state.counters["scans/s"] = benchmark::Counter(412.0 * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["file MB/s"] =
      benchmark::Counter(double(fs::file_size(bag)) * double(state.iterations()) / 1e6, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ReadBag)->Unit(benchmark::kMillisecond);

// The same 412 scans converted to ROS 2 bags (x y z doppler rcs as FLOAT64),
// written once into the temporary folder: 0 zstd .mcap, 1 lz4 .mcap,
// 2 unchunked .mcap, 3 .db3. Counters: scans and file bytes per second.
void BM_ReadRos2Bag(benchmark::State& state) {
  const std::string ros1 = std::string(RADARGAUSS_SHARED_DATA_DIR) + "/ti_mmwave_demo/demo_ti_mmwave_rospkg_format.bag";
  if (!RosbagSupported() || !fs::exists(ros1)) {
    state.SkipWithError("no ROS1 bag support or no shared data");
    return;
  }
  static const std::vector<std::string> bags = [&] {
    const std::vector<RadarScan> scans = ReadBagScans(ros1, "/ti_mmwave/radar_scan_pcl");
    const std::string dir = (fs::temp_directory_path() / "radargauss_bench_io").string();
    fs::create_directories(dir);
    std::vector<std::string> paths;
    const std::pair<const char*, McapCompression> mcaps[] = {{"zstd.mcap", McapCompression::kZstd},
                                                             {"lz4.mcap", McapCompression::kLz4},
                                                             {"unchunked.mcap", McapCompression::kNone}};
    for (const auto& [name, compression] : mcaps) {
      BagExportOptions options;
      options.mcap.compression = compression;
      options.mcap.chunked = std::string(name) != "unchunked.mcap";
      paths.push_back(dir + "/" + name);
      WriteRos2Bag(paths.back(), BagFormat::kMcap, scans, {}, nullptr, options);
    }
    paths.push_back(dir + "/bag.db3");
    WriteRos2Bag(paths.back(), BagFormat::kSqlite3, scans, {}, nullptr);
    return paths;
  }();
  const std::string& bag = bags[std::size_t(state.range(0))];
  std::size_t scans = 0;
  for (auto _ : state) scans += ReadBagScans(bag, "/radar/points").size();
  state.SetLabel(fs::path(bag).filename().string());
  state.counters["scans/s"] = benchmark::Counter(double(scans), benchmark::Counter::kIsRate);
  state.counters["file MB/s"] =
      benchmark::Counter(double(fs::file_size(bag)) * double(state.iterations()) / 1e6, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ReadRos2Bag)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

// The demo's drive with a 200 Hz IMU (120 scans) as `convert` writes it
// (zstd chunks of 1 MiB, scans and IMU interleaved by time), read through
// the bag reader: 0 the IMU alone, 1 the scans of the first 2 s, 2
// everything. Counters: the chunks decompressed and skipped per read.
void BM_ReadBagFiltered(benchmark::State& state) {
  static const std::string bag = [] {
    SimulationConfig config;
    config.scans = 120;
    config.imu_rate_hz = 200.0;
    const SimulatedSequence drive = Simulate(config);
    const std::string path = (fs::temp_directory_path() / "radargauss_bench_io_filtered.mcap").string();
    WriteRos2Bag(path, BagFormat::kMcap, drive.scans, drive.imu, &drive.ground_truth);
    return path;
  }();
  BagReadOptions options;
  const std::unique_ptr<BagReader> probe = OpenBag(bag);
  std::int64_t first = 0;
  probe->Read({{"/radar/points"}}, [&](const BagMessage& m) { first = first == 0 ? m.log_time : first; });
  if (state.range(0) == 0) options.topics = {"/imu/data"};
  if (state.range(0) == 1) options = {{"/radar/points"}, first, first + 2'000'000'000};
  std::size_t messages = 0;
  BagReadStatistics last;
  for (auto _ : state) {
    const std::unique_ptr<BagReader> reader = OpenBag(bag);
    reader->Read(options, [&](const BagMessage&) { ++messages; });
    last = reader->statistics();
  }
  state.SetLabel(state.range(0) == 0 ? "IMU alone" : state.range(0) == 1 ? "scans of 2 s" : "everything");
  state.counters["chunks read"] = double(last.chunks_read);
  state.counters["chunks skipped"] = double(last.chunks_skipped);
  state.counters["messages"] = double(messages) / double(state.iterations());
}
BENCHMARK(BM_ReadBagFiltered)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

// Odometry's Doppler RANSAC (support counted in voxels) on 1 and 2 threads:
// the hypotheses' supports are counted side by side.
void BM_EgoVelocity800(benchmark::State& state) {
  const RadarScan& scan = BenchmarkScan();
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(0)));
  EgoVelocityOptions options;
  options.consensus_voxel = 1.0;
  for (auto _ : state) benchmark::DoNotOptimize(EstimateEgoVelocity(scan, options).velocity);
  state.counters["points"] = double(scan.points.size());
}
BENCHMARK(BM_EgoVelocity800)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace
}  // namespace radargauss

BENCHMARK_MAIN();
