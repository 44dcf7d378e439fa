// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The outer problem's constraint rows as terms (formulation.md §10; docs/theory/outer-problem.md,
// "Constraint terms"). A term is one row family — velocity limits, torque limits, contact
// admissibility, inner feasibility, closing-joint limits, loop reach, the energy epigraph, tasks — as a
// const model: it lays out its rows and their sparsity, gives their bounds, kinds and names,
// and says how each row reads the motion. The motion problem (motion_problem.hpp) owns the
// terms, keeps one registry of their rows and evaluates them; nothing else names a family.
//
// A row reads one of three things:
//   control points  the term evaluates it from x and T itself (directValue, its derivatives and
//                   curvature): linear in the spline parameters, e.g. the velocity limits;
//   a sample        one output of the sample's evaluation (sample_outputs.hpp), times the term's
//                   sign, plus a slack variable of its own where the row has one (s − P);
//   a task instant  one component of its task's value (task.hpp).
// The Jacobian of the last two is the chain rule of their output's derivatives (motion_problem.cpp)
// and their Hessian contribution is their multiplier on that output (motion_hessian.cpp).
//
// A new family is one file (a class deriving from ConstraintTerm and its factory, declared
// below) and one line in makeConstraintTerms (constraint_term.cpp). The order of that list is
// the order of the rows within a sample.

#include <Eigen/Core>
#include <iosfwd>
#include <memory>
#include <string_view>
#include <vector>

#include "outer_nlp/closed_chains.hpp"
#include "outer_nlp/sample_outputs.hpp"

namespace mcopt {

class ContactAdmissibilityRows;
class MotionParametrization;
struct Scenario;

/// Where a term's rows are evaluated; it decides their instant, the suffix of their names and
/// how their multipliers reach the Hessian.
enum class RowPlace : unsigned char { ControlPoints, Sample, TaskInstant };

/// A kind of row: its key in result.json's `violation_by_kind`, the unit of its values and
/// whether `mcopt verify` checks it on the fine grid (false for rows on the solver's own
/// variables, which say nothing about the motion: the epigraph's slacks).
struct ConstraintKindInfo {
  std::string_view name, unit;
  bool verified = true;
};

/// What the terms read of the problem they belong to: references into the motion problem that
/// builds them (it outlives its terms).
struct TermContext {
  const Scenario& scenario;
  const MotionParametrization& parametrization;
  const SampleOutputs& outputs;
  const ClosedChains* closure;  ///< null without environment contacts
  const ContactAdmissibilityRows& support;  ///< the reference contact's rows, on W_ref
  const std::vector<ContactAdmissibilityRows>& contactRows;  ///< per environment contact, on its own wrench
  bool bilevel;  ///< the inner problem picks the wrenches
  // Sparsity: the joints whose motion changes Γ_j (per joint), every joint, and per task
  // instant the joints that move its task.
  const std::vector<std::vector<int>>& relatedJoints;
  const std::vector<int>& allJoints;
  const std::vector<std::vector<int>>& taskJoints;
  const std::vector<int>& torqueJoints;       ///< joints with a finite torque limit (when limited)
  const std::vector<bool>& omittedTorqueRows; ///< per sample and joint (s · n + j) left out; empty: none
  const std::vector<bool>& omittedClosingRows; ///< per sample and closing detail (s · 2c + k) left out; empty: none
  const std::vector<int>& taskOfInstant;      ///< the task of each task instant
};

/// How a term lays out the rows of one sample, task instant or (block −1) of the control
/// points: the motion problem's row registry, which records each row's Jacobian entries.
class RowSink {
 public:
  /// The sample or task instant whose rows are being laid out; −1 for control-point rows.
  virtual int block() const = 0;
  /// The contacts closed there (closed_chains.hpp).
  virtual ClosureSet closed() const = 0;
  /// Environment contact i's force columns at this sample (0: none there, or bilevel).
  virtual int forceColumnCount(int contact) const = 0;
  /// The epigraph slack of joint j at this sample.
  virtual int slackColumn(int joint) const = 0;
  /// A row reading output `output` (task instant: component): on the local spline parameters of
  /// `dependsOn`, on T when it is free, with `withForces` on every force column of the block,
  /// and on `slack` (≥ 0) with coefficient 1.
  virtual void outputRow(int detail, int output, const std::vector<int>& dependsOn, bool withForces, int slack = -1) = 0;
  /// A row reading output `output` that depends on environment contact i's force columns alone.
  virtual void contactRow(int detail, int output, int contact) = 0;
  /// A control-point row evaluated by the term (directValue): on variables `first` and
  /// `second`, then T when it is free (local columns 0, 1, 2).
  virtual void directRow(int detail, int first, int second) = 0;

