// SPDX-License-Identifier: BSD-3-Clause
// The scenario's contact-force formulation (contact_force_formulation.hpp), made by its
// registry entry (formulation_registry.hpp).
#include "outer_nlp/contact_force_formulation.hpp"

#include "outer_nlp/formulation_registry.hpp"

namespace mcopt {

std::unique_ptr<ContactForceFormulation> makeForceSplinesFormulation(const FormulationContext& context);  // force_variables_formulation.cpp

std::unique_ptr<ContactForceFormulation> makeContactForceFormulation(const FormulationContext& context) {
  // With the reference contact alone the wrench is W0 whatever the formulation (§5): the
  // single-level formulation without variables.
  if (context.scenario.contacts.empty()) return makeForceSplinesFormulation(context);
  return contactForceFormulation(context.scenario.contactForces).make(context);
}

}  // namespace mcopt
