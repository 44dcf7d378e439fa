// SPDX-License-Identifier: BSD-3-Clause
#include "sensitivity/bilevel_sample.hpp"

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"

namespace mcopt {

BilevelSample::BilevelSample(const DynamicsModel& model, std::vector<ContactSurface> contacts,
                             const MultiContactSettings& settings, const SensitivitySettings& sensitivity, double weight)
    : contacts_(std::move(contacts)),
      scale_(1.0 / (weight * weight)),
      sample_(model, contacts_, settings.problem),
      solver_(makeInnerSolver(settings.solverName, settings.solver)),
      sensitivity_(sensitivity) {
  if (contacts_.empty()) throw InputError("bilevel sample: no contact surface given");
  const int variables = sample_.problem.variableCount();
  torque_.setZero(model.jointCount());
  // Room for the largest active set, so that warm starts copy without allocating.
  result_.activeSet.reserve(static_cast<std::size_t>(sample_.problem.inequality.rows()) + sample_.problem.cones.size());
  if (settings.feasibility == InnerFeasibility::Margin) {
    // Moments in units of m g ℓ, ℓ the largest half-extent of the sample's contact rectangles.
    double length = 0.0;
    for (const ContactSurface& c : contacts_)
      length = std::max({length, std::abs(c.xMin), std::abs(c.xMax), std::abs(c.yMin), std::abs(c.yMax)});
    MarginSettings marginSettings;
    marginSettings.weight = weight;
    if (length > 0.0) marginSettings.length = length;
    margin_ = std::make_unique<AdmissibilityMargin>(sample_.problem, marginSettings);
    marginResult_.activeSet.reserve(static_cast<std::size_t>(sample_.problem.inequality.rows()) + 1);
    marginResult_.wrenches.setZero(variables);
  }
}

void BilevelSample::sizeDerivatives(int n) {
  const int variables = sample_.problem.variableCount();
  g_.setZero(n), linearDv_.setZero(n), linearDa_.setZero(n);
  for (Eigen::MatrixXd* m : {&dTorqueDq_, &dTorqueDv_, &dTorqueDa_, &dJ1Fdq_, &dTorque_, &scaled_, &fixedDq_, &fixedDv_, &fixedDa_})
    m->setZero(n, n);
  dF_.setZero(variables, 3 * n), stationarity_.setZero(variables, 3 * n), balance_.setZero(6, 3 * n);
  for (auto* m : {&dBFdq_, &dLeastSlackBFdq_, &dWorld_, &dTorqueT_, &dWorldT_}) m->setZero(6, n);
  for (Eigen::RowVectorXd* r : {&dInfeasibilityDq_, &dInfeasibilityDv_, &dInfeasibilityDa_}) r->setZero(n);
}

BilevelSample::~BilevelSample() = default;
BilevelSample::BilevelSample(BilevelSample&&) noexcept = default;
BilevelSample& BilevelSample::operator=(BilevelSample&&) noexcept = default;

void BilevelSample::warmStartFrom(const BilevelSample& other) {
  if (other.contactCount() != contactCount() || !other.hasResult() ||
      other.sample_.problem.contactColumn != sample_.problem.contactColumn)
    return;
  result_.wrenches = other.result_.wrenches;
  result_.activeSet = other.result_.activeSet;
  result_.inequalityMultipliers = other.result_.inequalityMultipliers;
  result_.coneMultipliers = other.result_.coneMultipliers;
  result_.balanceMultipliers = other.result_.balanceMultipliers;
  result_.barrier = other.result_.barrier;
  if (margin_ && other.margin_) marginResult_.activeSet = other.marginResult_.activeSet;
}

void BilevelSample::evaluate(const DynamicsModel& model, const DynamicsData& data, const DynamicsDerivatives* d,
                             const ActuatorSet& actuators, const Eigen::Ref<const Eigen::VectorXd>& v,
                             const Eigen::Ref<const Eigen::VectorXd>& a, bool withDerivatives, bool solveKkt) {
  const int n = model.jointCount(), nc = contactCount();
  if (withDerivatives && d == nullptr) throw InputError("bilevel sample: derivatives requested without dynamics derivatives");
  // The inner problem of this sample (formulation.md §5, §7): J1, the contact poses, W0.
  sample_.update(model, data, actuators, contacts_, v, a);
  solver_->solve(sample_.problem, result_);
  const Eigen::MatrixXd& J1 = sample_.wrenchToTorque;
  torque_ = data.tau;
  torque_.noalias() -= J1 * result_.wrenches;
  // The row: −m_ε (margin), or φ at the least-slack phase's point, the function whose
  // derivative the envelope theorem gives.
  const bool infeasible = result_.status == InnerStatus::Infeasible;
  if (infeasible) leastSlack_.noalias() = data.referenceWrench - sample_.problem.balance * result_.leastSlackWrenches;
  if (margin_) margin_->solve(sample_.problem, marginResult_);
  const bool byMargin = margin_ && marginResult_.solved;
  infeasibility_ = byMargin ? -marginResult_.margin : infeasible ? scale_ * leastSlack_.squaredNorm() : 0.0;
  hasWrenchDerivative_ = false;
  if (!withDerivatives) return;
  if (dTorqueDq_.rows() != n) sizeDerivatives(n);  // the first evaluation with derivatives

  // ∂(J1 F)/∂q and ∂(B F)/∂q at the chosen wrenches.
  dJ1Fdq_.setZero();
  dBFdq_.setZero();
  for (int i = 0; i < nc; ++i) {
    const Vector6 wrench = sample_.problem.contactWrench(result_.wrenches, i);
    wrenchMapDerivatives(model, data, sample_.frames[static_cast<std::size_t>(i)], wrench, dWorld_, dTorque_);
    dJ1Fdq_ += dTorque_;
    dBFdq_ += dWorld_;
  }
  // The row's derivative (header): −λᵀ (∂W0/∂x − ∂(B F)/∂x) at the margin's maximiser, or
  // φ's 2 sᵀ (∂W0/∂x − ∂(B F)/∂x)/(m g)² at the least-slack phase's own minimiser.
  if (byMargin) {
    balanceRowDerivative(model, data, *d, marginResult_.wrenches, marginResult_.balanceGradient, -1.0);
  } else if (infeasible) {
    balanceRowDerivative(model, data, *d, result_.leastSlackWrenches, leastSlack_, 2.0 * scale_);
  } else {
    dInfeasibilityDq_.setZero(), dInfeasibilityDv_.setZero(), dInfeasibilityDa_.setZero();
  }

  dF_.setZero();
  if (result_.status == InnerStatus::Optimal) {
    diagnostics_ = sensitivity_.factorize(sample_.problem, result_);
    // Right-hand sides at fixed F and multipliers (multi_contact_gradient.hpp).
    g_.noalias() = 2.0 * sample_.weights.cwiseProduct(torque_);
    g_ += sample_.linear;
    innerObjectiveTermDerivatives(actuators, v, linearDv_, linearDa_);
    for (int i = 0; i < nc; ++i) {
      transposedWrenchMapDerivatives(model, data, sample_.frames[static_cast<std::size_t>(i)], g_,
                                     result_.balanceMultipliers, dTorqueT_, dWorldT_);
      // The rows of the contact's variables: all six, or the force's three.
      const int size = sample_.problem.wrenchSize(i);
      stationarity_.block(sample_.problem.contactColumn[static_cast<std::size_t>(i)], 0, size, n) =
          (dWorldT_ - dTorqueT_).topRows(size);
    }
    const auto& weights = sample_.weights;
    scaled_.noalias() = 2.0 * weights.asDiagonal() * (d->dtauDq - dJ1Fdq_);
    stationarity_.leftCols(n).noalias() -= J1.transpose() * scaled_;
    scaled_.noalias() = 2.0 * weights.asDiagonal() * d->dtauDv;
    scaled_.diagonal() += linearDv_;
    stationarity_.middleCols(n, n).noalias() = -J1.transpose() * scaled_;
    scaled_.noalias() = 2.0 * weights.asDiagonal() * d->dtauDa;
    scaled_.diagonal() += linearDa_;
    stationarity_.rightCols(n).noalias() = -J1.transpose() * scaled_;
    balance_.leftCols(n) = dBFdq_ - d->dwrenchDq;
    balance_.middleCols(n, n) = -d->dwrenchDv;
    balance_.rightCols(n) = -d->dwrenchDa;
    if (solveKkt) sensitivity_.solve(stationarity_, balance_, dF_);
    hasWrenchDerivative_ = true;
  } else {
    diagnostics_ = SensitivityDiagnostics{};
  }
  fixedDq_ = d->dtauDq - dJ1Fdq_;
  fixedDv_ = d->dtauDv;
  fixedDa_ = d->dtauDa;
  updateTorqueDerivatives();
}

void BilevelSample::balanceRowDerivative(const DynamicsModel& model, const DynamicsData& data, const DynamicsDerivatives& d,
                                         const Eigen::VectorXd& wrenches, const Vector6& c, double factor) {
  dLeastSlackBFdq_.setZero();
  for (int i = 0; i < contactCount(); ++i) {
    const Vector6 wrench = sample_.problem.contactWrench(wrenches, i);
    wrenchMapDerivatives(model, data, sample_.frames[static_cast<std::size_t>(i)], wrench, dWorld_, dTorque_);
    dLeastSlackBFdq_ += dWorld_;
  }
  dInfeasibilityDq_.noalias() = factor * c.transpose() * (d.dwrenchDq - dLeastSlackBFdq_);
  dInfeasibilityDv_.noalias() = factor * c.transpose() * d.dwrenchDv;
  dInfeasibilityDa_.noalias() = factor * c.transpose() * d.dwrenchDa;
}

void BilevelSample::setWrenchDerivative(const Eigen::Ref<const Eigen::MatrixXd>& dF) {
  if (dF.rows() != dF_.rows() || dF.cols() != dF_.cols())
    throw InputError("bilevel sample: wrench derivative of " + std::to_string(dF.rows()) + " × " +
                     std::to_string(dF.cols()) + ", expected " + std::to_string(dF_.rows()) + " × " +
                     std::to_string(dF_.cols()));
  dF_ = dF;
  updateTorqueDerivatives();
}

void BilevelSample::updateTorqueDerivatives() {
  // dΓ/dx = dΓ0/dx − (∂J1/∂x) F − J1 dF/dx  (4.8)
  const Eigen::MatrixXd& J1 = sample_.wrenchToTorque;
  const Eigen::Index n = fixedDq_.cols();
  dTorqueDq_ = fixedDq_;
  dTorqueDq_.noalias() -= J1 * dF_.leftCols(n);
  dTorqueDv_ = fixedDv_;
  dTorqueDv_.noalias() -= J1 * dF_.middleCols(n, n);
  dTorqueDa_ = fixedDa_;
  dTorqueDa_.noalias() -= J1 * dF_.rightCols(n);
}

}  // namespace mcopt
