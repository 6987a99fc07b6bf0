#pragma once
/// \file
/// \brief The arm's state equation x' = f(x, p) in double (eq. 23 with the effects and their
/// states) and its exact Jacobians df/dx and df/dp by forward-mode AutoDiff through
/// ArmDynamics. The one place that differentiates f: the simulator's Jacobian (ArmSystem) and
/// the linearisation for control (linearisation.hpp) both call it.

#include <algorithm>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "softrne/config.hpp"
#include "softrne/algorithms/derivatives.hpp"
#include "softrne/arm/arm_dynamics.hpp"
#include "softrne/chain/derivative_workspace.hpp"

namespace softrne::sim {

/// \brief How ArmJacobian differentiates the acceleration rows; both are exact (AutoDiff).
/// - inverse_dynamics: \f$\partial\ddot q/\partial x = M^{-1}(\partial\tau/\partial x -
///   \partial\,\mathrm{ID}(q,\dot q,\ddot q^*)/\partial x)\f$ at the current acceleration
///   \f$\ddot q^*\f$, with ID the chain's RNE (M qddot + C qdot + G) and tau every other
///   force (pressures, springs, dampers, effects). \f$\partial\mathrm{ID}/\partial(q,\dot q)\f$
///   comes from the core's derivatives (algorithms/derivatives.hpp, once per Jacobian), tau's
///   from AutoDiff through ArmDynamics::joint_forces per block, M's Cholesky factor from a
///   double evaluation. The cheaper method (the default). The pressures and the effect states
///   do not enter ID.
/// - forward_dynamics: AutoDiff through the whole right-hand side (kinematics, nq + 1 RNE
///   passes, Cholesky).
enum class JacobianMethod { inverse_dynamics, forward_dynamics };

/// \brief f(x, p) of an arm in double and its exact Jacobians A = df/dx (n x n) and
/// B = df/dp (n x num_inputs), x = [q, qdot, effect states], p the recorded (commanded)
/// pressures before any effect changes them. Holds its own double and AutoDiff evaluators and
/// workspaces: after construction nothing is allocated.
///
/// A transport delay (the input_delay effect) is not part of f: whoever feeds p applies it
/// (ArmSystem reads the pressures at t - delay).
class ArmJacobian {
 public:
  /// Derivative directions per AutoDiff pass: the core derivatives' block (kDerivativeBlock,
  /// chain/derivative_workspace.hpp). 2 (one SSE register) measured fastest for the 12-state
  /// bundled arm: 0.43M instructions per Jacobian against 0.67M with 4, 0.73M with 12.
  static constexpr int kBlock = kDerivativeBlock;
  /// The AutoDiff scalar, the one of rnea_derivatives (the chain's segments are instantiated
  /// once for both).
  using AD = DerivativeScalar<double>;
  using ADVector = Eigen::Matrix<AD, Eigen::Dynamic, 1>;  ///< a vector of AD scalars

  /// \brief The state equation of `desc`.
  /// \param[in] desc The arm; it must outlive this object.
  explicit ArmJacobian(const ArmDescription& desc);

  /// \return The number of states n (2 nq + the effects' states).
  int num_states() const { return desc_.num_states(); }
  /// \return The number of pressure inputs.
  int num_inputs() const { return desc_.num_inputs; }
  /// \return The arm.
  const ArmDescription& description() const { return desc_; }
  /// \brief Chooses how the acceleration rows are differentiated.
  /// \param[in] m The method.
  void set_method(JacobianMethod m) { method_ = m; }
  /// \return How the acceleration rows are differentiated.
  JacobianMethod method() const { return method_; }

  /// \brief x' = f(x, p) (eq. 23 with the effects) in double.
  /// \param[in] x The state, size num_states().
  /// \param[in] p The pressures, Pa, size num_inputs().
  /// \param[out] xdot Its time derivative.
  /// \return False if xdot is not finite.
  bool rhs(const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::Ref<const Eigen::VectorXd>& p,
           Eigen::Ref<Eigen::VectorXd> xdot);

  /// \brief The exact A = df/dx at (x, p) (the simulator's Jacobian).
  /// \param[in] x The state.
  /// \param[in] p The pressures, Pa.
  /// \param[out] A df/dx, num_states() x num_states().
  /// \return False if A is not finite.
  bool state_jacobian(const Eigen::Ref<const Eigen::VectorXd>& x,
                      const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::MatrixXd> A);

