// SPDX-License-Identifier: BSD-3-Clause
// The motion problem's structure: the rows laid out by the terms' registry (their order,
// kinds, names and instants), the Jacobian's sparsity, and the variable and row bounds.
#include "outer_nlp/motion_problem.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "core/contact_maps.hpp"
#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/spatial.hpp"
#include "core/trajectory_evaluation.hpp"
#include "outer_nlp/contact_force_formulation.hpp"
#include "outer_nlp/motion_workspace.hpp"

namespace mcopt {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

void MotionProblem::buildStructure() {
  // The one place rows and their Jacobian entries are enumerated: each term lays out its rows
  // (constraint_term.hpp) through this registry, the control points' first, then sample by
  // sample the terms in their order, then the task instants'.
  std::vector<int> rows, columns;
  using Source = JacobianEntry::Source;
  class Registry final : public RowSink {
   public:
    Registry(MotionProblem& problem, std::vector<int>& rows, std::vector<int>& columns)
        : p_(problem), rows_(rows), columns_(columns), freeT_(problem.durationIsFree()) {}
    void start(int term, bool task, int block) {
      term_ = term, task_ = task, block_ = block;
      place_ = p_.terms_[static_cast<std::size_t>(term)]->place();
      sign_ = p_.terms_[static_cast<std::size_t>(term)]->outputSign();
      b_ = block < 0 ? nullptr : task ? &p_.taskBlocks_[static_cast<std::size_t>(block)] : &p_.blocks_[static_cast<std::size_t>(block)];
    }
    int block() const override { return block_; }
    ClosureSet closed() const override { return b_->closed; }
    int forceColumnCount(int contact) const override {
      int count = 0;
      for (const LocalForceTerm& t : b_->forceTerms) count += t.contact == contact ? 6 : 0;
      return count;
    }
    int slackColumn(int joint) const override { return p_.slackIndex(block_, joint); }
    void outputRow(int detail, int output, const std::vector<int>& dependsOn, bool withForces, int slack) override {
      p_.rows_.push_back({term_, detail, block_, output, slack, place_, sign_});
      const SampleBlock& b = *b_;
      const int k = static_cast<int>(b.parameters.size()) / p_.jointCount_;
      for (const int j : dependsOn)
        for (int l = 0; l < k; ++l) entry(b.parameters[j * k + l], {Source::Parameter, task_, block_, output, j * k + l, sign_});
      if (freeT_) entry(p_.parameterCount_, {Source::Duration, task_, block_, output, -1, sign_});
      if (withForces)
        for (std::size_t c = 0; c < b.forceColumns.size(); ++c)
          entry(b.forceColumns[c], {Source::Force, task_, block_, output, static_cast<int>(c), sign_});
      if (slack >= 0) entry(slack, {Source::Slack, false, block_, -1, -1, 1.0});
    }
    void contactRow(int detail, int output, int contact) override {
      p_.rows_.push_back({term_, detail, block_, output, -1, place_, sign_});
      for (const LocalForceTerm& t : b_->forceTerms)
        for (int l = t.firstColumn; t.contact == contact && l < t.firstColumn + 6; ++l)
          entry(b_->forceColumns[static_cast<std::size_t>(l)], {Source::Force, task_, block_, output, l, sign_});
    }
    void directRow(int detail, int first, int second) override {
      p_.rows_.push_back({term_, detail, -1, -1, -1, RowPlace::ControlPoints, 1.0});
      entry(first, {Source::Direct, false, -1, -1, 0, 1.0});
      entry(second, {Source::Direct, false, -1, -1, 1, 1.0});
      if (freeT_) entry(p_.parameterCount_, {Source::Direct, false, -1, -1, 2, 1.0});
    }

   private:
    void entry(int column, JacobianEntry e) {
      if (!p_.derivativesLaidOut_) return;  // values only: the rows without their Jacobian
      rows_.push_back(static_cast<int>(p_.rows_.size()) - 1), columns_.push_back(column), p_.entries_.push_back(e);
    }
    MotionProblem& p_;
    std::vector<int>& rows_;
    std::vector<int>& columns_;
    const bool freeT_;
    int term_ = 0, block_ = -1;
    bool task_ = false;
    RowPlace place_ = RowPlace::Sample;
    double sign_ = 1.0;
    const SampleBlock* b_ = nullptr;
  };
  Registry registry(*this, rows, columns);
  const auto layOut = [&](RowPlace place, bool task, int block) {
    for (std::size_t t = 0; t < terms_.size(); ++t)
      if (terms_[t]->place() == place) registry.start(static_cast<int>(t), task, block), terms_[t]->appendRows(registry);
  };
  layOut(RowPlace::ControlPoints, false, -1);
  for (int s = 0; s < samples_.sampleCount(); ++s) layOut(RowPlace::Sample, false, s);
  for (std::size_t i = 0; i < taskBlocks_.size(); ++i) layOut(RowPlace::TaskInstant, true, static_cast<int>(i));
  jacobianRows_ = Eigen::Map<Eigen::VectorXi>(rows.data(), static_cast<Eigen::Index>(rows.size()));
  jacobianColumns_ = Eigen::Map<Eigen::VectorXi>(columns.data(), static_cast<Eigen::Index>(columns.size()));
}

std::vector<ConstraintKindInfo> MotionProblem::rowKinds() const {
  std::vector<ConstraintKindInfo> kinds;
  for (const auto& term : terms_)
    for (const ConstraintKindInfo& k : term->kinds()) kinds.push_back(k);
  return kinds;
}

double MotionProblem::Violations::of(std::string_view kind) const {
  for (const auto& [name, worst] : byKind)
    if (name == kind) return worst;
  throw std::out_of_range("no constraint term lays out rows of kind '" + std::string(kind) + "'");
}

std::string MotionProblem::rowSubject(int row) const {
  const Row& r = rows_[static_cast<std::size_t>(row)];
  std::ostringstream name;
  terms_[static_cast<std::size_t>(r.term)]->subject(r.detail, r.block, name);
  return name.str();
}

std::string MotionProblem::rowName(int row) const {
  const Row& r = rows_[static_cast<std::size_t>(row)];
  std::ostringstream name;
  name << rowSubject(row);
  switch (r.place) {
    case RowPlace::ControlPoints: name << " (control points)"; break;
    case RowPlace::TaskInstant: name << " at u = " << taskSamples_.time(r.block, 1.0) << " of the motion"; break;
    case RowPlace::Sample: name << " at sample " << r.block; break;
  }
  return name.str();
}

double MotionProblem::rowTime(int row, double T) const {
  const Row& r = rows_[static_cast<std::size_t>(row)];
  switch (r.place) {
    case RowPlace::ControlPoints: return std::numeric_limits<double>::quiet_NaN();
    case RowPlace::TaskInstant: return taskSamples_.time(r.block, T);
    case RowPlace::Sample: break;
  }
  return T * sampleTimes_[static_cast<std::size_t>(r.block)];
}

void MotionProblem::variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const {
  lower.setConstant(variableCount_, -kInf);
  upper.setConstant(variableCount_, kInf);
  const int m = parametrization_.parametersPerJoint();
  for (int j = 0; j < jointCount_; ++j) {
    const JointLimits& limit = scenario_.robot.joints[static_cast<std::size_t>(j)].limits;
    if (scenario_.positionLimits) {
      lower.segment(j * m, m).setConstant(limit.lower);
      upper.segment(j * m, m).setConstant(limit.upper);
    }
    if (scenario_.fixStart) lower[j * m] = upper[j * m] = scenario_.start[j];
    if (scenario_.fixEnd) {
      const int end = j * m + parametrization_.endParameter();
      lower[end] = upper[end] = scenario_.end[j];
    }
  }
  // Where a closing joint follows the closure its spline parameters are unused: fixed at the start posture.
  for (int j = 0; closure_ && j < jointCount_; ++j)
    for (int l = 0; l < m; ++l)
      if (unusedParameter_[static_cast<std::size_t>(j * m + l)]) lower[j * m + l] = upper[j * m + l] = scenario_.start[j];
  if (durationIsFree()) lower[parameterCount_] = scenario_.duration.lower, upper[parameterCount_] = scenario_.duration.upper;
  formulation_->variableBounds(lower, upper);
  forEachCostVariableBlock([&](const CostTerm& cost, int, int first, int size) {
    cost.sampleVariableBounds(lower.segment(first, size), upper.segment(first, size));
  });
}

void MotionProblem::variableUnits(Eigen::VectorXd& units) const {
  units.setOnes(variableCount_);
  formulation_->variableUnits(units);
}

void MotionProblem::constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const {
  lower.resize(constraintCount());
  upper.resize(constraintCount());
  for (int r = 0; r < constraintCount(); ++r) {
    const Row& row = rows_[static_cast<std::size_t>(r)];
    terms_[static_cast<std::size_t>(row.term)]->bounds(row.detail, row.block, lower[r], upper[r]);
  }
}

}  // namespace mcopt
