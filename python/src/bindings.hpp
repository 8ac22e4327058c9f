// SPDX-License-Identifier: BSD-3-Clause
// The parts of the Python module (module.cpp puts them together).
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "convert.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/matching_map.hpp"
#include "radargauss/core/trajectory.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"

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

// An object with mutable state that Python threads may share (RadarOdometry,
// RadarSlam, Relocalizer): every call runs under the object's own lock, taken
// with the GIL released, so a thread waiting for the lock never holds the GIL
// that the running call needs back. Calls on one object are serialised.
template <typename T>
class Locked {
 public:
  explicit Locked(std::unique_ptr<T> object) : object_(std::move(object)) {}

  // fn(object) under the lock without the GIL: fn touches no Python object
  // and returns its result by value (a copy of any reference into the object).
  template <typename Fn>
  auto With(Fn&& fn) {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(mutex_);
    return fn(*object_);
  }

 private:
  std::unique_ptr<T> object_;
  std::mutex mutex_;
};

// (stamps (N,), poses (N, 7)) and back; poses may also be (N, 4, 4).
py::tuple TrajectoryToArrays(const Trajectory& trajectory);
Trajectory TrajectoryFromArrays(const py::handle& stamps, const py::handle& poses, const std::string& name);

// The odometry's keywords (ValueError for a bad one); an (N, 7) IMU array
// [stamp wx wy wz ax ay az]; an inertial state as a dict (None before the
// window started); keywords split between the odometry's table and the window's.
OdometryOptions OdometryOptionsFrom(const py::kwargs& kwargs);
std::vector<ImuSample> ImuFromArray(const py::handle& value);
py::object StateToDict(const std::optional<InertialState>& state);
std::pair<OdometryOptions, RadarInertialOptions> InertialOptionsFrom(const py::kwargs& kwargs);

void BindData(py::module_& m);
void BindRig(py::module_& m);  // read_rig, estimate_rig_twist
void BindMap(py::module_& m);
void BindMatch(py::module_& m);
void BindOdometry(py::module_& m);
void BindSlam(py::module_& m);

}  // namespace radargauss::python
