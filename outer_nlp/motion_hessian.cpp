// SPDX-License-Identifier: BSD-3-Clause
// The per-sample Hessian models of the motion problem (formulation.md §10;
// docs/theory/outer-problem.md, "Hessian options"), assembled by motion_hessian_assembly.cpp.
//
// `exact` (sampleExactHessian) is the Hessian itself: the gauss-newton terms (the energy's
// and the epigraph's exact curvature in the outputs) plus Σ_o w_o ∇²y_o, the outputs' own
// curvature with each output's weight w_o held at the point. Along one state component the
// weighted output gradient Σ_o w_o ∇y_o is a polynomial of known degree (in q̇, q̈, a force
// variable) or a trigonometric polynomial (in a revolute joint's angle), so a stencil of
// that degree differentiates it exactly (derivative_stencil.hpp); a throw's rows, functions
// of the ball's state (a square root of it), take the flight's analytic curvature and a
// stencil of the ball's state alone (ball_flight_task.hpp). The duration's row and
// column follow by the chain rule from z_s = (B0 x, B1 x / T, B2 x / T²) and the objective's
// weight ∝ T:
//   ∂²L/∂x∂T = Bᵀ (H_s u + ĝ + c ∇E),  ∂²L/∂T² = uᵀ H_s u + gᵀ z'' + 2 c ∇E·u,
// u = ∂z/∂T = (0, −q̇/T, −2q̈/T), z'' = (0, 2q̇/T², 6q̈/T²), ĝ = (0, −g_q̇/T, −2g_q̈/T), g the
// sample's gradient in z, c ∇E its objective's per unit of T; the velocity-limit rows
// (∝ 1/T) add theirs.
#include <Eigen/Eigenvalues>
#include <cmath>

#include "outer_nlp/ball_flight_task.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/motion_workspace.hpp"
#include "sensitivity/bilevel_sample.hpp"

