#pragma once
/// \file
/// \brief Derivatives of the dynamics: \f$\partial\tau/\partial(q,\dot q,\ddot q)\f$ of the
/// inverse dynamics (rnea) and \f$\partial\ddot q/\partial(q,\dot q,\tau)\f$ of the forward
/// dynamics (eq. 23), as Pinocchio's computeRNEADerivatives and computeABADerivatives.
///
/// ## Method: forward-mode AutoDiff through the RNE, blocks of two directions
/// The RNE (rnea.hpp) is templated on the scalar, so rnea_derivatives runs it on the chain
/// cast to DerivativeScalar (Eigen's AutoDiffScalar with kDerivativeBlock = 2 fixed-size
/// derivatives), seeding two of the 2 nq variables (q, qdot) per pass: nq passes of the
/// kinematics and the two RNE recursions in AD. \f$\partial\tau/\partial\ddot q = M\f$ comes
/// from mass_matrix() in double (tau is linear in qddot). Why this method:
/// - one source of truth: the derivatives are those of the very code that computes tau, for
///   every segment type (lumped and distributed CC joints with their series switches,
///   revolute joints, rigid links) and both inertia-rate models, with no second derivation to
///   keep in step with the first; a new segment type is differentiated as soon as it has calc;
/// - exact to rounding (no step size), also at phi = 0 and across the series switch of the CC
///   functions (cc_functions.hpp), whose series are differentiated term by term;
/// - two directions fill one SSE register: measured fastest for the simulator's Jacobian
///   (sim::ArmSystem, 0.43M instructions against 0.67M with 4 and 0.73M with 12 directions);
///   one AD type serves every chain size and both chain kinds (compile time).
/// The price is the cost: nq passes, each about 4.5 double RNEs (Eigen's AutoDiffScalar
/// evaluates every operation on the value and both derivatives, with temporaries). Measured
/// (docs/performance.md, bench `*/rnea_derivatives` against `*/rnea`, same run): 28x rnea on
/// the paper's arm, 24x on 6 revolute joints, 123x on 30 (O(nq) passes of O(n)); the goal of
/// 4x on the paper's arm is not met. Tried and dropped: computing each pass's kinematics only
/// for the one segment whose coordinates it seeds (a segment's kinematics depend on its own
/// coordinates only): 15 % faster on the arm, 12-20 % slower on 6 revolute joints; the AD
/// recursions, not the kinematics, dominate. The goal needs the analytical recursion below.
///
/// ## What an analytical recursion would need
/// Pinocchio's computeRNEADerivatives differentiates the recursion itself: one forward pass
/// carrying, per frame, the motion derivatives \f$\partial(\omega,\alpha,a)/\partial q_k\f$ of
/// every ancestor coordinate as spatial cross products with the joint's motion subspace, and
/// one backward pass with the composite inertia and its "force cross" terms; cost about 2-3
/// RNEs. For softrne it would need, beyond Pinocchio's revolute case: per CC joint the second
/// derivatives of its pose (\f$\partial J_{distal}/\partial q\f$, \f$\partial\dot J\dot q/
/// \partial q\f$, \f$\partial J_{com}/\partial q\f$, \f$\partial^2 I/\partial q^2\f$ for the
/// inertia rate and the \f$-\tfrac12\omega^T\partial I/\partial q\,\omega\f$ term, and the
/// same per quadrature disk of a distributed joint), whose series below the switch would have
/// to be derived and tested anew; the segment's own body does not move rigidly with its
/// distal frame, so Pinocchio's composite-inertia shortcuts do not apply to it unchanged.
///
/// ## Forward dynamics
/// From \f$M(q)\ddot q = \tau - b(q,\dot q)\f$ with \f$\mathrm{ID}(q,\dot q,\ddot q) = M\ddot q +
/// b\f$: \f$\partial\ddot q/\partial x = -M^{-1}\,\partial\mathrm{ID}/\partial x\f$ at the
/// solution \f$\ddot q^*\f$ for x = q, qdot, and \f$\partial\ddot q/\partial\tau = M^{-1}\f$.
/// aba_derivatives computes \f$\ddot q^*\f$, M and its Cholesky factor by forward_dynamics()
/// and the partials of ID by the same AutoDiff passes as rnea_derivatives.

#include <limits>
#include <type_traits>
#include <variant>

#include <Eigen/Core>

#include "softrne/algorithms/cholesky.hpp"
#include "softrne/algorithms/forward_dynamics.hpp"
#include "softrne/algorithms/mass_matrix.hpp"
#include "softrne/algorithms/rnea.hpp"
#include "softrne/chain/derivative_workspace.hpp"
#include "softrne/chain/dynamic_chain.hpp"
#include "softrne/chain/static_chain.hpp"

