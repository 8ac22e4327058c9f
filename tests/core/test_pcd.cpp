// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/pcd.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "radargauss/core/error.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

namespace fs = std::filesystem;
using testing::SharedData;
using Pcd = testing::TempDirTest;

RadarScan ExampleScan(int n, bool with_std) {
  RadarScan scan;
  scan.timestamp = 12.5;
  scan.has_doppler = scan.has_rcs = true;
  for (int i = 0; i < n; ++i) {
    RadarPoint p;
    p.position = Eigen::Vector3d(1.0 + 0.37 * i, -2.0 + 0.11 * i, 0.013 * i);
    p.doppler = -3.0 + 0.01 * i;
    p.rcs = 10.0 - 0.25 * i;
    if (with_std) p.std_dev = MeasurementStd{0.1f, 0.002f * i, 0.003f, 0.05f};
    scan.points.push_back(p);
  }
  return scan;
}

// Reading back what was written gives the float32 values exactly.
void ExpectSameAsFloat(const RadarScan& read, const RadarScan& written) {
  ASSERT_EQ(read.points.size(), written.points.size());
  for (std::size_t i = 0; i < read.points.size(); ++i) {
    const RadarPoint& a = read.points[i];
    const RadarPoint& b = written.points[i];
    EXPECT_EQ(a.position, b.position.cast<float>().cast<double>());
    EXPECT_EQ(a.doppler, double(float(b.doppler)));
    EXPECT_EQ(a.rcs, double(float(b.rcs)));
    ASSERT_EQ(a.std_dev.has_value(), b.std_dev.has_value());
    if (a.std_dev) {
      EXPECT_EQ(a.std_dev->azimuth, b.std_dev->azimuth);
    }
  }
}

TEST_F(Pcd, RoundTripInEveryFormat) {
  for (const bool with_std : {false, true}) {
    const RadarScan scan = ExampleScan(257, with_std);
    for (const PcdFormat format : {PcdFormat::kAscii, PcdFormat::kBinary, PcdFormat::kBinaryCompressed}) {
      const std::string path = Path("1702450000.250000000.pcd");
      WritePcdScan(path, scan, format);
      const RadarScan read = ReadPcdScan(path);
      EXPECT_TRUE(read.has_doppler && read.has_rcs);
      EXPECT_NEAR(read.timestamp, 1702450000.25, 1e-6);
      ExpectSameAsFloat(read, scan);
    }
  }
}

TEST_F(Pcd, EmptyScanRoundTrips) {
  for (const PcdFormat format : {PcdFormat::kAscii, PcdFormat::kBinary, PcdFormat::kBinaryCompressed}) {
    WritePcdScan(Path("empty.pcd"), RadarScan{}, format);
    EXPECT_TRUE(ReadPcdScan(Path("empty.pcd")).points.empty());
  }
}

TEST_F(Pcd, FieldMappingAndSign) {
  const RadarScan scan = ExampleScan(5, false);
  const std::string path = Path("scan.pcd");
  WritePcdScan(path, scan, PcdFormat::kBinary);
  FieldMapping mapping;
  mapping.doppler_sign = -1.0;
  mapping.rcs_field = "none";
  const RadarScan read = ReadPcdScan(path, mapping);
  EXPECT_FALSE(read.has_rcs);
  EXPECT_EQ(read.points[2].rcs, 0.0);
  EXPECT_EQ(read.points[2].doppler, -double(float(scan.points[2].doppler)));
  mapping.rcs_field = "power";
  EXPECT_THROW(ReadPcdScan(path, mapping), DataError);
}

// Any PCL numeric type decodes: U2, I1, F8 and a COUNT > 1 field.
TEST_F(Pcd, DecodesIntegerAndDoubleFieldsInAscii) {
  const std::string path = WriteFile("types.pcd",
                                     "VERSION .7\nFIELDS x y z rcs velocity pad\nSIZE 8 4 4 2 1 4\n"
                                     "TYPE F F F U I F\nCOUNT 1 1 1 1 1 2\nWIDTH 2\nHEIGHT 1\n"
                                     "POINTS 2\nDATA ascii\n"
                                     "1.5 2 3 65535 -128 0 0\n-1 0.5 0 7 3 1 1\n");
  const RadarScan scan = ReadPcdScan(path);
  ASSERT_EQ(scan.points.size(), 2u);
  EXPECT_EQ(scan.points[0].position, Eigen::Vector3d(1.5, 2, 3));
  EXPECT_EQ(scan.points[0].rcs, 65535.0);
  EXPECT_EQ(scan.points[0].doppler, -128.0);
  EXPECT_EQ(scan.points[1].doppler, 3.0);
}

