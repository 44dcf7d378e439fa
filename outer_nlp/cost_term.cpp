// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/cost_term.hpp"

#include "outer_nlp/scenario.hpp"

namespace mcopt {

// The registry: the energy in the scenario's form, then the regularisation. A sample's
// integrand sums them in this order.
CostTerms makeCostTerms(const CostContext& context) {
  CostTerms terms;
  terms.push_back(context.scenario.energyForm == EnergyForm::Epigraph ? makeEpigraphEnergy(context)
                                                                       : makeSmoothMaximumEnergy(context));
  terms.push_back(makeAccelerationRegularisation(context));
  return terms;
}

}  // namespace mcopt
