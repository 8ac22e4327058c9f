// SPDX-License-Identifier: BSD-3-Clause
// Built when Debian's ROS1 bag library is absent: the bag API says so.
#include "radargauss/core/error.hpp"
#include "radargauss/io/rosbag.hpp"

namespace radargauss {

namespace {
DataError Unavailable(const std::string& path) {
  return FileError(path,
                   "radargauss was built without ROS1 bag support "
                   "(install librosbag-storage-dev libsensor-msgs-dev and reconfigure)");
}
}  // namespace

bool RosbagSupported() { return false; }
std::vector<BagTopic> ListRos1BagTopics(const std::string& bag_path) { throw Unavailable(bag_path); }
std::vector<RadarScan> ReadRos1BagScans(const std::string& bag_path, const std::string&, const FieldMapping&) {
  throw Unavailable(bag_path);
}
std::vector<ImuSample> ReadRos1BagImu(const std::string& bag_path, const std::string&, bool) {
  throw Unavailable(bag_path);
}

}  // namespace radargauss
