// SPDX-License-Identifier: BSD-3-Clause
// The energy's epigraph as a constraint term (constraint_term.hpp; formulation.md §6): with
// `energy: epigraph` the objective sums slacks s_js, and each sample's row s_js − P_js ≥ 0 makes
// s_js ≥ max(P_js, 0) at the optimum (the slacks' lower bound 0 is a variable bound). The row
// reads the power output with sign −1 and its own slack.
#include <limits>
#include <ostream>

#include "outer_nlp/constraint_term.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

namespace {

// Its rows bound the solver's own slacks: on a fine grid, where the slacks are set at
// max(P, 0), they say nothing about the motion (mcopt verify skips them).
constexpr ConstraintKindInfo kEpigraph{"energy_epigraph", "W", false};

class EnergyEpigraphTerm final : public SampleTermOfOneKind {
 public:
  explicit EnergyEpigraphTerm(const TermContext& c) : SampleTermOfOneKind(kEpigraph), c_(c) {}
  double outputSign() const override { return -1.0; }
  void appendRows(RowSink& sink) const override {
    if (c_.scenario.energyForm != EnergyForm::Epigraph) return;
    for (int j = 0; j < c_.outputs.joints; ++j)
      sink.outputRow(j, c_.outputs.power(j), c_.relatedJoints[static_cast<std::size_t>(j)], true, sink.slackColumn(j));
  }
  void bounds(int, int, double& lower, double& upper) const override {
    lower = 0.0, upper = std::numeric_limits<double>::infinity();
  }
  void subject(int joint, int, std::ostream& name) const override {
    name << "energy epigraph of " << c_.scenario.robot.joints[static_cast<std::size_t>(joint)].name;
  }

 private:
  TermContext c_;
};

}  // namespace

std::unique_ptr<const ConstraintTerm> makeEnergyEpigraphTerm(const TermContext& context) {
  return std::make_unique<EnergyEpigraphTerm>(context);
}

}  // namespace mcopt
