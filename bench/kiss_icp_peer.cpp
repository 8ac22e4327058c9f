// SPDX-License-Identifier: BSD-3-Clause
// kiss-icp's C++ core (kiss_icp::pipeline::KissICP) on a radargauss
// sequence, one thread unless told, for the odometry comparison of
// bench/RESULTS.md (scripts/peer_table.py):
// every point of each scan, no deskewing; writes the radar poses (TUM) and
// each RegisterFrame's time. Built by scripts/kiss_icp_peer.sh, not by CMake
// (kiss-icp, Sophus and robin-map are not Debian packages).
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "kiss_icp/pipeline/KissICP.hpp"
#include "radargauss/io/sequence.hpp"

namespace {

void WriteTumLine(std::ofstream& out, double stamp, const Sophus::SE3d& pose) {
  const Eigen::Quaterniond q = pose.unit_quaternion();
  char line[256];
  std::snprintf(line, sizeof line, "%.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", stamp, pose.translation().x(),
                pose.translation().y(), pose.translation().z(), q.x(), q.y(), q.z(), q.w());
  out << line;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 4 || argc > 7) {
    std::fprintf(stderr,
                 "usage: kiss_icp_peer SEQUENCE_DIR OUT.tum TIMES.csv [voxel_m=1] [max_range_m=100] [threads=1]\n");
    return 2;
  }
  const int threads = argc > 6 ? std::stoi(argv[6]) : 1;
  if (threads < 1) throw std::invalid_argument("threads must be >= 1");
  const tbb::global_control thread_limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  radargauss::SequenceOptions options;
  options.sequence_dir = argv[1];
  const radargauss::Sequence sequence = radargauss::LoadSequence(options);
  kiss_icp::pipeline::KISSConfig config;
  config.voxel_size = argc > 4 ? std::stod(argv[4]) : 1.0;
  config.max_range = argc > 5 ? std::stod(argv[5]) : 100.0;
  config.deskew = false;
  config.max_num_threads = threads;
  kiss_icp::pipeline::KissICP kiss(config);
  std::ofstream tum(argv[2]), times(argv[3]);
  if (!tum || !times) throw std::runtime_error("cannot write " + std::string(argv[2]) + " or " + argv[3]);
  times << "scan,time_ms\n";
  std::vector<double> ms;
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    const radargauss::RadarScan& scan = sequence.scans[k];
    std::vector<Eigen::Vector3d> frame;
    frame.reserve(scan.points.size());
    for (const radargauss::RadarPoint& p : scan.points) frame.push_back(p.position);
    const auto start = std::chrono::steady_clock::now();
    kiss.RegisterFrame(frame, {});
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    times << k << "," << ms.back() << "\n";
    WriteTumLine(tum, scan.timestamp, kiss.pose());
  }
  std::sort(ms.begin(), ms.end());
  if (!ms.empty()) {
    std::printf("kiss-icp: %zu scans, median %.3f ms, p90 %.3f ms\n", ms.size(), ms[ms.size() / 2],
                ms[std::min(ms.size() - 1, std::size_t(0.9 * double(ms.size())))]);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "kiss_icp_peer: %s\n", e.what());
  return 1;
}
