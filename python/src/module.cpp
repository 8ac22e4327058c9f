// SPDX-License-Identifier: BSD-3-Clause
// radargauss for Python (docs/python.md): the front door's jobs with numpy
// arrays in and out. Errors keep the library's one-line messages: bad input
// data raises radargauss.DataError (a ValueError), bad arguments ValueError.
#include <tbb/global_control.h>

#include <memory>

#include "bindings.hpp"
#include "radargauss/core/error.hpp"

namespace {

// The thread limit set_threads holds (none: every core), as --threads does.
std::unique_ptr<tbb::global_control> thread_limit;

}  // namespace

PYBIND11_MODULE(_radargauss, m) {
  namespace py = pybind11;
  m.doc() = "radargauss: 4D radar Gaussian-RCS maps, scan matching and odometry";
  py::register_exception<radargauss::DataError>(m, "DataError", PyExc_ValueError);
  radargauss::python::BindData(m);
  radargauss::python::BindRig(m);
  radargauss::python::BindMap(m);
  radargauss::python::BindMatch(m);
  radargauss::python::BindOdometry(m);
  radargauss::python::BindSlam(m);
  m.def(
      "set_threads",
      [](int threads) {
        if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores)");
        thread_limit.reset();
        if (threads > 0) {
          thread_limit =
              std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        }
      },
      py::arg("threads"), "Worker threads of the parallel stages (0: all cores), as the tool's --threads.");
  m.add_object("_cleanup", py::capsule([] { thread_limit.reset(); }));
}
