// SPDX-License-Identifier: BSD-3-Clause
#include "entry_points.hpp"

#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../apps/radargauss/yaml_config.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/experiment/experiment.hpp"
#include "radargauss/io/kitti_bin.hpp"
#include "radargauss/io/mcap.hpp"
#include "radargauss/io/pcd.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/map_tiles.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/slam/place_recognition.hpp"
#include "radargauss/core/trajectory.hpp"

namespace radargauss::fuzz {

namespace {

// The readers take paths: the input goes to a file of this process first.
std::string InputPath(const std::string& name) {
  return "/tmp/radargauss_fuzz_" + std::to_string(::getpid()) + "_" + name;
}

std::string WriteInput(const std::uint8_t* data, std::size_t size, const std::string& name) {
  const std::string path = InputPath(name);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return path;
}

template <typename Read>
void Expecting(const Read& read) {
  try {
    read();
  } catch (const DataError&) {
  }
}

void Pcd(const std::uint8_t* data, std::size_t size) {
  const std::string path = WriteInput(data, size, "1702450000.500000000.pcd");
  Expecting([&] { ReadPcdScan(path); });
}

// The first byte picks a layout; the rest is the file.
void KittiBin(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  static const char* kLayouts[] = {kViewOfDelftLayout, "x y z", "x,y,z,rcs,doppler", "time x doppler y z"};
  const std::vector<std::string> layout = ParseBinLayout(kLayouts[data[0] % 4]);
  const std::string path = WriteInput(data + 1, size - 1, "1702450000.5.bin");
  Expecting([&] { ReadKittiBin(path, layout); });
}

void Tum(const std::uint8_t* data, std::size_t size) {
  const std::string path = WriteInput(data, size, "trajectory.txt");
  Expecting([&] { ReadTum(path); });
}

// A map that reads is also indexed: the index is where a huge Gaussian hangs.
void MapFile(const std::uint8_t* data, std::size_t size) {
  const std::string path = WriteInput(data, size, "map.rgm");
  Expecting([&] {
    const GaussianMap map = ReadMap(path);
    const GaussianIndex index(map.gaussians);
    for (const Gaussian& g : map.gaussians) index.Associate(g.mean, 9.0);
  });
}

// A map whose CRC this entry point writes (the input's last four bytes are
// replaced), so that the fuzzer reaches the places section that the CRC
// hides from map_file; every place that reads is described by both
// descriptors, as the relocaliser describes them.
void MapPlaces(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return;
  std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::uint32_t crc =
      std::uint32_t(crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), uInt(bytes.size() - 4)));
  std::memcpy(&bytes[bytes.size() - 4], &crc, 4);
  const std::string path = WriteInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), "places.rgm");
  Expecting([&] {
    const GaussianMap map = ReadMap(path);
    PlaceRecognitionOptions options;
    for (const char* descriptor : {"scan-context", "radon"}) {
      options.descriptor = descriptor;
      PlaceDatabase places(options, [](int) -> std::shared_ptr<const PlaceDescription> { return nullptr; });
      for (const MapPlace& place : map.places) {
        places.Add(places.Describe(DownsampleSubmap(place.points, options.submap_voxel)));
      }
    }
  });
}

// Little-endian fields as a bag stores sensor_msgs/PointCloud2 (without the
// header): height, width, field count, fields (name length, name, offset,
// datatype, count), is_bigendian, point_step, row_step, then the data.
class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool U32(std::uint32_t& value) { return Copy(&value, 4); }
  bool U8(std::uint8_t& value) { return Copy(&value, 1); }
  bool Text(std::string& text) {
    std::uint8_t length = 0;
    if (!U8(length) || length > size_ - used_) return false;
    text.assign(reinterpret_cast<const char*>(data_ + used_), length);
    used_ += length;
    return true;
  }
  std::vector<std::uint8_t> Rest() const { return {data_ + used_, data_ + size_}; }

 private:
  bool Copy(void* value, std::size_t n) {
    if (n > size_ - used_) return false;
    std::memcpy(value, data_ + used_, n);
    used_ += n;
    return true;
  }
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t used_ = 0;
};

void PointCloud2(const std::uint8_t* data, std::size_t size) {
  Bytes bytes(data, size);
  PointCloud2Data cloud;
  std::uint8_t field_count = 0, big_endian = 0;
  if (!bytes.U32(cloud.height) || !bytes.U32(cloud.width) || !bytes.U8(field_count)) return;
  cloud.fields.resize(field_count);
  for (PointCloud2Field& field : cloud.fields) {
    if (!bytes.Text(field.name) || !bytes.U32(field.offset) || !bytes.U8(field.datatype) || !bytes.U32(field.count)) {
      return;
    }
  }
  if (!bytes.U8(big_endian) || !bytes.U32(cloud.point_step) || !bytes.U32(cloud.row_step)) return;
  cloud.is_bigendian = big_endian != 0;
  cloud.data = bytes.Rest();
  Expecting([&] { DecodePointCloud2(cloud, 1702450000.5, FieldMapping(), "message"); });
}

