// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/formulation_registry.hpp"

#include "core/errors.hpp"
#include "core/registry.hpp"

namespace mcopt {

// The factories, each in its formulation's file.
std::unique_ptr<ContactForceFormulation> makeBilevelFormulation(const FormulationContext& context);      // bilevel_formulation.cpp
std::unique_ptr<ContactForceFormulation> makeForceSplinesFormulation(const FormulationContext& context);  // force_variables_formulation.cpp
std::unique_ptr<ContactForceFormulation> makePerSampleForcesFormulation(const FormulationContext& context);  // force_variables_formulation.cpp

const std::vector<ContactForceFormulationEntry>& contactForceFormulations() {
  static const std::vector<ContactForceFormulationEntry> registry = {
      {"bilevel", "an inner problem per sample picks the wrenches; exact gradients through its KKT system", true, false,
       "inner problem", makeBilevelFormulation},
      {"splines", "each wrench component of a non-reference contact is a B-spline of NLP variables", false, false,
       "splines", makeForceSplinesFormulation},
      {"variables", "each wrench of a non-reference contact at each sample is an NLP variable", false, true,
       "linear interpolation", makePerSampleForcesFormulation},
  };
  return registry;
}

const std::vector<std::string>& contactForcesNames() {
  static const std::vector<std::string> names = registryNames(contactForceFormulations());
  return names;
}

const ContactForceFormulationEntry& contactForceFormulation(const std::string& name) {
  if (const ContactForceFormulationEntry* e = findInRegistry(contactForceFormulations(), name)) return *e;
  throw InputError("unknown contact-force formulation '" + name + "' (expected " + alternatives(contactForcesNames()) + ")");
}

}  // namespace mcopt
