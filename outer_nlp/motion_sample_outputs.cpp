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
#include "outer_nlp/motion_workspace.hpp"
#include "sensitivity/bilevel_sample.hpp"

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
  const int n = jointCount_, contacts = outputs_.contacts;
  const DynamicsModel& model = modelOf(s);  // with the ball before its release
  if (derivatives)
    inverseDynamicsDerivatives(model, w.data, w.derivatives, w.q, w.v, w.a);
  else
    inverseDynamics(model, w.data, w.q, w.v, w.a);
  const DynamicsDerivatives& d = w.derivatives;
  b.velocity = w.v;
  b.acceleration = w.a;
  b.wrenches.setZero();

  if (bilevel_) {
    // The inner problem picks the wrenches (formulation.md §7); Γ and its derivatives
    // through the KKT sensitivity (§8).
    BilevelSample& sample = *bilevelSamples_[static_cast<std::size_t>(s)];
    sample.evaluate(model, w.data, derivatives ? &d : nullptr, scenario_.actuators, w.v, w.a, derivatives);
    w.torque = sample.torque();
    b.y[outputs_.infeasibility()] = sample.infeasibility();
    const Eigen::VectorXd& F = sample.innerResult().wrenches;
    const ContactProblem& inner = sample.problem().problem;
    b.wrenches.head<6>() = inner.contactWrench(F, 0);
    for (int i = 0, k = 1; i < contacts; ++i)
      if (contactActive(i, s)) b.wrenches.segment<6>(6 * (1 + i)) = inner.contactWrench(F, k++);
    if (derivatives) {
      b.dyDq.topRows(n) = sample.torqueDq();
      b.dyDv.topRows(n) = sample.torqueDv();
      b.dyDa.topRows(n) = sample.torqueDa();
      b.dyDq.row(outputs_.infeasibility()) = sample.infeasibilityDq();
      b.dyDv.row(outputs_.infeasibility()) = sample.infeasibilityDv();
      b.dyDa.row(outputs_.infeasibility()) = sample.infeasibilityDa();
    }
  } else {
    // Γ = Γ0 − Σ J1_i F_i and W_ref = W0 − Σ wrenchToWorld_i F_i over the environment
    // contacts in contact here (formulation.md §5, §9); the reference contact takes W_ref.
    w.torque = w.data.tau;
    Vector6 reference = w.data.referenceWrench;
    if (derivatives) w.torqueDq = d.dtauDq, w.referenceDq = d.dwrenchDq;
    // A contact's rows depend on its own columns only: the others' entries must read zero
    // even in a block that served another sample (the Hessian's probes).
    if (derivatives) b.dyDz.setZero();
    for (int i = 0; i < contacts; ++i) {
      if (!forces_->active(i, s)) continue;
      Vector6 F = Vector6::Zero();
      for (const ContactForceParametrization::Term& t : forces_->terms(i, s)) F += t.weight * x.segment<6>(t.variable);
      b.wrenches.segment<6>(6 * (1 + i)) = F;
      const EnvironmentContact& contact = scenario_.contacts[static_cast<std::size_t>(i)];
      const ContactFrame frame = contactFrame(model, w.data, contact.surface.frame, contact.surface.placement);
      WrenchToTorque& toTorque = w.toTorque[static_cast<std::size_t>(i)];
      Matrix6& toWorld = w.toWorld[static_cast<std::size_t>(i)];
      wrenchToTorque(model, w.data, frame, toTorque);
      wrenchToWorld(frame, toWorld);
      w.torque.noalias() -= toTorque * F;
      reference.noalias() -= toWorld * F;
      contactRows_[static_cast<std::size_t>(i)].evaluate(F, b.y.segment(outputs_.contactRow(i, 0), outputs_.contactRowCount(1 + i)),
                                                        w.rowsByWrench[static_cast<std::size_t>(i)]);
      if (derivatives) {
        wrenchMapDerivatives(model, w.data, frame, F, w.dWorld, w.dTorque);
        w.torqueDq -= w.dTorque;
        w.referenceDq -= w.dWorld;
      }
    }
    const int perContact = support_.rowCount();
    ContactRowsByWrench& rowsByReference = w.rowsByReference;
    if (derivatives)
      support_.evaluate(reference, b.y.segment(outputs_.referenceRow(0), perContact), rowsByReference);
    else
      support_.evaluate(reference, b.y.segment(outputs_.referenceRow(0), perContact));
    b.wrenches.head<6>() = support_.contactWrench(reference);
    if (derivatives) {
      b.dyDq.topRows(n) = w.torqueDq;
      b.dyDv.topRows(n) = d.dtauDv;
      b.dyDa.topRows(n) = d.dtauDa;
      // Small products of run-time sizes: coefficient-based (lazyProduct), as Eigen's blocked
      // product may take heap workspace for them.
      b.dyDq.middleRows(outputs_.referenceRow(0), perContact).noalias() = rowsByReference.lazyProduct(w.referenceDq);
      b.dyDv.middleRows(outputs_.referenceRow(0), perContact).noalias() = rowsByReference.lazyProduct(d.dwrenchDv);
      b.dyDa.middleRows(outputs_.referenceRow(0), perContact).noalias() = rowsByReference.lazyProduct(d.dwrenchDa);
      // Force columns: ∂Γ/∂F_i = −J1_i, ∂rows_ref/∂F_i = −(∂rows/∂W_ref) wrenchToWorld_i,
      // ∂rows_i/∂F_i, each times the term's weight.
      // (`b` may be a Hessian probe: the sample's own block holds the column layout.)
      for (const SampleBlock::ForceTerm& t : blocks_[static_cast<std::size_t>(s)].forceTerms) {
        const auto i_ = static_cast<std::size_t>(t.contact);
        const int column = t.firstColumn;
        b.dyDz.block(outputs_.torque(0), column, n, 6) = -t.weight * w.toTorque[i_];
        b.dyDz.block(outputs_.referenceRow(0), column, perContact, 6).noalias() =
            -t.weight * rowsByReference.lazyProduct(w.toWorld[i_]);
        b.dyDz.block(outputs_.contactRow(t.contact, 0), column, outputs_.contactRowCount(1 + t.contact), 6) =
            t.weight * w.rowsByWrench[i_];
      }
    }
  }

  for (int j = 0; j < n; ++j) {
    const MotorPowerDerivatives p = motorPowerDerivatives(scenario_.actuators.joints[static_cast<std::size_t>(j)],
                                                          scenario_.actuators.frictionSharpness, w.torque[j], w.v[j],
                                                          w.a[j]);
    b.y[outputs_.torque(j)] = w.torque[j];
    b.y[outputs_.power(j)] = p.power;
    if (!derivatives) continue;
    const int row = outputs_.power(j);
    b.dyDq.row(row) = p.dTorque * b.dyDq.row(outputs_.torque(j));
    b.dyDv.row(row) = p.dTorque * b.dyDv.row(outputs_.torque(j));
    b.dyDa.row(row) = p.dTorque * b.dyDa.row(outputs_.torque(j));
    b.dyDv(row, j) += p.dVelocity;
    b.dyDa(row, j) += p.dAcceleration;
    if (b.dyDz.cols() > 0) b.dyDz.row(row) = p.dTorque * b.dyDz.row(outputs_.torque(j));
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
}

void MotionProblem::evaluateTaskInstant(int i, double T, bool derivatives, ThreadWorkspace& w) {
  SampleBlock& b = taskBlocks_[static_cast<std::size_t>(i)];
  taskSamples_.evaluate(i, controlPoints_, T, w.q, w.v, w.a);
  closeAndRemember(b, w, derivatives);
  taskOutputs(i, derivatives, w, b);
  if (!derivatives) return;
  if (closure_) {
    // Tasks read q and q̇; the closure's q_C and q̇_C depend on no q̈.
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
