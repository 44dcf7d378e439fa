// SPDX-License-Identifier: BSD-3-Clause
// The single-level formulations (formulation.md §9; contact_force_formulation.hpp): each
// environment contact's wrench is linear in NLP variables z (splines: a clamped cubic B-spline
// per component over its window; variables: six per sample in contact;
// contact_force_parametrization.hpp), Γ = Γ0 − Σ J1_i F_i, and the reference contact takes
// W_ref = W0 − Σ wrenchToWorld_i F_i, so the balance holds exactly. Every contact's
// admissibility rows are outer rows. With no environment contact this is the one-contact
// problem (W_ref = W0, no variables) whatever the scenario's formulation.
#include <memory>
#include <optional>
#include <vector>

#include "core/contact_maps.hpp"
#include "inner_qp/contact_problem.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"
#include "outer_nlp/contact_force_formulation.hpp"
#include "outer_nlp/motion_workspace.hpp"

namespace mcopt {

namespace {

class ForceVariablesFormulation final : public ContactForceFormulation {
 public:
  ForceVariablesFormulation(const FormulationContext& c, ContactForceParametrization::Layout layout)
      : scenario_(c.scenario), outputs_(c.outputs), support_(c.support), contactRows_(c.contactRows), layout_(layout),
        firstVariable_(c.firstVariable), weight_(c.weight) {
    if (!scenario_.contacts.empty())
      forces_.emplace(layout, c.windows, c.sampleTimes, c.active, scenario_.forceControlPoints, c.firstVariable);
  }

  int variableCount() const override { return forces_ ? forces_->variableCount() : 0; }
  bool variablesIndependentOfGrid() const override { return layout_ == ContactForceParametrization::Layout::Splines; }

  void variableBounds(Eigen::Ref<Eigen::VectorXd> lower, Eigen::Ref<Eigen::VectorXd> upper) const override {
    // A contact whose model holds a force alone (the point contact): its moment variables are
    // fixed at zero.
    for (int i = 0; forces_ && i < forces_->contactCount(); ++i) {
      const int size = contactModelOf(contactSpec(scenario_.contacts[static_cast<std::size_t>(i)].surface), scenario_.inner.problem)
                           .wrenchSize();
      if (size == 6) continue;
      for (int s = 0; s < forces_->sampleCount(); ++s)
        for (const ContactForceParametrization::Term& t : forces_->terms(i, s))
          lower.segment(t.variable + size, 6 - size).setZero(), upper.segment(t.variable + size, 6 - size).setZero();
    }
  }

  void variableUnits(Eigen::Ref<Eigen::VectorXd> units) const override {
    // `force_units: weight`: the wrenches in units of the robot's weight m g (newtons, and
    // newton-metres for the moments), next to the joints' radians (docs/theory/outer-problem.md,
    // "Units of the force variables").
    if (forces_ && scenario_.forceUnits == ForceUnits::Weight) units.segment(firstVariable_, forces_->variableCount()).setConstant(weight_);
  }

  void layOutForceColumns(int s, std::vector<LocalForceTerm>& terms, std::vector<int>& columns) const override {
    // Every term of every contact in contact here, six components each.
    for (int i = 0; forces_ && i < forces_->contactCount(); ++i)
      for (const ContactForceParametrization::Term& t : forces_->terms(i, s)) {
        terms.push_back({i, t.weight, static_cast<int>(columns.size())});
        for (int c = 0; c < 6; ++c) columns.push_back(t.variable + c);
      }
  }

  void fit(const std::vector<Eigen::MatrixXd>& wrenches, Eigen::Ref<Eigen::VectorXd> z) const override {
    if (forces_) forces_->fit(wrenches, z);
  }

