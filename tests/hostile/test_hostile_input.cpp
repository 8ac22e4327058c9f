// SPDX-License-Identifier: BSD-3-Clause
// Inputs built to hurt (docs/design/formats.md, "Bounds on input"): each is refused
// with a message naming the file and the fault, at once and without a large
// allocation, instead of crashing, hanging or running into UB.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/kitti_bin.hpp"
#include "radargauss/io/pcd.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/io/yaml_file.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/map/matching_map.hpp"
#include "radargauss/core/trajectory.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

using HostileInput = testing::TempDirTest;

// The message of the DataError `read` throws ("" when it throws none).
template <typename Read>
std::string ErrorOf(const Read& read) {
  try {
    read();
  } catch (const DataError& e) {
    return e.what();
  }
  return "";
}

// Growth of this process's peak resident memory while `run` runs, in MB.
template <typename Run>
double PeakGrowthMb(const Run& run) {
  rusage before{}, after{};
  getrusage(RUSAGE_SELF, &before);
  run();
  getrusage(RUSAGE_SELF, &after);
  return double(after.ru_maxrss - before.ru_maxrss) / 1024.0;
}

TEST_F(HostileInput, SimulatorYamlNamesFileLineAndRefusesNan) {
  const std::string key = WriteFile("key.yaml", "[]: 1\n");
  EXPECT_EQ(ErrorOf([&] { LoadSimulationConfig(key); }), key + ":1: a key must be a parameter name");
  const std::string nan = WriteFile("nan.yaml", "attitude_wobble_deg: .nan\n");
  EXPECT_EQ(ErrorOf([&] { LoadSimulationConfig(nan); }), nan + ": attitude_wobble_deg must be a finite number");
  const std::string inf = WriteFile("inf.yaml", "materials: {wall: {diffuse: .inf}}\n");
  EXPECT_NE(ErrorOf([&] { LoadSimulationConfig(inf); }).find("material 'wall' needs finite numbers"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { LoadSimulationConfig(dir_.string()); }).find("a directory"), std::string::npos);
}

Gaussian RoundGaussian(const Eigen::Vector3d& mean, double std) {
  Gaussian g;
  g.mean = mean;
  g.covariance = Eigen::Matrix3d::Identity() * std * std;
  return g;
}

// A map file (valid CRC) holding one Gaussian, and the error reading it gives.
std::string ReadOne(const std::string& path, const Gaussian& g) {
  GaussianMap map;
  map.gaussians = {RoundGaussian(Eigen::Vector3d::Zero(), 0.3), g};
  WriteMap(path, map);
  return ErrorOf([&] { ReadMap(path); });
}

TEST_F(HostileInput, MapFileBoundsMeansStdsAndRcs) {
  const std::string path = Path("m.rgm");
  EXPECT_NE(ReadOne(path, RoundGaussian(Eigen::Vector3d::Zero(), 1e4))
                .find(path + ": Gaussian 1: covariance with "
                             "principal stds outside"),
            std::string::npos);  // 10 km: hung the index
  EXPECT_NE(ReadOne(path, RoundGaussian(Eigen::Vector3d(1e300, 0, 0), 0.3)).find("mean beyond"), std::string::npos);
  EXPECT_NE(ReadOne(path, RoundGaussian(Eigen::Vector3d::Zero(), 1e-6)).find("principal stds"), std::string::npos);
  Gaussian nan_rcs = RoundGaussian(Eigen::Vector3d::Zero(), 0.3);
  nan_rcs.rcs.degree = 0;
  nan_rcs.rcs.scale = 1.0;
  nan_rcs.rcs.median = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(ReadOne(path, nan_rcs).find("non-finite RCS model"), std::string::npos);
  nan_rcs.rcs.median = 0.0;
  nan_rcs.rcs.coefficients[3] = std::numeric_limits<double>::infinity();
  EXPECT_NE(ReadOne(path, nan_rcs).find("non-finite RCS model"), std::string::npos);
  // The largest std the file allows indexes at the default cell.
  EXPECT_EQ(ReadOne(path, RoundGaussian(Eigen::Vector3d(5, 5, 5), 20.0)), "");
  EXPECT_NO_THROW(GaussianIndex(ReadMap(path).gaussians));
  EXPECT_EQ(ErrorOf([&] { ReadMap(dir_.string()); }), dir_.string() + ": is a directory, not a map");
}

