// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/peers/pcl_peers.hpp"

#include <gtest/gtest.h>

#include "radargauss/experiment/experiment.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/simulator/simulator.hpp"

namespace radargauss {
namespace {

// NDT and GICP on a short simulated sequence, from the protocol's errors
// (up to 1 m / 3 deg here): they run through the ScanMatcher interface and
// lower the errors.
TEST(PclPeers, LowerTheErrorsOnAShortSequence) {
  SimulationConfig config;
  config.scans = 20;
  config.seed = 4;
  const SimulatedSequence simulated = Simulate(config);
  const Sequence sequence = AsSequence(simulated);
  const MapCloud cloud = BuildMapCloud(sequence);
  const GaussianMap unused;
  const MatchingMap matching(unused, ExactMapOnly());
  const std::vector<SE3d> errors = InitialErrors(sequence.scans.size(), 1.0, 3.0, 42);
  for (const PclMethod method : {PclMethod::kNdt, PclMethod::kGicp}) {
    const PclPeerMatcher peer(method, cloud.points);
    const ConfigurationRun run =
        RunConfiguration(peer.Name(), 0.0, peer, matching, sequence.scans, sequence.poses, errors);
    double initial = 0.0;
    for (const ScanOutcome& o : run.outcomes) initial += o.initial_translation_error / run.outcomes.size();
    std::printf("%s: translation error %.3f -> %.3f m (median %.3f), rotation median %.3f deg\n", peer.Name().c_str(),
                initial, run.translation.mean, run.translation.median, run.rotation.median);
    EXPECT_LT(run.translation.median, 0.5 * initial) << peer.Name();
  }
}

}  // namespace
}  // namespace radargauss
