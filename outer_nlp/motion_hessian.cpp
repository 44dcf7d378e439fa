// SPDX-License-Identifier: BSD-3-Clause
// The Lagrangian's Hessian of the motion problem by per-sample differences (formulation.md
// §10; docs/theory/outer-problem.md, "Hessian options").
//
// At a fixed duration, every sample row and the objective's share of sample s depend on the
// spline parameters only through that sample's state z_s = (q, q̇, q̈) — linearly, z_s = B_s x
// — and on the sample's own force columns (splines, variables). So
//   ∇²L = Σ_s B_sᵀ H_s B_s + Σ_tasks B_tᵀ H_t B_t (+ the duration's row and column),
// with H_s the Hessian in z_s of that sample's terms Σ_o λ_o y_o + c_s σ_f Σ_j P⁺(P_j).
// H_s comes from forward differences of the sample's exact gradient in z_s: 3n (+ force
// columns) evaluations of one sample's derivatives (central differences, 20× more accurate
// on the kick, took 316 iterations against 361 but twice the Hessian's time: slower overall), where differencing the whole gradient
// costs one whole-trajectory evaluation per spline parameter. Samples are independent, so
// they run in parallel. `gauss-newton` assembles H_s from the sample's exact first
// derivatives instead (sampleGaussNewtonHessian: no extra evaluation; a model, not the
// Hessian). The duration's column (when it is free) is a forward difference of the whole
// gradient: T scales every sample's velocity and acceleration and the trapezoid weights.
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
#include <omp.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "outer_nlp/ball_flight_task.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/motion_workspace.hpp"
#include "sensitivity/bilevel_sample.hpp"

