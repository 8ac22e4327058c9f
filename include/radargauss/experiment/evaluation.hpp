// SPDX-License-Identifier: BSD-3-Clause
// Trajectory evaluation (docs/design/experiment.md, "Evaluation"): an estimate against a
// reference, poses matched by time. ATE after an alignment; RPE over
// segments of a fraction of the reference's path length from every start
// pose (the protocol of evo's RPE with the RA-L authors' settings), and over
// KITTI's 100-800 m segments when the path is long enough.
#pragma once

#include <string>
#include <vector>

#include "radargauss/lie/se3.hpp"
#include "radargauss/core/stats.hpp"
#include "radargauss/core/trajectory.hpp"

namespace radargauss {

enum class Alignment {
  kSe3,    // rotation and translation minimising the squared position error (Umeyama, no scale)
  kSim3,   // the same with a scale
  kFirst,  // the first matched estimate onto the first reference pose
  kNone,
};
std::string ToString(Alignment alignment);
Alignment AlignmentFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> AlignmentNames();

// Reference positions whose second principal spread is below this share of
// the first lie on a line: they leave the rotation about it free, and kSe3 /
// kSim3 take their rotation from the orientations instead (the mean of
// R_ref R_est^T projected on SO(3)).
inline constexpr double kThinTrajectory = 0.01;

struct EvaluationOptions {
  Alignment alignment = Alignment::kSe3;
  double time_tolerance = 0.02;  // s: an estimate pairs with the reference sample nearest in time within this
  std::vector<double> segment_fractions = {0.1, 0.2, 0.3, 0.4, 0.5};             // of the reference's path length
  std::vector<double> kitti_lengths = {100, 200, 300, 400, 500, 600, 700, 800};  // m, while shorter than the path
};

// The drift over segments of one length d: for every start i, j the first
// pose with path distance >= d, E = (Ref_i^-1 Ref_j)^-1 (Est_i^-1 Est_j);
// translation |t_E| / d_ij, horizontal the x-y part of t_E (the frame at the
// segment's end), rotation angle(E) / d_ij; means over the segments.
struct SegmentDrift {
  double length = 0.0;  // m
  std::size_t segments = 0;
  double translation = 0.0;  // %
  double horizontal = 0.0;   // %
  double rotation = 0.0;     // deg/m
};

struct Evaluation {
  std::size_t matched = 0;          // estimate poses paired with the reference
  double path_length = 0.0;         // m, of the matched reference poses
  SE3d alignment;                   // applied to the estimate: T_ref_est
  double scale = 1.0;               // kSim3's scale (1 otherwise)
  std::string alignment_note;       // how the alignment was found when not as asked (empty: as asked)
  ErrorStatistics ate_translation;  // m
  ErrorStatistics ate_rotation;     // deg
  std::vector<SegmentDrift> rpe;    // per segment fraction
  SegmentDrift rpe_mean;            // over every segment of every fraction
  std::vector<SegmentDrift> kitti;  // per KITTI length shorter than the path
};

// Throws DataError when fewer than 3 poses pair up, std::invalid_argument for bad options.
Evaluation EvaluateTrajectory(const Trajectory& estimate, const Trajectory& reference,
                              const EvaluationOptions& options = {});

// The rigid (or similarity, with `with_scale`) transform minimising
// sum |s R p_i + t - q_i|^2 (Umeyama 1991); returns it and writes the scale.
// Throws DataError when no scale fits (the points p all coincide).
SE3d AlignPoints(const std::vector<Eigen::Vector3d>& p, const std::vector<Eigen::Vector3d>& q, bool with_scale,
                 double& scale);

// evaluation.json and evaluation.md into `dir` (created); returns the Markdown.
std::string WriteEvaluation(const std::string& dir, const Evaluation& evaluation);

}  // namespace radargauss
