// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The contact-force formulations by name (a scenario's `contact_forces`, `mcopt run
// --contact-forces`, formulation.md §9). A formulation is one file, its ContactForceFormulation
// (contact_force_formulation.hpp) with a factory, and one entry in this registry
// (formulation_registry.cpp): what the scenario's checks, the continuation and the energy
// balance need to know of it comes from the entry, never from its name.
#include <memory>
#include <string>
#include <vector>

namespace mcopt {

struct FormulationContext;        // outer_nlp/contact_force_formulation.hpp
class ContactForceFormulation;    // outer_nlp/contact_force_formulation.hpp

struct ContactForceFormulationEntry {
  std::string name;
  std::string description;  ///< one line, for help texts
  /// An inner problem per sample picks the wrenches (formulation.md §7): the outputs are an
  /// inner optimum's, which the exact Hessian's stencils do not reach (exactHessianRefusal).
  bool innerProblem = false;
  /// Its variables belong to one grid of samples (a wrench per sample): a continuation stage
  /// cannot change the samples, and a result does not carry them to another grid.
  bool variablesPerSample = false;
  /// How its wrenches are known between the samples, as the energy balance's fine grid reads
  /// them (energy_balance.hpp `wrenches_between_samples`).
  std::string betweenSamples;
  std::unique_ptr<ContactForceFormulation> (*make)(const FormulationContext&) = nullptr;
};

/// Every registered formulation, in the order documents list them (bilevel first: the default).
const std::vector<ContactForceFormulationEntry>& contactForceFormulations();
/// Their names, in that order (the choices of `mcopt run --contact-forces`).
const std::vector<std::string>& contactForcesNames();
/// The formulation of that name; throws InputError "unknown contact-force formulation 'x'
/// (expected bilevel, splines or variables)" otherwise.
const ContactForceFormulationEntry& contactForceFormulation(const std::string& name);

}  // namespace mcopt
