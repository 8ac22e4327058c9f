// SPDX-License-Identifier: BSD-3-Clause
#include "cdr.hpp"

#include <cmath>

#include "radargauss/core/error.hpp"

namespace radargauss {

CdrReader::CdrReader(const std::uint8_t* data, std::size_t size, const std::string& source)
    : data_(data), size_(size), source_(source) {
  if (size < 4) throw FileError(source, "a CDR message shorter than its 4-byte header");
  if (data[0] != 0) throw FileError(source, "not a CDR message (encapsulation " + Kind() + ")");
  switch (data[1]) {
    case 0x00:  // CDR_BE
      big_endian_ = true;
      break;
    case 0x01:  // CDR_LE
      break;
    case 0x10:  // CDR2_BE
      big_endian_ = true;
      max_alignment_ = 4;
      break;
    case 0x11:  // CDR2_LE
      max_alignment_ = 4;
      break;
    default:
      throw FileError(source, "CDR encapsulation " + Kind() + " is not plain XCDR1 or XCDR2");
  }
  data_ += 4;
  size_ -= 4;
}

double CdrReader::Stamp() {
  const auto sec = Read<std::int32_t>();
  const auto nanosec = Read<std::uint32_t>();
  if (nanosec >= 1000000000u) throw FileError(source_, "a stamp's nanoseconds are 1e9 or more");
  return JoinStamp(sec, nanosec);
}

std::string CdrReader::String() {
  const auto n = Read<std::uint32_t>();
  Need(n);
  std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
  pos_ += n;
  if (!s.empty() && s.back() == '\0') s.pop_back();
  // A CDR string ends at its one NUL: one inside would cut every name and message short.
  if (s.find('\0') != std::string::npos) throw FileError(source_, "a string holds a NUL byte before its end");
  return s;
}

std::uint32_t CdrReader::Length(std::size_t element_bytes) {
  const auto n = Read<std::uint32_t>();
  if (std::uint64_t(n) * element_bytes > size_ - pos_) {
    throw FileError(source_, "a sequence of " + std::to_string(n) + " elements is longer than the message");
  }
  return n;
}

void CdrReader::Bytes(std::size_t n, std::vector<std::uint8_t>& out) {
  Need(n);
  out.assign(data_ + pos_, data_ + pos_ + n);
  pos_ += n;
}

Ros2Header CdrReader::Header() {
  Ros2Header header;
  header.stamp = Stamp();
  header.frame_id = String();
  return header;
}

Eigen::Vector3d CdrReader::Vector3() {
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v(i) = Read<double>();
  return v;
}

SE3d CdrReader::Pose() {
  const Eigen::Vector3d t = Vector3();
  double q[4];
  for (double& c : q) c = Read<double>();
  if (!(std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]) && std::isfinite(q[3])) || !t.allFinite() ||
      std::abs(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1.0) > 1e-3) {
    throw FileError(source_, "a pose that is not finite or whose quaternion is not unit");
  }
  return SE3d(SO3d::FromXyzw(q), t);
}

std::string CdrReader::Kind() const {
  static const char kHex[] = "0123456789abcdef";
  return std::string("0x") + kHex[data_[0] >> 4] + kHex[data_[0] & 15] + kHex[data_[1] >> 4] + kHex[data_[1] & 15];
}

void CdrReader::Need(std::uint64_t n) const {
  if (n > size_ - pos_) throw FileError(source_, "CDR message is shorter than its fields");
}

CdrWriter::CdrWriter(CdrEncoding encoding)
    : big_endian_(encoding == CdrEncoding::kXcdr1BigEndian || encoding == CdrEncoding::kXcdr2BigEndian),
      max_alignment_(encoding == CdrEncoding::kXcdr2LittleEndian || encoding == CdrEncoding::kXcdr2BigEndian ? 4 : 8) {
  const std::uint8_t kind = std::uint8_t((max_alignment_ == 4 ? 0x10 : 0x00) | (big_endian_ ? 0x00 : 0x01));
  bytes_ = {0x00, kind, 0x00, 0x00};
}

void CdrWriter::String(const std::string& s) {
  Write(std::uint32_t(s.size() + 1));
  bytes_.insert(bytes_.end(), s.begin(), s.end());
  bytes_.push_back(0);
}

void CdrWriter::Header(const Ros2Header& header) {
  std::int32_t sec;
  std::uint32_t nanosec;
  SplitStamp(header.stamp, sec, nanosec);
  Write(sec);
  Write(nanosec);
  String(header.frame_id);
}

}  // namespace radargauss