namespace softrne {
namespace detail {

/// \brief The chain's constants into ws.chain (a compile-time chain: a copy on the stack).
template <class... Segments>
void prepare_derivatives(const Chain<Segments...>& chain,
                         typename Chain<Segments...>::Data& data) {
  using AD = typename DerivativeWorkspace<Chain<Segments...>>::AD;
  data.derivatives.chain = chain.template cast<AD>();
}

/// \brief The chain's constants into ws.chain, segment by segment; the first call (or a chain
/// of another layout) builds the AD chain, its workspace and the outputs (allocates once).
template <class Scalar>
void prepare_derivatives(const DynamicChain<Scalar>& chain,
                         typename DynamicChain<Scalar>::Data& data) {
  auto& ws = data.derivatives;
  using AD = typename DerivativeWorkspace<DynamicChain<Scalar>>::AD;
  bool same = ws.chain.num_segments() == chain.num_segments();
  for (int i = 0; same && i < chain.num_segments(); ++i)
    std::visit(
        [&](const auto& seg) {
          using SegAD = decltype(seg.template cast<AD>());
          if (auto* s = std::get_if<SegAD>(&ws.chain.segment(i)))
            *s = seg.template cast<AD>();
          else
            same = false;
        },
        chain.segment(i));
  const int nq = chain.num_coordinates();
  if (!same) {
    ws.chain = chain.template cast<AD>();
    ws.data = ws.chain.make_data();
    ws.q.resize(nq);
    ws.qdot.resize(nq);
    ws.qddot.resize(nq);
  }
  ws.chain.gravity = chain.gravity.template cast<AD>();
  ws.chain.inertia_rate = chain.inertia_rate;
  for (auto* m : {&data.dtau_dq, &data.dtau_dqdot, &data.dqddot_dq, &data.dqddot_dqdot,
                  &data.dqddot_dtau})
    m->resize(nq, nq);  // no-op after the first call
}

/// \brief \f$\partial\tau/\partial q\f$ and \f$\partial\tau/\partial\dot q\f$ of the RNE at
/// (q, qdot, qddot) into data.dtau_dq and data.dtau_dqdot, by nq AutoDiff passes of two
/// directions (the file comment); tau itself into data.tau.
template <class ChainT, class Q, class Qd, class Qdd>
void rnea_derivative_passes(const ChainT& chain, typename ChainT::Data& data,
                            const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot,
                            const Eigen::MatrixBase<Qdd>& qddot) {
  static_assert(std::is_floating_point_v<typename ChainT::Scalar>,
                "softrne: derivatives need a chain of a floating-point scalar");
  constexpr int B = kDerivativeBlock;
  prepare_derivatives(chain, data);
  auto& ws = data.derivatives;
  const int nq = chain.num_coordinates();
  for (int i = 0; i < nq; ++i) ws.qddot(i) = typename std::decay_t<decltype(ws)>::AD(qddot(i));
  for (int start = 0; start < 2 * nq; start += B) {
    seed_block(q, 0, start, ws.q);
    seed_block(qdot, nq, start, ws.qdot);
    const auto& tau = rnea(ws.chain, ws.data, ws.q, ws.qdot, ws.qddot);
    for (int k = 0; k < B && start + k < 2 * nq; ++k) {
      const int c = start + k;
      auto& out = c < nq ? data.dtau_dq : data.dtau_dqdot;
      const int col = c < nq ? c : c - nq;
      for (int i = 0; i < nq; ++i) out(i, col) = tau(i).derivatives()(k);
    }
    if (start == 0)
      for (int i = 0; i < nq; ++i) data.tau(i) = tau(i).value();
  }
}

}  // namespace detail

/// \brief Derivatives of the inverse dynamics \f$\tau = M(q)\ddot q + C(q,\dot q)\dot q +
/// G(q)\f$ (rnea()): \f$\partial\tau/\partial q\f$, \f$\partial\tau/\partial\dot q\f$ and
/// \f$\partial\tau/\partial\ddot q = M(q)\f$, each in its own field of data (as Pinocchio's
/// computeRNEADerivatives). Exact (forward-mode AutoDiff through the RNE, this file's
/// comment); cost nq AD passes of the RNE plus mass_matrix(). Allocates nothing for a
/// compile-time chain; a DynamicChain's Data sizes its derivative workspace at the first call.
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar> of a floating-point Scalar.
/// \param[in] chain The model.
/// \param[in,out] data Its workspace, made by chain.make_data(); receives data.dtau_dq,
///   data.dtau_dqdot, data.mass_matrix (= d tau / d qddot) and data.tau (= rnea()).
/// \param[in] q The coordinates (dim chain.num_coordinates()).
/// \param[in] qdot Their rates (dim chain.num_coordinates()).
/// \param[in] qddot The accelerations (dim chain.num_coordinates()).
/// \throws std::invalid_argument (DynamicChain only, also in Release) if q, qdot or qddot has
///   another size than the chain or data was made for another chain.
template <class ChainT, class Q, class Qd, class Qdd>
void rnea_derivatives(const ChainT& chain, typename ChainT::Data& data,
                      const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot,
                      const Eigen::MatrixBase<Qdd>& qddot) {
  detail::check_argument(chain, "rnea_derivatives", "q", q);
  detail::check_argument(chain, "rnea_derivatives", "qdot", qdot);
  detail::check_argument(chain, "rnea_derivatives", "qddot", qddot);
  chain.check_data(data);
  detail::rnea_derivative_passes(chain, data, q, qdot, qddot);
  mass_matrix(chain, data, q);
}

/// \brief Derivatives of the forward dynamics \f$\ddot q = M(q)^{-1}(\tau - C(q,\dot q)\dot q -
/// G(q))\f$ (eq. 23; forward_dynamics(), aba()): \f$\partial\ddot q/\partial q\f$,
/// \f$\partial\ddot q/\partial\dot q\f$ and \f$\partial\ddot q/\partial\tau = M^{-1}\f$, each
/// in its own field of data (as Pinocchio's computeABADerivatives). With
/// \f$\ddot q^*\f$ from forward_dynamics(), \f$\partial\ddot q/\partial x =
/// -M^{-1}\partial\tau_{ID}/\partial x\f$ at \f$(q,\dot q,\ddot q^*)\f$, the partials of the
/// inverse dynamics from the same AutoDiff passes as rnea_derivatives(). If M is not positive
/// definite (never, for positive masses), every output is NaN.
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar> of a floating-point Scalar.
/// \param[in] chain The model.
/// \param[in,out] data Its workspace, made by chain.make_data(); receives data.dqddot_dq,
///   data.dqddot_dqdot, data.dqddot_dtau (= M^-1) and, on the way, what forward_dynamics()
///   leaves (data.qddot, data.mass_matrix, data.mass_factor, data.nonlinear_forces) and the
///   inverse-dynamics partials at qddot* (data.dtau_dq, data.dtau_dqdot, data.tau).
/// \param[in] q The coordinates (dim chain.num_coordinates()).
/// \param[in] qdot Their rates (dim chain.num_coordinates()).
/// \param[in] tau Every generalised force other than inertia and gravity (dim
///   chain.num_coordinates()), as for forward_dynamics(); held constant (its own dependence on
///   q or qdot, e.g. springs, is the caller's: add \f$M^{-1}\partial\tau/\partial x\f$).
/// \throws std::invalid_argument (DynamicChain only, also in Release) if q, qdot or tau has
///   another size than the chain or data was made for another chain.
template <class ChainT, class Q, class Qd, class Tau>
void aba_derivatives(const ChainT& chain, typename ChainT::Data& data,
                     const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot,
                     const Eigen::MatrixBase<Tau>& tau) {
  detail::check_argument(chain, "aba_derivatives", "q", q);
  detail::check_argument(chain, "aba_derivatives", "qdot", qdot);
  detail::check_argument(chain, "aba_derivatives", "tau", tau);
  chain.check_data(data);
  forward_dynamics(chain, data, q, qdot, tau);  // qddot*, M, its Cholesky factor
  if (!data.qddot.allFinite()) {
    detail::prepare_derivatives(chain, data);  // sizes the outputs of a runtime chain
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    data.dqddot_dq.setConstant(nan);
    data.dqddot_dqdot.setConstant(nan);
    data.dqddot_dtau.setConstant(nan);
    return;
  }
  detail::rnea_derivative_passes(chain, data, q, qdot, data.qddot);
  // M^-1 from the factor forward_dynamics left (cholesky.hpp), then the two products.
  const int nq = chain.num_coordinates();
  data.dqddot_dtau.setIdentity();
  for (int c = 0; c < nq; ++c) {
    auto column = data.dqddot_dtau.col(c);
    detail::cholesky_solve_factored(data.mass_factor, column);
  }
  data.dqddot_dq.noalias() = -data.dqddot_dtau * data.dtau_dq;
  data.dqddot_dqdot.noalias() = -data.dqddot_dtau * data.dtau_dqdot;
}

}  // namespace softrne
