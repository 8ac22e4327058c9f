// SPDX-License-Identifier: BSD-3-Clause
// Builds the Gaussian-RCS map of a sequence and writes it as a map file.
//   build_map SEQUENCE_DIR GROUND_TRUTH.tum MAP.rgm
#include <radargauss/radargauss.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s SEQUENCE_DIR GROUND_TRUTH.tum MAP.rgm\n", argv[0]);
    return 2;
  }
  try {
    radargauss::SequenceOptions input;
    input.sequence_dir = argv[1];
    input.ground_truth = argv[2];  // reference poses: the map is built in their frame
    const radargauss::Sequence sequence = radargauss::LoadSequence(input);

    radargauss::MapOptions options;  // the defaults of `radargauss build-map`
    options.rcs.max_degree = 3;      // SH degree of the RCS models
    const radargauss::GaussianMap map = radargauss::BuildMap(sequence, options);
    radargauss::WriteMap(argv[3], map);

    std::size_t with_rcs = 0;
    for (const radargauss::Gaussian& g : map.gaussians) with_rcs += g.rcs.valid() ? 1 : 0;
    std::printf("%zu scans -> %zu Gaussians (%zu with an RCS model) in %s\n", sequence.scans.size(),
                map.gaussians.size(), with_rcs, argv[3]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "build_map: %s\n", e.what());
    return 1;
  }
  return 0;
}
