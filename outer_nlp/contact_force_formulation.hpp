// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// How the motion problem chooses the environment contacts' wrenches at each sample
// (formulation.md §9): one interface, one implementation per formulation, the motion problem
// asking it and never which formulation it is.
//   bilevel              an inner problem per sample over the contacts active there picks them
//                        (bilevel_formulation.cpp; sensitivity/bilevel_sample.hpp): exact
//                        derivatives through its KKT system; the contacts' own rows are the
//                        inner problem's, and the outer problem bounds its infeasibility;
//   splines, variables   they are linear in NLP variables z (force_variables_formulation.cpp,
//                        contact_force_parametrization.hpp); the reference contact's wrench
//                        follows from the balance, W_ref = W0 − Σ_i wrenchToWorld_i F_i, and
//                        every contact's admissibility rows are outer rows.
// With the reference contact alone every formulation is the one-contact problem: W_ref = W0
// (force_variables_formulation.cpp without variables).
// A formulation is built once per problem from its layout (FormulationContext) and takes part
// in every sample's evaluation (sampleOutputs), in the order of the loop over the samples
// (core/sample_chunks.hpp).

#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

#include "core/dynamics_model.hpp"
#include "core/robot_files.hpp"
#include "inner_qp/inner_solver.hpp"
#include "outer_nlp/contact_admissibility.hpp"
#include "outer_nlp/contact_force_parametrization.hpp"
#include "outer_nlp/sample_outputs.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

struct MotionWorkspace;  // outer_nlp/motion_workspace.hpp

/// What a formulation is built from: the motion problem's layout, fixed before it.
struct FormulationContext {
  const Scenario& scenario;
  const SampleOutputs& outputs;
  const ContactAdmissibilityRows& support;                   ///< the reference contact's rows
  const std::vector<ContactAdmissibilityRows>& contactRows;  ///< per environment contact, on its own wrench
  const std::vector<std::array<double, 2>>& windows;         ///< per environment contact, normalised
  const std::vector<double>& sampleTimes;                    ///< normalised, per sample
  const std::vector<std::vector<bool>>& active;              ///< per environment contact and sample
  int firstVariable = 0;                                     ///< index in x of its first variable
  double weight = 0.0;                                       ///< m g [N]
  std::vector<const DynamicsModel*> sampleModels;            ///< per sample: the robot (with the ball while carried)
  std::vector<std::vector<ContactSurface>> sampleSurfaces;   ///< per sample: the reference surface, then the active contacts'
};

/// One sample's evaluation, as a formulation takes part in it: the state in w.q, w.v, w.a and
/// its inverse dynamics in w.data (with derivatives: in w.derivatives) are computed; the
/// formulation writes Γ into w.torque and, into the outputs below, each contact's wrench, the
/// rows it owns and (with derivatives) Γ's and those rows' derivatives in the state and in the
/// sample's force columns.
struct FormulationSample {
  int sample = 0;
  const DynamicsModel& model;
  MotionWorkspace& w;
  const Eigen::VectorXd& x;
  bool derivatives = false;
  const std::vector<LocalForceTerm>& forceTerms;  ///< the sample's force columns (its own block's layout)
  Eigen::VectorXd& y;                             ///< outputs (SampleOutputs order)
  Eigen::VectorXd& wrenches;                      ///< 6 (1 + contacts), zero where inactive on entry
  Eigen::MatrixXd &dyDq, &dyDv, &dyDa, &dyDz;
};

class ContactForceFormulation {
 public:
  virtual ~ContactForceFormulation() = default;

  /// The NLP variables it adds (z), from FormulationContext::firstVariable on.
  virtual int variableCount() const { return 0; }
  /// Their bounds, in the whole x's bounds (a force alone fixes its contact's moment variables at zero).
  virtual void variableBounds(Eigen::Ref<Eigen::VectorXd> lower, Eigen::Ref<Eigen::VectorXd> upper) const {
    (void)lower, (void)upper;
  }
  /// The size of one unit of each of its variables for the outer solver, in the whole x's
  /// units (ones on entry; NlpProblem::variableUnits).
  virtual void variableUnits(Eigen::Ref<Eigen::VectorXd> units) const { (void)units; }
  /// Sample s's force columns: the terms (contact, weight, first local column; six columns
  /// each) and each local column's variable.
  virtual void layOutForceColumns(int s, std::vector<LocalForceTerm>& terms, std::vector<int>& columns) const {
    (void)s, (void)terms, (void)columns;
  }
  /// Whether an inner problem picks the wrenches: then every output depends on the whole state
  /// (the Jacobian's sparsity), the contacts' own rows are the inner problem's and the outer
  /// problem bounds its infeasibility (contact_terms.cpp).
  virtual bool innerProblem() const { return false; }
  /// Before sample s's evaluation: `predecessor` is the sample the same thread evaluated just
  /// before it in its chunk, or −1 (core/sample_chunks.hpp).
  virtual void beforeSample(int s, int predecessor) { (void)s, (void)predecessor; }
  /// Γ, the wrenches, the rows it owns and their derivatives (FormulationSample).
  virtual void sampleOutputs(FormulationSample& sample) = 0;
  /// Whether a sample keeps state from its last evaluation (an inner answer, its warm start and
  /// reported status): the Hessian's probes then evaluate the sample again at its own point.
  virtual bool keepsSampleState() const { return false; }
  /// The inner problem's last answer at sample s; null without an inner problem.
  virtual const InnerResult* innerResult(int s) const {
    (void)s;
    return nullptr;
  }
  /// Its variables fitted to given wrenches (per environment contact, 6 × samples; columns
  /// where the contact is inactive ignored), into z (variableCount() entries).
  virtual void fit(const std::vector<Eigen::MatrixXd>& wrenches, Eigen::Ref<Eigen::VectorXd> z) const {
    (void)wrenches, (void)z;
  }
  /// Whether its variables mean the same on another grid of samples (force splines: their
  /// windows and control points do not depend on it), so that a point can carry them over.
  virtual bool variablesIndependentOfGrid() const { return false; }
};

/// The scenario's formulation (its `contact_forces`; with no environment contact, the
/// reference contact alone).
std::unique_ptr<ContactForceFormulation> makeContactForceFormulation(const FormulationContext& context);

}  // namespace mcopt
