// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A contact model (formulation.md §5): which wrenches F = (f, m) a contact admits, written in
// its own frame C (z = the surface normal into the robot). One type answers every layer:
//   - the inner problem's assembly asks it for each contact's linear rows (rows · F ≤ bound),
//     their names and kinds, and whether the friction cone stays a second-order cone;
//   - the sensitivity reads the assembled problem's per-contact row ranges and kinds, which
//     come from here, instead of assuming a layout;
//   - the single-level outer formulations ask it for the rows ≥ 0 they hold on a wrench
//     variable (admissibilityRows), affine in W_C plus at most one quadratic row.
// A new model is one file (a class deriving from ContactModel and its factory) and one line
// in the registry, contactModels() in contact_model.cpp. The bundled ones:
//   report       (report_contact.cpp)       fz ≥ f_min, centre of pressure in the rectangle, the
//                                           friction cone ‖(fx, fy)‖ ≤ μ fz kept as a cone
//   pyramid      (pyramid_contact.cpp)      the cone replaced by k inscribed facets
//   wrench-cone  (wrench_cone_contact.cpp)  Caron, Pham, Nakamura (ICRA 2015): the yaw moment
//                                           bounded as well
//   point        (point_contact.cpp)        a force at the contact point in the friction cone,
//                                           no moment (knuckles or a fingertip on a table)
// A model's wrench has wrenchSize() components: the six of (f, m), or the three of f alone
// (the moment is zero and is not a variable). Rows are always written over the six.

#include <Eigen/Core>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/spatial.hpp"

namespace mcopt {

class ContactModel;

/// One contact of an inner problem: frame C in the world (z = normal into the robot),
/// friction μ > 0, rectangle [xMin, xMax] × [yMin, yMax] in C (unused by a point contact), and
/// its own contact model when it differs from the problem's.
struct ContactSpec {
  std::string name;
  RigidTransform pose;
  double friction = 0.7;
  double xMin = 0, xMax = 0, yMin = 0, yMax = 0;
  double minNormalForce = 0.0;  ///< f_min ≥ 0
  std::shared_ptr<const ContactModel> model;  ///< null: the problem's (ContactProblemSettings::model)
};

/// What a contact-model row bounds (results group violations by it).
enum class ContactRowKind { NormalForce, CenterOfPressure, Friction, Yaw };

/// One contact's linear rows in its own frame, rows · F ≤ bound with F = (f, m) in C.
struct ContactModelRows {
  Eigen::Matrix<double, Eigen::Dynamic, 6> rows;
  Eigen::VectorXd bound;
  std::vector<std::string> names;     ///< fz_min, cop_x_max, …, facet_<k> or fx_max, …, yaw_min_3
  std::vector<ContactRowKind> kinds;
};

/// The rows ≥ 0 a single-level formulation holds on a contact's wrench W_C (in C):
///   row_k = offset_k + linear_k · W_C  (+ ½ W_Cᵀ quadratic W_C on quadraticRow).
/// Row 0 is f_z itself; the caller bounds it below by the contact's f_min.
struct AdmissibilityRows {
  Eigen::Matrix<double, Eigen::Dynamic, 6> linear;
  Eigen::VectorXd offset;
  int quadraticRow = -1;  ///< the one row with a quadratic part, or -1
  Eigen::Matrix<double, 6, 6> quadratic = Eigen::Matrix<double, 6, 6>::Zero();
  std::vector<std::string> names;
  std::vector<ContactRowKind> kinds;

  /// Makes `row` the smooth friction cone (μ² f_z² − f_x² − f_y²) / (m g)², scaled to the
  /// robot's weight m g [N] (the report's and the point contact's outer row).
  void setSmoothFrictionCone(int row, double friction, double weight);
};

/// Appends rows a · F ≤ bound over one contact's six wrench components (for a model's rows()).
class ContactRowWriter {
 public:
  enum Component { Fx = 0, Fy, Fz, Mx, My, Mz };
  explicit ContactRowWriter(ContactModelRows& out) : out_(out) {}
  void add(std::string name, ContactRowKind kind, std::initializer_list<std::pair<int, double>> terms,
           double bound = 0.0);
  /// The rows every bundled model starts with: fz ≥ f_min, then the centre of pressure in the
  /// rectangle, x_min fz ≤ −m_y ≤ x_max fz and y_min fz ≤ m_x ≤ y_max fz (report (2.21), with
  /// (2.20) corrected): fz_min, cop_x_max, cop_x_min, cop_y_max, cop_y_min.
  void addSupportRows(const ContactSpec& contact);
  int written() const { return static_cast<int>(next_); }

 private:
  ContactModelRows& out_;
  Eigen::Index next_ = 0;
};

class ContactModel {
 public:
  virtual ~ContactModel() = default;
  /// The name scenario files (`inner.contact_model`), `mcopt inner` and Python know it by.
  virtual std::string name() const = 0;
  /// Linear rows a contact has under the model.
  virtual int rowCount() const = 0;
  /// Wrench components that are variables: 6, (f, m); or 3, f alone with m = 0 (its rows
  /// then bound f only).
  virtual int wrenchSize() const { return 6; }
  /// Whether the model bounds the contact's extent (a rectangle must then be given).
  virtual bool hasRectangle() const { return true; }
  /// One contact's linear rows; the first is the normal force's fz ≥ f_min (kind NormalForce,
  /// the row the sensitivity reads an unloaded contact's push from).
  ContactModelRows rows(const ContactSpec& contact) const;
  /// Whether the friction cone ‖(fx, fy)‖ ≤ μ fz is kept as a second-order cone beside the
  /// linear rows (the inner solvers then hold it themselves).
  virtual bool hasSecondOrderCone() const { return false; }
  /// The rows ≥ 0 on W_C for a wrench the outer NLP holds itself; weight m g [N] scales a
  /// quadratic row to the robot. By default the linear rows as bound − rows · W_C with
  /// f_min = 0, so that row 0 is f_z.
  virtual AdmissibilityRows admissibilityRows(const ContactSpec& contact, double weight) const;

 protected:
  /// Writes rowCount() rows into out (sized by rows()).
  virtual void writeRows(const ContactSpec& contact, ContactRowWriter& out) const = 0;
};

/// A model's parameters, as scenario files and the CLI give them.
struct ContactModelOptions {
  int pyramidFacets = 8;  ///< pyramid: k ≥ 3 facets
};

/// One registered contact model: its name, one line on what it is, and its factory (which
/// throws InputError for options it cannot take).
struct ContactModelEntry {
  std::string name;
  std::string description;
  std::shared_ptr<const ContactModel> (*make)(const ContactModelOptions& options);
};

/// Every contact model, in the order documents list them (a new model: its file and one line
/// in contact_model.cpp).
const std::vector<ContactModelEntry>& contactModels();
/// Their names, in the same order.
const std::vector<std::string>& contactModelNames();
bool isContactModelName(const std::string& name);
/// "report, pyramid, wrench-cone or point".
std::string contactModelList();
/// The model by name; InputError naming the registered ones otherwise.
std::shared_ptr<const ContactModel> makeContactModel(const std::string& name, const ContactModelOptions& options = {});

std::shared_ptr<const ContactModel> makeReportContactModel(const ContactModelOptions& options = {});
std::shared_ptr<const ContactModel> makePyramidContactModel(const ContactModelOptions& options = {});
std::shared_ptr<const ContactModel> makeWrenchConeContactModel(const ContactModelOptions& options = {});
std::shared_ptr<const ContactModel> makePointContactModel(const ContactModelOptions& options = {});

}  // namespace mcopt
