// SPDX-License-Identifier: BSD-3-Clause
// radargauss convert: a sequence (PCD or KITTI folder, the Snail-Radar
// layout, a bag of any kind) with its IMU and reference to a ROS 2 bag; or
// a rig's radars to one bag, a topic each, with the rig file that reads it.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "option_flags.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/io/bag_writer.hpp"

namespace radargauss::cli {

namespace {

struct ConvertSettings {
  SequenceOptions sequence;
  std::string rig, rig_out;
  std::string imu, imu_topic, imu_stamps = "header";
  std::string out;
  std::string format;  // mcap, db3; empty: from --out's extension
  std::string compression = "zstd";
  bool unchunked = false;
  BagExportOptions bag;
};

BagFormat FormatOf(const ConvertSettings& s) {
  std::string format = s.format;
  if (format.empty()) {
    const std::size_t dot = s.out.rfind('.');
    format = dot == std::string::npos ? "" : s.out.substr(dot + 1);
  }
  if (format == "mcap") return BagFormat::kMcap;
  if (format == "db3") return BagFormat::kSqlite3;
  throw DataError("--out " + s.out + ": say --format mcap or db3 (or end the name in .mcap or .db3)");
}

// A rig's radars to one bag, radar `name`'s scans on /name/points (stamps
// on its own clock), and beside it the rig file naming that bag and topics.
int RunRigConvert(const ConvertSettings& s, BagFormat format) {
  namespace fs = std::filesystem;
  if (!s.sequence.sequence_dir.empty() || !s.sequence.bag.empty() || !s.sequence.ground_truth.empty()) {
    throw DataError("--rig names the radars' scans itself: drop --sequence, --bag and --gt");
  }
  if (!s.imu.empty() || !s.imu_topic.empty()) throw DataError("--rig: a rig's bag takes no IMU yet");
  const Rig rig = ReadRig(s.rig);
  std::string rig_out = s.rig_out;
  if (rig_out.empty()) rig_out = (fs::path(s.out).parent_path() / fs::path(s.out).stem()).string() + ".rig.yaml";
  const std::vector<std::vector<RadarScan>> scans = LoadRigScans(rig);
  std::vector<RigBagRadar> radars;
  Rig written = rig;
  for (std::size_t r = 0; r < rig.radars.size(); ++r) {
    written.radars[r].scans = SequenceOptions();
    written.radars[r].scans.bag = fs::relative(fs::absolute(s.out), fs::absolute(rig_out).parent_path()).string();
    written.radars[r].scans.topic = "/" + rig.radars[r].name + "/points";
  }
  for (std::size_t r = 0; r < rig.radars.size(); ++r) {
    radars.push_back({written.radars[r].scans.topic, rig.radars[r].name, &scans[r]});
  }
  WriteRigBag(s.out, format, radars, s.bag.mcap);
  WriteRig(rig_out, written);
  std::size_t count = 0;
  for (const auto& radar_scans : scans) count += radar_scans.size();
  std::printf("wrote %s: %zu scans of %zu radars on /<radar>/points; %s reads it\n", s.out.c_str(), count,
              rig.radars.size(), rig_out.c_str());
  return 0;
}

int RunConvert(ConvertSettings s) {
  const BagFormat format = FormatOf(s);
  if (!s.imu.empty() && !s.imu_topic.empty()) throw DataError("--imu and --imu-topic: give one");
  if (!s.imu_topic.empty() && s.sequence.bag.empty()) throw DataError("--imu-topic needs --bag");
  s.bag.mcap.compression = s.compression == "lz4"    ? McapCompression::kLz4
                           : s.compression == "none" ? McapCompression::kNone
                                                     : McapCompression::kZstd;
  s.bag.mcap.chunked = !s.unchunked;
  if (!s.rig.empty()) return RunRigConvert(s, format);
  if (!s.rig_out.empty()) throw DataError("--rig-out needs --rig");
  // The topics written, checked before anything is read.
  CheckBagTopics(
      {{"--scan-topic", s.bag.scan_topic}, {"--imu-topic-out", s.bag.imu_topic}, {"--pose-topic", s.bag.pose_topic}});
  // Every scan, the reference (when given) at those within its span.
  SequenceOptions scans_only = s.sequence;
  scans_only.ground_truth.clear();
  const Sequence sequence = LoadSequence(scans_only);
  std::optional<Trajectory> reference;
  if (!s.sequence.ground_truth.empty()) {
    reference =
        ReadRadarTrajectory(s.sequence.ground_truth, ResolveExtrinsic(s.sequence.extrinsic, s.sequence.ground_truth));
  }
  const std::vector<ImuSample> imu = !s.imu.empty() ? ReadImuFile(s.imu)
                                     : !s.imu_topic.empty()
                                         ? ReadBagImu(s.sequence.bag, s.imu_topic, s.imu_stamps == "record")
                                         : std::vector<ImuSample>{};
  // Stamps ROS cannot hold, named by their files before the bag is begun.
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    if (!FitsRosTime(sequence.scans[k].timestamp)) {
      const std::string source = k < sequence.scan_sources.size() ? sequence.scan_sources[k] : s.sequence.bag;
      throw FileError(source, "stamp " + std::to_string(sequence.scans[k].timestamp) +
                                  " s does not fit ROS's time (0 to 2^31 s since 1970)");
    }
  }
  for (const ImuSample& sample : imu) {
    if (!FitsRosTime(sample.stamp)) {
      throw FileError(s.imu.empty() ? s.sequence.bag + ":" + s.imu_topic : s.imu,
                      "IMU stamp " + std::to_string(sample.stamp) +
                          " s does not fit ROS's time (0 to 2^31 s since 1970; seconds expected)");
    }
  }
  WriteRos2Bag(s.out, format, sequence.scans, imu, reference ? &*reference : nullptr, s.bag);
  std::printf("wrote %s: %zu scans on %s%s%s\n", s.out.c_str(), sequence.scans.size(), s.bag.scan_topic.c_str(),
              imu.empty() ? "" : (", " + std::to_string(imu.size()) + " IMU samples on " + s.bag.imu_topic).c_str(),
              reference ? (", reference poses on " + s.bag.pose_topic).c_str() : "");
  return 0;
}

}  // namespace

