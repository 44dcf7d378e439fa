// SPDX-License-Identifier: BSD-3-Clause
// NLopt's augmented Lagrangian with L-BFGS (limited-memory quasi-Newton) on its subproblems:
// every constraint — the balance, the rows and the cones — goes into the augmented
// Lagrangian, whose subproblems are unconstrained.
#include <nlopt.h>

#include "inner_qp/nlopt_problem.hpp"

namespace mcopt {

std::unique_ptr<InnerSolver> makeAugLagLbfgsSolver(const InnerSettings& settings) {
  return inner_detail::makeNloptSolver("auglag-lbfgs", inner_detail::augmentedLagrangian(NLOPT_LD_LBFGS), settings);
}

}  // namespace mcopt
