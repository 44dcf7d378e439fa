// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Exact gradients of a multi-contact motion (the report's Figure 5.2 "gradient", formulation.md
// §8): for every sample the inner problem is solved, its KKT system factorised once, and the
// derivatives of the optimal wrenches with respect to the sample's state (q, q̇, q̈: 3n
// right-hand sides) solved from it; then
//     dΓ/dx = dΓ0/dx − (∂J1/∂x) F − J1 dF/dx                                    (4.8)
// and the chain rule through the splines' local support gives every sampled torque's and
// the energy's gradient with respect to the motion parameters and the duration.
//
// The right-hand sides, at fixed F and multipliers (∇_F L = −J1ᵀ g + ε F + Bᵀ λ + rows,
// g = 2 w∘Γ + l, Γ = Γ0 − J1 F):
//   ∂(∇_F L)/∂q = −∂(J1ᵀ g)/∂q|_g − J1ᵀ 2 diag(w) (∂Γ0/∂q − ∂(J1 F)/∂q) + ∂(Bᵀ λ)/∂q
//   ∂(∇_F L)/∂q̇ = −J1ᵀ (2 diag(w) ∂Γ0/∂q̇ + diag(∂l/∂q̇)),  the same for q̈
//   ∂(B F − W0)/∂x = ∂(B F)/∂q (q only) − ∂W0/∂x
// Samples whose inner result is not optimal have no derivative: their dF is left at zero
// and they are counted; degenerate samples (weakly active constraints, near-singular KKT)
// are counted too (SensitivityDiagnostics). Each sample is a BilevelSample
// (bilevel_sample.hpp, which the outer problem uses too), warm-started from its own previous
// result, or on the first evaluation from its predecessor in its chunk (core/sample_chunks.hpp):
// the results do not depend on the thread count.

#include <memory>
#include <vector>

#include "core/trajectory_gradient.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"
#include "sensitivity/bilevel_sample.hpp"
#include "sensitivity/inner_sensitivity.hpp"

namespace mcopt {

class SparseKktFactor;

struct SampleWrenchJacobian {
  Eigen::VectorXi parameters;  ///< global parameter index of each column
  /// Rows: the inner problem's wrench variables (ContactProblem::contactColumn; 6nc when every
  /// contact has six components, three for a force alone).
  Eigen::MatrixXd dFdx;        ///< variables × (jointCount · k)
  Eigen::VectorXd dFdT;        ///< variables
};

struct MultiContactGradient {
  TrajectoryGradient torqueAndEnergy;          ///< ∂E/∂x, ∂E/∂T and per-sample ∂Γ/∂x, ∂Γ/∂T with the inner wrenches
  std::vector<SampleWrenchJacobian> wrenches;  ///< per sample, dF/dx and dF/dT
  std::vector<SensitivityDiagnostics> diagnostics;  ///< per sample (default-constructed where there is no derivative)
  int degenerateSamples = 0;                   ///< one-sided derivatives (see SensitivityDiagnostics)
  int samplesWithoutDerivative = 0;            ///< inner result not optimal: dF taken as zero
};

class MultiContactGradientEvaluator {
 public:
  MultiContactGradientEvaluator(const DynamicsModel& model, ActuatorSet actuators, SampledTrajectory samples,
                                std::vector<ContactSurface> contacts, MultiContactSettings settings = {},
                                SensitivitySettings sensitivity = {});
  ~MultiContactGradientEvaluator();

  void evaluate(const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration, MultiContactResult& result,
                MultiContactGradient& gradient);

 private:
  struct Workspace;
  /// Pass 1: dynamics and the sample's inner solve, KKT factorisation and (per-sample
  /// layout) dF.
  void prepareSample(Workspace& w, int sample, double duration, MultiContactResult& r, MultiContactGradient& g);
  /// Pass 3: the chain rule through the splines, the energy.
  void finishSample(Workspace& w, int sample, double duration, MultiContactResult& r, MultiContactGradient& g,
                    ChunkedEnergyGradient::Sum& sum);
  /// Pass 2 of the all-samples layout: one block-diagonal sparse factorisation and solve.
  void solveAllSamples();

  const DynamicsModel& model_;
  ActuatorSet actuators_;
  SampledTrajectory samples_;
  std::vector<ContactSurface> contacts_;
  MultiContactSettings settings_;
  SensitivitySettings sensitivitySettings_;
  Eigen::MatrixXd controlPoints_;
  std::vector<std::unique_ptr<Workspace>> workspaces_;
  ChunkedEnergyGradient chunkSums_;
  std::vector<BilevelSample> bilevel_;  ///< one per sample
  std::unique_ptr<SparseKktFactor> allSamplesFactor_;  ///< KktLayout::AllSamples
  bool sized_ = false;  ///< an evaluation has run: every sample's buffers are sized (NoMallocScope)
};

}  // namespace mcopt