TEST(HostileIndex, RefusesAGaussianOfTooManyCellsAndSurvivesFarQueries) {
  const std::vector<Gaussian> huge = {RoundGaussian(Eigen::Vector3d::Zero(), 100.0)};
  EXPECT_NE(ErrorOf([&] { GaussianIndex(huge, 0.1); }).find("Gaussian 0 spans 2.16e+11 index cells"),
            std::string::npos);
  const GaussianIndex index({RoundGaussian(Eigen::Vector3d::Zero(), 0.3)});
  for (const double far : {1e300, -1e300, 1e19, std::numeric_limits<double>::max()}) {
    EXPECT_EQ(index.Associate(Eigen::Vector3d(far, 0.0, far), 9.0), -1);  // UB before saturation
  }
  EXPECT_EQ(index.Associate(Eigen::Vector3d(0.1, 0.0, 0.0), 9.0), 0);
}

// An ASCII PCD with `fields` fields and POINTS as large as its bytes allowed
// when only one digit and one separator per point were required.
std::string WideAsciiPcd(std::size_t fields, std::size_t data_bytes) {
  std::string names, sizes, types, counts;
  for (std::size_t i = 0; i < fields; ++i) {
    names += " f" + std::to_string(i);
    sizes += " 4";
    types += " F";
    counts += " 1";
  }
  const std::size_t points = data_bytes / 2;
  std::string text = "VERSION 0.7\nFIELDS" + names + "\nSIZE" + sizes + "\nTYPE" + types + "\nCOUNT" + counts +
                     "\nWIDTH " + std::to_string(points) + "\nHEIGHT 1\nPOINTS " + std::to_string(points) +
                     "\nDATA ascii\n";
  return text + std::string(data_bytes, '1');
}

TEST_F(HostileInput, WidePcdHeadersAreRefusedBeforeAllocating) {
  for (const std::size_t fields : {std::size_t(4096), std::size_t(20000)}) {
    const std::string path = WriteFile("wide.pcd", WideAsciiPcd(fields, 64 * 1024));
    std::string message;
    const double growth = PeakGrowthMb([&] { message = ErrorOf([&] { ReadPcdScan(path); }); });
    EXPECT_EQ(message, path + ": " + std::to_string(fields) + " FIELDS, more than 256");
    EXPECT_LT(growth, 100.0) << fields << " fields";
  }
  // Within the field bound, POINTS x values against the data's bytes.
  const std::string path = WriteFile("tall.pcd", WideAsciiPcd(200, 64 * 1024));
  std::string message;
  const double growth = PeakGrowthMb([&] { message = ErrorOf([&] { ReadPcdScan(path); }); });
  EXPECT_NE(message.find(path + ": truncated: POINTS 32768"), std::string::npos) << message;
  EXPECT_LT(growth, 100.0);
}

TEST(HostilePointCloud2, RowsOfWidthZeroAreRefusedAtOnce) {
  PointCloud2Data cloud;
  cloud.height = std::numeric_limits<std::uint32_t>::max();
  cloud.width = 0;
  cloud.fields = {{"x", 0, 7, 1}, {"y", 4, 7, 1}, {"z", 8, 7, 1}};
  cloud.point_step = 12;
  EXPECT_EQ(ErrorOf([&] { DecodePointCloud2(cloud, 0.0, FieldMapping(), "bag:/radar"); }),
            "bag:/radar: height 4294967295 rows of width 0");
  cloud.height = 1;  // an empty cloud is a scan without points
  EXPECT_EQ(ErrorOf([&] { DecodePointCloud2(cloud, 0.0, FieldMapping(), "bag:/radar"); }).find("height"),
            std::string::npos);
}

TEST_F(HostileInput, KittiBinNeedsALayout) {
  const std::string path = WriteFile("1.0.bin", std::string(28, '\0'));
  EXPECT_THROW(ReadKittiBin(path, {}), std::invalid_argument);
}

