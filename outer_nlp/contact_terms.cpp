// SPDX-License-Identifier: BSD-3-Clause
// The contacts as constraint terms (constraint_term.hpp; formulation.md §5, §9, §10):
//   contact admissibility  the contact model's rows ≥ 0 (contact_admissibility.hpp) on the
//                          wrenches the NLP carries: the reference contact's W_ref whenever the
//                          formulation is single-level (or it is the only contact), each
//                          environment contact's own wrench there; reported by the model's row
//                          kind: contact_unilateral (f_z ≥ f_min), contact_friction, contact_cop,
//                          contact_yaw;
//   inner_feasibility      bilevel: the inner problem's least balance slack φ ≤ 0 (the inner
//                          problem holds the contacts' own rows);
//   inner_margin           bilevel with inner.feasibility: margin, in the same output: the
//                          admissibility margin −m_ε ≤ 0 (inner_qp/admissibility_margin.hpp).
#include <limits>
#include <ostream>

#include "outer_nlp/constraint_term.hpp"
#include "outer_nlp/contact_admissibility.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr ConstraintKindInfo kUnilateral{"contact_unilateral", "contact row units (contact model)"};
constexpr ConstraintKindInfo kFriction{"contact_friction", "contact row units (contact model)"};
constexpr ConstraintKindInfo kCop{"contact_cop", "contact row units (contact model)"};
constexpr ConstraintKindInfo kYaw{"contact_yaw", "contact row units (contact model)"};
constexpr ConstraintKindInfo kInnerFeasibility{"inner_feasibility", "(slack / m g)^2"};
constexpr ConstraintKindInfo kInnerMargin{"inner_margin", "-margin / (m g)"};

/// detail: the row's index among every contact's rows (SampleOutputs::contactRowStart).
class ContactAdmissibilityTerm final : public ConstraintTerm {
 public:
  explicit ContactAdmissibilityTerm(const TermContext& c) : c_(c) {}
  RowPlace place() const override { return RowPlace::Sample; }
  std::vector<ConstraintKindInfo> kinds() const override { return {kUnilateral, kFriction, kCop, kYaw}; }
  const ConstraintKindInfo& kind(int detail, int) const override {
    switch (rowKind(detail)) {
      case ContactRowKind::NormalForce: return kUnilateral;
      case ContactRowKind::CenterOfPressure: return kCop;
      case ContactRowKind::Friction: return kFriction;
      case ContactRowKind::Yaw: return kYaw;
    }
    return kFriction;
  }
  void appendRows(RowSink& sink) const override {
    if (!c_.scenario.contactConstraints || c_.bilevel) return;
    for (int c = 0; c < c_.support.rowCount(); ++c) sink.outputRow(c, c_.outputs.referenceRow(c), c_.allJoints, true);
    // An environment contact's rows read its own wrench, in its own frame: only its variables.
    for (int i = 0; i < c_.outputs.contacts; ++i) {
      if (sink.forceColumnCount(i) == 0) continue;
      const ContactAdmissibilityRows& own = c_.contactRows[static_cast<std::size_t>(i)];
      for (int c = 0; c < own.rowCount(); ++c)
        sink.contactRow(c_.outputs.contactRowStart[static_cast<std::size_t>(i) + 1] + c, c_.outputs.contactRow(i, c), i);
    }
  }
  void bounds(int detail, int, double& lower, double& upper) const override {
    lower = rowKind(detail) == ContactRowKind::NormalForce ? c_.scenario.minimumNormalForce : 0.0;
    upper = kInf;
  }
  void subject(int detail, int, std::ostream& name) const override {
    const int contact = contactOf(detail);
    name << (contact == 0 ? c_.scenario.support.name : c_.scenario.contacts[static_cast<std::size_t>(contact - 1)].surface.name)
         << " " << rows(contact).rowName(detail - c_.outputs.contactRowStart[static_cast<std::size_t>(contact)]);
  }

 private:
  /// 0: the reference contact, 1 + i: environment contact i.
  int contactOf(int detail) const {
    int contact = 0;
    while (detail >= c_.outputs.contactRowStart[static_cast<std::size_t>(contact) + 1]) ++contact;
    return contact;
  }
  const ContactAdmissibilityRows& rows(int contact) const {
    return contact == 0 ? c_.support : c_.contactRows[static_cast<std::size_t>(contact - 1)];
  }
  ContactRowKind rowKind(int detail) const {
    const int contact = contactOf(detail);
    return rows(contact).rowKind(detail - c_.outputs.contactRowStart[static_cast<std::size_t>(contact)]);
  }
  TermContext c_;
};

/// The inner feasibility row: φ (inner_feasibility) or −m_ε (inner_margin), as the scenario's
/// inner.feasibility says; both kinds registered, one laid out.
class InnerFeasibilityTerm final : public ConstraintTerm {
 public:
  explicit InnerFeasibilityTerm(const TermContext& c) : c_(c) {}
  RowPlace place() const override { return RowPlace::Sample; }
  std::vector<ConstraintKindInfo> kinds() const override { return {kInnerFeasibility, kInnerMargin}; }
  const ConstraintKindInfo& kind(int, int) const override {
    return c_.scenario.inner.feasibility == InnerFeasibility::Margin ? kInnerMargin : kInnerFeasibility;
  }
  void appendRows(RowSink& sink) const override {
    if (c_.bilevel) sink.outputRow(0, c_.outputs.infeasibility(), c_.allJoints, false);
  }
  void bounds(int, int, double& lower, double& upper) const override { lower = -kInf, upper = 0.0; }
  void subject(int, int, std::ostream& name) const override {
    name << (c_.scenario.inner.feasibility == InnerFeasibility::Margin ? "inner problem admissibility margin"
                                                                        : "inner problem feasibility (balance slack)");
  }

 private:
  TermContext c_;
};

}  // namespace

std::unique_ptr<const ConstraintTerm> makeContactAdmissibilityTerm(const TermContext& context) {
  return std::make_unique<ContactAdmissibilityTerm>(context);
}
std::unique_ptr<const ConstraintTerm> makeInnerFeasibilityTerm(const TermContext& context) {
  return std::make_unique<InnerFeasibilityTerm>(context);
}

}  // namespace mcopt