namespace mcopt {

void MotionProblem::sampleLagrangianGradient(int s, const SampleBlock& b, const Eigen::Ref<const Eigen::VectorXd>& multipliers,
                                             double objectiveWeight, HessianWorkspace& h,
                                             Eigen::Ref<Eigen::VectorXd> gradient) const {
  // The rows' multipliers and the cost terms' slopes on the outputs, then the terms that read
  // the state directly (the regularisation w Σ q̈², formulation.md §10).
  const CostSample sample = costSample(s, b);
  h.weights = multipliers;
  for (const auto& term : costs_) term->addOutputSlopes(sample, objectiveWeight, h.weights);
  outputGradient(b, h.weights, gradient);
  for (const auto& term : costs_) term->addStateGradient(sample, objectiveWeight, gradient);
}

void MotionProblem::costOutputWeights(int s, const SampleBlock& b, double objectiveWeight, HessianWorkspace& h) const {
  const CostSample sample = costSample(s, b);
  h.costSlopes.setZero();
  h.costCurvatures.setZero();
  for (const auto& term : costs_) {
    term->addOutputSlopes(sample, objectiveWeight, h.costSlopes);
    term->addOutputCurvatures(sample, objectiveWeight, h.costCurvatures);
  }
}

void MotionProblem::outputGradient(const SampleBlock& b, const Eigen::VectorXd& weights,
                                   Eigen::Ref<Eigen::VectorXd> gradient) const {
  const int n = jointCount_;
  gradient.segment(0, n).noalias() = b.dyDq.transpose() * weights;
  gradient.segment(n, n).noalias() = b.dyDv.transpose() * weights;
  gradient.segment(2 * n, n).noalias() = b.dyDa.transpose() * weights;
  const Eigen::Index forces = gradient.size() - 3 * n;
  if (forces > 0) gradient.tail(forces).noalias() = b.dyDz.leftCols(forces).transpose() * weights;
}

void MotionProblem::referenceWrenchJacobian(int s, const ThreadWorkspace& w,
                                            Eigen::Ref<Eigen::Matrix<double, 6, Eigen::Dynamic>> jacobian) const {
  // W_ref = W0 − Σ wrenchToWorld_i F_i (sampleOutputs): its q columns with the environment
  // wrenches' share, q̇ and q̈ those of W0, and −weight · wrenchToWorld_i on each force term.
  const int n = jointCount_;
  jacobian.leftCols(n) = w.referenceDq;
  jacobian.middleCols(n, n) = w.derivatives.dwrenchDv;
  jacobian.middleCols(2 * n, n) = w.derivatives.dwrenchDa;
  for (const LocalForceTerm& t : blocks_[static_cast<std::size_t>(s)].forceTerms)
    jacobian.middleCols<6>(3 * n + t.firstColumn) = -t.weight * w.toWorld[static_cast<std::size_t>(t.contact)];
}

void MotionProblem::sampleExactHessian(int s, const SampleBlock& b, const Eigen::Ref<const Eigen::VectorXd>& multipliers,
                                       double objectiveWeight, double T, ThreadWorkspace& w, HessianWorkspace& h,
                                       SampleBlock& probe) {
  const int n = jointCount_, nf = static_cast<int>(b.forceColumns.size()), d = 3 * n + nf;
  // The energy's and the epigraph's curvature in the outputs (P in Γ, q̇, q̈; σ in P) ...
  sampleGaussNewtonHessian(s, b, multipliers, objectiveWeight, h);
  auto H = h.stateHessian.topLeftCorner(d, d);
  // ... the report model's friction-cone rows r(W), quadratic in the wrench: their
  // curvature λ_cone J_Wᵀ ∇²r J_W exactly, and their weights moved onto the wrench — ω =
  // Σ_r λ_r ∂r_r/∂W held at the point on W_ref, whose own curvature the stencils take (at
  // the wrench's degrees, half the rows') — and on the environment wrenches, which are
  // linear in the force variables (their rows' curvature is all there is) ...
  const bool throughWrenches = support_.hasQuadraticRows();
  samples_.evaluate(s, controlPoints_, T, w.q, w.v, w.a);
  if (throughWrenches) {
    sampleOutputs(s, h.probeX, true, w, probe);  // the point's ∂rows/∂W_ref and ∂W_ref/∂z in w
    h.wrenchWeights.setZero();
    for (int r = 0; r < support_.rowCount(); ++r)
      h.wrenchWeights += multipliers[outputs_.referenceRow(r)] * w.rowsByReference.row(r).transpose();
    auto J = h.wrenchJacobian.leftCols(d), CJ = h.curvedWrenchJacobian.leftCols(d);
    referenceWrenchJacobian(s, w, J);
    CJ.noalias() = support_.quadraticRowCurvature() * J;
    H.noalias() += multipliers[outputs_.referenceRow(support_.quadraticRow())] * J.transpose() * CJ;
    // An environment contact's wrench F_i = Σ_t weight_t z_t: its rows' curvature on each
    // pair of its own terms.
    for (const LocalForceTerm& a : b.forceTerms)
      for (const LocalForceTerm& c : b.forceTerms) {
        if (a.contact != c.contact) continue;
        const ContactAdmissibilityRows& rows = contactRows_[static_cast<std::size_t>(a.contact)];
        H.block<6, 6>(3 * n + a.firstColumn, 3 * n + c.firstColumn) +=
            a.weight * c.weight * multipliers[outputs_.contactRow(a.contact, rows.quadraticRow())] * rows.quadraticRowCurvature();
      }
  }
  // ... and the outputs' own: each output's weight at this point is its multiplier, plus on
  // Γ_j the power's slope times ∂P/∂Γ (P's own curvature is in the terms above).
  h.fixedWeights = multipliers;  // h.costSlopes: the Gauss–Newton part above set them at this sample
  for (int j = 0; j < n; ++j) {
    const double slope = multipliers[outputs_.power(j)] + h.costSlopes[outputs_.power(j)];
    const MotorPowerDerivatives p =
        motorPowerDerivatives(scenario_.actuators.joints[static_cast<std::size_t>(j)], scenario_.actuators.frictionSharpness,
                              b.y[outputs_.torque(j)], b.velocity[j], b.acceleration[j]);
    h.fixedWeights[outputs_.torque(j)] += slope * p.dTorque;
    h.fixedWeights[outputs_.power(j)] = 0.0;
  }
  if (throughWrenches)  // their rows' weights are on the wrenches now
    h.fixedWeights.segment(outputs_.referenceRow(0), outputs_.contactRowStart.back()).setZero();
  // Σ_o w_o ∇y_o at the probed state (and the wrench weights' share): what the stencils difference.
  auto probeGradient = [&](Eigen::Ref<Eigen::VectorXd> gradient) {
    sampleOutputs(s, h.probeX, true, w, probe);
    outputGradient(probe, h.fixedWeights, gradient);
    if (throughWrenches) {
      auto J = h.wrenchJacobian.leftCols(d);
      referenceWrenchJacobian(s, w, J);
      gradient.noalias() += J.transpose() * h.wrenchWeights;
    }
  };
  auto column = h.column.head(d), gradient = h.gradient.head(d), centre = h.centreGradient.head(d);
  probeGradient(centre);  // f(0) of the one-sided stencils (affine directions)
  for (int c = 0; c < d; ++c) {
    double* component = c < n           ? &w.q[c]
                        : c < 2 * n     ? &w.v[c - n]
                        : c < 3 * n     ? &w.a[c - 2 * n]
                                        : &h.probeX[b.forceColumns[static_cast<std::size_t>(c - 3 * n)]];
    const DerivativeStencil& stencil = c < n       ? exactStencils_.angle
                                       : c < 2 * n ? exactStencils_.velocity
                                       : c < 3 * n ? exactStencils_.acceleration
                                                   : exactStencils_.force;
    const double saved = *component;
    column = stencil.centre * centre;
    for (int m = 0; m < stencil.size(); ++m) {
      *component = saved + stencil.offsets[static_cast<std::size_t>(m)];
      probeGradient(gradient);
      column += stencil.weights[static_cast<std::size_t>(m)] * gradient;
    }
    *component = saved;
    H.col(c) += column;
  }
}

void MotionProblem::sampleGaussNewtonHessian(int s, const SampleBlock& b, const Eigen::Ref<const Eigen::VectorXd>& multipliers,
                                             double objectiveWeight, HessianWorkspace& h) const {
  // The sample's terms are functions of its outputs: c σ(P_j) (smooth maximum) or λ_P P_j
  // (epigraph) per joint, P_j = P(Γ_j, q̇_j, q̈_j) (core/actuators.hpp), and c w q̈² for the
  // regularisation. Their exact curvature in (Γ, q̇, q̈) and in P, chained through the exact
  // first derivatives of Γ (dynamics, contact wrenches, inner optimum) held in `b`:
  //   H_s = Σ_j [c σ'' ∇P ∇Pᵀ + (c σ' + λ_P) J_jᵀ ∇²P J_j] + 2 c w E_q̈ᵀ E_q̈,
  // J_j the rows (∇Γ_j, e_q̇j, e_q̈j). Left out: Σ_o λ_o ∇²y_o and (c σ' + λ_P) ∂P/∂Γ ∇²Γ_j, the
  // curvature of the outputs themselves. The cross terms of ∇²P (the mechanical power Γem Ω
  // is bilinear) make H_s indefinite; dropping them (a positive semidefinite model) was
  // measured: the kick did not converge in 3000 iterations (docs/reference/scenario-file.md).
  const int n = jointCount_, nf = static_cast<int>(b.forceColumns.size()), d = 3 * n + nf;
  auto H = h.stateHessian.topLeftCorner(d, d);
  H.setZero();
  costOutputWeights(s, b, objectiveWeight, h);
  auto gradientOf = [&](int output, Eigen::Ref<Eigen::VectorXd> row) {
    row.segment(0, n) = b.dyDq.row(output).transpose();
    row.segment(n, n) = b.dyDv.row(output).transpose();
    row.segment(2 * n, n) = b.dyDa.row(output).transpose();
    if (nf > 0) row.tail(nf) = b.dyDz.row(output).head(nf).transpose();
  };
  auto torqueGradient = h.base.head(d), powerGradient = h.gradient.head(d);
  for (int j = 0; j < n; ++j) {
    const double slope = multipliers[outputs_.power(j)] + h.costSlopes[outputs_.power(j)];
    const double curvature = h.costCurvatures[outputs_.power(j)];
    if (curvature != 0.0) {
      gradientOf(outputs_.power(j), powerGradient);
      H.selfadjointView<Eigen::Lower>().rankUpdate(powerGradient, curvature);
    }
    if (slope == 0.0) continue;
    gradientOf(outputs_.torque(j), torqueGradient);
    const Eigen::Matrix3d M =
        slope * motorPowerHessian(scenario_.actuators.joints[static_cast<std::size_t>(j)],
                                  scenario_.actuators.frictionSharpness, b.y[outputs_.torque(j)], b.velocity[j],
                                  b.acceleration[j]);
    // J_jᵀ M J_j in the lower triangle: the Γ–Γ term as a rank-one update, the cross terms on
    // the joint's own q̇ and q̈ columns (an entry on the diagonal takes both halves).
    H.selfadjointView<Eigen::Lower>().rankUpdate(torqueGradient, M(0, 0));
    const int v = n + j, a = 2 * n + j;
    for (int r = 0; r < d; ++r) {
      H(std::max(r, v), std::min(r, v)) += M(0, 1) * torqueGradient[r] * (r == v ? 2.0 : 1.0);
      H(std::max(r, a), std::min(r, a)) += M(0, 2) * torqueGradient[r] * (r == a ? 2.0 : 1.0);
    }
    H(v, v) += M(1, 1);
    H(a, v) += M(1, 2);
    H(a, a) += M(2, 2);
  }
  const CostSample sample = costSample(s, b);
  for (const auto& term : costs_) term->addStateHessian(sample, objectiveWeight, H);
  H.triangularView<Eigen::StrictlyUpper>() = H.transpose();  // the spreading reads the whole matrix
}


}  // namespace mcopt
