// SPDX-License-Identifier: BSD-3-Clause
// The report's contact model with the friction cone replaced by k facets inscribed in it:
// cos θ_i fx + sin θ_i fy ≤ μ cos(π/k) fz, θ_i = 2π i / k; every row linear.
#include <cmath>
#include <numbers>

#include "core/errors.hpp"
#include "inner_qp/contact_model.hpp"

namespace mcopt {

namespace {

class PyramidContactModel final : public ContactModel {
 public:
  explicit PyramidContactModel(int facets) : facets_(facets) {}
  std::string name() const override { return "pyramid"; }
  int rowCount() const override { return 5 + facets_; }

 protected:
  void writeRows(const ContactSpec& c, ContactRowWriter& out) const override {
    out.addSupportRows(c);
    const double inscribed = c.friction * std::cos(std::numbers::pi / facets_);
    using W = ContactRowWriter;
    for (int f = 0; f < facets_; ++f) {
      const double theta = 2.0 * std::numbers::pi * f / facets_;
      out.add("facet_" + std::to_string(f), ContactRowKind::Friction,
              {{W::Fx, std::cos(theta)}, {W::Fy, std::sin(theta)}, {W::Fz, -inscribed}});
    }
  }

 private:
  int facets_;
};

}  // namespace

std::shared_ptr<const ContactModel> makePyramidContactModel(const ContactModelOptions& options) {
  if (options.pyramidFacets < 3)
    throw InputError("pyramid facets: need at least 3, got " + std::to_string(options.pyramidFacets));
  return std::make_shared<PyramidContactModel>(options.pyramidFacets);
}

}  // namespace mcopt
