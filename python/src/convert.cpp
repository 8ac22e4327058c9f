// SPDX-License-Identifier: BSD-3-Clause
#include "convert.hpp"

#include <cmath>
#include <sstream>

namespace radargauss::python {

namespace {

std::string ShapeText(const py::array& array) {
  std::ostringstream text;
  text << "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) text << (i ? ", " : "") << array.shape(i);
  text << (array.ndim() == 1 ? ",)" : ")");
  return text.str();
}

std::string ShapeText(const std::vector<py::ssize_t>& shape) {
  std::ostringstream text;
  text << "(";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    text << (i ? ", " : "") << (shape[i] < 0 ? std::string("N") : std::to_string(shape[i]));
  }
  text << (shape.size() == 1 ? ",)" : ")");
  return text.str();
}

}  // namespace

Array CheckedArray(const py::handle& value, const std::vector<py::ssize_t>& shape, const std::string& name) {
  py::array array;
  if (py::isinstance<py::array>(value)) {
    array = py::reinterpret_borrow<py::array>(value);
    const char kind = array.dtype().kind();
    if (kind != 'f' || (array.itemsize() != 4 && array.itemsize() != 8)) {
      throw py::value_error(name + " must be float64 (or float32), not " + std::string(py::str(array.dtype())));
    }
  } else if (py::isinstance<py::sequence>(value) && !py::isinstance<py::str>(value)) {
    try {  // a list of numbers
      array = Array(py::reinterpret_borrow<py::object>(value));
    } catch (const py::error_already_set& e) {
      if (e.matches(PyExc_MemoryError)) throw;
      throw py::value_error(name + " must be numbers of shape " + ShapeText(shape));
    }
  } else {
    throw py::value_error(name + " must be an array of shape " + ShapeText(shape));
  }
  bool shape_ok = array.ndim() == py::ssize_t(shape.size());
  for (std::size_t i = 0; shape_ok && i < shape.size(); ++i) {
    shape_ok = shape[i] < 0 || array.shape(py::ssize_t(i)) == shape[i];
  }
  if (!shape_ok) {
    throw py::value_error(name + " must have shape " + ShapeText(shape) + ", not " + ShapeText(array));
  }
  // The converting constructor raises numpy's error (MemoryError for a copy
  // too large); ensure() would clear it and return no array.
  const Array converted(array);
  const double* data = converted.data();
  for (py::ssize_t i = 0; i < converted.size(); ++i) {
    if (!std::isfinite(data[i])) throw py::value_error(name + " holds a value that is not finite");
  }
  return converted;
}

Array NewArray(const std::vector<py::ssize_t>& shape) { return Array(shape); }

SE3d PoseFromPython(const py::handle& value, const std::string& name) {
  const py::array array = py::array::ensure(value);
  if (array && array.ndim() == 1 && array.shape(0) == 7) {
    const Array tum = CheckedArray(value, {7}, name);
    const double* p = tum.data();
    const double norm = std::sqrt(p[3] * p[3] + p[4] * p[4] + p[5] * p[5] + p[6] * p[6]);
    if (std::abs(norm - 1.0) > 1e-6) throw py::value_error(name + ": the quaternion is not of unit length");
    return SE3d(SO3d::FromXyzw(p + 3), Eigen::Vector3d(p[0], p[1], p[2]));
  }
  const Array matrix = CheckedArray(value, {4, 4}, name + " (a 4x4 matrix or [x y z qx qy qz qw])");
  const auto m = matrix.unchecked<2>();
  Eigen::Matrix3d rotation;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) rotation(r, c) = m(r, c);
  }
  const bool last_row = m(3, 0) == 0.0 && m(3, 1) == 0.0 && m(3, 2) == 0.0 && m(3, 3) == 1.0;
  if (!last_row || (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      rotation.determinant() < 0.0) {
    throw py::value_error(name + " is not a rigid transform (orthonormal rotation, last row 0 0 0 1)");
  }
  return SE3d(SO3d::FromMatrix(rotation), Eigen::Vector3d(m(0, 3), m(1, 3), m(2, 3)));
}

Array PoseToMatrix(const SE3d& pose) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = pose.rotation().Matrix();
  m.topRightCorner<3, 1>() = pose.translation();
  return MatrixToArray<4, 4>(m);
}

Array PoseToTum(const SE3d& pose) {
  Array out = NewArray({7});
  double* p = out.mutable_data();
  const Eigen::Quaterniond& q = pose.rotation().quaternion();
  const Eigen::Vector3d& t = pose.translation();
  const double values[7] = {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
  std::copy(values, values + 7, p);
  return out;
}

RadarScan ScanFromArrays(const py::handle& points, const py::object& doppler, const py::object& rcs, double stamp) {
  if (!std::isfinite(stamp)) throw py::value_error("stamp must be finite");
  const Array xyz = CheckedArray(points, {-1, 3}, "points");
  const py::ssize_t n = xyz.shape(0);
  RadarScan scan;
  scan.timestamp = stamp;
  scan.points.resize(std::size_t(n));
  const auto p = xyz.unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) scan.points[std::size_t(i)].position = Eigen::Vector3d(p(i, 0), p(i, 1), p(i, 2));
  if (!doppler.is_none()) {
    const Array values = CheckedArray(doppler, {n}, "doppler");
    for (py::ssize_t i = 0; i < n; ++i) scan.points[std::size_t(i)].doppler = values.at(i);
    scan.has_doppler = true;
  }
  if (!rcs.is_none()) {
    const Array values = CheckedArray(rcs, {n}, "rcs");
    for (py::ssize_t i = 0; i < n; ++i) scan.points[std::size_t(i)].rcs = values.at(i);
    scan.has_rcs = true;
  }
  return scan;
}

}  // namespace radargauss::python
