// SPDX-License-Identifier: BSD-3-Clause
// NLopt SLSQP on the inner problem (formulation.md §7): sequential quadratic programming on
// the balance equalities and every inequality at once, the report's FSQP analogue.
#include <nlopt.h>

#include "inner_qp/nlopt_problem.hpp"

namespace mcopt {

std::unique_ptr<InnerSolver> makeSlsqpSolver(const InnerSettings& settings) {
  return inner_detail::makeNloptSolver("slsqp", {NLOPT_LD_SLSQP}, settings);
}

}  // namespace mcopt
