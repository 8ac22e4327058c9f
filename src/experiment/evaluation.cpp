// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/experiment/evaluation.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/lie/nearest_rotation.hpp"
#include "radargauss/core/names.hpp"

namespace radargauss {

namespace {

const NamedValue<Alignment> kAlignmentNames[] = {
    {Alignment::kSe3, "se3"}, {Alignment::kSim3, "sim3"}, {Alignment::kFirst, "first"}, {Alignment::kNone, "none"}};

// The estimate and reference poses that pair up: for each estimate sample
// the reference sample nearest in time, within the tolerance, each once.
void MatchByTime(const Trajectory& estimate, const Trajectory& reference, double tolerance, std::vector<SE3d>& est,
                 std::vector<SE3d>& ref) {
  std::vector<double> times;
  for (const StampedPose& sample : reference) times.push_back(sample.time);
  std::size_t last = times.size();  // the reference sample paired last
  for (const StampedPose& sample : estimate) {
    const auto after = std::lower_bound(times.begin(), times.end(), sample.time);
    std::size_t nearest = std::size_t(after - times.begin());
    if (nearest == times.size() || (nearest > 0 && sample.time - times[nearest - 1] < times[nearest] - sample.time)) {
      if (nearest == 0) continue;
      --nearest;
    }
    if (std::abs(times[nearest] - sample.time) > tolerance || nearest == last) continue;
    est.push_back(sample.pose);
    ref.push_back(reference[nearest].pose);
    last = nearest;
  }
}

// The spread of points about their mean: the stds along the principal axes, largest last.
Eigen::Vector3d PrincipalSpread(const std::vector<Eigen::Vector3d>& points, Eigen::Vector3d& mean) {
  mean.setZero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= double(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter / double(points.size()), Eigen::EigenvaluesOnly);
  return solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
}

// The rotation nearest the mean of R_ref R_est^T over the pairs: the
// alignment's rotation as the orientations give it (docs/design/experiment.md, "Evaluation").
SO3d OrientationAlignment(const std::vector<SE3d>& est, const std::vector<SE3d>& ref) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < est.size(); ++k) sum += (ref[k].rotation() * est[k].rotation().Inverse()).Matrix();
  return SO3d::FromMatrix(NearestRotation(sum));
}

// T_ref_est (and the scale) that the alignment applies to the estimate. The
// reference positions fix the rotation unless they lie on a line (its
// second principal spread below kThinTrajectory of its first): then the
// rotation comes from the orientations, and `note` says so.
SE3d AlignmentOf(const std::vector<SE3d>& est, const std::vector<SE3d>& ref, Alignment alignment, double& scale,
                 std::string& note) {
  scale = 1.0;
  if (alignment == Alignment::kNone) return SE3d();
  if (alignment == Alignment::kFirst) return ref.front() * est.front().Inverse();
  std::vector<Eigen::Vector3d> p, q;
  for (std::size_t k = 0; k < est.size(); ++k) {
    p.push_back(est[k].translation());
    q.push_back(ref[k].translation());
  }
  Eigen::Vector3d p_mean, q_mean;
  const Eigen::Vector3d q_spread = PrincipalSpread(q, q_mean), p_spread = PrincipalSpread(p, p_mean);
  if (q_spread[1] > kThinTrajectory * q_spread[2]) return AlignPoints(p, q, alignment == Alignment::kSim3, scale);
  note = "rotation from the orientations: the reference positions lie on a line";
  if (alignment == Alignment::kSim3) {
    scale = q_spread.norm() / p_spread.norm();
    if (!(scale > 0.0 && std::isfinite(scale))) {
      throw DataError("a sim3 alignment needs an estimate that moves (its positions all coincide); use se3 or first");
    }
  }
  const SO3d rotation = OrientationAlignment(est, ref);
  return SE3d(rotation, q_mean - scale * (rotation * p_mean));
}