  /// \brief The exact A = df/dx and B = df/dp at (x, p), in one sweep over the columns of
  /// [x, p].
  /// \param[in] x The state.
  /// \param[in] p The pressures, Pa.
  /// \param[out] A df/dx, num_states() x num_states().
  /// \param[out] B df/dp, num_states() x num_inputs() (1/s per Pa in the velocity rows).
  /// \return False if A or B is not finite.
  bool jacobians(const Eigen::Ref<const Eigen::VectorXd>& x,
                 const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::MatrixXd> A,
                 Eigen::Ref<Eigen::MatrixXd> B);

 private:
  // Columns [0, ncols) of d f / d [x, p] into A (the first n) and B (the rest).
  bool differentiate(const Eigen::Ref<const Eigen::VectorXd>& x,
                     const Eigen::Ref<const Eigen::VectorXd>& p, int ncols,
                     Eigen::Ref<Eigen::MatrixXd> A, Eigen::Ref<Eigen::MatrixXd>* B);
  // Seeds x_ad_ and pin_ad_ with the values (x, p) and unit derivatives for the columns
  // [start, start + kBlock) of [x, p].
  void seed(const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::Ref<const Eigen::VectorXd>& p,
            int start);
  template <class P>
  void forward(const P& p, int start, int ncols, Eigen::Ref<Eigen::MatrixXd> A,
               Eigen::Ref<Eigen::MatrixXd>* B);
  template <class P>
  void inverse(const P& p, int start, int ncols, Eigen::Ref<Eigen::MatrixXd> A,
               Eigen::Ref<Eigen::MatrixXd>* B);
  // Column c of d f / d [x, p]: A's column c, or B's column c - n.
  double& entry(Eigen::Ref<Eigen::MatrixXd>& A, Eigen::Ref<Eigen::MatrixXd>* B, int row,
                int c) const {
    const int n = desc_.num_states();
    return c < n ? A(row, c) : (*B)(row, c - n);
  }

  const ArmDescription& desc_;
  ArmDynamics<double> f_;
  ArmDynamics<AD> f_ad_;
  DynamicChainData<double> id_data_;  // the derivatives of ID (inverse_dynamics)
  ADVector x_ad_, xd_ad_, q_ad_, v_ad_, p_ad_, pin_ad_;
  Eigen::VectorXd xdot_;
  Eigen::Matrix<double, Eigen::Dynamic, kBlock> dr_;
  JacobianMethod method_ = JacobianMethod::inverse_dynamics;
};

#if SOFTRNE_SIM_BODIES
// Compiled once in src/sim.cpp for the targets that link softrne::sim_compiled, inline
// otherwise (config.hpp), like ArmSystem's members.
SOFTRNE_SIM_INLINE ArmJacobian::ArmJacobian(const ArmDescription& desc)
    : desc_(desc), f_(desc), f_ad_(desc), id_data_(f_.chain().make_data()) {
  const int nq = desc.nq, ns = desc.num_states(), m = desc.num_inputs;
  x_ad_.resize(ns);
  xd_ad_.resize(ns);
  q_ad_.resize(nq);
  v_ad_.resize(nq);
  p_ad_.resize(m);
  pin_ad_.resize(m);
  xdot_.resize(ns);
  dr_.resize(nq, kBlock);
}

SOFTRNE_SIM_INLINE bool ArmJacobian::rhs(const Eigen::Ref<const Eigen::VectorXd>& x,
                                         const Eigen::Ref<const Eigen::VectorXd>& p,
                                         Eigen::Ref<Eigen::VectorXd> xdot) {
  f_.rhs(x, p, xdot);
  return xdot.allFinite();
}

SOFTRNE_SIM_INLINE bool ArmJacobian::state_jacobian(const Eigen::Ref<const Eigen::VectorXd>& x,
                                                    const Eigen::Ref<const Eigen::VectorXd>& p,
                                                    Eigen::Ref<Eigen::MatrixXd> A) {
  return differentiate(x, p, num_states(), A, nullptr);
}

SOFTRNE_SIM_INLINE bool ArmJacobian::jacobians(const Eigen::Ref<const Eigen::VectorXd>& x,
                                               const Eigen::Ref<const Eigen::VectorXd>& p,
                                               Eigen::Ref<Eigen::MatrixXd> A,
                                               Eigen::Ref<Eigen::MatrixXd> B) {
  return differentiate(x, p, num_states() + num_inputs(), A, &B);
}

SOFTRNE_SIM_INLINE void ArmJacobian::seed(const Eigen::Ref<const Eigen::VectorXd>& x,
                                          const Eigen::Ref<const Eigen::VectorXd>& p, int start) {
  // The variables of a pass are [x, p]: x from index 0, p from index num_states().
  detail::seed_block(x, 0, start, x_ad_);
  detail::seed_block(p, num_states(), start, pin_ad_);
}

SOFTRNE_SIM_INLINE bool ArmJacobian::differentiate(const Eigen::Ref<const Eigen::VectorXd>& x,
                                                   const Eigen::Ref<const Eigen::VectorXd>& p,
                                                   int ncols, Eigen::Ref<Eigen::MatrixXd> A,
                                                   Eigen::Ref<Eigen::MatrixXd>* B) {
  const int n = num_states();
  if (method_ == JacobianMethod::inverse_dynamics) {
    // Double evaluation: the acceleration qddot* and M's Cholesky factor at (x, p), then
    // d ID / d(q, qdot) at qddot*.
    f_.rhs(x, p, xdot_);
    if (!xdot_.allFinite()) return false;
    const int nq = desc_.nq;
    detail::rnea_derivative_passes(f_.chain(), id_data_, x.head(nq), x.segment(nq, nq),
                                   f_.data().qddot, false);
  }
  for (int start = 0; start < ncols; start += kBlock) {
    seed(x, p, start);
    // Only the p columns need derivatives through p: the state columns read p in double, as
    // the simulator always did.
    if (start + kBlock > n) {
      if (method_ == JacobianMethod::forward_dynamics)
        forward(pin_ad_, start, ncols, A, B);
      else
        inverse(pin_ad_, start, ncols, A, B);
    } else if (method_ == JacobianMethod::forward_dynamics) {
      forward(p, start, ncols, A, B);
    } else {
      inverse(p, start, ncols, A, B);
    }
  }
  return A.allFinite() && (!B || B->allFinite());
}

template <class P>
void ArmJacobian::forward(const P& p, int start, int ncols, Eigen::Ref<Eigen::MatrixXd> A,
                          Eigen::Ref<Eigen::MatrixXd>* B) {
  const int n = num_states();
  f_ad_.rhs(x_ad_, p, xd_ad_);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < kBlock && start + k < ncols; ++k)
      entry(A, B, i, start + k) = xd_ad_(i).derivatives()(k);
}

