// SPDX-License-Identifier: BSD-3-Clause
// The ROS1 bag reader and ROS1's serialisation, through Debian's ROS1 bag
// library. Built only when it is found (RADARGAUSS_HAVE_ROSBAG).
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <algorithm>
#include <limits>
#include <map>

#include "bag_readers.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"
#include "radargauss/io/bag_reader.hpp"

namespace radargauss {

bool RosbagSupported() { return true; }

namespace {

// The message in `m` as `Message`, or DataError naming `source`.
template <typename Message>
Message Deserialize(const BagMessage& m, const std::string& source) {
  Message message;
  try {
    ros::serialization::IStream stream(const_cast<std::uint8_t*>(m.data), std::uint32_t(m.size));
    ros::serialization::deserialize(stream, message);
  } catch (const std::exception& e) {
    throw FileError(source, std::string("message is cut short: ") + e.what());
  }
  return message;
}

class Ros1 final : public MessageCodec {
 public:
  // As ros::Time::toSec computes it.
  double RecordStamp(std::int64_t log_time) const override {
    ros::Time time;
    time.fromNSec(std::uint64_t(log_time));
    return time.toSec();
  }
  double PointCloud2(const BagMessage& m, const std::string& source, PointCloud2Data& cloud) const override {
    const auto msg = Deserialize<sensor_msgs::PointCloud2>(m, source);
    cloud.height = msg.height;
    cloud.width = msg.width;
    cloud.fields.clear();
    for (const auto& f : msg.fields) cloud.fields.push_back({f.name, f.offset, f.datatype, f.count});
    cloud.is_bigendian = msg.is_bigendian;
    cloud.point_step = msg.point_step;
    cloud.row_step = msg.row_step;
    cloud.data = msg.data;
    return msg.header.stamp.isZero() ? 0.0 : msg.header.stamp.toSec();
  }
  double Imu(const BagMessage& m, const std::string& source, ImuSample& sample) const override {
    const auto msg = Deserialize<sensor_msgs::Imu>(m, source);
    sample.angular_velocity = {msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z};
    sample.specific_force = {msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z};
    return msg.header.stamp.isZero() ? 0.0 : msg.header.stamp.toSec();
  }
  bool Pose(const BagMessage&, const std::string& source, const std::string&, double&, SE3d&) const override {
    throw NoPoses(source);
  }
  bool Path(const BagMessage&, const std::string& source, std::vector<StampedPose>&) const override {
    throw NoPoses(source);
  }

 private:
  static DataError NoPoses(const std::string& source) {
    return FileError(source, "reference poses are read from ROS 2 bags (convert a ROS1 bag's with a TUM file)");
  }
};

ros::Time TimeOf(std::int64_t ns) {
  if (ns <= 0) return ros::TIME_MIN;
  if (std::uint64_t(ns) >= ros::TIME_MAX.toNSec()) return ros::TIME_MAX;
  ros::Time time;
  time.fromNSec(std::uint64_t(ns));
  return time;
}

class Ros1Bag final : public BagReader {
 public:
  explicit Ros1Bag(const std::string& path) : BagReader(path) {
    CheckRegularInputFile(path, "ROS1 bag");
    try {
      bag_.open(path, rosbag::bagmode::Read);
    } catch (const std::exception& e) {
      throw FileError(path, std::string("cannot read ROS1 bag: ") + e.what());
    }
  }

  std::vector<BagTopic> Topics() override {
    std::map<std::string, BagTopic> topics;
    try {
      rosbag::View view(bag_);
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
      throw FileError(path(), std::string("corrupt ROS1 bag: ") + e.what());
    }
    std::vector<BagTopic> result;
    for (auto& entry : topics) result.push_back(entry.second);
    return result;
  }

  // The library's view, in time order; its own exceptions become DataError naming the bag.
  void Read(const BagReadOptions& options, const std::function<void(const BagMessage&)>& visit) override {
    if (options.end < options.start) return;
    std::vector<std::uint8_t> bytes;
    try {
      std::unique_ptr<rosbag::View> view =
          options.topics.empty() ? std::make_unique<rosbag::View>(bag_, TimeOf(options.start), TimeOf(options.end))
                                 : std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(options.topics),
                                                                  TimeOf(options.start), TimeOf(options.end));
      for (const rosbag::MessageInstance& message : *view) {
        bytes.resize(message.size());
        ros::serialization::OStream stream(bytes.data(), std::uint32_t(bytes.size()));
        message.write(stream);
        visit({&message.getTopic(), &message.getDataType(), std::int64_t(message.getTime().toNSec()), bytes.data(),
               bytes.size(), &Ros1Codec()});
      }
    } catch (const DataError&) {
      throw;
    } catch (const std::exception& e) {
      throw FileError(path(), std::string("corrupt ROS1 bag: ") + e.what());
    }
  }

 private:
  rosbag::Bag bag_;
};

}  // namespace

const MessageCodec& Ros1Codec() {
  static const Ros1 codec;
  return codec;
}

std::unique_ptr<BagReader> OpenRos1Bag(const std::string& path) { return std::make_unique<Ros1Bag>(path); }

}  // namespace radargauss
