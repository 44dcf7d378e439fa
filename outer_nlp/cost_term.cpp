// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/cost_term.hpp"

#include "outer_nlp/scenario.hpp"

namespace mcopt {

// The registry: the energy in the scenario's form, then the regularisation. A sample's
// integrand sums them in this order.
CostTerms makeCostTerms(const CostContext& context) {
  CostTerms terms;
  CostContext next = context;
  const auto add = [&](std::unique_ptr<const CostTerm> term) {
    next.firstVariable += term->variablesPerSample() * next.samples.sampleCount();
    terms.push_back(std::move(term));
  };
  add(context.scenario.energyForm == EnergyForm::Epigraph ? makeEpigraphEnergy(next) : makeSmoothMaximumEnergy(next));
  add(makeAccelerationRegularisation(next));
  return terms;
}

}  // namespace mcopt
