// SPDX-License-Identifier: BSD-3-Clause
// A point contact: a force f at the contact frame's origin, fz ≥ f_min and the friction cone
// fx² + fy² ≤ μ² fz² (kept as a second-order cone), and no moment — knuckles or a fingertip
// on a table. Its wrench has three components; the moment is zero, not a variable.
#include "inner_qp/contact_model.hpp"

namespace mcopt {

namespace {

class PointContactModel final : public ContactModel {
 public:
  std::string name() const override { return "point"; }
  int rowCount() const override { return 1; }
  int wrenchSize() const override { return 3; }
  bool hasRectangle() const override { return false; }
  bool hasSecondOrderCone() const override { return true; }

  /// f_z; (μ² f_z² − f_x² − f_y²) / (m g)², the cone scaled to the robot's weight.
  AdmissibilityRows admissibilityRows(const ContactSpec& c, double weight) const override {
    AdmissibilityRows out;
    out.names = {"f_z", "friction cone"};
    out.kinds = {ContactRowKind::NormalForce, ContactRowKind::Friction};
    out.linear.setZero(2, 6);
    out.offset.setZero(2);
    out.linear(0, ContactRowWriter::Fz) = 1.0;
    out.setSmoothFrictionCone(1, c.friction, weight);
    return out;
  }

 protected:
  void writeRows(const ContactSpec& c, ContactRowWriter& out) const override {
    out.add("fz_min", ContactRowKind::NormalForce, {{ContactRowWriter::Fz, -1.0}}, -c.minNormalForce);
  }
};

}  // namespace

std::shared_ptr<const ContactModel> makePointContactModel(const ContactModelOptions& /*options*/) {
  return std::make_shared<PointContactModel>();
}

}  // namespace mcopt
