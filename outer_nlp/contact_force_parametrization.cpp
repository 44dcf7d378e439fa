// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/contact_force_parametrization.hpp"

#include <Eigen/QR>

#include "core/bspline.hpp"
#include "core/errors.hpp"

namespace mcopt {

ContactForceParametrization::ContactForceParametrization(Layout layout,
                                                         const std::vector<std::array<double, 2>>& windows,
                                                         const std::vector<double>& u,
                                                         const std::vector<std::vector<bool>>& active,
                                                         int controlPoints, int firstVariable)
    : windows_(windows), firstVariable_(firstVariable) {
  const BSplineBasis basis(controlPoints);
  int next = firstVariable;
  terms_.resize(windows.size());
  for (std::size_t i = 0; i < windows.size(); ++i) {
    const auto& window = windows[i];
    auto& terms = terms_[i];
    terms.resize(u.size());
    for (std::size_t s = 0; s < u.size(); ++s) {
      if (!active[i][s]) continue;
      if (layout == Layout::PerSample) {
        terms[s].push_back({next, 1.0});
        next += 6;
        continue;
      }
      const double local = std::clamp((u[s] - window[0]) / (window[1] - window[0]), 0.0, 1.0);
      const LocalBasis b = basis.evaluate(local);
      for (int l = 0; l < 4; ++l)
        if (b.value[static_cast<std::size_t>(l)] != 0.0)
          terms[s].push_back({next + 6 * (b.first + l), b.value[static_cast<std::size_t>(l)]});
    }
    if (layout == Layout::Splines) next += 6 * controlPoints;
  }
  variableCount_ = next - firstVariable;
}

void ContactForceParametrization::fit(const std::vector<Eigen::MatrixXd>& wrenches, Eigen::Ref<Eigen::VectorXd> x) const {
  if (static_cast<int>(wrenches.size()) != contactCount())
    throw InputError("contact forces: fit needs one wrench matrix per contact");
  for (int i = 0; i < contactCount(); ++i) {
    // The contact's own variables form a contiguous range: a small least-squares problem
    // A z = F over the samples of its window, per wrench component.
    int first = -1, last = -1;
    const auto& perSample = terms_[static_cast<std::size_t>(i)];
    for (const auto& terms : perSample)
      for (const Term& t : terms) {
        first = first < 0 ? t.variable : std::min(first, t.variable);
        last = std::max(last, t.variable);
      }
    if (first < 0) continue;
    const int unknowns = (last - first) / 6 + 1;
    std::vector<int> samples;
    for (std::size_t s = 0; s < perSample.size(); ++s)
      if (!perSample[s].empty()) samples.push_back(static_cast<int>(s));
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(samples.size()), unknowns);
    Eigen::MatrixXd F(static_cast<Eigen::Index>(samples.size()), 6);
    for (std::size_t r = 0; r < samples.size(); ++r) {
      for (const Term& t : perSample[static_cast<std::size_t>(samples[r])])
        A(static_cast<Eigen::Index>(r), (t.variable - first) / 6) += t.weight;
      F.row(static_cast<Eigen::Index>(r)) = wrenches[static_cast<std::size_t>(i)].col(samples[r]).transpose();
    }
    const Eigen::MatrixXd z = A.colPivHouseholderQr().solve(F);  // unknowns × 6
    for (int k = 0; k < unknowns; ++k) x.segment<6>(first - firstVariable_ + 6 * k) = z.row(k).transpose();
  }
}

}  // namespace mcopt
