// SPDX-License-Identifier: BSD-3-Clause
// Every bag behind one reader (docs/design/formats.md, "One reader per
// format"): a ROS1 bag, a ROS 2 sqlite3 file, an MCAP file or a rosbag2
// folder, each read by its own BagReader and told apart by content in
// OpenBag alone. A read names the topics and the log-time range it wants;
// a reader skips what the filter excludes before it decompresses it (an
// MCAP chunk whose index lists none of the topics or lies outside the
// range is never read).
//
//   const std::unique_ptr<BagReader> bag = OpenBag(path);
//   bag->Read({{"/imu/data"}}, [&](const BagMessage& m) { ... });
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "radargauss/core/trajectory.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/lie/se3.hpp"

namespace radargauss {

class MessageCodec;

// One message; its topic, type and bytes live until the visitor returns.
struct BagMessage {
  const std::string* topic = nullptr;
  const std::string* type = nullptr;  // as the bag spells it: "sensor_msgs/msg/Imu" or "sensor_msgs/Imu"
  std::int64_t log_time = 0;          // ns: the recorder's receive time
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  const MessageCodec* codec = nullptr;  // how `data` is serialised
};

// What a read delivers: the messages of `topics` (every topic when empty)
// whose log time lies in [start, end] (ns).
struct BagReadOptions {
  std::vector<std::string> topics;
  std::int64_t start = std::numeric_limits<std::int64_t>::min();
  std::int64_t end = std::numeric_limits<std::int64_t>::max();
};

// What the reads so far cost: the compressed blocks (MCAP chunks) a reader
// decompressed and those it skipped by their index.
struct BagReadStatistics {
  std::size_t chunks_read = 0;
  std::size_t chunks_skipped = 0;
};

class BagReader {
 public:
  virtual ~BagReader() = default;
  // Every topic with its type, message count and time span.
  virtual std::vector<BagTopic> Topics() = 0;
  // Calls visit for every message the options admit, in log-time order (a
  // folder: file by file, as rosbag2 splits them by time; an MCAP file
  // without chunk indexes: in file order). Throws DataError naming the file
  // for a malformed bag.
  virtual void Read(const BagReadOptions& options, const std::function<void(const BagMessage&)>& visit) = 0;
  virtual BagReadStatistics statistics() const { return {}; }
  const std::string& path() const { return path_; }

 protected:
  explicit BagReader(std::string path) : path_(std::move(path)) {}

 private:
  std::string path_;
};

// The reader of whatever `path` holds (DetectBagFormat). Throws
// DataError naming it when it is no bag, or a ROS1 bag in a build without
// ROS1 support.
std::unique_ptr<BagReader> OpenBag(const std::string& path);

// How a bag's messages are serialised: CDR (ROS 2) or ROS1's. Each decoder
// fills its message and returns the header's stamp (0 when it is zero);
// DataError names `source` for a message that is not what it claims.
class MessageCodec {
 public:
  virtual ~MessageCodec() = default;
  // A message's stamp from its log time (ns), as the serialisation's own tools compute it.
  virtual double RecordStamp(std::int64_t log_time) const = 0;
  virtual double PointCloud2(const BagMessage& message, const std::string& source, PointCloud2Data& cloud) const = 0;
  virtual double Imu(const BagMessage& message, const std::string& source, ImuSample& sample) const = 0;
  // A reference pose: geometry_msgs PoseStamped, nav_msgs Odometry or the
  // transform of a tf2_msgs TFMessage whose child frame is `child_frame`
  // (false when the message holds none); its stamp is 0 when it is zero.
  virtual bool Pose(const BagMessage& message, const std::string& source, const std::string& child_frame, double& stamp,
                    SE3d& pose) const = 0;
  // A nav_msgs Path's poses with their stamps; false when the message is no Path.
  virtual bool Path(const BagMessage& message, const std::string& source, std::vector<StampedPose>& path) const = 0;
};

// The codecs of the two serialisations.
const MessageCodec& CdrCodec();
const MessageCodec& Ros1Codec();

}  // namespace radargauss
