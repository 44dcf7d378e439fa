// SPDX-License-Identifier: BSD-3-Clause
#include "sensitivity/inner_sensitivity.hpp"

#include <Eigen/LU>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <vector>

#include "core/errors.hpp"
#include "sensitivity/sparse_kkt_factor.hpp"

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
  if (nearSingular())
    s << "; near-singular (reciprocal condition " << reciprocalCondition << ", pivot ratio " << pivotRatio << ")";
  return s.str();
}

namespace {

/// x ← A⁻¹ x with PA = LU, in place on the leading rows of x (no allocation).
void solveInPlace(const Eigen::PartialPivLU<Eigen::MatrixXd>& lu, Eigen::Ref<Eigen::VectorXd> x, Eigen::Ref<Eigen::VectorXd> scratch) {
  scratch.noalias() = lu.permutationP() * x;
  lu.matrixLU().triangularView<Eigen::UnitLower>().solveInPlace(scratch);
  lu.matrixLU().triangularView<Eigen::Upper>().solveInPlace(scratch);
  x = scratch;
}

/// x ← A⁻ᵀ x: Aᵀ = Uᵀ Lᵀ P, so solve Uᵀ, then Lᵀ, then apply Pᵀ.
void solveTransposedInPlace(const Eigen::PartialPivLU<Eigen::MatrixXd>& lu, Eigen::Ref<Eigen::VectorXd> x,
                            Eigen::Ref<Eigen::VectorXd> scratch) {
  lu.matrixLU().triangularView<Eigen::Upper>().transpose().solveInPlace(x);
  lu.matrixLU().triangularView<Eigen::UnitLower>().transpose().solveInPlace(x);
  scratch.noalias() = lu.permutationP().transpose() * x;
  x = scratch;
}

/// 1 / (‖A‖₁ ‖A⁻¹‖₁) with ‖A⁻¹‖₁ estimated by Hager's method (Higham's refinement: at most
/// five sign iterations, then the alternating-sign test vector), the estimate LAPACK's
/// dgecon and Eigen's rcond make; written here with workspace vectors so that the
/// per-sample factorisation allocates nothing (Eigen's own allocates its vectors per call).
double reciprocalConditionEstimate(const Eigen::MatrixXd& a, const Eigen::PartialPivLU<Eigen::MatrixXd>& lu,
                                   Eigen::VectorXd& xBuffer, Eigen::VectorXd& signBuffer, Eigen::VectorXd& zBuffer) {
  const Eigen::Index k = a.rows();
  if (k == 0) return 1.0;
  double normA = 0.0;
  for (Eigen::Index c = 0; c < k; ++c) normA = std::max(normA, a.col(c).lpNorm<1>());
  if (normA == 0.0) return 0.0;
  auto x = xBuffer.head(k), sign = signBuffer.head(k), z = zBuffer.head(k);
  x.setConstant(1.0 / static_cast<double>(k));
  solveInPlace(lu, x, z);
  double estimate = x.lpNorm<1>();
  if (k > 1) {
    for (Eigen::Index i = 0; i < k; ++i) sign[i] = x[i] >= 0.0 ? 1.0 : -1.0;
    z = sign;
    solveTransposedInPlace(lu, z, x);
    for (int iteration = 0; iteration < 5; ++iteration) {
      Eigen::Index j = 0;
      const double zMax = z.cwiseAbs().maxCoeff(&j);
      x.setZero();
      x[j] = 1.0;
      solveInPlace(lu, x, z);
      const double previous = estimate;
      estimate = x.lpNorm<1>();
      bool sameSigns = true;
      for (Eigen::Index i = 0; i < k; ++i) sameSigns = sameSigns && (x[i] >= 0.0 ? 1.0 : -1.0) == sign[i];
      if (sameSigns || estimate <= previous) {
        estimate = std::max(estimate, previous);
        break;
      }
      for (Eigen::Index i = 0; i < k; ++i) sign[i] = x[i] >= 0.0 ? 1.0 : -1.0;
      z = sign;
      solveTransposedInPlace(lu, z, x);
      Eigen::Index jNext = 0;
      z.cwiseAbs().maxCoeff(&jNext);
      if (jNext == j || !(zMax > 0.0)) break;
    }
    // The alternating test vector catches what the sign iterations miss.
    for (Eigen::Index i = 0; i < k; ++i)
      x[i] = (i % 2 == 0 ? 1.0 : -1.0) * (1.0 + static_cast<double>(i) / static_cast<double>(k - 1));
    solveInPlace(lu, x, z);
    estimate = std::max(estimate, 2.0 * x.lpNorm<1>() / (3.0 * static_cast<double>(k)));
  }
  if (!(estimate > 0.0) || !std::isfinite(estimate)) return 0.0;
  return 1.0 / (normA * estimate);
}

/// The eigendecomposition K = V Λ Vᵀ of a symmetric matrix in workspace of its own size:
/// Eigen's SelfAdjointEigenSolver, step by step (tridiagonalisation, Q formed in place, QR
/// iterations), with the Householder workspace its compute() allocates on every call kept
/// here instead.
struct SymmetricEigen {
  explicit SymmetricEigen(Eigen::Index k) : vectors(k, k), values(k), subdiagonal(k > 1 ? k - 1 : 1), householder(k > 1 ? k - 1 : 1), workspace(k) {}

