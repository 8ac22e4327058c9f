// SPDX-License-Identifier: BSD-3-Clause
#include "option_fields.hpp"

#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "radargauss/names.hpp"

namespace radargauss::python {

namespace {

// A Python value as a field's C++ type, strictly: a bool is not a number, a
// float is finite, an integer fits.
template <typename T>
T FromPython(const py::handle& value, const std::string& keyword) {
  if constexpr (std::is_same_v<T, bool>) {
    if (!py::isinstance<py::bool_>(value)) throw py::type_error(keyword + " must be a bool");
    return value.cast<bool>();
  } else if constexpr (std::is_integral_v<T>) {
    if (py::isinstance<py::bool_>(value) || !py::isinstance<py::int_>(value)) {
      throw py::type_error(keyword + " must be an int");
    }
    const long long n = value.cast<long long>();
    if (n < (long long)std::numeric_limits<T>::min() || (unsigned long long)n > std::numeric_limits<T>::max()) {
      throw py::value_error(keyword + " is out of range");
    }
    return T(n);
  } else if constexpr (std::is_floating_point_v<T>) {
    if (py::isinstance<py::bool_>(value) || !(py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value))) {
      throw py::type_error(keyword + " must be a number");
    }
    const double x = value.cast<double>();
    if (!std::isfinite(x)) throw py::value_error(keyword + " must be finite");
    return x;
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    std::vector<double> out;
    for (const py::handle item : py::iter(value)) out.push_back(FromPython<double>(item, keyword));
    return out;
  } else if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
    const std::vector<double> xyz = FromPython<std::vector<double>>(value, keyword);
    if (xyz.size() != 3) throw py::value_error(keyword + " must hold 3 numbers");
    return Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
  } else {
    return PoseFromPython(value, keyword);
  }
}

template <typename T>
py::object ToPython(const T& value) {
  if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
    return py::cast(std::vector<double>{value.x(), value.y(), value.z()});
  } else if constexpr (std::is_same_v<T, SE3d>) {
    return PoseToMatrix(value);
  } else {
    return py::cast(value);
  }
}

template <typename T>
const char* TypeName() {
  if constexpr (std::is_same_v<T, bool>) return "bool";
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) return "int";
  if constexpr (std::is_floating_point_v<T>) return "float";
  if constexpr (std::is_same_v<T, std::vector<double>>) return "list of float";
  if constexpr (std::is_same_v<T, Eigen::Vector3d>) return "sequence of 3 float";
  if constexpr (std::is_same_v<T, SE3d>) return "array (4, 4) or (7,)";
  return "object";
}

template <typename Options, typename T>
OptionField<Options> MakeField(const char* keyword, const char* path, T& (*member)(Options&), const char* doc) {
  OptionField<Options> field{keyword, path, TypeName<T>(), doc, {}, {}};
  const std::string name = keyword;
  field.set = [member, name](Options& o, const py::handle& value) { member(o) = FromPython<T>(value, name); };
  field.get = [member](const Options& o) {
    Options copy = o;
    return ToPython(member(copy));
  };
  return field;
}

template <typename Options, typename Enum>
OptionField<Options> MakeEnumField(const char* keyword, const char* path, Enum& (*member)(Options&),
                                   Enum (*from_string)(const std::string&), const std::vector<std::string>& names,
                                   const char* doc) {
  OptionField<Options> field{keyword, path, "{'" + Joined(names, "', '") + "'}", doc, {}, {}};
  const std::string name = keyword;
  field.set = [member, from_string, name](Options& o, const py::handle& value) {
    if (!py::isinstance<py::str>(value)) throw py::type_error(name + " must be a str");
    member(o) = from_string(value.cast<std::string>());  // std::invalid_argument: ValueError
  };
  field.get = [member](const Options& o) {
    Options copy = o;
    return py::object(py::str(ToString(member(copy))));
  };
  return field;
}

}  // namespace

