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
  return inner_detail::makeNloptSolver("auglag-mma", inner_detail::augmentedLagrangian(NLOPT_LD_MMA), settings);
}

}  // namespace mcopt
