// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// MotionProblem's per-thread evaluation buffers, shared by its evaluation
// (motion_problem.cpp) and its Hessian (motion_hessian.cpp); not part of the interface.
#include <Eigen/Core>
#include <vector>

#include "core/contact_maps.hpp"
#include "core/dynamics_data.hpp"
#include "core/dynamics_derivatives.hpp"
#include "core/dynamics_model.hpp"
#include "core/spatial.hpp"
#include "outer_nlp/closed_chains.hpp"
#include "outer_nlp/contact_admissibility.hpp"
#include "outer_nlp/task.hpp"

namespace mcopt {

/// MotionProblem's per-thread buffers, sized once (the per-sample path allocates nothing).
struct MotionWorkspace {
  /// `held`: contacts held over the whole motion, `closing` their closing joints, `outputs` a
  /// sample's outputs (the chain rule through the closure works on those).
  /// `contactRows`: the admissibility rows of the reference contact, then of each environment contact.
  /// `taskRows`: the largest task dimension (the task instants' buffers' rows).
  MotionWorkspace(const DynamicsModel& model, const std::vector<int>& contactRows, int held = 0, int closing = 0,
                  int outputs = 0, int taskRows = kMaxTaskDimension)
      : data(model), derivatives(model), task(model), closure(model, held) {
    const int n = model.jointCount();
    q.setZero(n), v.setZero(n), a.setZero(n), torque.setZero(n);
    powerByTorque.setZero(n), powerByVelocity.setZero(n), powerByAcceleration.setZero(n);
    torqueDq.setZero(n, n), referenceDq.setZero(6, n), dWorld.setZero(6, n), dTorque.setZero(n, n);
    const std::size_t contacts = contactRows.size() - 1;
    toTorque.assign(contacts, WrenchToTorque::Zero(n, 6));
    toWorld.assign(contacts, Matrix6::Zero());
    for (std::size_t i = 0; i < contacts; ++i) rowsByWrench.emplace_back(ContactRowsByWrench::Zero(contactRows[i + 1], 6));
    rowsByReference.setZero(contactRows.front(), 6);
    gather.setZero(outputs, 3 * closing), foldQ.setZero(outputs, n), foldV.setZero(outputs, n), foldA.setZero(outputs, n);
    taskGather.setZero(taskRows, 3 * closing), taskFoldQ.setZero(taskRows, n), taskFoldV.setZero(taskRows, n),
        taskFoldA.setZero(taskRows, n);
  }
  DynamicsData data;
  DynamicsDerivatives derivatives;
  TaskWorkspace task;
  Eigen::VectorXd q, v, a, torque;
  Eigen::VectorXd powerByTorque, powerByVelocity, powerByAcceleration;  ///< ∂P_j/∂(Γ_j, q̇_j, q̈_j) at the sample
  Eigen::MatrixXd torqueDq, dTorque;
  Eigen::Matrix<double, 6, Eigen::Dynamic> referenceDq, dWorld;
  std::vector<WrenchToTorque> toTorque;  ///< per environment contact, J1_i
  std::vector<Matrix6> toWorld;          ///< per environment contact, wrenchToWorld_i
  std::vector<ContactRowsByWrench> rowsByWrench;  ///< per environment contact, ∂rows_i/∂F_i
  ContactRowsByWrench rowsByReference;           ///< ∂rows_ref/∂W_ref
  ClosedChainData closure;                       ///< the closure's Newton and its map
  Eigen::MatrixXd gather, foldQ, foldV, foldA;   ///< a sample's outputs folded through the closure
  Eigen::MatrixXd taskGather, taskFoldQ, taskFoldV, taskFoldA;  ///< a task instant's
};

}  // namespace mcopt
