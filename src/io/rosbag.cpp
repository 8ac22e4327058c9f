// SPDX-License-Identifier: BSD-3-Clause
// Built only when Debian's ROS1 bag library is found (RADARGAUSS_HAVE_ROSBAG).
#include "radargauss/io/rosbag.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <algorithm>
#include <map>

#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"

namespace radargauss {

bool RosbagSupported() { return true; }

namespace {

void OpenBag(rosbag::Bag& bag, const std::string& path) {
  CheckRegularInputFile(path, "ROS1 bag");
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw FileError(path, std::string("cannot read ROS1 bag: ") + e.what());
  }
}

}  // namespace

std::vector<BagTopic> ListRos1BagTopics(const std::string& bag_path) {
  rosbag::Bag bag;
  OpenBag(bag, bag_path);
  std::map<std::string, BagTopic> topics;
  try {
    rosbag::View view(bag);
    for (const rosbag::ConnectionInfo* connection : view.getConnections()) {
      BagTopic& topic = topics[connection->topic];
      topic.name = connection->topic;
      topic.type = connection->datatype;
    }
    for (const rosbag::MessageInstance& message : view) {
      BagTopic& topic = topics[message.getTopic()];
      const double t = message.getTime().toSec();
      topic.first = topic.messages == 0 ? t : std::min(topic.first, t);
      topic.last = std::max(topic.last, t);
      ++topic.messages;
    }
  } catch (const std::exception& e) {
    throw FileError(bag_path, std::string("corrupt ROS1 bag: ") + e.what());
  }
  std::vector<BagTopic> result;
  for (auto& entry : topics) result.push_back(entry.second);
  return result;
}

namespace {

// Calls read(message, source) for every message of `topic` in bag order,
// `source` naming it ("<bag>:<topic>#<index>"); a missing topic and
// the library's own exceptions become DataError naming the bag.
template <typename Read>
void ForEachMessage(const std::string& bag_path, const std::string& topic, Read&& read) {
  rosbag::Bag bag;
  OpenBag(bag, bag_path);
  std::size_t index = 0;
  try {
    rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{topic}));
    for (const rosbag::MessageInstance& message : view) {
      read(message, bag_path + ":" + topic + "#" + std::to_string(index++));
    }
  } catch (const DataError&) {
    throw;
  } catch (const std::exception& e) {
    throw FileError(bag_path, std::string("corrupt ROS1 bag: ") + e.what());
  }
  if (index == 0) throw FileError(bag_path, "no messages on topic '" + topic + "'");
}

// The message as `Message`, or DataError naming `source` and the type it holds.
template <typename Message>
typename Message::ConstPtr Instantiate(const rosbag::MessageInstance& message, const std::string& source,
                                       const char* type) {
  const typename Message::ConstPtr msg = message.instantiate<Message>();
  if (!msg) throw FileError(source, "message is " + message.getDataType() + ", not " + type);
  return msg;
}

}  // namespace

std::vector<RadarScan> ReadRos1BagScans(const std::string& bag_path, const std::string& topic,
                                        const FieldMapping& mapping) {
  std::vector<RadarScan> scans;
  ForEachMessage(bag_path, topic, [&](const rosbag::MessageInstance& message, const std::string& source) {
    const auto msg = Instantiate<sensor_msgs::PointCloud2>(message, source, "sensor_msgs/PointCloud2");
    PointCloud2Data cloud;
    cloud.height = msg->height;
    cloud.width = msg->width;
    for (const auto& f : msg->fields) cloud.fields.push_back({f.name, f.offset, f.datatype, f.count});
    cloud.is_bigendian = msg->is_bigendian;
    cloud.point_step = msg->point_step;
    cloud.row_step = msg->row_step;
    cloud.data = msg->data;
    const double stamp = msg->header.stamp.isZero() ? message.getTime().toSec() : msg->header.stamp.toSec();
    scans.push_back(DecodePointCloud2(cloud, stamp, mapping, source));
  });
  return scans;
}

std::vector<ImuSample> ReadRos1BagImu(const std::string& bag_path, const std::string& topic, bool record_time) {
  std::vector<ImuSample> samples;
  ForEachMessage(bag_path, topic, [&](const rosbag::MessageInstance& message, const std::string& source) {
    const auto msg = Instantiate<sensor_msgs::Imu>(message, source, "sensor_msgs/Imu");
    ImuSample sample;
    sample.stamp = record_time || msg->header.stamp.isZero() ? message.getTime().toSec() : msg->header.stamp.toSec();
    sample.angular_velocity = {msg->angular_velocity.x, msg->angular_velocity.y, msg->angular_velocity.z};
    sample.specific_force = {msg->linear_acceleration.x, msg->linear_acceleration.y, msg->linear_acceleration.z};
    AppendBagImuSample(samples, sample, source);
  });
  return samples;
}

}  // namespace radargauss
