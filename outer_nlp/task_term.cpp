// SPDX-License-Identifier: BSD-3-Clause
// The scenario's tasks as a constraint term (constraint_term.hpp; formulation.md §10): at each
// task instant, a row per bounded component of its task's value (task.hpp). A contact's window
// ends inside the motion are tasks too (its frame at its world pose and at rest where the
// splines meet the closure), reported as `closure`; every other task as `task`.
#include <cmath>
#include <ostream>

#include "outer_nlp/constraint_term.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

namespace {

constexpr ConstraintKindInfo kTask{"task", "task units (m, m/s, rad)"};
constexpr ConstraintKindInfo kClosure{"closure", "task units (m, m/s, rad)"};

/// block: the task instant; detail: the component.
class TaskTerm final : public ConstraintTerm {
 public:
  explicit TaskTerm(const TermContext& c) : c_(c) {}
  RowPlace place() const override { return RowPlace::TaskInstant; }
  std::vector<ConstraintKindInfo> kinds() const override { return {kClosure, kTask}; }
  const ConstraintKindInfo& kind(int, int instant) const override { return task(instant).closure ? kClosure : kTask; }
  void appendRows(RowSink& sink) const override {
    const int instant = sink.block();
    const TaskSpec& spec = task(instant);
    for (int c = 0; c < spec.dimension(); ++c) {
      if (!std::isfinite(spec.lower[c]) && !std::isfinite(spec.upper[c])) continue;
      sink.outputRow(c, c, c_.taskJoints[static_cast<std::size_t>(instant)], false);
    }
  }
  void bounds(int component, int instant, double& lower, double& upper) const override {
    const TaskSpec& spec = task(instant);
    lower = spec.lower[component], upper = spec.upper[component];
  }
  void subject(int component, int instant, std::ostream& name) const override {
    const TaskSpec& spec = task(instant);
    name << (spec.closure ? "" : "task '") << spec.name << (spec.closure ? "" : "'") << " component "
         << spec.task->componentName(component);
  }

 private:
  const TaskSpec& task(int instant) const {
    return c_.scenario.tasks[static_cast<std::size_t>(c_.taskOfInstant[static_cast<std::size_t>(instant)])];
  }
  TermContext c_;
};

}  // namespace

std::unique_ptr<const ConstraintTerm> makeTaskTerm(const TermContext& context) { return std::make_unique<TaskTerm>(context); }

}  // namespace mcopt