namespace mcopt {

namespace {

/// Forward-difference step for a variable of magnitude `value` (as the generic differences).
inline double differenceStep(double value) { return 1e-6 * std::max(1.0, std::abs(value)); }

}  // namespace

void MotionProblem::lagrangianHessian(const Eigen::VectorXd& x, double objectiveFactor,
                                      const Eigen::Ref<const Eigen::VectorXd>& multipliers, Eigen::VectorXd& values) {
  if (scenario_.hessian == HessianOption::SampleDifferences || scenario_.hessian == HessianOption::ConvexSampleDifferences ||
      scenario_.hessian == HessianOption::GaussNewton || scenario_.hessian == HessianOption::Exact)
    sampleDifferencesHessian(x, objectiveFactor, multipliers, values);
  else
    NlpProblem::lagrangianHessian(x, objectiveFactor, multipliers, values);
}

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
  for (const SampleBlock::ForceTerm& t : blocks_[static_cast<std::size_t>(s)].forceTerms)
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
    for (const SampleBlock::ForceTerm& a : b.forceTerms)
      for (const SampleBlock::ForceTerm& c : b.forceTerms) {
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

void MotionProblem::sampleDifferencesHessian(const Eigen::VectorXd& x, double objectiveFactor,
                                             const Eigen::Ref<const Eigen::VectorXd>& multipliers,
                                             Eigen::VectorXd& values) {
  evaluate(x, true);
  const int n = jointCount_, curved = nonlinearVariableCount(), N = samples_.sampleCount();
  const double T = duration(x);

  // Each row's multiplier on the output it reads, times the term's sign (an epigraph row reads
  // −P); a slack enters linearly.
  sampleMultipliers_.setZero(outputs_.size(), N);
  taskMultipliers_.setZero(taskRows_, static_cast<Eigen::Index>(taskBlocks_.size()));
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    const double lambda = row.sign * multipliers[static_cast<Eigen::Index>(r)];
    switch (row.place) {
      case RowPlace::ControlPoints: break;  // linear in x at a fixed duration: the duration's part below
      case RowPlace::TaskInstant: taskMultipliers_(row.output, row.block) += lambda; break;
      case RowPlace::Sample: sampleMultipliers_(row.output, row.block) += lambda; break;
    }
  }

  const int threads = static_cast<int>(workspaces_.size());
  if (hessianWorkspaces_.size() != static_cast<std::size_t>(threads)) {
    hessianWorkspaces_.assign(static_cast<std::size_t>(threads), HessianWorkspace{});
    std::size_t forceColumns = 0;
    for (const SampleBlock& b : blocks_) forceColumns = std::max(forceColumns, b.forceColumns.size());
    const int outputs = outputs_.size(), contacts = outputs_.contacts;
    // Sized once for the largest sample (3n states + its force columns): the per-sample
    // loop below works on leading blocks and allocates nothing.
    const int largest = 3 * n + static_cast<int>(forceColumns), largestLocal = 4 * n + static_cast<int>(forceColumns);
    for (HessianWorkspace& h : hessianWorkspaces_) {
      h.weights.setZero(outputs), h.base.setZero(largest), h.gradient.setZero(largest);
      h.costSlopes.setZero(outputs), h.costCurvatures.setZero(outputs);
      h.stateHessian.setZero(largest, largest), h.spread.setZero(largest, largestLocal);
      h.fixedWeights.setZero(outputs), h.zeroWeights.setZero(outputs), h.column.setZero(largest);
      h.centreGradient.setZero(largest);
      h.objectiveGradient.setZero(largest), h.stateByDuration.setZero(largest), h.durationRow.setZero(largest);
      h.wrenchJacobian.setZero(6, largest), h.curvedWrenchJacobian.setZero(6, largest);
      const int closing = 3 * outputs_.closing;
      h.foldColumns.setZero(largest, closing), h.foldRows.setZero(closing, largest);
      h.probeMap.setZero(closing, 3 * n), h.closedState.setZero(3 * n);
    }
    localHessians_.assign(blocks_.size() + taskBlocks_.size(), LocalHessian{});
    for (LocalHessian& l : localHessians_)  // + 1: the duration's row and column (exact option)
      l.values.setZero(largestLocal + 1, largestLocal + 1), l.columns.reserve(static_cast<std::size_t>(largestLocal + 1));
    probes_.assign(static_cast<std::size_t>(threads), SampleBlock{});
    taskProbes_.assign(static_cast<std::size_t>(threads), SampleBlock{});
    for (SampleBlock& p : taskProbes_) p.y.setZero(taskRows_), p.dyDq.setZero(taskRows_, n), p.dyDv.setZero(taskRows_, n);
    for (SampleBlock& p : probes_) {
      p.y.setZero(outputs), p.wrenches.setZero(6 * (1 + contacts)), p.velocity.setZero(n), p.acceleration.setZero(n);
      p.dyDq.setZero(outputs, n), p.dyDv.setZero(outputs, n), p.dyDa.setZero(outputs, n);
      p.dyDz.setZero(outputs, static_cast<Eigen::Index>(forceColumns));
    }
  }

#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num();
    ThreadWorkspace& w = workspaces_[static_cast<std::size_t>(t)];
    HessianWorkspace& h = hessianWorkspaces_[static_cast<std::size_t>(t)];
    SampleBlock& probe = probes_[static_cast<std::size_t>(t)];
    SampleBlock& taskProbe = taskProbes_[static_cast<std::size_t>(t)];
    h.probeX = x;

    // Writes Bᵀ H B into the slot's LocalHessian: B maps the local spline parameters (k per joint, their
    // weights in q, q̇ = (1/T) dq/du, q̈ = (1/T²) d²q/du²) and the force columns to the state.
    const bool convex = scenario_.hessian == HessianOption::ConvexSampleDifferences;
    const bool exact = scenario_.hessian == HessianOption::Exact, freeDuration = durationIsFree();
    // Symmetrises the leading d × d block of the state Hessian (and, for the convex option,
    // projects it onto the positive semidefinite cone).
    auto symmetrise = [&](int d) {
      auto H = h.stateHessian.topLeftCorner(d, d);
      for (int r = 0; r < d; ++r)
        for (int c = 0; c < r; ++c) H(r, c) = H(c, r) = 0.5 * (H(r, c) + H(c, r));
      if (!convex) return;
      h.eigen.compute(H);
      H.noalias() = h.eigen.eigenvectors() * h.eigen.eigenvalues().cwiseMax(0.0).asDiagonal() *
                    h.eigen.eigenvectors().transpose();
    };
    // With `duration`, also the row and column of T from h.durationRow (∂²L/∂z∂T in the
    // state and force columns) and h.durationCurvature (∂²L/∂T²).
    // With closed chains (`map`, closed_chains.hpp) the state Hessian H, in the full state, is
    // first brought to the spline joints' by x = T x_F (T the identity on the spline joints, the
    // map on the closing ones): Tᵀ H T, and Tᵀ on the duration's row — the chain rule of the
    // gradient, the closure's own curvature left out (a Gauss–Newton term in the map).
    auto spread = [&](const LocalParameterWeights& weights, const Eigen::VectorXi& parameters, int stateBlocks,
                      const std::vector<int>& forceColumns, LocalHessian& out, bool duration, const Eigen::MatrixXd* map,
                      ClosureSet closed) {
      const int k = weights.count, nf = static_cast<int>(forceColumns.size()), d = stateBlocks * n + nf;
      if (map) {
        const int c = outputs_.closing, sc = stateBlocks * c;
        const std::vector<int>& closing = closure_->closingJoints();
        const auto M = map->topLeftCorner(sc, stateBlocks * n);
        auto Hfull = h.stateHessian.topLeftCorner(d, d);
        // The map's row g is closing joint g % c's in state block g / c.
        auto stateOf = [&](int g) { return (g / c) * n + closing[static_cast<std::size_t>(g % c)]; };
        // (the map's rows of a joint not closed here are zero: its column and row stay)
        auto isClosed = [&](int g) { return closure_->closesIn(closing[static_cast<std::size_t>(g % c)], closed); };
        auto G = h.foldColumns.topLeftCorner(d, sc);  // H T: the closed columns through the map
        for (int g = 0; g < sc; ++g) {
          G.col(g).setZero();
          if (isClosed(g)) G.col(g) = Hfull.col(stateOf(g)), Hfull.col(stateOf(g)).setZero();
        }
        Hfull.leftCols(stateBlocks * n).noalias() += G * M;
        auto R = h.foldRows.topLeftCorner(sc, d);  // Tᵀ (H T): the closed rows likewise
        for (int g = 0; g < sc; ++g) {
          R.row(g).setZero();
          if (isClosed(g)) R.row(g) = Hfull.row(stateOf(g)), Hfull.row(stateOf(g)).setZero();
        }
        Hfull.topRows(stateBlocks * n).noalias() += M.transpose() * R;
        if (duration) foldGradient(*map, closed, stateBlocks, h.durationRow.head(stateBlocks * n));
      }
      const int local = n * k + nf;
      const double scale[3] = {1.0, 1.0 / T, 1.0 / (T * T)};
      auto weight = [&](int block, int l) {
        return scale[block] * (block == 0 ? weights.value[static_cast<std::size_t>(l)]
                               : block == 1 ? weights.d1[static_cast<std::size_t>(l)]
                                            : weights.d2[static_cast<std::size_t>(l)]);
      };
      const auto H = h.stateHessian.topLeftCorner(d, d);
      auto HB = h.spread.topLeftCorner(d, local);  // H B
      HB.setZero();
      for (int j = 0; j < n; ++j)
        for (int l = 0; l < k; ++l)
          for (int block = 0; block < stateBlocks; ++block) HB.col(j * k + l) += weight(block, l) * H.col(block * n + j);
      for (int f = 0; f < nf; ++f) HB.col(n * k + f) = H.col(stateBlocks * n + f);
      auto BHB = out.values.topLeftCorner(local, local);  // Bᵀ H B
      BHB.setZero();
      for (int j = 0; j < n; ++j)
        for (int l = 0; l < k; ++l)
          for (int block = 0; block < stateBlocks; ++block) BHB.row(j * k + l) += weight(block, l) * HB.row(block * n + j);
      for (int f = 0; f < nf; ++f) BHB.row(n * k + f) = HB.row(stateBlocks * n + f);
      out.size = local;
      out.columns.resize(static_cast<std::size_t>(local));
      for (int c = 0; c < n * k; ++c) out.columns[static_cast<std::size_t>(c)] = parameters[c];
      for (int f = 0; f < nf; ++f) out.columns[static_cast<std::size_t>(n * k + f)] = forceColumns[static_cast<std::size_t>(f)];
      if (!duration) return;
      const auto byDuration = h.durationRow.head(d);
      auto row = out.values.row(local).head(local);
      row.setZero();
      for (int j = 0; j < n; ++j)
        for (int l = 0; l < k; ++l)
          for (int block = 0; block < stateBlocks; ++block) row[j * k + l] += weight(block, l) * byDuration[block * n + j];
      for (int f = 0; f < nf; ++f) row[n * k + f] = byDuration[stateBlocks * n + f];
      out.values.col(local).head(local) = row.transpose();
      out.values(local, local) = h.durationCurvature;
      out.size = local + 1;
      out.columns.push_back(parameterCount_);
    };

#pragma omp for schedule(static)
    for (int s = 0; s < N; ++s) {
      const SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
      const int nf = static_cast<int>(b.forceColumns.size()), d = 3 * n + nf;
      const double objectiveWeight = objectiveFactor * sampleWeights_[static_cast<std::size_t>(s)] * T;
      const auto lambda = sampleMultipliers_.col(s);
      if (scenario_.hessian == HessianOption::GaussNewton) {
        sampleGaussNewtonHessian(s, b, lambda, objectiveWeight, h);
        spread(samples_.weights(s), b.parameters, 3, b.forceColumns, localHessians_[static_cast<std::size_t>(s)], false, closure_ ? &b.closureMap : nullptr, b.closed);
        continue;
      }
      if (exact) {
        sampleExactHessian(s, b, lambda, objectiveWeight, T, w, h, probe);
        symmetrise(d);
        if (freeDuration) {
          // The chain rule through z_s(x, T) and the objective's weight c T (file comment).
          const auto H = h.stateHessian.topLeftCorner(d, d);
          auto g = h.base.head(d), cE = h.objectiveGradient.head(d), u = h.stateByDuration.head(d), dz = h.durationRow.head(d);
          sampleLagrangianGradient(s, b, lambda, objectiveWeight, h, g);
          sampleLagrangianGradient(s, b, h.zeroWeights, objectiveWeight / T, h, cE);
          u.setZero();
          u.segment(n, n) = -b.velocity / T;
          u.segment(2 * n, n) = -2.0 / T * b.acceleration;
          dz.noalias() = H * u;
          h.durationCurvature = u.dot(dz) + 2.0 / (T * T) * g.segment(n, n).dot(b.velocity) +
                                6.0 / (T * T) * g.segment(2 * n, n).dot(b.acceleration) + 2.0 * cE.dot(u);
          dz.segment(n, n) -= g.segment(n, n) / T;
          dz.segment(2 * n, n) -= 2.0 / T * g.segment(2 * n, n);
          dz += cE;
        }
        spread(samples_.weights(s), b.parameters, 3, b.forceColumns, localHessians_[static_cast<std::size_t>(s)], freeDuration, closure_ ? &b.closureMap : nullptr, b.closed);
        continue;
      }
      auto base = h.base.head(d), gradient = h.gradient.head(d);
      sampleLagrangianGradient(s, b, lambda, objectiveWeight, h, base);
      samples_.evaluate(s, controlPoints_, T, w.q, w.v, w.a);
      closeState(b, w, nullptr);  // the sample's own state
      // Closed chains: differences in the spline joints' state, each probe closed again (the
      // closure's own curvature included), the gradients brought to that state by the map.
      if (closure_) {
        foldGradient(b.closureMap, b.closed, 3, base.head(3 * n));
        h.closedState << w.q, w.v, w.a;
      }
      for (int c = 0; c < d; ++c) {
        const bool state = c < 3 * n;
        if (closure_ && state && closure_->closesIn(c % n, b.closed)) {
          h.stateHessian.col(c).head(d).setZero();
          continue;
        }
        // Perturb one state component (or force variable), evaluate the sample there.
        double* component = c < n           ? &w.q[c]
                            : c < 2 * n     ? &w.v[c - n]
                            : c < 3 * n     ? &w.a[c - 2 * n]
                                            : &h.probeX[b.forceColumns[static_cast<std::size_t>(c - 3 * n)]];
        const double saved = *component, step = differenceStep(saved);
        *component = saved + step;
        if (closure_ && state) closure_->close(model_, w.closure, w.q, w.v, w.a, &h.probeMap, b.closed);
        sampleOutputs(s, h.probeX, true, w, probe);
        *component = saved;
        if (closure_ && state) w.q = h.closedState.head(n), w.v = h.closedState.segment(n, n), w.a = h.closedState.tail(n);
        sampleLagrangianGradient(s, probe, lambda, objectiveWeight, h, gradient);
        if (closure_) foldGradient(state ? h.probeMap : b.closureMap, b.closed, 3, gradient.head(3 * n));
        h.stateHessian.col(c).head(d) = (gradient - base) / step;
      }
      // A bilevel sample keeps its last inner solution (its warm start, its reported status):
      // leave it at the unperturbed state.
      if (bilevel_) sampleOutputs(s, h.probeX, false, w, probe);
      symmetrise(d);
      spread(samples_.weights(s), b.parameters, 3, b.forceColumns, localHessians_[static_cast<std::size_t>(s)], false, nullptr, 0);
    }

#pragma omp for schedule(static)
    for (int i = 0; i < static_cast<int>(taskBlocks_.size()); ++i) {
      const TaskSpec& spec = scenario_.tasks[static_cast<std::size_t>(taskOfInstant_[static_cast<std::size_t>(i)])];
      const Task& task = *spec.task;
      const auto lambda = taskMultipliers_.col(i).head(spec.dimension());
      LocalHessian& slot = localHessians_[blocks_.size() + static_cast<std::size_t>(i)];
      slot.size = 0;
      if ((lambda.array() == 0.0).all()) continue;  // no bounded component
      const SampleBlock& b = taskBlocks_[static_cast<std::size_t>(i)];
      // Positions, orientations and the centre of mass read q alone; velocities q and q̇.
      const bool velocity = task.readsVelocity();
      const int d = velocity ? 2 * n : n;
      auto base = h.base.head(d), gradient = h.gradient.head(d);
      base.head(n).noalias() = b.dyDq.transpose() * lambda;
      if (velocity) base.tail(n).noalias() = b.dyDv.transpose() * lambda;
      taskSamples_.evaluate(i, controlPoints_, T, w.q, w.v, w.a);
      closeState(b, w, nullptr);
      const int taskBlocks = velocity ? 2 : 1;
      if (closure_ && !exact) {  // as the samples': differences in the spline joints' state
        foldGradient(b.closureMap, b.closed, taskBlocks, base);
        h.closedState << w.q, w.v, w.a;
      }
      const bool durationTerms = exact && freeDuration && velocity;
      // A throw's rows are functions of the ball's state k = (p, v_p): their exact Hessian is the
      // flight's curvature through ∂k/∂z plus the stencil of wᵀ ∇k, w held (ball_flight_task.hpp).
      const BallFlightTask* flight = exact ? task.ballFlight() : nullptr;
      if (flight) {
        inverseDynamics(model_, w.data, w.q, w.v, w.a);
        flight->flightCurvature(model_, w.data, lambda, w.task, h.ballWeights, h.stateHessian.topLeftCorner(d, d));
      }
      if (durationTerms) {  // u = ∂z/∂T = (0, −q̇/T) at the instant, before the probes move q̇
        h.stateByDuration.head(n).setZero();
        h.stateByDuration.segment(n, n) = -w.v / T;
      }
      for (int c = 0; c < d; ++c) {
        double& component = c < n ? w.q[c] : w.v[c - n];
        const double saved = component;
        if (exact) {
          // The task's gradient with its multipliers is trigonometric in an angle and linear in q̇.
          const DerivativeStencil& stencil = c < n ? exactStencils_.taskAngle : exactStencils_.taskVelocity;
          auto column = h.column.head(d);
          column.setZero();
          for (int m = 0; m < stencil.size(); ++m) {
            component = saved + stencil.offsets[static_cast<std::size_t>(m)];
            if (flight) {
              inverseDynamics(model_, w.data, w.q, w.v, w.a);
              flight->ballStateGradient(model_, w.data, h.ballWeights, w.task, gradient.head(n), gradient.tail(n));
            } else {
              taskOutputs(i, true, w, taskProbe);
              gradient.head(n).noalias() = taskProbe.dyDq.topRows(lambda.size()).transpose() * lambda;
              if (velocity) gradient.tail(n).noalias() = taskProbe.dyDv.topRows(lambda.size()).transpose() * lambda;
            }
            column += stencil.weights[static_cast<std::size_t>(m)] * gradient;
          }
          component = saved;
          if (flight)
            h.stateHessian.col(c).head(d) += column;
          else
            h.stateHessian.col(c).head(d) = column;
          continue;
        }
        if (closure_ && closure_->closesIn(c % n, b.closed)) {
          h.stateHessian.col(c).head(d).setZero();
          continue;
        }
        const double step = differenceStep(saved);
        component = saved + step;
        if (closure_) closure_->close(model_, w.closure, w.q, w.v, w.a, &h.probeMap, b.closed);
        taskOutputs(i, true, w, taskProbe);
        component = saved;
        if (closure_) w.q = h.closedState.head(n), w.v = h.closedState.segment(n, n), w.a = h.closedState.tail(n);
        gradient.head(n).noalias() = taskProbe.dyDq.topRows(lambda.size()).transpose() * lambda;
        if (velocity) gradient.tail(n).noalias() = taskProbe.dyDv.topRows(lambda.size()).transpose() * lambda;
        if (closure_) foldGradient(h.probeMap, b.closed, taskBlocks, gradient);
        h.stateHessian.col(c).head(d) = (gradient - base) / step;
      }
      symmetrise(d);
      if (durationTerms) {
        // z = (q, q̇ = B1 x / T): u = (0, −q̇/T), ĝ = (0, −g_q̇/T), z'' = (0, 2q̇/T²) = −2u/T.
        const auto H = h.stateHessian.topLeftCorner(d, d);
        const auto u = h.stateByDuration.head(d);
        auto dz = h.durationRow.head(d);
        dz.noalias() = H * u;
        h.durationCurvature = u.dot(dz) - 2.0 / T * base.tail(n).dot(u.tail(n));
        dz.tail(n) -= base.tail(n) / T;
      }
      spread(taskSamples_.weights(i), b.parameters, velocity ? 2 : 1, {}, slot, durationTerms, nullptr, 0);
    }
  }

