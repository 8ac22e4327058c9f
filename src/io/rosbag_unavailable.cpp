// SPDX-License-Identifier: BSD-3-Clause
// Built when Debian's ROS1 bag library is absent: a ROS1 bag is refused, saying so.
#include "bag_readers.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/bag_reader.hpp"

namespace radargauss {

namespace {

DataError Unavailable(const std::string& path) {
  return FileError(path,
                   "radargauss was built without ROS1 bag support "
                   "(install librosbag-storage-dev libsensor-msgs-dev and reconfigure)");
}

// No ROS1 message is ever read: OpenRos1Bag refuses first.
class Ros1 final : public MessageCodec {
 public:
  double RecordStamp(std::int64_t log_time) const override { return double(log_time) * 1e-9; }
  double PointCloud2(const BagMessage&, const std::string& source, PointCloud2Data&) const override {
    throw Unavailable(source);
  }
  double Imu(const BagMessage&, const std::string& source, ImuSample&) const override { throw Unavailable(source); }
  bool Pose(const BagMessage&, const std::string& source, const std::string&, double&, SE3d&) const override {
    throw Unavailable(source);
  }
  bool Path(const BagMessage&, const std::string& source, std::vector<StampedPose>&) const override {
    throw Unavailable(source);
  }
};

}  // namespace

bool RosbagSupported() { return false; }
const MessageCodec& Ros1Codec() {
  static const Ros1 codec;
  return codec;
}
std::unique_ptr<BagReader> OpenRos1Bag(const std::string& path) { throw Unavailable(path); }

}  // namespace radargauss