  bool compute(const Eigen::MatrixXd& k) {
    const Eigen::Index n = k.rows();
    vectors = k.triangularView<Eigen::Lower>();
    double scale = vectors.cwiseAbs().maxCoeff();  // to [-1, 1], against over- and underflow
    if (scale == 0.0) scale = 1.0;
    vectors.triangularView<Eigen::Lower>() /= scale;
    if (n == 1) {
      values[0] = vectors(0, 0) * scale;
      vectors(0, 0) = 1.0;
      return true;
    }
    Eigen::internal::tridiagonalization_inplace(vectors, householder);
    values = vectors.diagonal();
    subdiagonal = vectors.diagonal<-1>();
    Eigen::HouseholderSequence<Eigen::MatrixXd, Eigen::VectorXd, 1>(vectors, householder).setLength(n - 1).setShift(1).evalTo(
        vectors, workspace);
    const Eigen::ComputationInfo info = Eigen::internal::computeFromTridiagonal_impl(values, subdiagonal, 30 * n, true, vectors);
    values *= scale;
    return info == Eigen::Success;
  }

  Eigen::MatrixXd vectors;
  Eigen::VectorXd values, subdiagonal, householder, workspace;
};

/// x = K⁺ b = V Λ⁺ Vᵀ b for symmetric K = V Λ Vᵀ, eigenvalues below ε k max|λ| taken as
/// zero (the rank threshold of Eigen's complete orthogonal decomposition). `projected` is
/// workspace with at least K's rows and b's columns.
void leastNormSolve(const SymmetricEigen& eigen, const Eigen::Ref<const Eigen::MatrixXd>& b, Eigen::MatrixXd& projected,
                    Eigen::Ref<Eigen::MatrixXd> x) {
  const Eigen::Index k = b.rows();
  if (projected.rows() < k || projected.cols() != b.cols()) projected.resize(k, b.cols());
  auto vtb = projected.topRows(k);
  vtb.noalias() = eigen.vectors.transpose() * b;
  const double threshold = Eigen::NumTraits<double>::epsilon() * static_cast<double>(k) * eigen.values.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < k; ++i) {
    if (std::abs(eigen.values[i]) > threshold)
      vtb.row(i) /= eigen.values[i];
    else
      vtb.row(i).setZero();
  }
  x.noalias() = eigen.vectors * vtb;
}

}  // namespace

