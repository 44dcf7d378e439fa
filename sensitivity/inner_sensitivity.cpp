#include "sensitivity/inner_sensitivity.hpp"

#include <Eigen/KLUSupport>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SparseCore>
#include <Eigen/UmfPackSupport>
#include <cmath>
#include <sstream>
#include <vector>

#include "core/errors.hpp"

namespace mcopt {

const char* toString(KktBackend backend) {
  switch (backend) {
    case KktBackend::Dense: return "dense";
    case KktBackend::SparseKlu: return "klu";
    case KktBackend::SparseUmfpack: return "umfpack";
  }
  return "dense";
}

KktBackend parseKktBackend(const std::string& name) {
  if (name == "dense") return KktBackend::Dense;
  if (name == "klu") return KktBackend::SparseKlu;
  if (name == "umfpack") return KktBackend::SparseUmfpack;
  throw InputError("KKT backend: expected dense, klu or umfpack; got '" + name + "'");
}

std::string SensitivityDiagnostics::describe() const {
  std::ostringstream s;
  s << "KKT " << size << " × " << size << ": " << activeRows << " active rows, " << activeCones << " active cones, "
    << unloadedContacts << " unloaded contacts";
  if (weaklyActive > 0) s << "; " << weaklyActive << " weakly active constraints left out (one-sided derivatives)";
  if (reciprocalCondition < 1e-13) s << "; near-singular (reciprocal condition " << reciprocalCondition << ")";
  return s.str();
}

struct InnerSensitivity::Impl {
  SensitivitySettings settings;
  SensitivityDiagnostics diagnostics;
  int variables = 0;
  Eigen::MatrixXd kkt;
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> rankRevealing;
  bool useRankRevealing = false;
  Eigen::SparseMatrix<double> sparse;
  Eigen::KLU<Eigen::SparseMatrix<double>> klu;
  Eigen::UmfPackLU<Eigen::SparseMatrix<double>> umfpack;
  KktBackend backendInUse = KktBackend::Dense;
  Eigen::MatrixXd weightedWrenchToTorque;  ///< diag(w) J1 of the factorised problem, for dataSensitivities
  Eigen::MatrixXd lagrangianHessian, rhs, solution;
  std::vector<char> active;
  // One matrix and LU per possible system size (n + 6 … n + 6 + rows + cones), all made when a
  // problem shape is first seen: factorising exactly the used block costs what a variable
  // size would, and allocates nothing afterwards.
  int smallest = 0, capacity = -1;
  std::vector<Eigen::MatrixXd> systemBySize;
  std::vector<Eigen::PartialPivLU<Eigen::MatrixXd>> luBySize;
  int used = 0;  ///< size of the system in use
  const Eigen::MatrixXd& system() const { return systemBySize[static_cast<std::size_t>(used - smallest)]; }
  const Eigen::PartialPivLU<Eigen::MatrixXd>& factor() const { return luBySize[static_cast<std::size_t>(used - smallest)]; }
};

InnerSensitivity::InnerSensitivity(SensitivitySettings settings) : impl_(std::make_unique<Impl>()) {
  impl_->settings = settings;
}
InnerSensitivity::~InnerSensitivity() = default;
InnerSensitivity::InnerSensitivity(InnerSensitivity&&) noexcept = default;
InnerSensitivity& InnerSensitivity::operator=(InnerSensitivity&&) noexcept = default;

const SensitivityDiagnostics& InnerSensitivity::diagnostics() const { return impl_->diagnostics; }

const SensitivityDiagnostics& InnerSensitivity::factorize(const ContactProblem& p, const InnerResult& r) {
  Impl& m = *impl_;
  const int nc = p.contactCount, n = 6 * nc;
  if (r.status != InnerStatus::Optimal)
    throw InputError(std::string("sensitivity: the inner result is ") + toString(r.status) +
                     ", not optimal: no derivative of the optimal wrenches exists there");
  if (r.wrenches.size() != n || r.inequalityMultipliers.size() != p.inequality.rows() ||
      r.coneMultipliers.size() != 3 * static_cast<Eigen::Index>(p.cones.size()))
    throw InputError("sensitivity: the inner result does not belong to this problem (sizes differ)");
  m.variables = n;
  m.diagnostics = {};
  m.weightedWrenchToTorque = p.weightedWrenchToTorque;
  const Eigen::VectorXd& F = r.wrenches;
  const double scale = 1.0 + p.hessian.cwiseAbs().maxCoeff() + p.gradient.cwiseAbs().maxCoeff() +
                       p.balanceTarget.cwiseAbs().maxCoeff();
  const double strict = m.settings.strictMultiplier * scale;
  const double forceScale = 1.0 + F.cwiseAbs().maxCoeff();
  const auto rowCount = static_cast<int>(p.inequality.rows());
  const auto coneCount = static_cast<int>(p.cones.size());
  const int perContact = rowCount / nc;  // assembly order: each contact's rows together, fz_min first
  m.active.assign(static_cast<std::size_t>(rowCount + coneCount), 0);
  for (int a : r.activeSet) m.active[static_cast<std::size_t>(a)] = 1;

  // Assembled in a buffer of the largest size (one slot per linear row and cone; an unloaded
  // contact's pins, ≤ 6, take the slots of its own rows and cone, ≥ 6 in every contact model),
  // the used rows first; the used block is then factorised.
  const int size = n + 6 + rowCount + coneCount;
  m.kkt.setZero(size, size);
  m.lagrangianHessian = p.hessian;
  m.kkt.block(n, 0, 6, n) = p.balance;
  m.kkt.block(0, n, n, 6) = p.balance.transpose();
  int next = n + 6;
  auto addRow = [&](const auto& row) {
    m.kkt.block(next, 0, 1, n) = row;
    m.kkt.block(0, next, n, 1) = row.transpose();
    ++next;
  };
  auto addUnit = [&](int column) {
    m.kkt(next, column) = 1.0;
    m.kkt(column, next) = 1.0;
    ++next;
  };
  for (int i = 0; i < nc; ++i) {
    const int fzRow = perContact * i;
    const double fz = F[6 * i + 2];
    const int cone = p.cones.empty() ? -1 : i;  // report model: cone i belongs to contact i
    // Held at zero by its fz_min row or by its cone's apex (the active-set method certifies
    // an unloaded contact through the cone's planes, whose multipliers make y_z).
    const bool apex = cone >= 0 && m.active[static_cast<std::size_t>(rowCount + cone)];
    // An interior-point result stops near the apex, not on it: a contact whose normal and
    // shear forces are both negligible is unloaded too (never a curvature ν / ‖f_t‖ there).
    const double shearNorm = F.segment<2>(6 * i).norm();
    const bool nearApex = std::abs(fz) <= m.settings.unloadedForce * forceScale &&
                          shearNorm <= m.settings.unloadedForce * forceScale;
    if ((m.active[static_cast<std::size_t>(fzRow)] || apex) && nearApex) {
      // Unloaded: held at zero wrench while its pushing multiplier is positive.
      ++m.diagnostics.unloadedContacts;
      double push = r.inequalityMultipliers[fzRow];
      if (cone >= 0) push += r.coneMultipliers[3 * cone + 2];
      if (!(push > strict)) ++m.diagnostics.weaklyActive;
      bool yawHeld = false;
      for (int k = fzRow; k < fzRow + perContact; ++k) yawHeld |= p.inequality(k, 6 * i + 5) != 0.0;
      for (int component = 0; component < (yawHeld ? 6 : 5); ++component) addUnit(6 * i + component);
      continue;
    }
    for (int k = fzRow; k < fzRow + perContact; ++k) {
      if (!m.active[static_cast<std::size_t>(k)]) continue;
      if (r.inequalityMultipliers[k] > strict) {
        addRow(p.inequality.row(k));
        ++m.diagnostics.activeRows;
      } else {
        ++m.diagnostics.weaklyActive;
      }
    }
    if (cone >= 0 && m.active[static_cast<std::size_t>(rowCount + cone)]) {
      const FrictionCone& c = p.cones[static_cast<std::size_t>(cone)];
      const double nu = r.coneMultipliers[3 * cone + 2] / c.friction;
      const Eigen::Vector2d shear = F.segment<2>(c.index);
      const double norm = shear.norm();
      if (nu > strict && norm > m.settings.unloadedForce * forceScale) {
        const Eigen::Vector2d u = shear / norm;
        m.kkt(next, c.index) = m.kkt(c.index, next) = u.x();
        m.kkt(next, c.index + 1) = m.kkt(c.index + 1, next) = u.y();
        m.kkt(next, c.index + 2) = m.kkt(c.index + 2, next) = -c.friction;
        ++next;
        m.lagrangianHessian.block<2, 2>(c.index, c.index) += (nu / norm) * (Eigen::Matrix2d::Identity() - u * u.transpose());
        ++m.diagnostics.activeCones;
      } else {
        ++m.diagnostics.weaklyActive;
      }
    }
  }
  m.kkt.topLeftCorner(n, n) = m.lagrangianHessian;
  if (m.capacity != size || m.smallest != n + 6) {
    m.smallest = n + 6, m.capacity = size;
    m.systemBySize.clear();
    m.luBySize.clear();
    for (int k = m.smallest; k <= size; ++k) {
      m.systemBySize.emplace_back(k, k);
      m.luBySize.emplace_back(k);
    }
  }
  m.used = next;
  m.diagnostics.size = next;
  Eigen::MatrixXd& system = m.systemBySize[static_cast<std::size_t>(next - m.smallest)];
  system = m.kkt.topLeftCorner(next, next);

  // Dense LU always gives the condition estimate; a near-singular system (dependent active
  // rows, whose multipliers are then not unique while dF is) is solved in the least-norm sense.
  Eigen::PartialPivLU<Eigen::MatrixXd>& lu = m.luBySize[static_cast<std::size_t>(next - m.smallest)];
  lu.compute(system);
  m.diagnostics.reciprocalCondition = lu.rcond();
  if (!std::isfinite(m.diagnostics.reciprocalCondition)) m.diagnostics.reciprocalCondition = 0.0;
  m.useRankRevealing = m.diagnostics.reciprocalCondition < 1e-13;
  if (m.useRankRevealing) m.rankRevealing.compute(system);
  m.backendInUse = KktBackend::Dense;
  if (m.settings.backend != KktBackend::Dense && !m.useRankRevealing) {
    m.sparse = system.sparseView();
    if (m.settings.backend == KktBackend::SparseKlu) {
      m.klu.compute(m.sparse);
      if (m.klu.info() == Eigen::Success) m.backendInUse = KktBackend::SparseKlu;
    } else {
      m.umfpack.compute(m.sparse);
      if (m.umfpack.info() == Eigen::Success) m.backendInUse = KktBackend::SparseUmfpack;
    }
  }
  return m.diagnostics;
}

const Eigen::MatrixXd& InnerSensitivity::kktMatrix() const { return impl_->system(); }

void InnerSensitivity::rightHandSide(const Eigen::Ref<const Eigen::MatrixXd>& dStationarity,
                                     const Eigen::Ref<const Eigen::MatrixXd>& dBalance, Eigen::MatrixXd& rhs) const {
  const int n = impl_->variables, size = impl_->diagnostics.size;
  if (size == 0) throw InputError("sensitivity: right-hand side before factorize");
  rhs.setZero(size, dStationarity.cols());
  rhs.topRows(n) = -dStationarity;
  rhs.middleRows(n, 6) = -dBalance;
}

void InnerSensitivity::solve(const Eigen::Ref<const Eigen::MatrixXd>& dStationarity,
                             const Eigen::Ref<const Eigen::MatrixXd>& dBalance, Eigen::MatrixXd& dWrenches,
                             Eigen::MatrixXd* dBalanceMultipliers) const {
  Impl& m = *impl_;
  const int n = m.variables, size = m.diagnostics.size;
  if (size == 0) throw InputError("sensitivity: solve before factorize");
  if (dStationarity.rows() != n || dBalance.rows() != 6 || dStationarity.cols() != dBalance.cols())
    throw InputError("sensitivity: right-hand sides must be 6nc × m and 6 × m");
  // Buffers reused from call to call (allocation-free for the same shapes: the per-sample
  // path of MultiContactGradientEvaluator).
  Eigen::MatrixXd& rhs = impl_->rhs;
  Eigen::MatrixXd& solution = impl_->solution;
  rhs.setZero(size, dStationarity.cols());
  rhs.topRows(n) = -dStationarity;
  rhs.middleRows(n, 6) = -dBalance;
  solution.resize(size, dStationarity.cols());
  switch (m.backendInUse) {
    case KktBackend::SparseKlu: solution = m.klu.solve(rhs); break;
    case KktBackend::SparseUmfpack: solution = m.umfpack.solve(rhs); break;
    case KktBackend::Dense:
      if (m.useRankRevealing)
        solution = m.rankRevealing.solve(rhs);
      else
        solution.noalias() = m.factor().solve(rhs);
      break;
  }
  dWrenches = solution.topRows(n);
  if (dBalanceMultipliers != nullptr) *dBalanceMultipliers = solution.middleRows(n, 6);
}

void InnerSensitivity::dataSensitivities(const ContactProblem& p, Eigen::MatrixXd& dTau0,
                                         Eigen::MatrixXd& dBalanceWrench) const {
  const int n = impl_->variables;
  if (p.weightedWrenchToTorque.cols() != n) throw InputError("sensitivity: problem differs from the factorised one");
  const Eigen::MatrixXd dStationarityDtau0 = -2.0 * p.weightedWrenchToTorque.transpose();  // ∂c/∂τ0
  solve(dStationarityDtau0, Eigen::MatrixXd::Zero(6, dStationarityDtau0.cols()), dTau0);
  solve(Eigen::MatrixXd::Zero(n, 6), -Eigen::MatrixXd::Identity(6, 6), dBalanceWrench);  // ∂(B F − W)/∂W = −1
}

}  // namespace mcopt
