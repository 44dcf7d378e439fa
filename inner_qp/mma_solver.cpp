// SPDX-License-Identifier: BSD-3-Clause
// NLopt's augmented Lagrangian with Svanberg's MMA (method of moving asymptotes, the
// globally convergent CCSA form) on its subproblems. Every constraint — the balance, the rows
// and the cones — goes into the augmented Lagrangian, so MMA minimises without constraints:
// handing it the rows and cones directly (NLOPT_AUGLAG_EQ, the balance alone penalised) was
// measured and reaches no optimum on the baseline problems (docs/theory/inner-problem.md).
#include <nlopt.h>

#include "inner_qp/nlopt_problem.hpp"

namespace mcopt {

std::unique_ptr<InnerSolver> makeAugLagMmaSolver(const InnerSettings& settings) {
  inner_detail::NloptMethod method;
  method.algorithm = NLOPT_AUGLAG;
  method.local = NLOPT_LD_MMA;
  method.scaled = true;
  method.xtolRel = 1e-12;
  method.ftolRel = 1e-15;
  method.localXtolRel = 1e-12;
  method.localFtolRel = 1e-14;
  method.evaluationsPerIteration = 20;
  return inner_detail::makeNloptSolver("auglag-mma", method, settings);
}

}  // namespace mcopt