// A process that has ended: its pid is free (until the system reuses it).
pid_t EndedPid() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, nullptr, 0);
  return child;
}

TEST_F(HostileInput, WritesRemoveTemporariesOfEndedProcesses) {
  const std::string stale = WriteFile("map.rgm.radargauss-tmp." + std::to_string(EndedPid()), "half a map");
  const std::string live = WriteFile("map.rgm.radargauss-tmp." + std::to_string(getppid()), "a writer at work");
  const std::string other = WriteFile("notes.tmp." + std::to_string(EndedPid()), "another program's");
  WriteFileAtomically(Path("map.rgm"), [](std::ostream& out) { out << "whole"; });
  EXPECT_FALSE(std::filesystem::exists(stale));
  EXPECT_TRUE(std::filesystem::exists(live));
  EXPECT_TRUE(std::filesystem::exists(other));
  EXPECT_TRUE(std::filesystem::exists(Path("map.rgm")));
}

// Special files are refused by their type before a read: /dev/zero never
// ends, a FIFO blocks until a writer comes.
TEST_F(HostileInput, SpecialFilesAreRefusedByType) {
  EXPECT_EQ(ErrorOf([] { ReadMap("/dev/zero"); }), "/dev/zero: is a character device, not a map");
  EXPECT_EQ(ErrorOf([] { ReadTum("/dev/zero"); }), "/dev/zero: is a character device, not a TUM trajectory");
  EXPECT_EQ(ErrorOf([] { LoadSimulationConfig("/dev/zero"); }),
            "/dev/zero: is a character device, not a simulation config");
  const std::string fifo = Path("fifo.pcd");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(ErrorOf([&] { ReadPcdScan(fifo); }), fifo + ": is a FIFO, not a PCD file");
  EXPECT_EQ(ErrorOf([&] { ReadYamlDocument(fifo, "configuration file"); }),
            fifo + ": is a FIFO, not a configuration file");
  EXPECT_EQ(ErrorOf([&] { ReadMap(Path("absent.rgm")); }), Path("absent.rgm") + ": cannot open map (no such file)");
}

TEST_F(HostileInput, ConfigFilesAreOneBoundedDocumentWithoutRepeatedKeys) {
  const auto error = [&](const std::string& text) {
    return ErrorOf([&] { ReadYamlDocument(WriteFile("c.yaml", text), "configuration file"); });
  };
  const std::string path = Path("c.yaml");
  EXPECT_EQ(error("seed: 1\nscans: 4\nseed: 2\n"), path + ":3: key 'seed' given twice (first on line 1)");
  EXPECT_EQ(error("materials:\n  wall: {diffuse: 1, diffuse: 2}\n"),
            path + ":2: key 'diffuse' given twice (first on line 2)");
  EXPECT_EQ(error("seed: 1\n---\nseed: 2\n"), path + ": more than one YAML document (a configuration file is one)");
  EXPECT_EQ(error(", "), path + ": more than one YAML document (a configuration file is one)");  // LoadAll hung
  EXPECT_EQ(error(std::string(40, '[') + std::string(40, ']')), path + ":1: nested more than 32 levels");
  EXPECT_EQ(error("seed: 1\n" + std::string(kMaxConfigFileBytes, '#')),
            path + ": configuration file of 1048584 bytes, more than 1048576");
  EXPECT_EQ(error("seed: [1\n"), path + ":2: YAML: end of sequence flow not found");
  EXPECT_EQ(error("seed: 1\n---\n"), "") << "a document end marker alone is one document";
  EXPECT_EQ(ErrorOf([&] { LoadSimulationConfig(WriteFile("w.yaml", "seed: 1\nseed: 2\n")); }),
            Path("w.yaml") + ":2: key 'seed' given twice (first on line 1)");
}