  void sampleOutputs(FormulationSample& f) override {
    // Γ = Γ0 − Σ J1_i F_i and W_ref = W0 − Σ wrenchToWorld_i F_i over the environment
    // contacts in contact here (formulation.md §5, §9); the reference contact takes W_ref.
    const int n = f.model.jointCount(), s = f.sample, contacts = outputs_.contacts;
    const DynamicsModel& model = f.model;
    MotionWorkspace& w = f.w;
    const DynamicsDerivatives& d = w.derivatives;
    const bool derivatives = f.derivatives;
    w.torque = w.data.tau;
    Vector6 reference = w.data.referenceWrench;
    if (derivatives) w.torqueDq = d.dtauDq, w.referenceDq = d.dwrenchDq;
    // A contact's rows depend on its own columns only: the others' entries must read zero
    // even in a block that served another sample (the Hessian's probes).
    if (derivatives) f.dyDz.setZero();
    for (int i = 0; i < contacts; ++i) {
      if (!forces_->active(i, s)) continue;
      Vector6 F = Vector6::Zero();
      for (const ContactForceParametrization::Term& t : forces_->terms(i, s)) F += t.weight * f.x.segment<6>(t.variable);
      f.wrenches.segment<6>(6 * (1 + i)) = F;
      const EnvironmentContact& contact = scenario_.contacts[static_cast<std::size_t>(i)];
      const ContactFrame frame = contactFrame(model, w.data, contact.surface.frame, contact.surface.placement);
      WrenchToTorque& toTorque = w.toTorque[static_cast<std::size_t>(i)];
      Matrix6& toWorld = w.toWorld[static_cast<std::size_t>(i)];
      wrenchToTorque(model, w.data, frame, toTorque);
      wrenchToWorld(frame, toWorld);
      w.torque.noalias() -= toTorque * F;
      reference.noalias() -= toWorld * F;
      contactRows_[static_cast<std::size_t>(i)].evaluate(F, f.y.segment(outputs_.contactRow(i, 0), outputs_.contactRowCount(1 + i)),
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
      support_.evaluate(reference, f.y.segment(outputs_.referenceRow(0), perContact), rowsByReference);
    else
      support_.evaluate(reference, f.y.segment(outputs_.referenceRow(0), perContact));
    f.wrenches.head<6>() = support_.contactWrench(reference);
    if (!derivatives) return;
    f.dyDq.topRows(n) = w.torqueDq;
    f.dyDv.topRows(n) = d.dtauDv;
    f.dyDa.topRows(n) = d.dtauDa;
    // Small products of run-time sizes: coefficient-based (lazyProduct), as Eigen's blocked
    // product may take heap workspace for them.
    f.dyDq.middleRows(outputs_.referenceRow(0), perContact).noalias() = rowsByReference.lazyProduct(w.referenceDq);
    f.dyDv.middleRows(outputs_.referenceRow(0), perContact).noalias() = rowsByReference.lazyProduct(d.dwrenchDv);
    f.dyDa.middleRows(outputs_.referenceRow(0), perContact).noalias() = rowsByReference.lazyProduct(d.dwrenchDa);
    // Force columns: ∂Γ/∂F_i = −J1_i, ∂rows_ref/∂F_i = −(∂rows/∂W_ref) wrenchToWorld_i,
    // ∂rows_i/∂F_i, each times the term's weight. (The outputs may be a Hessian probe's: the
    // sample's own layout, f.forceTerms, holds the columns.)
    for (const LocalForceTerm& t : f.forceTerms) {
      const auto i_ = static_cast<std::size_t>(t.contact);
      const int column = t.firstColumn;
      f.dyDz.block(outputs_.torque(0), column, n, 6) = -t.weight * w.toTorque[i_];
      f.dyDz.block(outputs_.referenceRow(0), column, perContact, 6).noalias() =
          -t.weight * rowsByReference.lazyProduct(w.toWorld[i_]);
      f.dyDz.block(outputs_.contactRow(t.contact, 0), column, outputs_.contactRowCount(1 + t.contact), 6) =
          t.weight * w.rowsByWrench[i_];
    }
  }

 private:
  const Scenario& scenario_;
  const SampleOutputs& outputs_;
  const ContactAdmissibilityRows& support_;
  const std::vector<ContactAdmissibilityRows>& contactRows_;
  ContactForceParametrization::Layout layout_;
  int firstVariable_ = 0;
  double weight_ = 0.0;  ///< m g [N]
  std::optional<ContactForceParametrization> forces_;  ///< none without environment contacts
};

}  // namespace

std::unique_ptr<ContactForceFormulation> makeForceSplinesFormulation(const FormulationContext& context) {
  return std::make_unique<ForceVariablesFormulation>(context, ContactForceParametrization::Layout::Splines);
}

std::unique_ptr<ContactForceFormulation> makePerSampleForcesFormulation(const FormulationContext& context) {
  return std::make_unique<ForceVariablesFormulation>(context, ContactForceParametrization::Layout::PerSample);
}

}  // namespace mcopt