struct InnerSensitivity::Impl {
  SensitivitySettings settings;
  SensitivityDiagnostics diagnostics;
  int variables = 0;
  Eigen::MatrixXd kkt;
  // Near-singular systems (formulation.md §8: dependent active rows, or a null space no row
  // or curvature fixes) are solved in the least-norm sense through the symmetric KKT
  // matrix's eigendecomposition, K⁺ = V Λ⁺ Vᵀ — the minimum-norm solution a complete
  // orthogonal decomposition gives, in workspace of the largest size made with the problem's
  // shape (the COD's solve allocated its temporaries every call). A system of a smaller size
  // k is decomposed as diag(K, s I) with s = max|K_ij| ≤ ‖K‖₂: its pseudo-inverse is
  // diag(K⁺, I/s), the rank threshold (set by max|λ|) is K's own, and nothing is made later —
  // where the debug build's no-malloc check is armed (core/no_malloc_scope.hpp) — at the
  // price of a capacity-sized decomposition for the rare near-singular sample.
  std::unique_ptr<SymmetricEigen> eigen;
  Eigen::MatrixXd padded;     ///< diag(K, s I), capacity × capacity
  Eigen::MatrixXd projected;  ///< Vᵀ b, then Λ⁺ Vᵀ b (capacity × columns)
  bool useRankRevealing = false;
  std::unique_ptr<SparseKktFactor> sparseFactor;  ///< the klu and umfpack backends
  KktBackend backendInUse = KktBackend::Dense;
  Eigen::MatrixXd weightedWrenchToTorque;  ///< diag(w) J1 of the factorised problem, for dataSensitivities
  Eigen::MatrixXd lagrangianHessian, rhs, solution;
  std::vector<char> active;
  // One matrix and LU per possible system size (n + 6 … n + 6 + rows + cones), all made when a
  // problem shape is first seen: factorising exactly the used block costs what a variable
  // size would, and allocates nothing afterwards.
  int smallest = 0, capacity = -1;
  std::vector<Eigen::MatrixXd> systemBySize;
  // Workspace of the condition estimate and of the solves, sized to the largest system (and
  // the right-hand sides' column count) and used by their leading rows.
  Eigen::VectorXd estimateX, estimateSign, estimateZ;
  std::vector<Eigen::PartialPivLU<Eigen::MatrixXd>> luBySize;
  int used = 0;  ///< size of the system in use
  const Eigen::MatrixXd& system() const { return systemBySize[static_cast<std::size_t>(used - smallest)]; }
  const Eigen::PartialPivLU<Eigen::MatrixXd>& factor() const { return luBySize[static_cast<std::size_t>(used - smallest)]; }
};

InnerSensitivity::InnerSensitivity(SensitivitySettings settings) : impl_(std::make_unique<Impl>()) {
  impl_->settings = settings;
  if (settings.backend != KktBackend::Dense)
    impl_->sparseFactor = std::make_unique<SparseKktFactor>(
        settings.backend == KktBackend::SparseKlu ? SparseKktFactor::Library::Klu : SparseKktFactor::Library::Umfpack);
}
InnerSensitivity::~InnerSensitivity() = default;
InnerSensitivity::InnerSensitivity(InnerSensitivity&&) noexcept = default;
InnerSensitivity& InnerSensitivity::operator=(InnerSensitivity&&) noexcept = default;

const SensitivityDiagnostics& InnerSensitivity::diagnostics() const { return impl_->diagnostics; }