  // Summed in sample order, whatever thread computed each term: the same Hessian, to the
  // bit, for any thread count (docs/developers/determinism.md, "Determinism").
  Eigen::MatrixXd& hessian = hessianSum_;
  hessian.setZero(curved, curved);
  for (const LocalHessian& l : localHessians_)
    for (int r = 0; r < l.size; ++r)
      for (int c = 0; c < l.size; ++c)
        hessian(l.columns[static_cast<std::size_t>(r)], l.columns[static_cast<std::size_t>(c)]) += l.values(r, c);

  if (durationIsFree() && scenario_.hessian == HessianOption::Exact) {
    // The samples and task instants brought theirs; the control-point rows (the velocity
    // limits, (x_second − x_first) / T) bring their own terms' curvature in T.
    const int column = parameterCount_;
    for (std::size_t r = 0; r < rows_.size(); ++r) {
      if (rows_[r].place == RowPlace::ControlPoints)
        terms_[static_cast<std::size_t>(rows_[r].term)]->addDirectHessian(rows_[r].detail, multipliers[static_cast<Eigen::Index>(r)],
                                                                           x, T, column, hessian);
    }
  } else if (durationIsFree()) {
    // The duration's row and column: a forward difference of the whole gradient.
    const int column = parameterCount_;
    Eigen::VectorXd base, plus, shifted = x;
    lagrangianGradient(x, objectiveFactor, multipliers, base);
    const double step = differenceStep(x[column]);
    shifted[column] += step;
    lagrangianGradient(shifted, objectiveFactor, multipliers, plus);
    const Eigen::VectorXd difference = (plus - base).head(curved) / step;
    hessian.row(column) = difference.transpose();
    hessian.col(column) = difference;
  }

  values.resize(static_cast<Eigen::Index>(curved) * (curved + 1) / 2);
  for (int r = 0; r < curved; ++r)
    for (int c = 0; c <= r; ++c) values[lowerTriangleIndex(r, c)] = 0.5 * (hessian(r, c) + hessian(c, r));
}

}  // namespace mcopt
