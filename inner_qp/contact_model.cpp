// SPDX-License-Identifier: BSD-3-Clause
#include "inner_qp/contact_model.hpp"

#include <algorithm>

#include "core/errors.hpp"
#include "core/registry.hpp"

namespace mcopt {

void ContactRowWriter::add(std::string name, ContactRowKind kind, std::initializer_list<std::pair<int, double>> terms,
                           double bound) {
  if (next_ >= out_.rows.rows()) throw std::logic_error("contact model: more rows written than its rowCount()");
  out_.names[static_cast<std::size_t>(next_)] = std::move(name);
  out_.kinds[static_cast<std::size_t>(next_)] = kind;
  out_.rows.row(next_).setZero();
  for (const auto& [component, value] : terms) out_.rows(next_, component) += value;
  out_.bound[next_] = bound;
  ++next_;
}

void ContactRowWriter::addSupportRows(const ContactSpec& c) {
  using K = ContactRowKind;
  add("fz_min", K::NormalForce, {{Fz, -1.0}}, -c.minNormalForce);     // fz ≥ f_min
  add("cop_x_max", K::CenterOfPressure, {{My, -1.0}, {Fz, -c.xMax}});  // −m_y ≤ x_max fz
  add("cop_x_min", K::CenterOfPressure, {{My, 1.0}, {Fz, c.xMin}});    // x_min fz ≤ −m_y
  add("cop_y_max", K::CenterOfPressure, {{Mx, 1.0}, {Fz, -c.yMax}});   // m_x ≤ y_max fz
  add("cop_y_min", K::CenterOfPressure, {{Mx, -1.0}, {Fz, c.yMin}});   // y_min fz ≤ m_x
}

void AdmissibilityRows::setSmoothFrictionCone(int row, double friction, double weight) {
  const double scale = 1.0 / (weight * weight);
  linear.row(row).setZero();
  offset[row] = 0.0;
  quadraticRow = row;
  quadratic.setZero();
  quadratic.diagonal().head<3>() << -2.0 * scale, -2.0 * scale, 2.0 * friction * friction * scale;
}

ContactModelRows ContactModel::rows(const ContactSpec& contact) const {
  const int count = rowCount();
  ContactModelRows out;
  out.rows.resize(count, 6);
  out.bound.resize(count);
  out.names.resize(static_cast<std::size_t>(count));
  out.kinds.resize(static_cast<std::size_t>(count));
  ContactRowWriter writer(out);
  writeRows(contact, writer);
  if (writer.written() != count || count == 0 || out.kinds.front() != ContactRowKind::NormalForce)
    throw std::logic_error("contact model '" + name() + "': wrote " + std::to_string(writer.written()) + " of its " +
                           std::to_string(count) + " rows, or not the normal force first");
  return out;
}

AdmissibilityRows ContactModel::admissibilityRows(const ContactSpec& contact, double /*weight*/) const {
  // With f_min = 0 row 0 is −(−f_z) = f_z; the caller bounds it by f_min.
  ContactSpec unbounded = contact;
  unbounded.minNormalForce = 0.0;
  const ContactModelRows linear = rows(unbounded);
  AdmissibilityRows out;
  out.linear = -linear.rows;
  out.offset = linear.bound;
  out.names = linear.names;
  out.kinds = linear.kinds;
  return out;
}

const std::vector<ContactModelEntry>& contactModels() {
  static const std::vector<ContactModelEntry> registry = {
      {"report", "the report's: fz ≥ f_min, centre of pressure in the rectangle, a circular friction cone",
       makeReportContactModel},
      {"pyramid", "the report's with the friction cone replaced by inscribed facets (pyramid_facets)",
       makePyramidContactModel},
      {"wrench-cone", "Caron, Pham, Nakamura's wrench cone of a rectangle: the yaw moment bounded too",
       makeWrenchConeContactModel},
      {"point", "a force at the contact point in the friction cone, no moment (knuckles, a fingertip)",
       makePointContactModel},
  };
  return registry;
}

const std::vector<std::string>& contactModelNames() {
  static const std::vector<std::string> names = registryNames(contactModels());
  return names;
}

bool isContactModelName(const std::string& name) {
  const auto& names = contactModelNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string contactModelList() { return alternatives(contactModelNames()); }

std::shared_ptr<const ContactModel> makeContactModel(const std::string& name, const ContactModelOptions& options) {
  if (const ContactModelEntry* e = findInRegistry(contactModels(), name)) return e->make(options);
  throw InputError("contact model: expected " + contactModelList() + "; got '" + name + "'");
}

}  // namespace mcopt
