// SPDX-License-Identifier: BSD-3-Clause
// CDR, the byte layout of ROS 2 messages (XCDR1 and XCDR2, either byte
// order): a reader that checks every length against the message and a
// writer, for ros2_messages.cpp's decoders and encoders.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/lie/se3.hpp"

namespace radargauss {

// Reads one CDR message: the encapsulation header picks the byte order and
// the alignment rule; offsets align from the end of that header. Throws
// FileError naming `source` for a message shorter than its fields.
class CdrReader {
 public:
  CdrReader(const std::uint8_t* data, std::size_t size, const std::string& source);

  template <typename T>
  T Read() {
    Align(sizeof(T));
    Need(sizeof(T));
    std::uint8_t bytes[sizeof(T)];
    for (std::size_t i = 0; i < sizeof(T); ++i) bytes[i] = data_[pos_ + (big_endian_ ? sizeof(T) - 1 - i : i)];
    pos_ += sizeof(T);
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }
  double Stamp();
  std::string String();
  // A sequence's length, checked against the bytes left at `element_bytes` each.
  std::uint32_t Length(std::size_t element_bytes);
  void Bytes(std::size_t n, std::vector<std::uint8_t>& out);
  Ros2Header Header();
  Eigen::Vector3d Vector3();
  SE3d Pose();  // position, then orientation x y z w
  void Skip(std::size_t doubles) {
    for (std::size_t i = 0; i < doubles; ++i) Read<double>();
  }

 private:
  std::string Kind() const;
  void Align(std::size_t n) {
    const std::size_t a = std::min(n, max_alignment_);
    pos_ = std::min(size_, (pos_ + a - 1) / a * a);
  }
  void Need(std::uint64_t n) const;
  const std::uint8_t* data_;
  std::size_t size_, pos_ = 0;
  const std::string& source_;
  bool big_endian_ = false;
  std::size_t max_alignment_ = 8;
};

class CdrWriter {
 public:
  explicit CdrWriter(CdrEncoding encoding);
  template <typename T>
  void Write(T value) {
    const std::size_t a = std::min(sizeof(T), max_alignment_);
    while ((bytes_.size() - 4) % a != 0) bytes_.push_back(0);
    std::uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    for (std::size_t i = 0; i < sizeof(T); ++i) bytes_.push_back(raw[big_endian_ ? sizeof(T) - 1 - i : i]);
  }
  void String(const std::string& s);
  void Header(const Ros2Header& header);
  void Vector3(const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) Write(v(i));
  }
  void Covariance(int n) {
    for (int i = 0; i < n; ++i) Write(0.0);
  }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  bool big_endian_;
  std::size_t max_alignment_;
  std::vector<std::uint8_t> bytes_;
};

}  // namespace radargauss
