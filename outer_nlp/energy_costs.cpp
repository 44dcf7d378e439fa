// SPDX-License-Identifier: BSD-3-Clause
// The electrical energy as cost terms (cost_term.hpp; formulation.md §6): the integrand
// Σ_j max(P_js, 0) in one of the scenario's two energy forms:
//   smooth maximum  Σ_j σ(P_js), σ(P) = (P + sqrt(P² + ε²)) / 2 (smooth_maximum.hpp): a function
//                   of the sample's power outputs, through whose derivatives its gradient goes;
//   epigraph        Σ_j s_js, slacks of x that the epigraph's rows s_js − P_js ≥ 0
//                   (energy_epigraph_term.cpp) and their lower bound 0 make max(P_js, 0) at the
//                   optimum: linear in x.
#include <algorithm>

#include "core/robot_model.hpp"
#include "outer_nlp/cost_term.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/smooth_maximum.hpp"

namespace mcopt {

namespace {

class SmoothMaximumEnergy final : public CostTerm {
 public:
  explicit SmoothMaximumEnergy(const CostContext& c) : c_(c), epsilon_(c.scenario.smoothing) {}
  std::string_view name() const override { return "energy (smooth maximum)"; }
  CostNeeds needs() const override { return CostNeeds::Derivatives; }
  void addValue(const CostSample& sample, const Eigen::VectorXd&, double& sum) const override {
    for (int j = 0; j < c_.outputs.joints; ++j) sum += smoothMaximum(sample.y[c_.outputs.power(j)], epsilon_);
  }
  void addGradient(const CostSample& sample, const Eigen::VectorXd&, double weight, double T, Eigen::VectorXd& gradient,
                   double& dT) const override {
    for (int j = 0; j < c_.outputs.joints; ++j) {
      const int row = c_.outputs.power(j);
      const double p = sample.y[row], slope = weight * smoothMaximumSlope(p, epsilon_);
      for (Eigen::Index k = 0; k < sample.parameters.size(); ++k) gradient[sample.parameters[k]] += slope * sample.dyDx(row, k);
      for (std::size_t k = 0; k < sample.forceColumns.size(); ++k)
        gradient[sample.forceColumns[k]] += slope * sample.dyDz(row, static_cast<Eigen::Index>(k));
      // The weight c_s T is proportional to T.
      dT += slope * sample.dyDT[row] + weight / T * smoothMaximum(p, epsilon_);
    }
  }
  void addOutputSlopes(const CostSample& sample, double weight, Eigen::Ref<Eigen::VectorXd> slopes) const override {
    for (int j = 0; j < c_.outputs.joints; ++j) {
      const int row = c_.outputs.power(j);
      slopes[row] += weight * smoothMaximumSlope(sample.y[row], epsilon_);
    }
  }
  void addOutputCurvatures(const CostSample& sample, double weight, Eigen::Ref<Eigen::VectorXd> curvatures) const override {
    for (int j = 0; j < c_.outputs.joints; ++j) {
      const int row = c_.outputs.power(j);
      curvatures[row] += weight * smoothMaximumCurvature(sample.y[row], epsilon_);
    }
  }

 private:
  CostContext c_;
  double epsilon_;
};

class EpigraphEnergy final : public CostTerm {
 public:
  explicit EpigraphEnergy(const CostContext& c) : c_(c) {}
  std::string_view name() const override { return "energy (epigraph)"; }
  CostNeeds needs() const override { return CostNeeds::Nothing; }
  void addValue(const CostSample& sample, const Eigen::VectorXd& x, double& sum) const override {
    sum += x.segment(firstSlack(sample), c_.outputs.joints).sum();
  }
  void addGradient(const CostSample& sample, const Eigen::VectorXd& x, double weight, double T, Eigen::VectorXd& gradient,
                   double& dT) const override {
    const int first = firstSlack(sample), n = c_.outputs.joints;
    gradient.segment(first, n).array() += weight;
    dT += weight / T * x.segment(first, n).sum();
  }

  // A slack per joint, s ≥ 0, started at max(P, 0) of the motion's power (docs/theory/
  // outer-problem.md, "Continuation"): the epigraph's rows hold there with equality or slack.
  int variablesPerSample() const override { return c_.outputs.joints; }
  void sampleVariableBounds(Eigen::Ref<Eigen::VectorXd> lower, Eigen::Ref<Eigen::VectorXd>) const override {
    lower.setZero();
  }
  void startSampleVariables(const CostSample& sample, Eigen::Ref<Eigen::VectorXd> slacks) const override {
    for (int j = 0; j < c_.outputs.joints; ++j) slacks[j] = std::max(0.0, sample.y[c_.outputs.power(j)]);
  }

 private:
  int firstSlack(const CostSample& sample) const { return c_.firstVariable + sample.index * c_.outputs.joints; }
  CostContext c_;
};

}  // namespace

std::unique_ptr<const CostTerm> makeSmoothMaximumEnergy(const CostContext& context) {
  return std::make_unique<SmoothMaximumEnergy>(context);
}
std::unique_ptr<const CostTerm> makeEpigraphEnergy(const CostContext& context) { return std::make_unique<EpigraphEnergy>(context); }

}  // namespace mcopt