const SensitivityDiagnostics& InnerSensitivity::factorize(const ContactProblem& p, const InnerResult& r) {
  Impl& m = *impl_;
  const int nc = p.contactCount, n = p.variableCount();
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
  const double scale = p.dataScale();
  const double strict = m.settings.strictMultiplier * scale;
  const double forceScale = 1.0 + F.cwiseAbs().maxCoeff();
  const auto rowCount = static_cast<int>(p.inequality.rows());
  const auto coneCount = static_cast<int>(p.cones.size());
  m.active.assign(static_cast<std::size_t>(rowCount + coneCount), 0);
  for (int a : r.activeSet) m.active[static_cast<std::size_t>(a)] = 1;

  // Assembled in a buffer of the largest size (per contact, one slot per linear row and cone,
  // or its pins when unloaded, at most 6), the used rows first; the used block is then factorised.
  int size = n + 6;
  for (int i = 0; i < nc; ++i) {
    const int own = p.contactRowStart[static_cast<std::size_t>(i) + 1] - p.contactRowStart[static_cast<std::size_t>(i)] +
                    (p.contactCone[static_cast<std::size_t>(i)] >= 0 ? 1 : 0);
    size += std::max(own, 6);
  }
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
  // A barrier answer (InnerResult::barrier > 0) is the central point of every row at once:
  // its stationarity H F + c + Bᵀλ − μ Σ_i g_i / s_i = 0 with s = b − G F differentiates to the
  // curvature Gᵀ diag(μ / s²) G = Gᵀ diag(z / s) G on H, and the balance rows alone (no active set).
  const bool barrier = r.barrier > 0.0;
  if (barrier && coneCount > 0)
    throw InputError("sensitivity: a barrier answer of a problem with second-order cones (the barrier solver takes linear models only)");
  if (barrier) {
    for (int k = 0; k < rowCount; ++k) {
      const double slack = p.inequalityBound[k] - p.inequality.row(k).dot(F);
      if (!(slack > 0.0) || !(r.inequalityMultipliers[k] > 0.0))
        throw InputError("sensitivity: a barrier answer with row " + p.rowNames[static_cast<std::size_t>(k)] +
                         " not strictly inside (slack " + std::to_string(slack) + ")");
      m.lagrangianHessian.noalias() += (r.inequalityMultipliers[k] / slack) * p.inequality.row(k).transpose() * p.inequality.row(k);
    }
  }
  for (int i = 0; i < nc && !barrier; ++i) {
    // The contact's rows and cone, as its model laid them out (contact_problem.hpp).
    const int fzRow = p.normalForceRow(i);
    const int rowEnd = p.contactRowStart[static_cast<std::size_t>(i) + 1];
    const int column = p.contactColumn[static_cast<std::size_t>(i)], components = p.wrenchSize(i);
    const double fz = F[column + 2];
    const int cone = p.contactCone[static_cast<std::size_t>(i)];
    // Held at zero by its fz_min row or by its cone's apex (the active-set method certifies
    // an unloaded contact through the cone's planes, whose multipliers make y_z).
    const bool apex = cone >= 0 && m.active[static_cast<std::size_t>(rowCount + cone)];
    // An interior-point result stops near the apex, not on it: a contact whose normal and
    // shear forces are both negligible is unloaded too (never a curvature ν / ‖f_t‖ there).
    const double shearNorm = F.segment<2>(column).norm();
    const bool nearApex = std::abs(fz) <= m.settings.unloadedForce * forceScale &&
                          shearNorm <= m.settings.unloadedForce * forceScale;
    if ((m.active[static_cast<std::size_t>(fzRow)] || apex) && nearApex) {
      // Unloaded: held at zero wrench while its pushing multiplier is positive.
      ++m.diagnostics.unloadedContacts;
      double push = r.inequalityMultipliers[fzRow];
      if (cone >= 0) push += r.coneMultipliers[3 * cone + 2];
      if (!(push > strict)) ++m.diagnostics.weaklyActive;
      bool yawHeld = false;
      for (int k = fzRow; k < rowEnd; ++k) yawHeld |= p.rowKinds[static_cast<std::size_t>(k)] == ContactRowKind::Yaw;
      // f and m_x, m_y pinned (m_z too where the yaw is bounded); a force alone: f.
      for (int component = 0; component < std::min(components, yawHeld ? 6 : 5); ++component) addUnit(column + component);
      continue;
    }
    for (int k = fzRow; k < rowEnd; ++k) {
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
      if (!m.sparseFactor) m.luBySize.emplace_back(k);  // the dense backend's LU per size
    }
    m.estimateX.resize(size), m.estimateSign.resize(size), m.estimateZ.resize(size);
    m.eigen = std::make_unique<SymmetricEigen>(size);
    m.padded.resize(size, size);
  }
  m.used = next;
  m.diagnostics.size = next;
  Eigen::MatrixXd& system = m.systemBySize[static_cast<std::size_t>(next - m.smallest)];
  system = m.kkt.topLeftCorner(next, next);

  // The backend's own factorisation gives the condition estimate; a near-singular system
  // (dependent active rows, whose multipliers are then not unique while dF is) is solved in
  // the least-norm sense (formulation.md §8), whatever the backend.
  m.backendInUse = m.settings.backend;
  if (m.sparseFactor) {
    const bool factorised = m.sparseFactor->factorize(system, n + 6);
    m.diagnostics.reciprocalCondition = factorised ? m.sparseFactor->reciprocalCondition() : 0.0;
    m.diagnostics.pivotRatio = factorised ? m.sparseFactor->pivotRatio() : 0.0;
    m.diagnostics.analysisReused = m.sparseFactor->reusedAnalysis();
  } else {
    Eigen::PartialPivLU<Eigen::MatrixXd>& lu = m.luBySize[static_cast<std::size_t>(next - m.smallest)];
    lu.compute(system);
    m.diagnostics.reciprocalCondition = reciprocalConditionEstimate(system, lu, m.estimateX, m.estimateSign, m.estimateZ);
    const auto pivots = lu.matrixLU().diagonal().cwiseAbs();
    m.diagnostics.pivotRatio = pivots.minCoeff() / pivots.maxCoeff();
  }
  if (!std::isfinite(m.diagnostics.reciprocalCondition)) m.diagnostics.reciprocalCondition = 0.0;
  if (!std::isfinite(m.diagnostics.pivotRatio)) m.diagnostics.pivotRatio = 0.0;
  // Either figure: the estimate can miss an exact dependency (SensitivityDiagnostics::pivotRatio:
  // slsqp's active set on the lean reach's still hand), and the LU then solves to NaN.
  m.useRankRevealing = m.diagnostics.nearSingular();
  if (m.useRankRevealing) {
    m.backendInUse = KktBackend::Dense;
    double padding = system.cwiseAbs().maxCoeff();
    if (padding == 0.0) padding = 1.0;
    m.padded.setZero();
    m.padded.topLeftCorner(next, next) = system;
    m.padded.diagonal().tail(m.capacity - next).setConstant(padding);
    if (!m.eigen->compute(m.padded)) m.diagnostics.reciprocalCondition = 0.0;
  }
  m.diagnostics.backend = m.backendInUse;
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
    throw InputError("sensitivity: right-hand sides must be (wrench variables) × m and 6 × m");
  // Buffers reused from call to call (allocation-free for the same shapes: the per-sample
  // path of MultiContactGradientEvaluator).
  // The system's size follows the active set from sample to sample: the buffers have the
  // largest size's rows and are used by their leading `size` rows.
  const Eigen::Index columns = dStationarity.cols();
  if (m.rhs.rows() != m.capacity || m.rhs.cols() != columns) m.rhs.resize(m.capacity, columns);
  if (m.solution.rows() != m.capacity || m.solution.cols() != columns) m.solution.resize(m.capacity, columns);
  if (m.projected.rows() != m.capacity || m.projected.cols() != columns) m.projected.resize(m.capacity, columns);
  auto rhs = m.rhs.topRows(size);
  auto solution = m.solution.topRows(size);
  rhs.setZero();
  rhs.topRows(n) = -dStationarity;
  rhs.middleRows(n, 6) = -dBalance;
  if (m.useRankRevealing) {
    m.rhs.bottomRows(m.capacity - size).setZero();  // the padding's rows: its part of the solution is 0
    leastNormSolve(*m.eigen, m.rhs, m.projected, m.solution);
  } else if (m.backendInUse == KktBackend::Dense) {
    solution.noalias() = m.factor().solve(rhs);
  } else {
    solution = rhs;
    m.sparseFactor->solveInPlace(solution);
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
