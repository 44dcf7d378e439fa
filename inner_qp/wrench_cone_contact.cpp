// SPDX-License-Identifier: BSD-3-Clause
// The wrench cone of a rectangular contact (Caron, Pham, Nakamura, ICRA 2015), taken about
// the rectangle's centre, with the inscribed friction pyramid μ̃ = μ/√2 (their inner
// approximation): |fx|, |fy| ≤ μ̃ fz; the centre of pressure in the rectangle; and the yaw bounds
//   −μ̃(X+Y) fz + |Y fx − μ̃ m_x| + |X fy − μ̃ m_y| ≤ m_z ≤ μ̃(X+Y) fz − |Y fx + μ̃ m_x| − |X fy + μ̃ m_y|
// (X, Y half-sizes), each absolute value expanded into linear rows. Every wrench it admits,
// the report model admits; it forbids the yaw slip besides.
#include <numbers>

#include "inner_qp/contact_model.hpp"

namespace mcopt {

namespace {

class WrenchConeContactModel final : public ContactModel {
 public:
  std::string name() const override { return "wrench-cone"; }
  int rowCount() const override { return 5 + 4 + 8; }

 protected:
  void writeRows(const ContactSpec& c, ContactRowWriter& out) const override {
    out.addSupportRows(c);
    using W = ContactRowWriter;
    using K = ContactRowKind;
    // About the rectangle's centre (cx, cy): m'_x = m_x − cy fz, m'_y = m_y + cx fz,
    // m'_z = m_z − cx fy + cy fx. With μ̃ = μ/√2 the pyramid |fx|, |fy| ≤ μ̃ fz is
    // inscribed in the circular cone (Caron et al. §III).
    const double mu = c.friction / std::numbers::sqrt2;
    const double cx = 0.5 * (c.xMin + c.xMax), cy = 0.5 * (c.yMin + c.yMax);
    const double X = 0.5 * (c.xMax - c.xMin), Y = 0.5 * (c.yMax - c.yMin);
    out.add("fx_max", K::Friction, {{W::Fx, 1.0}, {W::Fz, -mu}});
    out.add("fx_min", K::Friction, {{W::Fx, -1.0}, {W::Fz, -mu}});
    out.add("fy_max", K::Friction, {{W::Fy, 1.0}, {W::Fz, -mu}});
    out.add("fy_min", K::Friction, {{W::Fy, -1.0}, {W::Fz, -mu}});
    int yaw = 0;
    for (double s1 : {-1.0, 1.0})
      for (double s2 : {-1.0, 1.0}) {
        // m'_z ≤ μ(X+Y) fz − s1 (Y fx + μ m'_x) − s2 (X fy + μ m'_y)
        out.add("yaw_max_" + std::to_string(yaw), K::Yaw,
                {{W::Mz, 1.0}, {W::Fy, -cx}, {W::Fx, cy}, {W::Fz, -mu * (X + Y)}, {W::Fx, s1 * Y}, {W::Mx, s1 * mu},
                 {W::Fz, -s1 * mu * cy}, {W::Fy, s2 * X}, {W::My, s2 * mu}, {W::Fz, s2 * mu * cx}});
        // −m'_z ≤ μ(X+Y) fz − s1 (Y fx − μ m'_x) − s2 (X fy − μ m'_y)
        out.add("yaw_min_" + std::to_string(yaw++), K::Yaw,
                {{W::Mz, -1.0}, {W::Fy, cx}, {W::Fx, -cy}, {W::Fz, -mu * (X + Y)}, {W::Fx, s1 * Y}, {W::Mx, -s1 * mu},
                 {W::Fz, s1 * mu * cy}, {W::Fy, s2 * X}, {W::My, -s2 * mu}, {W::Fz, -s2 * mu * cx}});
      }
  }
};

}  // namespace

std::shared_ptr<const ContactModel> makeWrenchConeContactModel(const ContactModelOptions& /*options*/) {
  return std::make_shared<WrenchConeContactModel>();
}

}  // namespace mcopt
