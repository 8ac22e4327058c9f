// SPDX-License-Identifier: BSD-3-Clause
// radargauss refine: joint refinement of a trajectory's poses and a map's SH
// coefficients (docs/design/solvers.md, "Joint refinement"), evaluated against a
// reference before and after when one is given.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "option_flags.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/solvers/joint_refinement.hpp"

namespace radargauss::cli {

namespace {

struct RefineSettings {
  SequenceOptions sequence;  // ground_truth: the poses to refine
  std::string map_path;
  std::string reference;
  std::string out;
  JointRefinementOptions refinement;
};

Trajectory TrajectoryOf(const Sequence& sequence, const std::vector<SE3d>& poses) {
  Trajectory trajectory;
  for (std::size_t k = 0; k < poses.size(); ++k) trajectory.Append(sequence.scans[k].timestamp, poses[k]);
  return trajectory;
}

void PrintEvaluation(const char* label, const Trajectory& estimate, const std::string& reference,
                     const std::string& dir) {
  const Evaluation e = EvaluateTrajectory(estimate, ReadTum(reference));
  WriteEvaluation(dir, e);
  std::printf("%s: ATE RMSE %.3f m / %.3f deg, RPE %.3f %% / %.5f deg/m\n", label, e.ate_translation.rmse,
              e.ate_rotation.rmse, e.rpe_mean.translation, e.rpe_mean.rotation);
}

int RunRefine(const RefineSettings& s) {
  if (s.sequence.ground_truth.empty()) throw DataError("refine needs --poses");
  const Sequence sequence = LoadSequence(s.sequence);
  const GaussianMap map = ReadMap(s.map_path);
  StagedFolder folder(s.out);  // a bad --out fails before the refinement
  JointRefinementResult result;
  try {
    result = RefineJointly(sequence.scans, sequence.poses, map, s.refinement);
  } catch (const DataError& e) {  // the map the scans miss: name it
    throw FileError(s.map_path, e.what());
  }
  namespace fs = std::filesystem;
  const Trajectory before = TrajectoryOf(sequence, sequence.poses), after = TrajectoryOf(sequence, result.poses);
  WriteTum((fs::path(folder.path()) / "refined.tum").string(), after);
  WriteMap((fs::path(folder.path()) / "refined.rgm").string(), result.map);
  std::printf(
      "refined %zu poses and %zu Gaussians' SH coefficients: cost %.6g -> %.6g in %d Ceres iterations "
      "(%s), %.1f s\n",
      result.poses.size(), result.map.gaussians.size(), result.initial_cost, result.final_cost, result.iterations,
      result.converged ? "converged" : result.reason.c_str(), result.time_ms / 1000.0);
  if (!s.reference.empty()) {
    PrintEvaluation("before", before, s.reference, (fs::path(folder.path()) / "before").string());
    PrintEvaluation("after", after, s.reference, (fs::path(folder.path()) / "after").string());
  }
  folder.Commit();
  std::printf("wrote %s/refined.tum and refined.rgm\n", s.out.c_str());
  return 0;
}

}  // namespace

Subcommand AddRefine(CLI::App& parent) {
  auto s = std::make_shared<RefineSettings>();
  s->refinement.matching.w_rcs = 0.25;
  s->refinement.relative_pose_prior = 1.0;
  CLI::App* app = parent.add_subcommand("refine", "Jointly refine a trajectory's poses and a map's SH coefficients");
  // The sequence's poses are the trajectory to refine; --gt is the reference.
  AddSequenceOptions(app, s->sequence, "--poses", "Trajectory to refine (TUM, radar poses)");
  app->get_option("--poses")->required();
  app->add_option("--gt", s->reference, "Reference trajectory (TUM) to evaluate against before and after");
  app->add_option("--map", s->map_path, "Map file (.rgm)")->required();
  app->add_option("--out", s->out, "Output folder (refined.tum, refined.rgm)")->required();
  AddTableOptions(app, JointRefinementOptionTable(), s->refinement);
  return {app, [s] { return RunRefine(*s); }};
}

}  // namespace radargauss::cli
