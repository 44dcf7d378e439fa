// SPDX-License-Identifier: BSD-3-Clause
// The motion problem's closure by construction (docs/theory/outer-problem.md, "Closure by
// construction"): each closed sample's closing joints solved from the others, warm-started
// along the motion, and the closure's map folded into the sample's derivatives.
#include "outer_nlp/motion_problem.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "core/contact_maps.hpp"
#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/spatial.hpp"
#include "core/trajectory_evaluation.hpp"
#include "outer_nlp/motion_workspace.hpp"

namespace mcopt {

bool MotionProblem::closeState(const SampleBlock& b, ThreadWorkspace& w, Eigen::MatrixXd* map, ClosureOrder order) const {
  if (!closure_) return true;
  // Newton from the angles reached last at this instant: the same closure, in one or two steps.
  if (!b.startFromSplines) closure_->placeAngles(b.closedAngles, b.closed, w.q);
  return closure_->close(model_, w.closure, w.q, w.v, w.a, map, b.closed, order);
}

void MotionProblem::startClosureAlongTheMotion(const Eigen::MatrixXd& controlPoints, double T) {
  ThreadWorkspace& w = workspaces_.front();
  for (std::size_t s = 0; s < blocks_.size(); ++s) {
    SampleBlock& b = blocks_[s];
    samples_.evaluate(static_cast<int>(s), controlPoints, T, w.q, w.v, w.a);
    // From the sample before where it closed the same joints (a window's start: the splines').
    if (s > 0 && !b.startFromSplines) closure_->placeAngles(blocks_[s - 1].closedAngles, b.closed & blocks_[s - 1].closed, w.q);
    closure_->close(model_, w.closure, w.q, w.v, w.a, nullptr, b.closed);
    b.closedAngles.setConstant(std::numeric_limits<double>::quiet_NaN());
    closure_->readAngles(w.q, b.closed, b.closedAngles);
  }
  startTaskClosures();
  closureStarted_ = true;
}

void MotionProblem::checkLoopReaches() const {
  const double margin = scenario_.closureReachMargin;
  DynamicsData data(model_);
  for (int i = 0; i < closure_->contactCount(); ++i) {
    const LoopReach& reach = closure_->reach(i);
    const std::string loop = closure_->loopName(scenario_.robot, i);
    if (!std::isfinite(reach.longest))
      throw InputError(scenario_.file.string() + ": closure_reach_margin: " + loop +
                       " has a sliding joint without limits, so no longest reach");
    for (const auto& [fixed, posture, u, side, name] :
         {std::tuple{scenario_.fixStart, &scenario_.start, 0.0, +1, "start"}, std::tuple{scenario_.fixEnd, &scenario_.end, 1.0, -1, "end"}}) {
      if (!fixed || !((closure_->closedAt(u, side) >> i) & 1U)) continue;
      forwardKinematics(model_, data, *posture);
      const double ratio = closure_->reachRatio(data, i);
      if (ratio > 1.0 - margin)
        throw InputError(scenario_.file.string() + ": closure_reach_margin: the fixed " + name + " posture stretches " + loop +
                         " to " + std::to_string(ratio) + " of its longest reach (" + std::to_string(reach.longest) +
                         " m), beyond 1 − " + std::to_string(margin) + "; lower the margin or bend the posture");
    }
  }
}

void MotionProblem::startTaskClosures() {
  for (std::size_t i = 0; i < taskBlocks_.size(); ++i) {
    SampleBlock& t = taskBlocks_[i];
    const double u = taskSamples_.time(static_cast<int>(i), 1.0);
    for (int k = 0; k < outputs_.closing; ++k) {
      double nearest = std::numeric_limits<double>::infinity();
      t.closedAngles[k] = std::numeric_limits<double>::quiet_NaN();
      for (std::size_t s = 0; s < blocks_.size(); ++s) {
        const double distance = std::abs(sampleTimes_[s] - u);
        if (std::isfinite(blocks_[s].closedAngles[k]) && distance < nearest) nearest = distance, t.closedAngles[k] = blocks_[s].closedAngles[k];
      }
    }
  }
}

void MotionProblem::closeAndRemember(SampleBlock& b, ThreadWorkspace& w, bool derivatives, ClosureOrder order) {
  if (!closure_ || !closeState(b, w, derivatives ? &b.closureMap : nullptr, order)) return;
  closure_->readAngles(w.q, b.closed, b.closedAngles);
}

void MotionProblem::foldClosure(const SampleBlock& b, Eigen::Ref<Eigen::MatrixXd> gather, Eigen::Ref<Eigen::MatrixXd> dq,
                                Eigen::Ref<Eigen::MatrixXd> dv, Eigen::Ref<Eigen::MatrixXd> da) const {
  // ∂y/∂x_F = ∂y/∂x_F|_C fixed + ∂y/∂x_C M, x = (q, q̇, q̈); the closing joints' own columns then read zero.
  const int c = outputs_.closing, n = jointCount_;
  const std::vector<int>& closing = closure_->closingJoints();
  for (int k = 0; k < c; ++k) {
    const int j = closing[static_cast<std::size_t>(k)];
    gather.col(k) = b.dyDq.col(j), gather.col(c + k) = b.dyDv.col(j), gather.col(2 * c + k) = b.dyDa.col(j);
  }
  dq = b.dyDq, dv = b.dyDv, da = b.dyDa;
  dq.noalias() += gather * b.closureMap.leftCols(n);
  dv.noalias() += gather * b.closureMap.middleCols(n, n);
  da.noalias() += gather * b.closureMap.rightCols(n);
  for (const int j : closing)
    if (closure_->closesIn(j, b.closed)) dq.col(j).setZero(), dv.col(j).setZero(), da.col(j).setZero();
}

void MotionProblem::foldGradient(const Eigen::MatrixXd& map, ClosureSet closed, int stateBlocks,
                                 Eigen::Ref<Eigen::VectorXd> gradient) const {
  const int c = outputs_.closing, n = jointCount_;
  const std::vector<int>& closing = closure_->closingJoints();
  for (int block = 0; block < stateBlocks; ++block)
    for (int k = 0; k < c; ++k) {
      if (!closure_->closesIn(closing[static_cast<std::size_t>(k)], closed)) continue;
      const int at = block * n + closing[static_cast<std::size_t>(k)];
      const double g = gradient[at];
      gradient[at] = 0.0;
      if (g != 0.0) gradient.head(stateBlocks * n) += g * map.row(block * c + k).head(stateBlocks * n).transpose();
    }
}

Eigen::MatrixXd MotionProblem::closureAngles() const {
  Eigen::MatrixXd angles(outputs_.closing, static_cast<Eigen::Index>(blocks_.size()));
  for (std::size_t s = 0; s < blocks_.size() && outputs_.closing > 0; ++s) angles.col(static_cast<Eigen::Index>(s)) = blocks_[s].closedAngles;
  return angles;
}

void MotionProblem::startClosureAt(const Eigen::MatrixXd& angles) {
  if (!closure_ || angles.rows() != outputs_.closing || angles.cols() != static_cast<Eigen::Index>(blocks_.size())) return;
  for (std::size_t s = 0; s < blocks_.size(); ++s) blocks_[s].closedAngles = angles.col(static_cast<Eigen::Index>(s));
  startTaskClosures();
  closureStarted_ = true;
  cacheValid_ = false;
}

}  // namespace mcopt
