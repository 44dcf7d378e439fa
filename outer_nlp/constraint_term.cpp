// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/constraint_term.hpp"

namespace mcopt {

// The registry. Within a sample the rows follow this order; control-point rows come before
// every sample's, task instants' after.
ConstraintTerms makeConstraintTerms(const TermContext& context) {
  ConstraintTerms terms;
  terms.push_back(makeVelocityLimitTerm(context));
  terms.push_back(makeTorqueLimitTerm(context));
  terms.push_back(makeContactAdmissibilityTerm(context));
  terms.push_back(makeInnerFeasibilityTerm(context));
  terms.push_back(makeClosingJointLimitTerm(context));
  terms.push_back(makeLoopReachTerm(context));
  terms.push_back(makeEnergyEpigraphTerm(context));
  terms.push_back(makeTaskTerm(context));
  return terms;
}

}  // namespace mcopt
