// SPDX-License-Identifier: BSD-3-Clause
// The regularisation w Σ_j q̈_js² as a cost term (cost_term.hpp; formulation.md §10; the
// scenario's `regularisation.acceleration_weight`, 0 by default), over the spline joints: a
// joint that follows a closure at a sample has the closure's q̈, not the splines'. It reads the
// state directly: q̈_j = Σ_l d2_l x_{j,l} / T², so ∂q̈_j/∂x_{j,l} = d2_l / T² and ∂q̈/∂T = −2 q̈ / T.
#include "core/bspline.hpp"
#include "outer_nlp/cost_term.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

namespace {

class AccelerationRegularisation final : public CostTerm {
 public:
  explicit AccelerationRegularisation(const CostContext& c) : c_(c), weight_(c.scenario.accelerationWeight) {}
  std::string_view name() const override { return "acceleration regularisation"; }
  CostNeeds needs() const override { return weight_ > 0.0 ? CostNeeds::Values : CostNeeds::Nothing; }
  void addValue(const CostSample& sample, const Eigen::VectorXd&, double& sum) const override {
    if (weight_ <= 0.0) return;
    for (int j = 0; j < c_.outputs.joints; ++j)
      if (spline(sample, j)) sum += weight_ * sample.acceleration[j] * sample.acceleration[j];
  }
  void addGradient(const CostSample& sample, const Eigen::VectorXd&, double weight, double T, Eigen::VectorXd& gradient,
                   double& dT) const override {
    if (weight_ <= 0.0) return;
    const LocalParameterWeights& local = c_.samples.weights(sample.index);
    const double scale = weight * weight_;
    const int m = c_.parametrization.parametersPerJoint();
    double squared = 0.0;
    for (int j = 0; j < c_.outputs.joints; ++j) {
      if (!spline(sample, j)) continue;
      const double a = sample.acceleration[j];
      squared += a * a;
      for (int l = 0; l < local.count; ++l)
        gradient[j * m + local.parameter[static_cast<std::size_t>(l)]] += scale * 2.0 * a * local.d2[static_cast<std::size_t>(l)] / (T * T);
    }
    // d/dT of c_s T w Σ q̈²: the weight's T, and q̈ ∝ 1/T².
    dT += scale * (squared / T - 4.0 * squared / T);
  }
  // In the state (q, q̇, q̈): 2 c w q̈_j and 2 c w on the q̈ diagonal.
  void addStateGradient(const CostSample& sample, double weight, Eigen::Ref<Eigen::VectorXd> gradient) const override {
    const int n = c_.outputs.joints;
    for (int j = 0; j < n; ++j)
      if (spline(sample, j)) gradient[2 * n + j] += 2.0 * weight * weight_ * sample.acceleration[j];
  }
  void addStateHessian(const CostSample& sample, double weight, Eigen::Ref<Eigen::MatrixXd> H) const override {
    const int n = c_.outputs.joints;
    for (int j = 0; j < n; ++j)
      if (spline(sample, j)) H(2 * n + j, 2 * n + j) += 2.0 * weight * weight_;
  }

 private:
  bool spline(const CostSample& sample, int joint) const { return !c_.closure || !c_.closure->closesIn(joint, sample.closed); }
  CostContext c_;
  double weight_;
};

}  // namespace

std::unique_ptr<const CostTerm> makeAccelerationRegularisation(const CostContext& context) {
  return std::make_unique<AccelerationRegularisation>(context);
}

}  // namespace mcopt
