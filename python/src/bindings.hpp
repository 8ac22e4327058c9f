// SPDX-License-Identifier: BSD-3-Clause
// The parts of the Python module (module.cpp puts them together).
#pragma once

#include <memory>

#include "convert.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/matching_map.hpp"
#include "radargauss/trajectory.hpp"

namespace radargauss::python {

// A map as Python holds it: the Gaussians and, built on first use, the
// coarse-to-fine MatchingMap that `match` needs (as `radargauss localize` builds it).
class PyMap {
 public:
  explicit PyMap(GaussianMap map) : map_(std::make_shared<const GaussianMap>(std::move(map))) {}
  const GaussianMap& map() const { return *map_; }
  const MatchingMap& matching() const;

 private:
  std::shared_ptr<const GaussianMap> map_;
  mutable std::shared_ptr<const MatchingMap> matching_;
};

// (stamps (N,), poses (N, 7)) and back; poses may also be (N, 4, 4).
py::tuple TrajectoryToArrays(const Trajectory& trajectory);
Trajectory TrajectoryFromArrays(const py::handle& stamps, const py::handle& poses, const std::string& name);

void BindData(py::module_& m);
void BindMap(py::module_& m);
void BindMatch(py::module_& m);
void BindOdometry(py::module_& m);
void BindSlam(py::module_& m);

}  // namespace radargauss::python
