// SPDX-License-Identifier: BSD-3-Clause
// The motion problem's points (formulation.md §9, §10): an initial point from the start and
// end postures, a point from motion parameters, the wrench variables carried from another
// problem's point, and the motion parameters reported for a point.
#include "outer_nlp/motion_problem.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/contact_maps.hpp"
#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/spatial.hpp"
#include "core/trajectory_evaluation.hpp"
#include "outer_nlp/contact_force_formulation.hpp"
#include "outer_nlp/motion_workspace.hpp"
#include "sensitivity/bilevel_sample.hpp"

namespace mcopt {

Eigen::VectorXd MotionProblem::initialPoint(const Eigen::VectorXd& start, const Eigen::VectorXd& end) {
  return pointFromMotion(parametrization_.interpolatedMotion(start, end), scenario_.duration.initial);
}

Eigen::VectorXd MotionProblem::initialPoint(const Eigen::VectorXd& start, const Eigen::VectorXd& end,
                                            const std::vector<HeldPosture>& held) {
  if (held.empty()) return initialPoint(start, end);
  // The path's corners: (0, start), each held posture at its two ends, (1, end).
  std::vector<std::pair<double, Eigen::VectorXd>> corners{{0.0, start}};
  std::vector<HeldPosture> sorted = held;
  std::sort(sorted.begin(), sorted.end(), [](const HeldPosture& a, const HeldPosture& b) { return a.begin < b.begin; });
  for (const HeldPosture& h : sorted) {
    if (h.posture.size() != jointCount_) throw std::invalid_argument("initialPoint: a held posture of the wrong size");
    corners.emplace_back(std::max(h.begin, corners.back().first), h.posture);
    corners.emplace_back(std::max(h.end, corners.back().first), h.posture);
  }
  corners.emplace_back(1.0, parametrization_.periodic() ? start : end);
  const int G = 20 * parametrization_.controlPointCount(), m = parametrization_.parametersPerJoint();
  std::vector<double> times;
  for (int g = 0; g < G; ++g) times.push_back(static_cast<double>(g) / (G - 1));
  const SampledTrajectory grid(parametrization_, times);
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(G, m);
  for (int g = 0; g < G; ++g) {
    const LocalParameterWeights& local = grid.weights(g);
    for (int l = 0; l < local.count; ++l) basis(g, local.parameter[static_cast<std::size_t>(l)]) += local.value[static_cast<std::size_t>(l)];
  }
  // The end parameters stay at start and end (the interpolation's): the others fitted.
  Eigen::VectorXd parameters = parametrization_.interpolatedMotion(start, end);
  std::vector<int> fixed{0};
  if (!parametrization_.periodic()) fixed.push_back(parametrization_.endParameter());
  std::vector<int> free;
  for (int l = 0; l < m; ++l)
    if (std::find(fixed.begin(), fixed.end(), l) == fixed.end()) free.push_back(l);
  Eigen::MatrixXd A(G, static_cast<Eigen::Index>(free.size()));
  for (std::size_t f = 0; f < free.size(); ++f) A.col(static_cast<Eigen::Index>(f)) = basis.col(free[f]);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  Eigen::VectorXd target(G);
  for (int j = 0; j < jointCount_; ++j) {
    for (int g = 0; g < G; ++g) {
      const double u = times[static_cast<std::size_t>(g)];
      std::size_t k = 1;
      while (k + 1 < corners.size() && corners[k].first < u) ++k;
      const auto& [u0, q0] = corners[k - 1];
      const auto& [u1, q1] = corners[k];
      const double t = u1 > u0 ? std::clamp((u - u0) / (u1 - u0), 0.0, 1.0) : 1.0;
      target[g] = (1.0 - t) * q0[j] + t * q1[j];
      for (const int l : fixed) target[g] -= basis(g, l) * parameters[j * m + l];
    }
    const Eigen::VectorXd fitted = qr.solve(target);
    for (std::size_t f = 0; f < free.size(); ++f) parameters[j * m + free[f]] = fitted[static_cast<Eigen::Index>(f)];
  }
  return pointFromMotion(parameters, scenario_.duration.initial);
}

Eigen::VectorXd MotionProblem::pointFromMotion(const Eigen::VectorXd& motionParameters, double T) {
  return motionPoint(motionParameters, T, nullptr);
}

Eigen::VectorXd MotionProblem::pointFromMotion(const Eigen::VectorXd& motionParameters, double T,
                                               const Eigen::VectorXd& forceVariables) {
  if (forceVariables.size() != forceVariableCount())
    throw std::invalid_argument("pointFromMotion: " + std::to_string(forceVariables.size()) + " force variables for " +
                                std::to_string(forceVariableCount()));
  return motionPoint(motionParameters, T, &forceVariables);
}

Eigen::VectorXd MotionProblem::motionPoint(const Eigen::VectorXd& motionParameters, double T,
                                           const Eigen::VectorXd* forceVariables) {
  if (motionParameters.size() != parameterCount_)
    throw std::invalid_argument("pointFromMotion: " + std::to_string(motionParameters.size()) + " spline parameters for " +
                                std::to_string(parameterCount_));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(variableCount_);
  x.head(parameterCount_) = motionParameters;
  const int m = parametrization_.parametersPerJoint();
  for (int j = 0; closure_ && j < jointCount_; ++j)
    for (int l = 0; l < m; ++l)
      if (unusedParameter_[static_cast<std::size_t>(j * m + l)]) x[j * m + l] = scenario_.start[j];  // (variableBounds)
  if (durationIsFree()) x[parameterCount_] = T;
  if (forceVariableCount() > 0 && forceVariables != nullptr) {
    x.segment(forceStart_, forceVariableCount()) = *forceVariables;
  } else if (forceVariableCount() > 0) {
    // The inner problem's wrenches along the initial motion: an admissible start, and the
    // bilevel optimum's forces are a feasible point of these formulations (formulation.md §9).
    // Its exact optimum, by the active-set method whatever `inner.solver` says: that is the
    // bilevel formulation's choice (the barrier's central point, an SLSQP answer), and a
    // single-level start should not hang on it (measured: the weight shift's `variables` run
    // from the barrier's wrenches ended `maximum_iterations` at 74.0 J, from the exact optima
    // optimal at 63.35 J).
    MultiContactSettings exact = scenario_.inner;
    exact.solverName = "active-set";
    std::vector<Eigen::MatrixXd> wrenches(scenario_.contacts.size(), Eigen::MatrixXd::Zero(6, samples_.sampleCount()));
    ThreadWorkspace& w = workspaces_.front();
    Eigen::MatrixXd controlPoints;
    parametrization_.controlPoints(x.head(parameterCount_), controlPoints);
    if (closure_ && !closureStarted_) startClosureAlongTheMotion(controlPoints, duration(x));
    std::unique_ptr<BilevelSample> previous;
    for (int s = 0; s < samples_.sampleCount(); ++s) {
      std::vector<int> which;
      for (int i = 0; i < outputs_.contacts; ++i)
        if (contactActive(i, s)) which.push_back(i);
      samples_.evaluate(s, controlPoints, duration(x), w.q, w.v, w.a);
      closeState(blocks_[static_cast<std::size_t>(s)], w, nullptr);
      inverseDynamics(modelOf(s), w.data, w.q, w.v, w.a);
      auto sample =
          std::make_unique<BilevelSample>(modelOf(s), surfacesInContact(s), exact, scenario_.sensitivity, weight_);
      if (previous) sample->warmStartFrom(*previous);
      sample->evaluate(modelOf(s), w.data, nullptr, scenario_.actuators, w.v, w.a, false);
      for (std::size_t k = 0; k < which.size(); ++k)
        wrenches[static_cast<std::size_t>(which[k])].col(s) =
            sample->problem().problem.contactWrench(sample->innerResult().wrenches, 1 + static_cast<int>(k));
      previous = std::move(sample);
    }
    formulation_->fit(wrenches, x.segment(forceStart_, forceVariableCount()));
  }
  startCostVariables(x);
  return x;
}

void MotionProblem::startCostVariables(Eigen::VectorXd& x) {
  if (variableCount_ == slackStart_) return;  // no cost term has variables of its own
  evaluate(x, false);
  forEachCostVariableBlock([&](const CostTerm& cost, int s, int first, int size) {
    cost.startSampleVariables(costSample(s, blocks_[static_cast<std::size_t>(s)]), x.segment(first, size));
  });
}

Eigen::VectorXd MotionProblem::pointWithWrenchesFrom(MotionProblem& other, const Eigen::VectorXd& x) {
  if (other.scenario_.contactForces != scenario_.contactForces || other.parameterCount_ != parameterCount_ ||
      (other.forceVariableCount() != 0) != (forceVariableCount() != 0))
    throw std::invalid_argument("pointWithWrenchesFrom: not the same scenario on another grid");
  if (forceVariableCount() == 0) return pointFromMotion(other.motionParameters(x), other.duration(x));
  Eigen::VectorXd y = Eigen::VectorXd::Zero(variableCount_);
  y.head(parameterCount_) = other.motionParameters(x);
  if (durationIsFree()) y[parameterCount_] = other.duration(x);
  if (formulation_->variablesIndependentOfGrid()) {
    if (other.forceVariableCount() != forceVariableCount())
      throw std::invalid_argument("pointWithWrenchesFrom: force splines of another size");
    y.segment(forceStart_, forceVariableCount()) = x.segment(other.forceStart_, other.forceVariableCount());
  } else {
    // Piecewise linear in time through other's samples, within the carried and the released
    // parts of a throw apart (the release instant is a sample of both grids, twice), and on the
    // same side of an instant sampled twice (a window's end: each side its own wrench).
    other.evaluate(x, false);
    const int M = other.samples_.sampleCount(), N = samples_.sampleCount();
    std::vector<Eigen::MatrixXd> wrenches(scenario_.contacts.size(), Eigen::MatrixXd::Zero(6, N));
    auto order = [](double u, int side) { return u + 1e-11 * side; };  // a twin just before or after its instant
    for (int s = 0; s < N; ++s) {
      const double u = order(sampleTimes_[static_cast<std::size_t>(s)], sampleSides_[static_cast<std::size_t>(s)]);
      const bool carried = loaded_[static_cast<std::size_t>(s)];
      int before = -1, after = -1;
      for (int k = 0; k < M; ++k) {
        if (other.loaded_[static_cast<std::size_t>(k)] != carried) continue;
        const double uk = order(other.sampleTimes_[static_cast<std::size_t>(k)], other.sampleSides_[static_cast<std::size_t>(k)]);
        if (uk <= u + 1e-12) before = k;
        if (uk >= u - 1e-12 && after < 0) after = k;
      }
      if (before < 0) before = after;
      if (after < 0) after = before;
      const double u0 = other.sampleTimes_[static_cast<std::size_t>(before)], u1 = other.sampleTimes_[static_cast<std::size_t>(after)];
      const double t = u1 > u0 ? (sampleTimes_[static_cast<std::size_t>(s)] - u0) / (u1 - u0) : 0.0;
      const SampleBlock& b0 = other.blocks_[static_cast<std::size_t>(before)];
      const SampleBlock& b1 = other.blocks_[static_cast<std::size_t>(after)];
      for (std::size_t i = 0; i < scenario_.contacts.size(); ++i) {
        const auto at = 6 * (1 + static_cast<Eigen::Index>(i));
        wrenches[i].col(s) = (1.0 - t) * b0.wrenches.segment<6>(at) + t * b1.wrenches.segment<6>(at);
      }
    }
    formulation_->fit(wrenches, y.segment(forceStart_, forceVariableCount()));
  }
  startCostVariables(y);
  return y;
}

Eigen::VectorXd MotionProblem::pointWithWrenches(const Eigen::VectorXd& motionParameters, double T,
                                                 const std::vector<Eigen::MatrixXd>& wrenches) {
  if (forceVariableCount() == 0) throw std::invalid_argument("pointWithWrenches: the formulation has no force variables");
  Eigen::VectorXd z = Eigen::VectorXd::Zero(forceVariableCount());
  formulation_->fit(wrenches, z);
  return pointFromMotion(motionParameters, T, z);
}

Eigen::VectorXd MotionProblem::reportedMotionParameters(const Eigen::VectorXd& x) {
  Eigen::VectorXd parameters = motionParameters(x);
  if (!closure_) return parameters;
  evaluate(x, false);
  const int N = samples_.sampleCount(), m = parametrization_.parametersPerJoint();
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(N, m);
  for (int s = 0; s < N; ++s) {
    const LocalParameterWeights& local = samples_.weights(s);
    for (int l = 0; l < local.count; ++l) basis(s, local.parameter[static_cast<std::size_t>(l)]) += local.value[static_cast<std::size_t>(l)];
  }
  // Per closing joint: its unused parameters fitted, least squares, to the closure's angles at
  // the samples where it is closed, the used ones (its spline outside a window) kept.
  for (int k = 0; k < outputs_.closing; ++k) {
    const int j = closure_->closingJoints()[static_cast<std::size_t>(k)];
    std::vector<int> rows, free;
    for (int s = 0; s < N; ++s)
      if (closure_->closesIn(j, blocks_[static_cast<std::size_t>(s)].closed)) rows.push_back(s);
    for (int l = 0; l < m; ++l)
      if (unusedParameter_[static_cast<std::size_t>(j * m + l)]) free.push_back(l);
    if (rows.empty() || free.empty()) continue;
    Eigen::MatrixXd A(rows.size(), free.size());
    Eigen::VectorXd residual(rows.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const int s = rows[r];
      residual[static_cast<Eigen::Index>(r)] = blocks_[static_cast<std::size_t>(s)].y[outputs_.closingPosition(k)];
      for (int l = 0; l < m; ++l) {
        const auto at = std::find(free.begin(), free.end(), l);
        if (at == free.end())
          residual[static_cast<Eigen::Index>(r)] -= basis(s, l) * parameters[j * m + l];
        else
          A(static_cast<Eigen::Index>(r), at - free.begin()) = basis(s, l);
      }
    }
    const Eigen::VectorXd fitted = A.colPivHouseholderQr().solve(residual);
    for (std::size_t f = 0; f < free.size(); ++f) parameters[j * m + free[f]] = fitted[static_cast<Eigen::Index>(f)];
  }
  return parameters;
}

}  // namespace mcopt