// An MCAP file, every message visited (chunks decompressed, CRCs checked),
// then read again through its chunk index, filtered as a bag's IMU is.
void Mcap(const std::uint8_t* data, std::size_t size) {
  const std::string path = WriteInput(data, size, "bag.mcap");
  Expecting([&] {
    McapReader reader(path);
    reader.ForEachMessage([](const McapMessage&) {});
  });
  Expecting([&] {
    McapReader reader(path);
    const std::string topic = reader.channels().empty() ? "/imu" : reader.channels().back().topic;
    reader.Read({{topic}, 1, ~0ull - 1}, [](const McapMessage&) {});
  });
}

// The first byte picks the message type; the rest is its CDR. A point cloud
// that decodes goes on to DecodePointCloud2, as a bag's scans do.
void Cdr(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  static const char* kPoseTypes[] = {"geometry_msgs/msg/PoseStamped", "nav_msgs/msg/Odometry",
                                     "tf2_msgs/msg/TFMessage"};
  const int kind = data[0] % 5;
  ++data;
  --size;
  Expecting([&] {
    if (kind == 0) {
      PointCloud2Data cloud;
      const Ros2Header header = DecodeRos2PointCloud2(data, size, "message", cloud);
      DecodePointCloud2(cloud, header.stamp, FieldMapping(), "message");
    } else if (kind == 1) {
      ImuSample sample;
      DecodeRos2Imu(data, size, "message", sample);
    } else {
      double stamp = 0.0;
      SE3d pose;
      DecodeRos2Pose(kPoseTypes[kind - 2], data, size, "message", "base_link", stamp, pose);
    }
  });
}

void SimulatorYaml(const std::uint8_t* data, std::size_t size) {
  const std::string path = WriteInput(data, size, "world.yaml");
  Expecting([&] { LoadSimulationConfig(path); });
}

// The configuration reader reads its file by path (the stream is unused).
void CliYaml(const std::uint8_t* data, std::size_t size) {
  const std::string path = WriteInput(data, size, "config.yaml");
  std::istringstream unused;
  try {
    YamlConfig("localize", path).from_config(unused);
  } catch (const CLI::ConversionError&) {
  }
}

void RigYaml(const std::uint8_t* data, std::size_t size) {
  const std::string path = WriteInput(data, size, "rig.yaml");
  Expecting([&] { ReadRig(path); });
}

// One shard folder merged alone: every field of shard.json is read.
void ShardJson(const std::uint8_t* data, std::size_t size) {
  const std::string dir = InputPath("shard");
  ::mkdir(dir.c_str(), 0700);
  WriteInput(data, size, "shard/shard.json");
  Expecting([&] {
    std::vector<SE3d> references;
    MergeShards({dir}, references);
  });
}

}  // namespace

// The tiles the map_tiles target's index refers to: three Gaussians, two in
// tile (0, 0) and one in (1, 0) at 100 m, written once per process
// (scripts/fuzz_seeds.py writes their true index as the seed).
std::string TilesFolder() {
  static const std::string folder = [] {
    const std::string dir = InputPath("tiles");
    std::filesystem::remove_all(dir);
    GaussianMap map;
    for (const double x : {10.0, 150.0, 20.0}) {
      Gaussian g;
      g.mean = Eigen::Vector3d(x, 5.0, 0.0);
      map.gaussians.push_back(g);
    }
    WriteMapTiles(dir, map, 100.0);
    return dir;
  }();
  return folder;
}

// A tiles.json over TilesFolder's tiles, read whole and by neighbourhood.
void MapTiles(const std::uint8_t* data, std::size_t size) {
  const std::string dir = TilesFolder();
  std::ofstream(dir + "/tiles.json", std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), std::streamsize(size));
  Expecting([&] { ReadMapTiles(dir); });
  Expecting([&] { ReadMapTiles(dir, Eigen::Vector2d(120.0, 0.0), 30.0); });
}

const std::vector<Target>& Targets() {
  static const std::vector<Target> targets = {{"pcd", Pcd},
                                              {"kitti_bin", KittiBin},
                                              {"tum", Tum},
                                              {"map_file", MapFile},
                                              {"pointcloud2", PointCloud2},
                                              {"simulator_yaml", SimulatorYaml},
                                              {"cli_yaml", CliYaml},
                                              {"shard_json", ShardJson},
                                              {"map_places", MapPlaces},
                                              {"mcap", Mcap},
                                              {"cdr", Cdr},
                                              {"map_tiles", MapTiles},
                                              {"rig_yaml", RigYaml}};
  return targets;
}

}  // namespace radargauss::fuzz
