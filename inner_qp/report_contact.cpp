// SPDX-License-Identifier: BSD-3-Clause
// The report's contact model (formulation.md §5; report (2.18)–(2.21), the slip of (2.20)
// corrected): fz ≥ f_min, the centre of pressure in the rectangle, and the friction cone
// fx² + fy² ≤ μ² fz², which the inner problem keeps as a second-order cone.
#include "inner_qp/contact_model.hpp"

namespace mcopt {

namespace {

class ReportContactModel final : public ContactModel {
 public:
  std::string name() const override { return "report"; }
  int rowCount() const override { return 5; }
  bool hasSecondOrderCone() const override { return true; }

  /// Six smooth rows: f_z; (μ² f_z² − f_x² − f_y²) / (m g)², the cone scaled to the robot's
  /// weight; −m_y − x_min f_z, x_max f_z + m_y, m_x − y_min f_z, y_max f_z − m_x.
  AdmissibilityRows admissibilityRows(const ContactSpec& c, double weight) const override {
    AdmissibilityRows out;
    out.names = {"f_z", "friction cone", "CoP x ≥ x_min", "CoP x ≤ x_max", "CoP y ≥ y_min", "CoP y ≤ y_max"};
    using K = ContactRowKind;
    out.kinds = {K::NormalForce, K::Friction, K::CenterOfPressure, K::CenterOfPressure, K::CenterOfPressure,
                 K::CenterOfPressure};
    enum { Fx = 0, Fy, Fz, Mx, My };
    out.linear.setZero(6, 6);
    out.offset.setZero(6);
    out.linear(0, Fz) = 1.0;
    out.linear(2, Fz) = -c.xMin, out.linear(2, My) = -1.0;
    out.linear(3, Fz) = c.xMax, out.linear(3, My) = 1.0;
    out.linear(4, Fz) = -c.yMin, out.linear(4, Mx) = 1.0;
    out.linear(5, Fz) = c.yMax, out.linear(5, Mx) = -1.0;
    out.setSmoothFrictionCone(1, c.friction, weight);
    return out;
  }

 protected:
  void writeRows(const ContactSpec& c, ContactRowWriter& out) const override { out.addSupportRows(c); }
};

}  // namespace

std::shared_ptr<const ContactModel> makeReportContactModel(const ContactModelOptions& /*options*/) {
  return std::make_shared<ReportContactModel>();
}

}  // namespace mcopt