TEST_F(Pcd, DecodesBinaryWithPaddingFieldAndDouble) {
  std::string bytes =
      "VERSION 0.7\nFIELDS x y z _ doppler\nSIZE 4 4 4 1 8\nTYPE F F F U F\nCOUNT 1 1 1 3 1\n"
      "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary\n";
  const float xyz[3] = {4.0f, 5.0f, 6.0f};
  const char pad[3] = {1, 2, 3};
  const double doppler = -7.25;
  bytes.append(reinterpret_cast<const char*>(xyz), 12);
  bytes.append(pad, 3);
  bytes.append(reinterpret_cast<const char*>(&doppler), 8);
  const RadarScan scan = ReadPcdScan(WriteFile("pad.pcd", bytes));
  ASSERT_EQ(scan.points.size(), 1u);
  EXPECT_EQ(scan.points[0].position, Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(scan.points[0].doppler, -7.25);
}

// A malformed corpus: every fault a clear DataError naming the file.
TEST_F(Pcd, MalformedFilesGiveClearErrors) {
  WritePcdScan(Path("good_binary.pcd"), ExampleScan(40, true), PcdFormat::kBinary);
  WritePcdScan(Path("good_compressed.pcd"), ExampleScan(40, true), PcdFormat::kBinaryCompressed);
  const auto read_bytes = [&](const std::string& name) {
    std::ifstream in(Path(name), std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  const std::string binary = read_bytes("good_binary.pcd");
  const std::string compressed = read_bytes("good_compressed.pcd");
  const auto replace = [](std::string text, const std::string& from, const std::string& to) {
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  const std::string header_ascii =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
      "POINTS 2\nDATA ascii\n";
  std::string corrupt_lzf = compressed;
  for (std::size_t i = compressed.size() - 40; i < compressed.size(); ++i) corrupt_lzf[i] = char(0xFF);

  const std::vector<std::pair<std::string, std::string>> corpus = {
      {binary.substr(0, binary.size() - 7), "truncated"},
      {replace(binary, "WIDTH 40", "WIDTH 41"), "differs from POINTS"},
      {replace(binary, "POINTS 40", "POINTS 4000000000000"), "WIDTH"},
      {replace(replace(binary, "WIDTH 40", "WIDTH 4000000000"), "POINTS 40", "POINTS 4000000000"), "truncated"},
      {replace(binary, "TYPE F F F", "TYPE F Q F"), "unknown TYPE"},
      {replace(binary, "SIZE 4 4 4", "SIZE 4 3 4"), "unknown TYPE/SIZE"},
      {replace(binary, "DATA binary", "DATA bzip2"), "unknown DATA"},
      {replace(binary, "COUNT 1 1 1 1 1 1 1 1 1", "COUNT 1 1 1"), "differ in length"},
      {replace(binary, "FIELDS x y z", "FIELDS a y z"), "no 'x' field"},
      {binary.substr(0, 60), "no DATA line"},
      {"", "no DATA line"},
      {compressed.substr(0, compressed.size() - 10), "truncated"},
      {corrupt_lzf, "corrupt LZF"},
      {replace(compressed, "POINTS 40", "POINTS 39"), "differs from POINTS"},
      {header_ascii + "1 2 3\n", "truncated"},
      {header_ascii + "1 2 3\n4 5   \n", "has 2 values"},
      {header_ascii + "1 2 3\n4 5 x\n", "not a number"},
      {header_ascii + "1 2 3\n4 5 nan\n", "non-finite position"},
      {header_ascii + "1 2 3\n4 5 6\n7 8 9\n", "more data lines"},
  };
  for (std::size_t i = 0; i < corpus.size(); ++i) {
    const std::string path = WriteFile("bad" + std::to_string(i) + ".pcd", corpus[i].first);
    try {
      ReadPcdScan(path);
      ADD_FAILURE() << "case " << i << " (" << corpus[i].second << ") was accepted";
    } catch (const DataError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(path + ":", 0), 0u) << message;
      EXPECT_NE(message.find(corpus[i].second), std::string::npos) << "case " << i << ": " << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
  EXPECT_THROW(ReadPcdScan(Path("absent.pcd")), DataError);
}

TEST(PcdFileNames, TimestampFromFileName) {
  double t = 0.0;
  ASSERT_TRUE(TimestampFromFileName("/a/1702450000.123456789.pcd", t));
  EXPECT_NEAR(t, 1702450000.123456789, 3e-7);
  ASSERT_TRUE(TimestampFromFileName("0.083221619.pcd", t));
  EXPECT_DOUBLE_EQ(t, 0.083221619);
  EXPECT_FALSE(TimestampFromFileName("frame_001.pcd", t));
  EXPECT_FALSE(TimestampFromFileName("12.pcd", t));
}

// The NTU Eagle sample: facts from its README.
TEST(PcdRealData, NtuEagleScans) {
  const std::string dir = SharedData("ntu4dradlm_loop1_eagle/points");
  if (dir.empty()) GTEST_SKIP() << "shared data not found";
  const RadarScan first = ReadPcdScan(dir + "/0.000000000.pcd");
  EXPECT_EQ(first.points.size(), 4010u);
  EXPECT_TRUE(first.has_doppler);
  EXPECT_FALSE(first.has_rcs);
  EXPECT_EQ(first.timestamp, 0.0);
  std::size_t files = 0, total = 0, min_points = SIZE_MAX, max_points = 0;
  double min_doppler = 1e9, max_doppler = -1e9;
  bool all_forward = true;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".pcd") continue;
    const RadarScan scan = ReadPcdScan(entry.path().string());
    ++files;
    total += scan.points.size();
    min_points = std::min(min_points, scan.points.size());
    max_points = std::max(max_points, scan.points.size());
    for (const RadarPoint& p : scan.points) {
      min_doppler = std::min(min_doppler, p.doppler);
      max_doppler = std::max(max_doppler, p.doppler);
      all_forward = all_forward && p.position.x() > 0.0;
    }
  }
  EXPECT_EQ(files, 500u);
  EXPECT_EQ(total, 1988584u);
  EXPECT_EQ(min_points, 1971u);
  EXPECT_EQ(max_points, 5980u);
  EXPECT_NEAR(min_doppler, -14.9, 0.05);
  EXPECT_NEAR(max_doppler, 8.2, 0.05);
  EXPECT_TRUE(all_forward);
}

}  // namespace
}  // namespace radargauss