Subcommand AddConvert(CLI::App& parent) {
  auto s = std::make_shared<ConvertSettings>();
  CLI::App* app = parent.add_subcommand("convert", "Write a sequence (scans, IMU, reference) as a ROS 2 bag");
  AddSequenceOptions(app, s->sequence);
  app->add_option("--rig", s->rig,
                  "Rig file (docs/design/rig.md): every radar's scans to one bag, /<radar>/points each, instead of "
                  "--sequence");
  app->add_option("--rig-out", s->rig_out, "With --rig: the rig file that reads the bag (default: --out as .rig.yaml)");
  app->add_option("--imu", s->imu, "IMU file of lines 'stamp wx wy wz ax ay az' to include");
  app->add_option("--imu-topic", s->imu_topic, "sensor_msgs/Imu topic of --bag to include");
  app->add_option("--imu-stamps", s->imu_stamps, "Stamp the IMU by its header or by the bag's record time")
      ->check(CLI::IsMember({"header", "record"}))
      ->capture_default_str();
  app->add_option("--out", s->out, "The bag file to write (.mcap or .db3)")->required();
  app->add_option("--format", s->format, "mcap or db3 (default: --out's extension)")
      ->check(CLI::IsMember({"mcap", "db3"}));
  app->add_option("--compression", s->compression, "MCAP chunk compression")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}))
      ->capture_default_str();
  AddBoolFlag(app, "--unchunked", s->unchunked, "MCAP without chunks (no compression, no message indexes)");
  app->add_option("--scan-topic", s->bag.scan_topic, "Topic of the scans")->capture_default_str();
  app->add_option("--imu-topic-out", s->bag.imu_topic, "Topic of the IMU")->capture_default_str();
  app->add_option("--pose-topic", s->bag.pose_topic, "Topic of the reference poses")->capture_default_str();
  return {app, [s] { return RunConvert(*s); }};
}

}  // namespace radargauss::cli
