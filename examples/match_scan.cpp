// SPDX-License-Identifier: BSD-3-Clause
// Matches one scan of a sequence against a map, from its reference pose
// moved by about 1 m and 3 degrees, and prints how far the match ends from
// the reference.
//   match_scan SEQUENCE_DIR GROUND_TRUTH.tum MAP.rgm [SCAN_INDEX]
#include <radargauss/radargauss.hpp>

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

int main(int argc, char** argv) {
  using namespace radargauss;
  if (argc != 4 && argc != 5) {
    std::fprintf(stderr, "usage: %s SEQUENCE_DIR GROUND_TRUTH.tum MAP.rgm [SCAN_INDEX]\n", argv[0]);
    return 2;
  }
  try {
    SequenceOptions input;
    input.sequence_dir = argv[1];
    input.ground_truth = argv[2];
    const Sequence sequence = LoadSequence(input);
    const std::size_t k = argc == 5 ? std::stoul(argv[4]) : sequence.scans.size() / 2;
    if (k >= sequence.scans.size()) throw DataError("scan index out of range");

    const MatchingMap map(ReadMap(argv[3]));  // the map and its coarse-to-fine indexes
    Eigen::Matrix<double, 6, 1> error;        // [rho; phi]: ~1 m and ~3 deg
    error << 0.8, -0.5, 0.2, 0.0, 0.01, 0.05;
    const SE3d& reference = sequence.poses[k];
    const SE3d initial = reference * SE3d::Exp(error);

    MatchOptions options;           // the own Gauss-Newton (options.solver)
    options.matching.w_rcs = 0.25;  // eq. 2's weight of the RCS term
    const ScanMatchingResult result = Match(sequence.scans[k], map, initial, options);

    const double translation = (result.pose.translation() - reference.translation()).norm();
    const double rotation = (reference.rotation().Inverse() * result.pose.rotation()).Log().norm() * 180.0 / M_PI;
    std::printf("scan %zu: %s after %d iterations, %zu geometric and %zu RCS residuals\n", k,
                result.converged ? "converged" : result.reason.c_str(), result.iterations, result.n_geo, result.n_rcs);
    std::printf("error: translation %.4f m, rotation %.4f deg\n", translation, rotation);
    std::printf("information diagonal [dt; dphi]:");
    for (int i = 0; i < 6; ++i) std::printf(" %.4g", result.information(i, i));
    std::printf("\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "match_scan: %s\n", e.what());
    return 1;
  }
  return 0;
}
