// SPDX-License-Identifier: BSD-3-Clause
// numpy arrays in and out of the Python module, checked: a wrong shape,
// dtype or a non-finite value is a ValueError naming the argument.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss::python {

namespace py = pybind11;
using Array = py::array_t<double, py::array::c_style>;

// `value` as a C-contiguous float64 array of `shape` (-1: any length);
// float32 is widened, any other dtype refused.
Array CheckedArray(const py::handle& value, const std::vector<py::ssize_t>& shape, const std::string& name);
// A new float64 array of `shape` (row-major).
Array NewArray(const std::vector<py::ssize_t>& shape);

// T_world_frame from a 4x4 matrix whose rotation block is orthonormal with
// determinant 1 (to 1e-6), or from a TUM 7-vector [x y z qx qy qz qw].
SE3d PoseFromPython(const py::handle& value, const std::string& name);
Array PoseToMatrix(const SE3d& pose);
Array PoseToTum(const SE3d& pose);  // [x y z qx qy qz qw], exactly the stored numbers

// A scan from an (N, 3) position array and optional (N,) Doppler and RCS.
RadarScan ScanFromArrays(const py::handle& points, const py::object& doppler, const py::object& rcs, double stamp);

template <int Rows, int Cols>
Array MatrixToArray(const Eigen::Matrix<double, Rows, Cols>& m) {
  Array out = NewArray({Rows, Cols});
  auto view = out.mutable_unchecked<2>();
  for (int r = 0; r < Rows; ++r) {
    for (int c = 0; c < Cols; ++c) view(r, c) = m(r, c);
  }
  return out;
}

}  // namespace radargauss::python
