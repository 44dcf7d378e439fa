// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Ipopt as the outer solver (outer_solver.hpp): exact first derivatives, the declared sparse
// Jacobian, a limited-memory Hessian unless the settings say otherwise, the scenario's options
// on top of ours (docs/reference/scenario-file.md, "Ipopt options we set"). Registered as
// "ipopt" in outer_solver.cpp.

#include <memory>

#include "outer_nlp/outer_solver.hpp"

namespace mcopt {

std::unique_ptr<OuterSolver> makeIpoptSolver();

}  // namespace mcopt
