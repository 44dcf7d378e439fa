// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Configuration optimisation (report §3.5, formulation.md §10): a static posture q for the
// start or the end of the motion that minimises the static electrical power under the
// support contact and the tasks that hold at that instant.
//
// Static: q̇ = q̈ = 0, so Γ = gravity torques and the motor speed is zero. With Ω = 0 the
// dry friction can hold up to Γ_d of the load (the report: "dry friction effect is opposed
// to the gravity effects"), so the winding carries Γem = max(|Γ/N| − Γ_d, 0) and
//   P_static = Σ_j (R_j / K_j²) max(|Γ_j / N_j| − Γ_d,j, 0)²,
// which is C¹ (its slope is continuous at |Γ/N| = Γ_d). Constraints: joint limits (bounds),
// the support contact rows of W0 (contact_admissibility.hpp), position, orientation and
// centre-of-mass tasks at that instant (velocity tasks are zero-velocity-free: ignored).
//
// With a `near` posture it is a reach instead: the posture closest to `near` (½‖q − near‖²)
// that meets the tasks at that instant, without the support's rows — the posture the initial
// motion passes through where a contact with a window holds (its closure one of those tasks:
// the closing joints can then reach it; motion_problem.hpp).

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/dynamics_derivatives.hpp"
#include "outer_nlp/nlp_problem.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/contact_admissibility.hpp"
#include "outer_nlp/task.hpp"

namespace mcopt {

class ConfigurationProblem final : public NlpProblem {
 public:
  /// instant: time of the posture in the motion [s] (0 for the start, T for the end).
  ConfigurationProblem(const Scenario& scenario, const DynamicsModel& model, const ContactAdmissibilityRows& support,
                       double instant, std::optional<Eigen::VectorXd> near = std::nullopt);

  int variableCount() const override { return jointCount_; }
  int constraintCount() const override { return static_cast<int>(rowTask_.size()); }
  const Eigen::VectorXi& jacobianRows() const override { return jacobianRows_; }
  const Eigen::VectorXi& jacobianColumns() const override { return jacobianColumns_; }
  void variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override;
  void constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override;
  double objective(const Eigen::VectorXd& q) override;
  void objectiveGradient(const Eigen::VectorXd& q, Eigen::VectorXd& gradient) override;
  void constraints(const Eigen::VectorXd& q, Eigen::VectorXd& values) override;
  void jacobianValues(const Eigen::VectorXd& q, Eigen::VectorXd& values) override;
  std::string rowName(int row) const override;

  /// Static electrical power [W] (the objective without `near`).
  double staticPower(const Eigen::VectorXd& q);

 private:
  void evaluate(const Eigen::VectorXd& q);

  const Scenario& scenario_;
  const DynamicsModel& model_;
  const ContactAdmissibilityRows& support_;
  std::optional<Eigen::VectorXd> near_;
  int supportRows_ = 0;              ///< the support's rows first (none for a reach)
  int jointCount_;
  std::vector<int> tasks_;           ///< scenario tasks that hold at the instant
  std::vector<int> rowTask_;         ///< −1 for the contact rows, else the task
  std::vector<int> rowComponent_;
  Eigen::VectorXi jacobianRows_, jacobianColumns_;

  DynamicsData data_;
  DynamicsDerivatives derivatives_;
  TaskWorkspace taskWorkspace_;
  ContactRowsByWrench rowsByWrench_;
  Eigen::VectorXd zero_, cachedQ_, rows_;
  Eigen::MatrixXd rowsByQ_;
  Eigen::VectorXd taskValue_;  ///< kMaxTaskDimension: a task uses its leading rows
  Eigen::MatrixXd taskDq_, taskDv_;
  bool cacheValid_ = false;
};

}  // namespace mcopt