// Aliases of aliases expand exponentially: a few hundred bytes would take
// minutes to walk. The node count with aliases expanded is bounded before
// any walk, whatever the shape: sequences, maps, merge keys, one long chain.
TEST_F(HostileInput, ConfigFilesBoundTheirNodesWithAliasesExpanded) {
  const auto laughs = [](int levels, bool maps) {
    std::string text = maps ? "l0: &l0 {a: x, b: x, c: x, d: x, e: x, f: x, g: x, h: x, i: x, j: x}\n"
                            : "l0: &l0 [x, x, x, x, x, x, x, x, x, x]\n";
    for (int level = 1; level < levels; ++level) {
      const std::string alias = "*l" + std::to_string(level - 1);
      text += "l" + std::to_string(level) + ": &l" + std::to_string(level) + (maps ? " {" : " [");
      for (int k = 0; k < 10; ++k) {
        if (k > 0) text += ", ";
        text += maps ? std::string(1, char('a' + k)) + ": " + alias : alias;
      }
      text += maps ? "}\n" : "]\n";
    }
    return text;
  };
  const std::string path = Path("c.yaml");
  const std::string refused = path + ":6: more than 262144 YAML nodes with aliases expanded";  // the 10^6 level
  for (const bool maps : {false, true}) {
    EXPECT_EQ(ErrorOf([&] { ReadYamlDocument(WriteFile("c.yaml", laughs(10, maps)), "configuration file"); }), refused)
        << (maps ? "maps" : "sequences");
    EXPECT_EQ(ErrorOf([&] { ReadYamlDocument(WriteFile("c.yaml", laughs(4, maps)), "configuration file"); }), "")
        << "10^4 nodes are within the bound";
  }
  // Merge keys and a list of one alias repeated: the same count, other shapes.
  std::string merges = "base: &base " + laughs(1, true).substr(8);
  for (int level = 1; level < 7; ++level) {
    merges += "m" + std::to_string(level) + ": &m" + std::to_string(level) + " {";
    for (int k = 0; k < 10; ++k) {
      merges += std::string(k > 0 ? ", " : "") + char('a' + k) + ": *" +
                (level == 1 ? std::string("base") : "m" + std::to_string(level - 1));
    }
    merges += "}\n";
  }
  EXPECT_EQ(ErrorOf([&] { ReadYamlDocument(WriteFile("c.yaml", merges + "top: {<<: *m6}\n"), "configuration file"); }),
            path + ":6: more than 262144 YAML nodes with aliases expanded");
  std::string chain = "x: &x [" + std::string(100, '1') + "]\nlist: [";
  for (int k = 0; k < 140000; ++k) chain += k > 0 ? ", *x" : "*x";
  EXPECT_EQ(ErrorOf([&] { ReadYamlDocument(WriteFile("c.yaml", chain + "]\n"), "configuration file"); }),
            path + ":2: more than 262144 YAML nodes with aliases expanded");
}

TEST_F(HostileInput, OutputsAreRegularFilesInExistingFolders) {
  const auto write = [](const std::string& path) { WriteFileAtomically(path, [](std::ostream& out) { out << "x"; }); };
  const std::string fifo = Path("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(ErrorOf([&] { write(fifo); }), fifo + ": is not a regular file (a device or FIFO?); refused as an output");
  // A device node is of the FIFO's class; /dev/null itself is not tried (as root, a
  // regression would replace it): tests/tools/hostile_cli_test.sh makes one with mknod.
  EXPECT_EQ(ErrorOf([&] { CheckOutputFile("/dev/null"); }),
            "/dev/null: is not a regular file (a device or FIFO?); refused as an output");
  EXPECT_EQ(ErrorOf([&] { write(dir_.string()); }), dir_.string() + ": is a folder, not a file to write");
  EXPECT_EQ(ErrorOf([&] { write(Path("absent/map.rgm")); }), Path("absent/map.rgm") + ": its folder does not exist");
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
  EXPECT_EQ(ErrorOf([&] { StagedFolder folder(fifo); }),
            fifo + ": exists and is not a folder; refused as an output folder");
}

// A results folder holds its old content or the complete new one; what the
// run did not write stays, a folder it wrote is replaced whole.
TEST_F(HostileInput, StagedFoldersReplaceTheOldResultsWhole) {
  namespace fs = std::filesystem;
  const std::string out = Path("results");
  const auto run = [&](const std::vector<std::string>& files, bool fail) {
    StagedFolder folder(out + "/");
    for (const std::string& name : files) {
      fs::create_directories((fs::path(folder.path()) / name).parent_path());
      WriteFileAtomically(folder.path() + "/" + name, [&](std::ostream& o) { o << (fail ? "new " : "") << name; });
    }
    if (fail) throw DataError("the run failed");
    folder.Commit();
  };
  run({"a.csv", "runs/one.tum"}, false);
  WriteFile("results/plot.png", "a plot");
  EXPECT_EQ(ErrorOf([&] { run({"a.csv", "b.csv"}, true); }), "the run failed");
  EXPECT_FALSE(fs::exists(Path("results/b.csv")));
  run({"a.csv", "runs/two.tum"}, false);
  EXPECT_TRUE(fs::exists(Path("results/plot.png")));  // kept
  EXPECT_TRUE(fs::exists(Path("results/runs/two.tum")));
  EXPECT_FALSE(fs::exists(Path("results/runs/one.tum")));  // its folder was rewritten
  std::size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) entries += entry.path().filename() != "results";
  EXPECT_EQ(entries, 0u) << "a staging folder was left";
}

