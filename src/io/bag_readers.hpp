// SPDX-License-Identifier: BSD-3-Clause
// The readers of each bag format, opened by OpenBag (io/bag_reader.hpp)
// once it has told the format by content. Internal to src/io.
#pragma once

#include <memory>
#include <string>

#include "radargauss/io/bag_reader.hpp"

namespace radargauss {

std::unique_ptr<BagReader> OpenMcapBag(const std::string& path);
std::unique_ptr<BagReader> OpenSqliteBag(const std::string& path);
std::unique_ptr<BagReader> OpenRos2Folder(const std::string& path);
// src/io/rosbag.cpp, or its stand-in without ROS1's library (which refuses).
std::unique_ptr<BagReader> OpenRos1Bag(const std::string& path);

}  // namespace radargauss
