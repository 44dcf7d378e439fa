// SPDX-License-Identifier: BSD-3-Clause
// One sample of the motion problem (formulation.md §9, §10): its state from the splines, the
// closure, the contact-force formulation's wrenches and the outputs every row and cost reads,
// with their derivatives; and the same for a task instant between samples. The loop over the
// samples is MotionProblem::evaluate (motion_problem.cpp).
#include "outer_nlp/motion_problem.hpp"

#include <cmath>
#include <string>

#include "core/contact_maps.hpp"
#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/spatial.hpp"
#include "core/trajectory_evaluation.hpp"
#include "outer_nlp/contact_force_formulation.hpp"
#include "outer_nlp/motion_workspace.hpp"

namespace mcopt {

void MotionProblem::evaluateSample(int s, const Eigen::VectorXd& x, double T, bool derivatives, ThreadWorkspace& w) {
  SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
  samples_.evaluate(s, controlPoints_, T, w.q, w.v, w.a);
  closeAndRemember(b, w, derivatives);
  sampleOutputs(s, x, derivatives, w, b);
  if (!derivatives) return;
  if (closure_) {
    foldClosure(b, w.gather, w.foldQ, w.foldV, w.foldA);
    samples_.chainRule(s, T, w.foldQ, w.foldV, w.foldA, b.dyDx, b.parameters);
  } else {
    samples_.chainRule(s, T, b.dyDq, b.dyDv, b.dyDa, b.dyDx, b.parameters);
  }
  // The closing joints' state scales with T as the splines' (it is theirs through the closure).
  SampledTrajectory::durationDerivative(T, b.dyDv, b.dyDa, w.v, w.a, b.dyDT);
}

void MotionProblem::sampleOutputs(int s, const Eigen::VectorXd& x, bool derivatives, ThreadWorkspace& w,
                                  SampleBlock& b) {
  const int n = jointCount_;
  const DynamicsModel& model = modelOf(s);  // with the ball before its release
  if (derivatives)
    inverseDynamicsDerivatives(model, w.data, w.derivatives, w.q, w.v, w.a);
  else
    inverseDynamics(model, w.data, w.q, w.v, w.a);
  b.velocity = w.v;
  b.acceleration = w.a;
  b.wrenches.setZero();
  // Γ, the contact wrenches and the formulation's rows (contact_force_formulation.hpp).
  FormulationSample sample{s, model, w, x, derivatives, blocks_[static_cast<std::size_t>(s)].forceTerms,
                           b.y, b.wrenches, b.dyDq, b.dyDv, b.dyDa, b.dyDz};
  formulation_->sampleOutputs(sample);

  // P_j = P(Γ_j, q̇_j, q̈_j): its rows are ∂P/∂Γ times Γ_j's, plus its own q̇_j and q̈_j
  // entries. The torque and power rows are two blocks of n rows (sample_outputs.hpp): the
  // products are taken block by block (contiguous columns, not rows n apart).
  for (int j = 0; j < n; ++j) {
    const MotorPowerDerivatives p = motorPowerDerivatives(scenario_.actuators.joints[static_cast<std::size_t>(j)],
                                                          scenario_.actuators.frictionSharpness, w.torque[j], w.v[j],
                                                          w.a[j]);
    b.y[outputs_.torque(j)] = w.torque[j];
    b.y[outputs_.power(j)] = p.power;
    if (!derivatives) continue;
    w.powerByTorque[j] = p.dTorque, w.powerByVelocity[j] = p.dVelocity, w.powerByAcceleration[j] = p.dAcceleration;
  }
  if (derivatives) {
    const int torques = outputs_.torque(0), powers = outputs_.power(0);
    const auto scale = w.powerByTorque.asDiagonal();
    b.dyDq.middleRows(powers, n).noalias() = scale * b.dyDq.middleRows(torques, n);
    b.dyDv.middleRows(powers, n).noalias() = scale * b.dyDv.middleRows(torques, n);
    b.dyDa.middleRows(powers, n).noalias() = scale * b.dyDa.middleRows(torques, n);
    b.dyDv.middleRows(powers, n).diagonal() += w.powerByVelocity;
    b.dyDa.middleRows(powers, n).diagonal() += w.powerByAcceleration;
    if (b.dyDz.cols() > 0) b.dyDz.middleRows(powers, n).noalias() = scale * b.dyDz.middleRows(torques, n);
  }
  // The closing joints' angles and velocities, for their limits (their derivatives in the
  // full state: unit rows, folded through the closure by the caller).
  for (int k = 0; k < outputs_.closing; ++k) {
    const int j = closure_->closingJoints()[static_cast<std::size_t>(k)];
    b.y[outputs_.closingPosition(k)] = w.q[j];
    b.y[outputs_.closingVelocity(k)] = w.v[j];
    if (!derivatives) continue;
    for (const int row : {outputs_.closingPosition(k), outputs_.closingVelocity(k)}) {
      b.dyDq.row(row).setZero(), b.dyDv.row(row).setZero(), b.dyDa.row(row).setZero();
      if (b.dyDz.cols() > 0) b.dyDz.row(row).setZero();
    }
    b.dyDq(outputs_.closingPosition(k), j) = 1.0;
    b.dyDv(outputs_.closingVelocity(k), j) = 1.0;
  }
  // Each held contact's loop's reach, a fraction of its longest (closed_chains.hpp LoopReach):
  // a function of the pose alone.
  for (int i = 0; i < outputs_.reaches; ++i) {
    const int row = outputs_.loopReach(i);
    if (!derivatives) {
      b.y[row] = closure_->reachRatio(w.data, i);
      continue;
    }
    b.dyDq.row(row).setZero(), b.dyDv.row(row).setZero(), b.dyDa.row(row).setZero();
    if (b.dyDz.cols() > 0) b.dyDz.row(row).setZero();
    b.y[row] = closure_->reachRatio(model, w.data, i, b.dyDq.row(row));
  }
}

void MotionProblem::evaluateTaskInstant(int i, double T, bool derivatives, ThreadWorkspace& w) {
  SampleBlock& b = taskBlocks_[static_cast<std::size_t>(i)];
  taskSamples_.evaluate(i, controlPoints_, T, w.q, w.v, w.a);
  // Tasks read q and q̇ (the dynamics' forward pass takes the splines' q̈, which no task reads).
  closeAndRemember(b, w, derivatives, ClosureOrder::Velocities);
  taskOutputs(i, derivatives, w, b);
  if (!derivatives) return;
  if (closure_) {
    // The closure's q_C and q̇_C depend on no q̈ (the map's q̈ rows are zero).
    const Eigen::Index d = b.y.size();
    foldClosure(b, w.taskGather.topRows(d), w.taskFoldQ.topRows(d), w.taskFoldV.topRows(d), w.taskFoldA.topRows(d));
    taskSamples_.chainRule(i, T, w.taskFoldQ.topRows(d), w.taskFoldV.topRows(d), Eigen::MatrixXd(), b.dyDx, b.parameters);
  } else {
    taskSamples_.chainRule(i, T, b.dyDq, b.dyDv, Eigen::MatrixXd(), b.dyDx, b.parameters);
  }
  SampledTrajectory::durationDerivative(T, b.dyDv, b.dyDa, w.v, w.a, b.dyDT);
}

void MotionProblem::taskOutputs(int i, bool derivatives, ThreadWorkspace& w, SampleBlock& b) {
  const Task& task = *scenario_.tasks[static_cast<std::size_t>(taskOfInstant_[static_cast<std::size_t>(i)])].task;
  const int d = task.dimension();  // b's leading rows: a probe has taskRows_
  inverseDynamics(model_, w.data, w.q, w.v, w.a);
  if (derivatives)
    task.calcDiff(model_, w.data, w.task, b.y.head(d), b.dyDq.topRows(d), b.dyDv.topRows(d));
  else
    task.calc(model_, w.data, w.task, b.y.head(d));
}

}  // namespace mcopt
