// SPDX-License-Identifier: BSD-3-Clause
// The contact-force formulations by the scenario's `contact_forces` (contact_force_formulation.hpp).
#include "outer_nlp/contact_force_formulation.hpp"

namespace mcopt {

std::unique_ptr<ContactForceFormulation> makeBilevelFormulation(const FormulationContext& context);         // bilevel_formulation.cpp
std::unique_ptr<ContactForceFormulation> makeForceVariablesFormulation(const FormulationContext& context);  // force_variables_formulation.cpp

std::unique_ptr<ContactForceFormulation> makeContactForceFormulation(const FormulationContext& context) {
  // With the reference contact alone the wrench is W0 whatever the formulation (§5).
  if (!context.scenario.contacts.empty() && context.scenario.contactForces == ContactForces::Bilevel)
    return makeBilevelFormulation(context);
  return makeForceVariablesFormulation(context);
}

}  // namespace mcopt