// A field by its C++ member path, stringified so that the table names the
// member it sets.
#define RADARGAUSS_FIELD(Options, keyword, path, doc) \
  MakeField<Options>(                                 \
      keyword, #path, +[](Options & o) -> auto& { return o.path; }, doc)
#define RADARGAUSS_ENUM(Options, keyword, path, from_string, names, doc) \
  MakeEnumField<Options>(                                                \
      keyword, #path, +[](Options & o) -> auto& { return o.path; }, from_string, names(), doc)

const std::vector<OptionField<MatchOptions>>& MatchFields() {
  using O = MatchOptions;
  static const std::vector<OptionField<O>> fields = {
      RADARGAUSS_ENUM(O, "solver", solver, SolverKindFromString, ScanMatcherNames, "the solver"),
      RADARGAUSS_FIELD(O, "w_rcs", matching.w_rcs, "eq. 2's RCS weight w, in [0, 1]"),
      RADARGAUSS_ENUM(O, "loss", matching.geometric_loss.type, LossTypeFromString, LossNames,
                      "robust loss of the geometric term"),
      RADARGAUSS_FIELD(O, "loss_scale", matching.geometric_loss.scale, "its scale a"),
      RADARGAUSS_ENUM(O, "rcs_loss", matching.rcs_loss.type, LossTypeFromString, LossNames,
                      "robust loss of the RCS term (the paper: cauchy)"),
      RADARGAUSS_FIELD(O, "rcs_loss_scale", matching.rcs_loss.scale, "its scale a"),
      RADARGAUSS_ENUM(O, "rcs_translation", matching.rcs_translation, RcsTranslationFromString, RcsTranslationNames,
                      "the RCS term on the rotation alone (the paper) or on the full pose"),
      RADARGAUSS_ENUM(O, "jacobians", matching.jacobians, JacobianModeFromString, JacobianModeNames,
                      "closed-form Jacobians or Jets through the Ceres functors"),
      RADARGAUSS_FIELD(O, "gate", matching.gate, "association gate tau (Mahalanobis distance)"),
      RADARGAUSS_FIELD(O, "max_iterations", matching.max_iterations, "outer iterations on the exact map"),
      RADARGAUSS_FIELD(O, "coarse_iterations", matching.coarse_iterations, "outer iterations per coarse level"),
      RADARGAUSS_FIELD(O, "coarse_voxel_per_sigma", matching.coarse_voxel_per_sigma,
                       "coarse levels match voxel centroids of this many sigma_k (0: the points)"),
      RADARGAUSS_FIELD(O, "coarse_points", matching.coarse_points,
                       "at most this many points per coarse level (0: all)"),
      RADARGAUSS_FIELD(O, "geometric_first", matching.geometric_first,
                       "with 0 < w < 1, the geometric term alone first on the exact map"),
      RADARGAUSS_FIELD(O, "reassociate", matching.reassociate, "False: associate once at the initial pose"),
      RADARGAUSS_FIELD(O, "reassociation_translation", matching.reassociation_translation,
                       "m: re-associate on the exact map once the pose moved this far"),
      RADARGAUSS_FIELD(O, "reassociation_rotation", matching.reassociation_rotation, "rad: or turned this far"),
      RADARGAUSS_FIELD(O, "translation_tolerance", matching.translation_tolerance,
                       "m: converged when a step on the exact map is smaller"),
      RADARGAUSS_FIELD(O, "rotation_tolerance", matching.rotation_tolerance, "rad: and its rotation smaller"),
      RADARGAUSS_FIELD(O, "coarse_translation_tolerance", matching.coarse_translation_tolerance,
                       "m: the same on coarse levels"),
      RADARGAUSS_FIELD(O, "coarse_rotation_tolerance", matching.coarse_rotation_tolerance,
                       "rad: the same on coarse levels"),
      RADARGAUSS_FIELD(O, "gn_max_step_halvings", gauss_newton.max_step_halvings,
                       "Gauss-Newton: halvings of a step that raises eq. 2 (0: plain steps)"),
      RADARGAUSS_FIELD(O, "gn_loss_curvature", gauss_newton.loss_curvature,
                       "Gauss-Newton: the losses' curvature in the Hessian (else IRLS)"),
      RADARGAUSS_FIELD(O, "ceres_dogleg", ceres.dogleg, "Ceres: dogleg instead of Levenberg-Marquardt"),
      RADARGAUSS_FIELD(O, "ceres_max_inner_iterations", ceres.max_inner_iterations,
                       "Ceres: iterations per solve in the stages that steer"),
      RADARGAUSS_FIELD(O, "ceres_max_exact_inner_iterations", ceres.max_exact_inner_iterations,
                       "Ceres: iterations per solve in the last stage"),
      RADARGAUSS_ENUM(O, "ceres_blocks", ceres.blocks, CeresBlocksFromString, CeresBlocksNames,
                      "Ceres: how analytic terms enter the problem"),
      RADARGAUSS_FIELD(O, "ceres_threads", ceres.threads, "Ceres: threads"),
      RADARGAUSS_FIELD(O, "ceres_function_tolerance", ceres.function_tolerance, "Ceres: per solve"),
      RADARGAUSS_FIELD(O, "ceres_gradient_tolerance", ceres.gradient_tolerance, "Ceres: per solve"),
      RADARGAUSS_FIELD(O, "ceres_parameter_tolerance", ceres.parameter_tolerance, "Ceres: per solve"),
      RADARGAUSS_FIELD(O, "mh_starts", hypotheses.starts, "multi-hypothesis: starts (1..13)"),
      RADARGAUSS_FIELD(O, "mh_xy_offset", hypotheses.xy_offset, "multi-hypothesis: m, x/y offset of the starts"),
      RADARGAUSS_FIELD(O, "mh_yaw_offset", hypotheses.yaw_offset, "multi-hypothesis: rad, yaw offset of the starts"),
  };
  return fields;
}

namespace {

// Odometry's own fields (the match's follow them in OdometryFields).
std::vector<OptionField<OdometryOptions>> OwnOdometryFields() {
  using O = OdometryOptions;
  return {
      RADARGAUSS_FIELD(O, "ego_min_range", ego_velocity.min_range, "m: Doppler filter range gate"),
      RADARGAUSS_FIELD(O, "ego_max_range", ego_velocity.max_range, "m"),
      RADARGAUSS_FIELD(O, "ego_outlier_probability", ego_velocity.outlier_probability,
                       "RANSAC: expected outlier share"),
      RADARGAUSS_FIELD(O, "ego_success_probability", ego_velocity.success_probability,
                       "RANSAC: wanted chance of one clean draw"),
      RADARGAUSS_FIELD(O, "ego_inlier_threshold", ego_velocity.inlier_threshold, "m/s: |v_d - H v| of an inlier"),
      RADARGAUSS_FIELD(O, "ego_zero_velocity_threshold", ego_velocity.zero_velocity_threshold,
                       "m/s: 75th percentile of |v_d| below it: standing"),
      RADARGAUSS_FIELD(O, "ego_zero_velocity_sigma", ego_velocity.zero_velocity_sigma, "m/s: std when standing"),
      RADARGAUSS_FIELD(O, "ego_seed", ego_velocity.seed, "RANSAC seed"),
      RADARGAUSS_FIELD(O, "ego_consensus_voxel", ego_velocity.consensus_voxel,
                       "m: support counted in voxels of this edge (0: points)"),
      RADARGAUSS_FIELD(O, "gate_sigmas", gate_sigmas, "velocity gate around the prediction, in sigmas"),
      RADARGAUSS_FIELD(O, "acceleration_std", acceleration_std, "m/s^2: process noise of the velocity"),
      RADARGAUSS_FIELD(O, "min_gate", min_gate, "m/s: smallest velocity gate"),
      RADARGAUSS_FIELD(O, "min_static_points", min_static_points, "fewer Doppler inliers: the prediction stands in"),
      RADARGAUSS_FIELD(O, "velocity_weight", velocity_weight, "weight of the Doppler velocity term (0: off)"),
      RADARGAUSS_FIELD(O, "velocity_floor", velocity_floor, "m: std of the velocity term's floor"),
      RADARGAUSS_FIELD(O, "velocity_vertical_floor", velocity_vertical_floor,
                       "m: the floor along the radar's z (0: velocity_floor)"),
      RADARGAUSS_FIELD(O, "rotation_weight", rotation_weight, "weight of the rotation term (0: off)"),
      RADARGAUSS_FIELD(O, "rotation_rate_std_deg", rotation_rate_std_deg,
                       "deg/s about x, y, z: rate changes the rotation term allows"),
      RADARGAUSS_FIELD(O, "mounting_deg", mounting_deg, "roll, pitch, yaw of the radar on the vehicle (deg)"),
      RADARGAUSS_FIELD(O, "estimate_elevation_bias", elevation_bias.estimate,
                       "follow the Doppler velocity's elevation"),
      RADARGAUSS_FIELD(O, "elevation_bias_window", elevation_bias.window, "scans the bias's median is over"),
      RADARGAUSS_FIELD(O, "elevation_bias_min_speed", elevation_bias.min_speed, "m/s: slower scans leave the bias"),
      RADARGAUSS_FIELD(O, "region", map.region, "m: edge of the local map's regions"),
      RADARGAUSS_FIELD(O, "region_capacity", map.region_capacity, "points a region keeps (the newest)"),
      RADARGAUSS_FIELD(O, "region_min_points", map.min_points, "points a region needs for its first fit"),
      RADARGAUSS_ENUM(O, "map_estimator", map.estimator, MapEstimatorFromString, MapEstimatorNames,
                      "region Gaussians: refit (k-means + EM) or incremental statistics"),
      RADARGAUSS_FIELD(O, "republish_kl", map.republish_kl, "nats: KL a Gaussian moves before it is republished"),
      RADARGAUSS_FIELD(O, "refit_growth", map.refit_growth, "refit once the new points reach this share"),
      RADARGAUSS_FIELD(O, "active_radius", map.active_radius, "m: regions farther from the radar leave"),
      RADARGAUSS_FIELD(O, "azimuth_std_deg", map.azimuth_std_deg,
                       "deg: Gaussians this angle x range wide horizontally"),
      RADARGAUSS_FIELD(O, "elevation_std_deg", map.elevation_std_deg, "deg: Gaussians this angle x range high"),
      RADARGAUSS_ENUM(O, "gaussians_builder", map.gaussians.builder, MapBuilderFromString, MapBuilderNames,
                      "region fit: k-means (build-map's) or voxel"),
      RADARGAUSS_FIELD(O, "gaussians_downsample_voxel", map.gaussians.downsample_voxel, "m: voxel downsampling"),
      RADARGAUSS_FIELD(O, "gaussians_points_per_gaussian", map.gaussians.points_per_gaussian, "points per Gaussian"),
      RADARGAUSS_FIELD(O, "gaussians_kmeans_iterations", map.gaussians.kmeans_iterations, "Lloyd iterations"),
      RADARGAUSS_FIELD(O, "gaussians_em_iterations", map.gaussians.em_iterations, "hard-EM rounds"),
      RADARGAUSS_FIELD(O, "gaussians_min_std", map.gaussians.min_std, "m: smallest principal std"),
      RADARGAUSS_FIELD(O, "gaussians_seed", map.gaussians.seed, "k-means seed"),
      RADARGAUSS_FIELD(O, "gaussians_ndt_voxel", map.gaussians.ndt_voxel, "m: voxel builder's edge"),
      RADARGAUSS_FIELD(O, "gaussians_ndt_min_points", map.gaussians.ndt_min_points,
                       "voxel builder: points a voxel needs"),
      RADARGAUSS_FIELD(O, "gaussians_index_cell", map.gaussians.index_cell, "m: cell of the fit's index"),
      RADARGAUSS_FIELD(O, "gaussians_association_gate", map.gaussians.association_gate, "members' Mahalanobis gate"),
      RADARGAUSS_FIELD(O, "rcs_max_degree", map.rcs.max_degree, "SH degree of the RCS models (0..3)"),
      RADARGAUSS_FIELD(O, "rcs_adaptive", map.rcs.adaptive, "lower the degree when members are too few"),
      RADARGAUSS_ENUM(O, "rcs_incidence", map.rcs.incidence, IncidenceModelFromString, IncidenceModelNames,
                      "incidence vector of the RCS models"),
      RADARGAUSS_FIELD(O, "rcs_rank_threshold", map.rcs.rank_threshold, "relative pivot threshold of the fit"),
      RADARGAUSS_FIELD(O, "map_inflation", map.matching.inflation, "m: sigma_k of the coarse levels, coarse first"),
      RADARGAUSS_FIELD(O, "map_index_cell", map.matching.index_cell, "m: cell of the exact level's index"),
      RADARGAUSS_ENUM(O, "map_coarse", map.matching.coarse, CoarseLevelsFromString, CoarseLevelsNames,
                      "how the coarse levels are made"),
      RADARGAUSS_FIELD(O, "map_coarse_gate", map.matching.coarse_gate, "tau on the coarse levels"),
      RADARGAUSS_FIELD(O, "map_updatable", map.matching.updatable, "an updatable matching map"),
      RADARGAUSS_FIELD(O, "keyframe_distance", keyframe_distance, "m since the last keyframe: the scan enters the map"),
      RADARGAUSS_FIELD(O, "keyframe_angle_deg", keyframe_angle_deg, "deg: or turned this far"),
      RADARGAUSS_FIELD(O, "min_matched_points", min_matched_points,
                       "fewer associated points: the prediction stands in"),
      RADARGAUSS_FIELD(O, "initial_pose", initial_pose, "T_world_radar of the first scan"),
  };
}

}  // namespace

const std::vector<OptionField<OdometryOptions>>& OdometryFields() {
  static const std::vector<OptionField<OdometryOptions>> fields = [] {
    std::vector<OptionField<OdometryOptions>> out = OwnOdometryFields();
    for (const OptionField<MatchOptions>& f : MatchFields()) {
      out.push_back({f.keyword, "match." + f.path, f.type, f.doc,
                     [set = f.set](OdometryOptions& o, const py::handle& value) { set(o.match, value); },
                     [get = f.get](const OdometryOptions& o) { return get(o.match); }});
    }
    return out;
  }();
  return fields;
}

#undef RADARGAUSS_FIELD
#undef RADARGAUSS_ENUM

}  // namespace radargauss::python
