// SPDX-License-Identifier: BSD-3-Clause
// radargauss evaluate: an estimated trajectory against a reference (ATE, RPE).
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/experiment/evaluation.hpp"

namespace radargauss::cli {

namespace {

struct EvaluateSettings {
  std::string estimate;
  std::string reference;
  std::string alignment = ToString(EvaluationOptions().alignment);
  double time_tolerance = EvaluationOptions().time_tolerance;
  std::string out;
};

int RunEvaluate(const EvaluateSettings& s) {
  EvaluationOptions options;
  options.alignment = AlignmentFromString(s.alignment);
  options.time_tolerance = s.time_tolerance;
  const Evaluation evaluation = EvaluateTrajectory(ReadTum(s.estimate), ReadTum(s.reference), options);
  if (!s.out.empty()) {
    StagedFolder folder(s.out);
    WriteEvaluation(folder.path(), evaluation);
    folder.Commit();
  }
  std::printf("%zu poses paired, reference path %.1f m, %s alignment (scale %.4f)%s%s\n", evaluation.matched,
              evaluation.path_length, s.alignment.c_str(), evaluation.scale,
              evaluation.alignment_note.empty() ? "" : "; ", evaluation.alignment_note.c_str());
  std::printf("ATE translation: RMSE %.3f m, mean %.3f, median %.3f, max %.3f\n", evaluation.ate_translation.rmse,
              evaluation.ate_translation.mean, evaluation.ate_translation.median, evaluation.ate_translation.max);
  std::printf("ATE rotation: RMSE %.3f deg, mean %.3f, median %.3f, max %.3f\n", evaluation.ate_rotation.rmse,
              evaluation.ate_rotation.mean, evaluation.ate_rotation.median, evaluation.ate_rotation.max);
  std::printf(
      "RPE over 10-50%% of the path: translation %.3f %%, horizontal %.3f %%, rotation %.5f deg/m (%zu "
      "segments)\n",
      evaluation.rpe_mean.translation, evaluation.rpe_mean.horizontal, evaluation.rpe_mean.rotation,
      evaluation.rpe_mean.segments);
  for (const SegmentDrift& d : evaluation.kitti) {
    std::printf("KITTI %4.0f m: translation %.3f %%, rotation %.5f deg/m (%zu segments)\n", d.length, d.translation,
                d.rotation, d.segments);
  }
  if (!s.out.empty()) std::printf("wrote %s/evaluation.json and evaluation.md\n", s.out.c_str());
  return 0;
}

}  // namespace

Subcommand AddEvaluate(CLI::App& parent) {
  auto s = std::make_shared<EvaluateSettings>();
  CLI::App* app = parent.add_subcommand("evaluate", "ATE and RPE of an estimated trajectory against a reference");
  app->add_option("--est", s->estimate, "Estimated trajectory (TUM)")->required();
  app->add_option("--ref", s->reference, "Reference trajectory (TUM)")->required();
  app->add_option("--align", s->alignment, "Alignment of the estimate (sim3 rescales the RPE too)")
      ->check(CLI::IsMember(AlignmentNames()))
      ->capture_default_str();
  app->add_option("--time-tolerance", s->time_tolerance, "Largest time difference of a pose pair (s)")
      ->check(NonNegative())
      ->capture_default_str();
  app->add_option("--out", s->out, "Folder for evaluation.json and evaluation.md");
  return {app, [s] { return RunEvaluate(*s); }};
}

}  // namespace radargauss::cli
