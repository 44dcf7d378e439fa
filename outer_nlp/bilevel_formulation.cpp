// SPDX-License-Identifier: BSD-3-Clause
// The bilevel formulation (formulation.md §7, §8, §9; contact_force_formulation.hpp): at every
// sample an inner problem over the contacts active there picks the wrenches, and Γ and the inner
// problem's infeasibility φ take their derivatives through its KKT sensitivity
// (sensitivity/bilevel_sample.hpp). Each sample keeps its answer: the next evaluation's warm start.
#include <memory>
#include <vector>

#include "outer_nlp/contact_force_formulation.hpp"
#include "outer_nlp/motion_workspace.hpp"
#include "sensitivity/bilevel_sample.hpp"

namespace mcopt {

namespace {

class BilevelFormulation final : public ContactForceFormulation {
 public:
  explicit BilevelFormulation(const FormulationContext& c) : scenario_(c.scenario), outputs_(c.outputs), active_(c.active) {
    for (std::size_t s = 0; s < c.sampleModels.size(); ++s)
      samples_.push_back(std::make_unique<BilevelSample>(*c.sampleModels[s], c.sampleSurfaces[s], scenario_.inner,
                                                         scenario_.sensitivity, c.weight));
  }

  bool innerProblem() const override { return true; }
  bool keepsSampleState() const override { return true; }
  const InnerResult* innerResult(int s) const override { return &samples_[static_cast<std::size_t>(s)]->innerResult(); }

  void beforeSample(int s, int predecessor) override {
    // A sample without an answer of its own (the first evaluation) starts from its predecessor's.
    BilevelSample& sample = *samples_[static_cast<std::size_t>(s)];
    if (predecessor >= 0 && !sample.hasResult()) sample.warmStartFrom(*samples_[static_cast<std::size_t>(predecessor)]);
  }

  void sampleOutputs(FormulationSample& f) override {
    const int n = f.model.jointCount(), s = f.sample;
    MotionWorkspace& w = f.w;
    BilevelSample& sample = *samples_[static_cast<std::size_t>(s)];
    sample.evaluate(f.model, w.data, f.derivatives ? &w.derivatives : nullptr, scenario_.actuators, w.v, w.a, f.derivatives);
    w.torque = sample.torque();
    f.y[outputs_.infeasibility()] = sample.infeasibility();
    const Eigen::VectorXd& F = sample.innerResult().wrenches;
    const ContactProblem& inner = sample.problem().problem;
    f.wrenches.head<6>() = inner.contactWrench(F, 0);
    for (int i = 0, k = 1; i < outputs_.contacts; ++i)
      if (active_[static_cast<std::size_t>(i)][static_cast<std::size_t>(s)])
        f.wrenches.segment<6>(6 * (1 + i)) = inner.contactWrench(F, k++);
    if (!f.derivatives) return;
    f.dyDq.topRows(n) = sample.torqueDq();
    f.dyDv.topRows(n) = sample.torqueDv();
    f.dyDa.topRows(n) = sample.torqueDa();
    f.dyDq.row(outputs_.infeasibility()) = sample.infeasibilityDq();
    f.dyDv.row(outputs_.infeasibility()) = sample.infeasibilityDv();
    f.dyDa.row(outputs_.infeasibility()) = sample.infeasibilityDa();
  }

 private:
  const Scenario& scenario_;
  const SampleOutputs& outputs_;
  const std::vector<std::vector<bool>>& active_;
  std::vector<std::unique_ptr<BilevelSample>> samples_;
};

}  // namespace

std::unique_ptr<ContactForceFormulation> makeBilevelFormulation(const FormulationContext& context) {
  return std::make_unique<BilevelFormulation>(context);
}

}  // namespace mcopt
