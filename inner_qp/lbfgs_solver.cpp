// SPDX-License-Identifier: BSD-3-Clause
// NLopt's augmented Lagrangian with L-BFGS (limited-memory quasi-Newton) on its subproblems:
// every constraint — the balance, the rows and the cones — goes into the augmented
// Lagrangian, whose subproblems are unconstrained.
#include <nlopt.h>

#include "inner_qp/nlopt_problem.hpp"

namespace mcopt {

std::unique_ptr<InnerSolver> makeAugLagLbfgsSolver(const InnerSettings& settings) {
  inner_detail::NloptMethod method;
  method.algorithm = NLOPT_AUGLAG;
  method.local = NLOPT_LD_LBFGS;
  method.scaled = true;
  method.xtolRel = 1e-12;
  method.ftolRel = 1e-15;
  method.localXtolRel = 1e-12;
  method.localFtolRel = 1e-14;
  method.evaluationsPerIteration = 20;
  return inner_detail::makeNloptSolver("auglag-lbfgs", method, settings);
}

}  // namespace mcopt