SE3d Aligned(const SE3d& pose, const SE3d& alignment, double scale) {
  return SE3d(alignment.rotation() * pose.rotation(),
              scale * (alignment.rotation() * pose.translation()) + alignment.translation());
}

double AngleDeg(const SO3d& rotation) { return rotation.Log().norm() * 180.0 / M_PI; }

// Sums over the segments of one length (SegmentDrift), before the means.
struct DriftSums {
  std::size_t segments = 0;
  double translation = 0.0, horizontal = 0.0, rotation = 0.0;
  void Add(const DriftSums& other) {
    segments += other.segments;
    translation += other.translation;
    horizontal += other.horizontal;
    rotation += other.rotation;
  }
  SegmentDrift Mean(double length) const {
    const double n = std::max<double>(1.0, double(segments));
    return {length, segments, translation / n, horizontal / n, rotation / n};
  }
};

DriftSums Drift(const std::vector<SE3d>& est, const std::vector<SE3d>& ref, const std::vector<double>& distance,
                double length) {
  DriftSums sums;
  const std::size_t n = est.size();
  std::size_t j = 0;
  for (std::size_t i = 0; i < n; ++i) {
    j = std::max(j, i + 1);
    while (j < n && distance[j] - distance[i] < length) ++j;
    if (j == n) break;
    const double d = distance[j] - distance[i];
    const SE3d error = (ref[i].Inverse() * ref[j]).Inverse() * (est[i].Inverse() * est[j]);
    ++sums.segments;
    sums.translation += 100.0 * error.translation().norm() / d;
    sums.horizontal += 100.0 * error.translation().head<2>().norm() / d;
    sums.rotation += AngleDeg(error.rotation()) / d;
  }
  return sums;
}

}  // namespace

std::string ToString(Alignment alignment) { return NameOf(kAlignmentNames, alignment); }
Alignment AlignmentFromString(const std::string& name) { return ValueNamed(kAlignmentNames, name, "alignment"); }
std::vector<std::string> AlignmentNames() { return NamesOf(kAlignmentNames); }

SE3d AlignPoints(const std::vector<Eigen::Vector3d>& p, const std::vector<Eigen::Vector3d>& q, bool with_scale,
                 double& scale) {
  Eigen::Matrix3Xd source(3, p.size()), target(3, q.size());
  for (std::size_t k = 0; k < p.size(); ++k) {
    source.col(Eigen::Index(k)) = p[k];
    target.col(Eigen::Index(k)) = q[k];
  }
  const Eigen::Matrix4d T = Eigen::umeyama(source, target, with_scale);
  scale = with_scale ? std::cbrt(T.topLeftCorner<3, 3>().determinant()) : 1.0;
  // The scale is the ratio of the two spreads: points that all coincide have none (0 / 0).
  if (!(scale > 0.0 && std::isfinite(scale))) {
    throw DataError("a sim3 alignment needs an estimate that moves (its positions all coincide); use se3 or first");
  }
  return SE3d(SO3d::FromMatrix(T.topLeftCorner<3, 3>() / scale), T.topRightCorner<3, 1>());
}

