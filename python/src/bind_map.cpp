// SPDX-License-Identifier: BSD-3-Clause
// Gaussian-RCS maps in Python: build, read, write, and their arrays.
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/map_tiles.hpp"
#include "radargauss/map/pipeline.hpp"
#include "radargauss/radargauss.hpp"
#include "radargauss/residuals/rcs_likelihood.hpp"

namespace radargauss::python {

const MatchingMap& PyMap::matching() const {
  if (!matching_) matching_ = std::make_shared<const MatchingMap>(map_);
  return *matching_;
}

namespace {

// An (K, ...) array of one quantity of every Gaussian.
template <typename Fill>
Array PerGaussian(const GaussianMap& map, std::vector<py::ssize_t> shape, const Fill& fill) {
  shape.insert(shape.begin(), py::ssize_t(map.gaussians.size()));
  Array out = NewArray(shape);
  double* p = out.mutable_data();
  for (const Gaussian& g : map.gaussians) p = fill(g, p);
  return out;
}

// A (K,) array of one number of every Gaussian, `value(g)`.
template <typename Value>
Array EachGaussian(const PyMap& m, const Value& value) {
  return PerGaussian(m.map(), {}, [&](const Gaussian& g, double* p) {
    *p = double(value(g));
    return p + 1;
  });
}

void BindMapClass(py::module_& m) {
  py::class_<PyMap, std::shared_ptr<PyMap>>(m, "GaussianMap",
                                            "A Gaussian-RCS map; every array is a copy (the Gaussians are "
                                            "stored one by one, not as columns).")
      .def("__len__", [](const PyMap& m) { return m.map().gaussians.size(); })
      .def_property_readonly("incidence", [](const PyMap& m) { return ToString(m.map().incidence); })
      .def_property_readonly("means",
                             [](const PyMap& m) {
                               return PerGaussian(m.map(), {3}, [](const Gaussian& g, double* p) {
                                 return std::copy(g.mean.data(), g.mean.data() + 3, p);
                               });
                             })
      .def_property_readonly("covariances",
                             [](const PyMap& m) {
                               return PerGaussian(m.map(), {3, 3}, [](const Gaussian& g, double* p) {
                                 for (int r = 0; r < 3; ++r) {
                                   for (int c = 0; c < 3; ++c) *p++ = g.covariance(r, c);
                                 }
                                 return p;
                               });
                             })
      .def_property_readonly(
          "point_counts",
          [](const PyMap& m) { return EachGaussian(m, [](const Gaussian& g) { return g.point_count; }); })
      .def_property_readonly(
          "rcs_degrees", [](const PyMap& m) { return EachGaussian(m, [](const Gaussian& g) { return g.rcs.degree; }); },
          "SH degree of each RCS model, -1 where a Gaussian has none")
      .def_property_readonly(
          "rcs_medians", [](const PyMap& m) { return EachGaussian(m, [](const Gaussian& g) { return g.rcs.median; }); })
      .def_property_readonly(
          "rcs_scales", [](const PyMap& m) { return EachGaussian(m, [](const Gaussian& g) { return g.rcs.scale; }); })
      .def_property_readonly(
          "rcs_coefficients",
          [](const PyMap& m) {
            const py::ssize_t n = py::ssize_t(ShCoefficientCount(kMaxShDegree));
            return PerGaussian(m.map(), {n}, [](const Gaussian& g, double* p) {
              return std::copy(g.rcs.coefficients.begin(), g.rcs.coefficients.end(), p);
            });
          },
          "(K, 16) real SH coefficients of the normalised RCS, zero beyond each model's degree")
      .def_property_readonly(
          "rcs_spreads",
          [](const PyMap& m) { return EachGaussian(m, [](const Gaussian& g) { return g.rcs.spread_db; }); },
          "std (dB) of each RCS fit's residuals, its coefficients' degrees of freedom taken out")
      .def_property_readonly(
          "rcs_explained",
          [](const PyMap& m) { return EachGaussian(m, [](const Gaussian& g) { return g.rcs.explained; }); },
          "share of each Gaussian's RCS variance its model's view explains (adjusted R^2, in [0, 1])")
      .def_property_readonly(
          "rcs_inliers",
          [](const PyMap& m) { return EachGaussian(m, [](const Gaussian& g) { return g.rcs.inliers; }); },
          "members each RCS model was fitted to (its inliers)")
      .def(
          "rcs_weight",
          [](const PyMap& m, const std::string& likelihood, double expected_spread) {
            RcsTermOptions options;
            options.likelihood = RcsLikelihoodFromString(likelihood);
            options.expected_spread_db = expected_spread;
            return RcsWeightFromMap(SummariseRcs(m.map(), options));
          },
          py::arg("likelihood") = "decibel", py::arg("expected_spread") = 0.0,
          "eq. 2's w_rcs chosen from the map's RCS fits (localize --w-rcs-from-map; docs/design.md)");
}

MapOptions BuildOptions(const std::string& builder, double points_per_gaussian, double min_std,
                        const std::string& incidence, int max_degree, bool doppler_filter) {
  MapOptions options;
  options.gaussians.builder = MapBuilderFromString(builder);
  options.gaussians.points_per_gaussian = points_per_gaussian;
  options.gaussians.min_std = min_std;
  options.rcs.incidence = IncidenceModelFromString(incidence);
  options.rcs.max_degree = max_degree;
  options.cloud.doppler_filter = doppler_filter;
  return options;
}

}  // namespace

void BindMap(py::module_& m) {
  BindMapClass(m);
  const MapOptions defaults;
  m.def(
      "build_map",
      [](const py::object& scans_or_sequence, const py::object& poses, const std::string& builder,
         double points_per_gaussian, double min_std, const std::string& incidence, int max_degree,
         bool doppler_filter) {
        const MapOptions options =
            BuildOptions(builder, points_per_gaussian, min_std, incidence, max_degree, doppler_filter);
        if (py::isinstance<Sequence>(scans_or_sequence)) {
          const Sequence& sequence = scans_or_sequence.cast<const Sequence&>();
          py::gil_scoped_release release;
          return std::make_shared<PyMap>(BuildMap(sequence, options));
        }
        const std::vector<RadarScan> scans = scans_or_sequence.cast<std::vector<RadarScan>>();
        const py::sequence pose_list = poses.cast<py::sequence>();
        if (pose_list.size() != scans.size()) throw py::value_error("build_map needs one pose per scan");
        std::vector<SE3d> world_poses;
        for (std::size_t i = 0; i < scans.size(); ++i) {
          world_poses.push_back(PoseFromPython(pose_list[i], "poses[" + std::to_string(i) + "]"));
        }
        py::gil_scoped_release release;
        return std::make_shared<PyMap>(BuildMap(scans, world_poses, options));
      },
      py::arg("scans"), py::arg("poses") = py::none(), py::arg("builder") = "kmeans",
      py::arg("points_per_gaussian") = defaults.gaussians.points_per_gaussian,
      py::arg("min_std") = defaults.gaussians.min_std, py::arg("incidence") = "offset",
      py::arg("max_degree") = defaults.rcs.max_degree, py::arg("doppler_filter") = true,
      "The map of `radargauss build-map`: from a Sequence with poses, or from a list of Scans and their poses "
      "T_world_radar (4x4 or [x y z qx qy qz qw]). builder: kmeans or voxel; incidence: offset, view or none.");
  m.def(
      "read_map", [](const std::string& path) { return std::make_shared<PyMap>(ReadMapOrTiles(path)); },
      py::arg("path"), "Reads a .rgm map file (validated: docs/design/formats.md, \"Bounds on input\").");
  m.def(
      "write_map", [](const std::string& path, const PyMap& map) { WriteMap(path, map.map()); }, py::arg("path"),
      py::arg("map"), "Writes a .rgm map file atomically.");
}

}  // namespace radargauss::python
