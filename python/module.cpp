// SPDX-License-Identifier: BSD-3-Clause
// The Python module `mcopt` (docs/reference/python.md): robot models, dynamics and their derivatives,
// the inner contact-force problem with its solvers and sensitivity, and scenarios run with
// a progress callback. The command line's readers and writers are shared (apps/), so the
// module returns what the CLI writes and refuses what it refuses, with the same messages.
#include "core/errors.hpp"
#include "core/version.hpp"
#include "python/bindings.hpp"

PYBIND11_MODULE(mcopt, m) {
  namespace py = pybind11;
  m.doc() = R"doc(mcopt: whole-body motion optimisation for humanoid robots in multi-contact.

Robot (URDF + side files) → Dynamics (Newton–Euler with a fixed reference body, exact
derivatives) → InnerProblem / InnerSolver / InnerResult (contact wrenches of one sample,
their sensitivity) → Scenario (a whole motion optimisation, as `mcopt run`). Arrays are
numpy float64; joint arrays are in the robot's URDF joint order. Bad input raises
mcopt.InputError (a ValueError) with the command line's message.)doc";
  m.attr("__version__") = mcopt::kVersion;
  py::register_exception<mcopt::InputError>(m, "InputError", PyExc_ValueError);
  mcopt::python::bindRobot(m);
  mcopt::python::bindDynamics(m);
  mcopt::python::bindInner(m);
  mcopt::python::bindScenario(m);
}
