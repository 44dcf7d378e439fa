// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The Python module `mcopt` (docs/reference/python.md): one bind function per family, and the
// conversions they share. Values cross as numpy arrays (float64, C order) and dicts; every
// array argument is checked for its shape and element type before it reaches C++, so a
// wrong array is a Python exception naming the argument, never a crash.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>

namespace mcopt::python {

namespace py = pybind11;

void bindRobot(py::module_& m);
void bindDynamics(py::module_& m);
void bindInner(py::module_& m);
void bindScenario(py::module_& m);

/// Held by whatever runs Ipopt from Python (Scenario.run, InnerSolver("ipopt").solve), taken
/// with the GIL released: Ipopt 3.11's MUMPS is not thread-safe, and with the GIL released two
/// Python threads could otherwise run it at once (inner_qp/ipopt_solver.cpp serialises the
/// inner solves among themselves only).
std::mutex& ipoptMutex();

/// A JSON value as Python: objects → dict, lists of numbers → 1-D numpy arrays, lists of
/// equally long lists of numbers → 2-D arrays, other lists → lists, null → None.
py::object toPython(const nlohmann::json& value);
py::object toPython(const nlohmann::ordered_json& value);

/// A float64 array of `value`'s data: any sequence of numbers numpy can read. Throws
/// ValueError "<name>: expected …" when it is not numeric or not finite.
py::array_t<double, py::array::c_style> numericArray(const py::handle& value, const std::string& name);

/// A vector of exactly `size` numbers (a 1-D array, or a list).
Eigen::VectorXd vectorArgument(const py::handle& value, const std::string& name, Eigen::Index size);

/// A rows × cols matrix (rows or cols < 0: any).
Eigen::MatrixXd matrixArgument(const py::handle& value, const std::string& name, Eigen::Index rows, Eigen::Index cols);

/// States as a matrix with one row per state: a (n,) array is one state, (N, n) N states.
/// `batch` tells which one was given, so that results come back in the same shape.
Eigen::MatrixXd statesArgument(const py::handle& value, const std::string& name, Eigen::Index n, bool& batch);

py::array_t<double> matrixToNumpy(const Eigen::Ref<const Eigen::MatrixXd>& m);  ///< 2-D
py::array_t<double> vectorToNumpy(const Eigen::Ref<const Eigen::VectorXd>& v);  ///< 1-D

}  // namespace mcopt::python