 protected:
  ~RowSink() = default;
};

class ConstraintTerm {
 public:
  virtual ~ConstraintTerm() = default;
  virtual RowPlace place() const = 0;
  /// Every kind of row the term can lay out, rows or not in this problem (result.json lists each).
  virtual std::vector<ConstraintKindInfo> kinds() const = 0;
  /// The kind of one of its rows (`detail` and `block` as appendRows gave them).
  virtual const ConstraintKindInfo& kind(int detail, int block) const = 0;
  /// Lays out the rows of sink.block() (of every control point at −1), in the NLP's order.
  virtual void appendRows(RowSink& sink) const = 0;
  virtual void bounds(int detail, int block, double& lower, double& upper) const = 0;
  /// What a row bounds, without its instant: "torque limit of LLEG_JOINT3".
  virtual void subject(int detail, int block, std::ostream& name) const = 0;
  /// The factor on the output a row reads: −1 for s − P.
  virtual double outputSign() const { return 1.0; }
  /// Control-point rows: the value at x and the duration T, its derivative along local column
  /// k (directRow's), and λ times its second derivatives added to `hessian` (T's column
  /// `durationColumn`; called only when T is free).
  virtual double directValue(int /*detail*/, const Eigen::VectorXd& /*x*/, double /*T*/) const { return 0.0; }
  virtual double directDerivative(int /*detail*/, int /*k*/, const Eigen::VectorXd& /*x*/, double /*T*/) const { return 0.0; }
  virtual void addDirectHessian(int /*detail*/, double /*lambda*/, const Eigen::VectorXd& /*x*/, double /*T*/,
                                int /*durationColumn*/, Eigen::MatrixXd& /*hessian*/) const {}
};

/// A term whose rows are all of one kind and at the samples (torque limits, closing-joint
/// limits, inner feasibility, the epigraph's rows). `kind` has static storage.
class SampleTermOfOneKind : public ConstraintTerm {
 public:
  explicit SampleTermOfOneKind(const ConstraintKindInfo& kind) : kind_(kind) {}
  RowPlace place() const override { return RowPlace::Sample; }
  std::vector<ConstraintKindInfo> kinds() const override { return {kind_}; }
  const ConstraintKindInfo& kind(int, int) const override { return kind_; }

 private:
  const ConstraintKindInfo& kind_;
};

using ConstraintTerms = std::vector<std::unique_ptr<const ConstraintTerm>>;

/// The registry: every term, in the order of the rows within a sample (constraint_term.cpp).
ConstraintTerms makeConstraintTerms(const TermContext& context);

// The bundled terms, a file each.
std::unique_ptr<const ConstraintTerm> makeVelocityLimitTerm(const TermContext& context);     // limit_terms.cpp
std::unique_ptr<const ConstraintTerm> makeTorqueLimitTerm(const TermContext& context);       // limit_terms.cpp
std::unique_ptr<const ConstraintTerm> makeClosingJointLimitTerm(const TermContext& context); // limit_terms.cpp
std::unique_ptr<const ConstraintTerm> makeLoopReachTerm(const TermContext& context);         // loop_reach_term.cpp
std::unique_ptr<const ConstraintTerm> makeContactAdmissibilityTerm(const TermContext& context);  // contact_terms.cpp
std::unique_ptr<const ConstraintTerm> makeInnerFeasibilityTerm(const TermContext& context);      // contact_terms.cpp
std::unique_ptr<const ConstraintTerm> makeEnergyEpigraphTerm(const TermContext& context);   // energy_epigraph_term.cpp
std::unique_ptr<const ConstraintTerm> makeTaskTerm(const TermContext& context);             // task_term.cpp

}  // namespace mcopt