Evaluation EvaluateTrajectory(const Trajectory& estimate, const Trajectory& reference,
                              const EvaluationOptions& options) {
  if (!(options.time_tolerance >= 0.0)) throw std::invalid_argument("time tolerance must be >= 0");
  std::vector<SE3d> est, ref;
  MatchByTime(estimate, reference, options.time_tolerance, est, ref);
  if (est.size() < 3) {
    throw DataError("only " + std::to_string(est.size()) + " estimate poses pair with the reference in time (need 3)");
  }
  Evaluation e;
  e.matched = est.size();
  e.alignment = AlignmentOf(est, ref, options.alignment, e.scale, e.alignment_note);
  std::vector<double> translation, rotation, distance = {0.0};
  for (std::size_t k = 0; k < est.size(); ++k) {
    est[k] = Aligned(est[k], e.alignment, e.scale);
    translation.push_back((est[k].translation() - ref[k].translation()).norm());
    rotation.push_back(AngleDeg(ref[k].rotation().Inverse() * est[k].rotation()));
    if (k > 0) distance.push_back(distance.back() + (ref[k].translation() - ref[k - 1].translation()).norm());
  }
  e.path_length = distance.back();
  e.ate_translation = Statistics(translation);
  e.ate_rotation = Statistics(rotation);
  DriftSums all;
  for (const double fraction : options.segment_fractions) {
    if (!(fraction > 0.0)) throw std::invalid_argument("segment fractions must be > 0");
    const DriftSums sums = Drift(est, ref, distance, fraction * e.path_length);
    e.rpe.push_back(sums.Mean(fraction * e.path_length));
    all.Add(sums);
  }
  e.rpe_mean = all.Mean(0.0);
  for (const double length : options.kitti_lengths) {
    if (length < e.path_length) e.kitti.push_back(Drift(est, ref, distance, length).Mean(length));
  }
  return e;
}

namespace {

nlohmann::json ToJson(const ErrorStatistics& s) {
  return {{"mean", s.mean}, {"median", s.median}, {"rmse", s.rmse}, {"max", s.max}};
}

nlohmann::json ToJson(const SegmentDrift& d) {
  return {{"length_m", d.length},
          {"segments", d.segments},
          {"translation_percent", d.translation},
          {"horizontal_percent", d.horizontal},
          {"rotation_deg_per_m", d.rotation}};
}

std::string Markdown(const Evaluation& e) {
  std::ostringstream md;
  md.precision(3);
  md << std::fixed << "| poses | path m | ATE t RMSE m | ATE t max m | ATE r RMSE deg | RPE t % | RPE horizontal % "
     << "| RPE r deg/m |\n|---|---|---|---|---|---|---|---|\n| " << e.matched << " | " << e.path_length << " | "
     << e.ate_translation.rmse << " | " << e.ate_translation.max << " | " << e.ate_rotation.rmse << " | "
     << e.rpe_mean.translation << " | " << e.rpe_mean.horizontal << " | " << e.rpe_mean.rotation << " |\n";
  if (!e.alignment_note.empty()) md << "\nAlignment: " << e.alignment_note << ".\n";
  md << "\n| segment m | segments | t % | horizontal % | r deg/m |\n|---|---|---|---|---|\n";
  for (const std::vector<SegmentDrift>* list : {&e.rpe, &e.kitti}) {
    for (const SegmentDrift& d : *list) {
      md << "| " << d.length << " | " << d.segments << " | " << d.translation << " | " << d.horizontal << " | "
         << d.rotation << " |\n";
    }
  }
  return md.str();
}

}  // namespace

std::string WriteEvaluation(const std::string& dir, const Evaluation& e) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) throw FileError(dir, "cannot create the output folder: " + error.message());
  nlohmann::json json = {{"matched", e.matched},
                         {"path_length_m", e.path_length},
                         {"scale", e.scale},
                         {"ate_translation_m", ToJson(e.ate_translation)},
                         {"ate_rotation_deg", ToJson(e.ate_rotation)},
                         {"rpe", ToJson(e.rpe_mean)},
                         {"rpe_segments", nlohmann::json::array()},
                         {"kitti_segments", nlohmann::json::array()},
                         {"alignment_note", e.alignment_note}};
  for (const SegmentDrift& d : e.rpe) json["rpe_segments"].push_back(ToJson(d));
  for (const SegmentDrift& d : e.kitti) json["kitti_segments"].push_back(ToJson(d));
  WriteFileAtomically((fs::path(dir) / "evaluation.json").string(),
                      [&](std::ostream& out) { out << json.dump(2) << "\n"; });
  const std::string markdown = Markdown(e);
  WriteFileAtomically((fs::path(dir) / "evaluation.md").string(), [&](std::ostream& out) { out << markdown; });
  return markdown;
}

}  // namespace radargauss