// A results folder that is replaced keeps what the user set on it (mode,
// setgid), loses the earlier run's files that describe its outputs
// (superseded), and is never the root or a shared (sticky) folder.
TEST_F(HostileInput, StagedFoldersKeepTheFoldersModeAndDropSupersededFiles) {
  namespace fs = std::filesystem;
  const std::string out = Path("kept");
  fs::create_directories(out);
  WriteFile("kept/evaluation.json", "{\"an\": \"earlier run\"}");
  WriteFile("kept/notes.txt", "the user's");
  for (const mode_t mode : {mode_t(0700), mode_t(02750), mode_t(0755)}) {
    ASSERT_EQ(::chmod(out.c_str(), mode), 0);
    StagedFolder folder(out, {"evaluation.json", "evaluation.md"});
    WriteFileAtomically(folder.path() + "/odometry.tum", [](std::ostream& o) { o << "0 0 0 0 0 0 0 1\n"; });
    folder.Commit();
    struct stat status {};
    ASSERT_EQ(::stat(out.c_str(), &status), 0);
    EXPECT_EQ(status.st_mode & 07777, mode) << std::oct << mode;
  }
  EXPECT_FALSE(fs::exists(Path("kept/evaluation.json"))) << "an earlier run's evaluation beside a new trajectory";
  EXPECT_TRUE(fs::exists(Path("kept/notes.txt")));
  EXPECT_TRUE(fs::exists(Path("kept/odometry.tum")));
  const std::string shared = Path("shared");
  fs::create_directories(shared);
  ASSERT_EQ(::chmod(shared.c_str(), 01777), 0);
  EXPECT_EQ(ErrorOf([&] { StagedFolder folder(shared); }),
            shared + ": is a shared folder (sticky bit, as /tmp); name a folder of its own inside it");
  EXPECT_EQ(ErrorOf([&] { StagedFolder folder("/tmp"); }),
            "/tmp: is a shared folder (sticky bit, as /tmp); name a folder of its own inside it");
  EXPECT_EQ(ErrorOf([&] { StagedFolder folder("/"); }), "/: is the root folder; refused as an output folder");
  EXPECT_EQ(ErrorOf([&] { StagedFolder folder(shared + "/mine"); }), "") << "a folder of its own inside it";
}

TEST(HostileIndex, BlursAndCellsBeyondTheirBoundsAreRefusedAtOnce) {
  GaussianMap map;
  map.gaussians = {RoundGaussian(Eigen::Vector3d::Zero(), 0.3)};
  for (const double sigma : {1e300, 1e160, std::numeric_limits<double>::infinity(), 101.0}) {
    MatchingMapOptions options;
    options.inflation = {sigma};
    EXPECT_THROW(MatchingMap(map, options), std::invalid_argument) << sigma;
  }
  MatchingMapOptions options;
  options.index_cell = 1e300;
  EXPECT_THROW(MatchingMap(map, options), std::invalid_argument);
  Gaussian infinite = RoundGaussian(Eigen::Vector3d::Zero(), 0.3);
  infinite.covariance(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ErrorOf([&] { GaussianIndex({infinite}); }), "Gaussian 0 has a non-finite mean or covariance");
}

}  // namespace
}  // namespace radargauss