template <class P>
void ArmJacobian::inverse(const P& p, int start, int ncols, Eigen::Ref<Eigen::MatrixXd> A,
                          Eigen::Ref<Eigen::MatrixXd>* B) {
  const ArmDescription& d = desc_;
  const int nq = d.nq, n = num_states(), nz = d.num_effect_states;
  const int cols = std::min(kBlock, ncols - start);
  const Eigen::MatrixXd& L = f_.data().mass_factor;  // Cholesky factor in the lower triangle
  // d qdot / d qdot = I; d qdot / d (q, z, p) = 0.
  for (int k = 0; k < cols; ++k)
    for (int i = 0; i < nq; ++i) entry(A, B, i, start + k) = start + k == nq + i ? 1.0 : 0.0;
  q_ad_ = x_ad_.head(nq);
  v_ad_ = x_ad_.segment(nq, nq);
  const auto xs = x_ad_.segment(2 * nq, nz);
  f_ad_.effective_pressures(xs, p, p_ad_);
  const auto& tau = f_ad_.joint_forces(q_ad_, v_ad_, p_ad_, xs);
  for (int i = 0; i < nq; ++i)
    for (int k = 0; k < kBlock; ++k) dr_(i, k) = tau(i).derivatives()(k);
  for (int k = 0; k < cols; ++k) {  // ID depends on q and qdot only
    const int c = start + k;
    if (c < nq)
      dr_.col(k) -= id_data_.dtau_dq.col(c);
    else if (c < 2 * nq)
      dr_.col(k) -= id_data_.dtau_dqdot.col(c - nq);
  }
  L.triangularView<Eigen::Lower>().solveInPlace(dr_);
  L.transpose().triangularView<Eigen::Upper>().solveInPlace(dr_);
  for (int k = 0; k < cols; ++k)
    for (int i = 0; i < nq; ++i) entry(A, B, nq + i, start + k) = dr_(i, k);
  // Effect states: differentiate their own derivative (it may depend on q, qdot and p).
  f_ad_.effect_state_derivative(xs, q_ad_, v_ad_, p, xd_ad_.segment(2 * nq, nz));
  for (int i = 2 * nq; i < n; ++i)
    for (int k = 0; k < cols; ++k) entry(A, B, i, start + k) = xd_ad_(i).derivatives()(k);
}
#endif  // SOFTRNE_SIM_BODIES

}  // namespace softrne::sim
