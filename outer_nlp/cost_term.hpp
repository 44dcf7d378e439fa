// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The outer problem's objective as terms (formulation.md §6, §10; docs/theory/outer-problem.md,
// "Objective terms"): E = Σ_s c_s T Σ_terms integrand_s, c_s the trapezoid weight (a fraction of
// T). A cost term is one integrand — the electrical energy as a smooth maximum Σ_j σ(P_js), or
// as the epigraph's slacks Σ_j s_js, and the regularisation w Σ_j q̈_js² — as a const model: its
// value at a sample, its exact gradient in x and T, and its share of the sample Hessians (its
// slopes and curvatures in the sample's outputs, and its gradient and Hessian in the state it
// reads directly). The motion problem (motion_problem.hpp) sums them; the constraint rows are
// the constraint terms' (constraint_term.hpp).
//
// A new term is one file (a class deriving from CostTerm and its factory, declared below) and
// one line in makeCostTerms (cost_term.cpp), whose order is the order of the sums.

#include <Eigen/Core>
#include <memory>
#include <string_view>
#include <vector>

#include "core/bspline.hpp"
#include "outer_nlp/closed_chains.hpp"
#include "outer_nlp/sample_outputs.hpp"

namespace mcopt {

struct Scenario;

/// What a term's value and gradient read of an evaluation of the samples: nothing (x alone),
/// the outputs' values, or their derivatives too.
enum class CostNeeds : unsigned char { Nothing, Values, Derivatives };

/// What the cost terms read of the problem they belong to (references into the motion problem
/// that builds them; it outlives its terms).
struct CostContext {
  const Scenario& scenario;
  const SampleOutputs& outputs;
  const ClosedChains* closure;  ///< null without environment contacts
  const MotionParametrization& parametrization;
  const SampledTrajectory& samples;
  /// The first of the term's own variables (CostTerm::variablesPerSample), sample by sample:
  /// sample s's at firstVariable + s · variablesPerSample. makeCostTerms lays the terms' variables
  /// out one after the other, in the registry's order, after every other variable.
  int firstVariable;
};

/// One sample as a cost term sees it: its outputs and state, and (after an evaluation with
/// derivatives) the outputs' derivatives in its local spline parameters, T and force columns.
struct CostSample {
  int index;
  const Eigen::VectorXd& y;             ///< outputs, SampleOutputs order
  const Eigen::VectorXd& acceleration;  ///< q̈
  ClosureSet closed;                    ///< contacts closed here: their closing joints follow the closure
  const Eigen::MatrixXd& dyDx;
  const Eigen::VectorXd& dyDT;
  const Eigen::MatrixXd& dyDz;
  const Eigen::VectorXi& parameters;    ///< the global variable of each local spline parameter
  const std::vector<int>& forceColumns; ///< the global variable of each local force column
};

class CostTerm {
 public:
  virtual ~CostTerm() = default;
  virtual std::string_view name() const = 0;
  virtual CostNeeds needs() const = 0;
  /// Its integrand at a sample, added to `sum` (the caller weighs the sum by c_s T).
  virtual void addValue(const CostSample& sample, const Eigen::VectorXd& x, double& sum) const = 0;
  /// The gradient of weight · integrand (weight = c_s T) in x, added to `gradient`, and its
  /// derivative in T (the weight's included) to `dT`.
  virtual void addGradient(const CostSample& sample, const Eigen::VectorXd& x, double weight, double T,
                           Eigen::VectorXd& gradient, double& dT) const = 0;
  // The sample Hessians' share (motion_hessian.cpp), `weight` = c_s T times Ipopt's objective
  // factor. Terms that read the outputs give their slopes and (diagonal) curvatures in them;
  // terms that read the state (q, q̇, q̈) directly give their gradient and Hessian there.
  virtual void addOutputSlopes(const CostSample& /*sample*/, double /*weight*/, Eigen::Ref<Eigen::VectorXd> /*slopes*/) const {}
  virtual void addOutputCurvatures(const CostSample& /*sample*/, double /*weight*/,
                                   Eigen::Ref<Eigen::VectorXd> /*curvatures*/) const {}
  virtual void addStateGradient(const CostSample& /*sample*/, double /*weight*/, Eigen::Ref<Eigen::VectorXd> /*gradient*/) const {}
  /// Into the lower triangle of H (3n + force columns square).
  virtual void addStateHessian(const CostSample& /*sample*/, double /*weight*/, Eigen::Ref<Eigen::MatrixXd> /*H*/) const {}

  // Variables of its own (the epigraph's slacks, one per joint and sample), from
  // CostContext::firstVariable on; the problem is linear in them (after NlpProblem::
  // nonlinearVariableCount), so the sample Hessians never see them.
  virtual int variablesPerSample() const { return 0; }
  /// Their bounds, one sample's (variablesPerSample() entries each).
  virtual void sampleVariableBounds(Eigen::Ref<Eigen::VectorXd> /*lower*/, Eigen::Ref<Eigen::VectorXd> /*upper*/) const {}
  /// Their values at a point whose motion is evaluated: one sample's, from its outputs.
  virtual void startSampleVariables(const CostSample& /*sample*/, Eigen::Ref<Eigen::VectorXd> /*variables*/) const {}
};

using CostTerms = std::vector<std::unique_ptr<const CostTerm>>;

/// The registry: the scenario's energy form, then the regularisation (cost_term.cpp); each
/// term's own variables after the previous term's, from context.firstVariable on.
CostTerms makeCostTerms(const CostContext& context);

// The bundled terms.
std::unique_ptr<const CostTerm> makeSmoothMaximumEnergy(const CostContext& context);  // energy_costs.cpp
std::unique_ptr<const CostTerm> makeEpigraphEnergy(const CostContext& context);       // energy_costs.cpp
std::unique_ptr<const CostTerm> makeAccelerationRegularisation(const CostContext& context);  // acceleration_regularisation.cpp

}  // namespace mcopt
