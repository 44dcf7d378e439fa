// SPDX-License-Identifier: BSD-3-Clause
// The loops' reach as a constraint term (constraint_term.hpp; docs/theory/outer-problem.md,
// "Closure by construction"):
//   loop_reach  each held contact's loop, at the samples where it is closed, at most
//               1 − closure_reach_margin of its longest reach (closed_chains.hpp LoopReach):
//               away from full stretch, where the closure folds.
// Without the margin (its default, 0) there are no such rows.
#include <limits>
#include <ostream>

#include "outer_nlp/constraint_term.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

namespace {

constexpr ConstraintKindInfo kLoopReach{"loop_reach", "of the longest reach"};

/// detail i: held contact i's loop.
class LoopReachTerm final : public SampleTermOfOneKind {
 public:
  explicit LoopReachTerm(const TermContext& c) : SampleTermOfOneKind(kLoopReach), c_(c) {}
  void appendRows(RowSink& sink) const override {
    for (int i = 0; i < c_.outputs.reaches; ++i)
      if ((sink.closed() >> i) & 1U) sink.outputRow(i, c_.outputs.loopReach(i), c_.allJoints, false);
  }
  void bounds(int, int, double& lower, double& upper) const override {
    lower = -std::numeric_limits<double>::infinity();
    upper = 1.0 - c_.scenario.closureReachMargin;
  }
  void subject(int contact, int, std::ostream& name) const override {
    name << "reach of " << c_.closure->loopName(c_.scenario.robot, contact);
  }

 private:
  TermContext c_;
};

}  // namespace

std::unique_ptr<const ConstraintTerm> makeLoopReachTerm(const TermContext& context) {
  return std::make_unique<LoopReachTerm>(context);
}

}  // namespace mcopt
