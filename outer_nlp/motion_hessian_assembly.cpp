// SPDX-License-Identifier: BSD-3-Clause
// The Lagrangian's Hessian of the motion problem assembled from per-sample Hessians
// (formulation.md §10; docs/theory/outer-problem.md, "Hessian options"); the per-sample
// models themselves (gauss-newton, exact) are in motion_hessian.cpp.
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
#include <omp.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "outer_nlp/ball_flight_task.hpp"
#include "outer_nlp/contact_force_formulation.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/motion_workspace.hpp"

namespace mcopt {

void MotionProblem::lagrangianHessian(const Eigen::VectorXd& x, double objectiveFactor,
                                      const Eigen::Ref<const Eigen::VectorXd>& multipliers, Eigen::VectorXd& values) {
  if (hessian_ == HessianOption::SampleDifferences || hessian_ == HessianOption::ConvexSampleDifferences ||
      hessian_ == HessianOption::GaussNewton || hessian_ == HessianOption::Exact)
    sampleDifferencesHessian(x, objectiveFactor, multipliers, values);
  else
    NlpProblem::lagrangianHessian(x, objectiveFactor, multipliers, values);
}

void MotionProblem::hessianPattern(std::vector<int>& rows, std::vector<int>& columns) const {
  if (hessian_ != HessianOption::SampleDifferences && hessian_ != HessianOption::ConvexSampleDifferences &&
      hessian_ != HessianOption::GaussNewton && hessian_ != HessianOption::Exact)
    return NlpProblem::hessianPattern(rows, columns);
  // The motion's block (spline parameters and T) is declared dense; each sample's force
  // columns meet only that sample's local parameters and its own force columns (what its slot's
  // Bᵀ H B adds to below), and the duration when it is free. The motion's block has holes too
  // (parameters whose splines share no sample), but telling Ipopt so moved two bundled bilevel
  // optima by more than 1 % and saves little: its part of the factorisation is dense anyway
  // (docs/developers/lab-notes/neighbours-and-stage-one.md, "The Hessian's sparsity").
  const int curved = nonlinearVariableCount(), motion = forceStart_;
  std::vector<char> meet(static_cast<std::size_t>(curved) * static_cast<std::size_t>(curved), 0);
  auto mark = [&](int r, int c) { meet[static_cast<std::size_t>(std::max(r, c)) * static_cast<std::size_t>(curved) + static_cast<std::size_t>(std::min(r, c))] = 1; };
  for (int r = 0; r < motion; ++r)
    for (int c = 0; c <= r; ++c) mark(r, c);
  for (const SampleBlock& b : blocks_)
    for (const int f : b.forceColumns) {
      for (const int p : b.parameters) mark(f, p);
      for (const int g : b.forceColumns) mark(f, g);
      if (durationIsFree()) mark(f, parameterCount_);
    }
  rows.clear(), columns.clear();
  for (int r = 0; r < curved; ++r)
    for (int c = 0; c <= r; ++c)
      if (meet[static_cast<std::size_t>(r) * static_cast<std::size_t>(curved) + static_cast<std::size_t>(c)]) rows.push_back(r), columns.push_back(c);
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
    const bool convex = hessian_ == HessianOption::ConvexSampleDifferences;
    const bool exact = hessian_ == HessianOption::Exact, freeDuration = durationIsFree();
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
      auto BHB = out.values.topLeftCorner(local, local);  // Bᵀ H B, column by column (contiguous)
      for (int c = 0; c < local; ++c) {
        const auto from = HB.col(c);
        auto to = BHB.col(c);
        for (int j = 0; j < n; ++j)
          for (int l = 0; l < k; ++l) {
            double sum = 0.0;
            for (int block = 0; block < stateBlocks; ++block) sum += weight(block, l) * from[block * n + j];
            to[j * k + l] = sum;
          }
        for (int f = 0; f < nf; ++f) to[n * k + f] = from[stateBlocks * n + f];
      }
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

    // The task instants first: each one's differences (with closed chains, a closure a probe)
    // cost as much as several samples, so a thread takes each and the others start on the
    // samples, shared as threads come free. Every slot is computed alike on any thread: the sum
    // below is the same whatever the schedule.
#pragma omp for schedule(dynamic) nowait
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
        // A probe closes what the task reads: q, and q̇ when it reads velocities.
        if (closure_)
          closure_->close(model_, w.closure, w.q, w.v, w.a, &h.probeMap, b.closed,
                          velocity ? ClosureOrder::Velocities : ClosureOrder::Positions);
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

#pragma omp for schedule(dynamic)
    for (int s = 0; s < N; ++s) {
      const SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
      const int nf = static_cast<int>(b.forceColumns.size()), d = 3 * n + nf;
      const double objectiveWeight = objectiveFactor * sampleWeights_[static_cast<std::size_t>(s)] * T;
      const auto lambda = sampleMultipliers_.col(s);
      if (hessian_ == HessianOption::GaussNewton) {
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
        // Perturb one state component (or force variable, by a step in its own unit), evaluate the sample there.
        const int force = state ? -1 : b.forceColumns[static_cast<std::size_t>(c - 3 * n)];
        double* component = c < n           ? &w.q[c]
                            : c < 2 * n     ? &w.v[c - n]
                            : c < 3 * n     ? &w.a[c - 2 * n]
                                            : &h.probeX[force];
        const double saved = *component, step = differenceStep(saved, state ? 1.0 : units_[force]);
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
      if (formulation_->keepsSampleState()) sampleOutputs(s, h.probeX, false, w, probe);
      symmetrise(d);
      spread(samples_.weights(s), b.parameters, 3, b.forceColumns, localHessians_[static_cast<std::size_t>(s)], false, nullptr, 0);
    }
  }

  // Summed in sample order, whatever thread computed each term: the same Hessian, to the
  // bit, for any thread count (docs/developers/determinism.md, "Determinism").
  // Each thread sums a range of the columns, every entry still in slot order.
  Eigen::MatrixXd& hessian = hessianSum_;
  hessian.setZero(curved, curved);
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num(), parts = omp_get_num_threads();
    const int first = static_cast<int>(static_cast<long>(curved) * t / parts);
    const int last = static_cast<int>(static_cast<long>(curved) * (t + 1) / parts);
    for (const LocalHessian& l : localHessians_)
      for (int c = 0; c < l.size; ++c) {
        const int column = l.columns[static_cast<std::size_t>(c)];
        if (column < first || column >= last) continue;
        for (int r = 0; r < l.size; ++r) hessian(l.columns[static_cast<std::size_t>(r)], column) += l.values(r, c);
      }
  }

  if (durationIsFree() && hessian_ == HessianOption::Exact) {
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
