#pragma once
/// \file
/// \brief Derivatives of the dynamics: \f$\partial\tau/\partial(q,\dot q,\ddot q)\f$ of the
/// inverse dynamics (rnea) and \f$\partial\ddot q/\partial(q,\dot q,\tau)\f$ of the forward
/// dynamics (eq. 23), as Pinocchio's computeRNEADerivatives and computeABADerivatives.
///
/// ## Method: the RNE's tangent, AutoDiff only on the perturbed segment
/// The directions come in blocks of two, (q_i, qdot_i) for each coordinate i, and a block
/// changes the RNE in three ways that are handled apart:
/// - **the coordinate's own segment s** changes its kinematics (pose, Jacobians, their rates,
///   its configuration-dependent inertia and every series below the CC functions' switches):
///   its `calc`, `forward_step` and `backward_step` run in forward-mode AutoDiff
///   (DerivativeScalar, two directions), the very code rnea() runs, on that segment alone;
/// - **the segments after s** keep their kinematics but their base moves: the motion's
///   derivatives are carried tip-wards and their loads' derivatives formed by the tangent
///   steps of derivative_steps.hpp, in double, a 3 x 2 block per vector;
/// - **every segment**: the wrench's derivatives come back base-wards, through s in AutoDiff
///   and through the segments before s as a pure transmission (their loads do not move).
/// So nq blocks cost nq AutoDiff evaluations of one segment plus O(n) double tangent steps
/// each, against nq AutoDiff passes of the whole RNE before (28-35x rnea on the paper's arm;
/// now 18x, docs/performance.md has both). Still exact to rounding (no step size), at phi = 0 and
/// across the series switches, for every segment type (a new one is differentiated as soon as
/// it has calc: the tangent steps read only the fields every segment's kinematics have).
/// Analytical recursions for the CC joint itself (Pinocchio's computeRNEADerivatives has them
/// for rigid joints) would also remove the AutoDiff on segment s: they need the second
/// derivatives of a CC joint's pose, Jacobians and inertia (\f$\partial J/\partial q\f$,
/// \f$\partial\dot J\dot q/\partial q\f$, \f$\partial^2 I/\partial q^2\f$, per quadrature disk
/// for a distributed joint) and their series below the switch, derived and tested anew.
///
/// ## Forward dynamics
/// From \f$M(q)\ddot q = \tau - b(q,\dot q)\f$ with \f$\mathrm{ID}(q,\dot q,\ddot q) = M\ddot q +
/// b\f$: \f$\partial\ddot q/\partial x = -M^{-1}\,\partial\mathrm{ID}/\partial x\f$ at the
/// solution \f$\ddot q^*\f$ for x = q, qdot, and \f$\partial\ddot q/\partial\tau = M^{-1}\f$.
/// aba_derivatives computes \f$\ddot q^*\f$, M and its Cholesky factor by forward_dynamics()
/// and the partials of ID by the same passes as rnea_derivatives.

#include <limits>
#include <type_traits>
#include <variant>

#include <Eigen/Core>

#include "softrne/algorithms/cholesky.hpp"
#include "softrne/algorithms/derivative_steps.hpp"
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
    ws.load_tangents.resize(static_cast<std::size_t>(chain.num_segments()));
  }
  ws.chain.gravity = chain.gravity.template cast<AD>();
  ws.chain.inertia_rate = chain.inertia_rate;
  for (auto* m : {&data.dtau_dq, &data.dtau_dqdot, &data.dqddot_dq, &data.dqddot_dqdot,
                  &data.dqddot_dtau})
    m->resize(nq, nq);  // no-op after the first call
}

/// \brief The values of a FrameMotion as AutoDiff constants (no derivatives).
template <class AD>
FrameMotion<AD> autodiff_constant(const FrameMotion<double>& m) {
  FrameMotion<AD> out;
  out.omega = m.omega.template cast<AD>();
  out.alpha = m.alpha.template cast<AD>();
  out.acc = m.acc.template cast<AD>();
  return out;
}

/// \brief The derivatives of an AutoDiff 3-vector as the columns of a block.
template <class V>
Tangent3 derivatives_of(const V& v) {
  Tangent3 t;
  for (int r = 0; r < 3; ++r) t.row(r) = v(r).derivatives().transpose();
  return t;
}

/// \brief An AutoDiff 3-vector: values from `value`, derivatives from the block `d`.
template <class AD>
Eigen::Matrix<AD, 3, 1> with_derivatives(const Eigen::Vector3d& value, const Tangent3& d) {
  Eigen::Matrix<AD, 3, 1> v;
  for (int r = 0; r < 3; ++r) {
    v(r).value() = value(r);
    v(r).derivatives() = d.row(r).transpose();
  }
  return v;
}

/// \brief \f$\partial\tau/\partial q\f$ and \f$\partial\tau/\partial\dot q\f$ of the RNE at
/// (q, qdot, qddot) into data.dtau_dq and data.dtau_dqdot (the file comment: one block
/// (q_i, qdot_i) per coordinate, AutoDiff on the coordinate's own segment, the tangent steps
/// elsewhere); tau itself into data.tau, and the RNE's kinematics, motions, loads and wrenches
/// at that point into data.
template <class ChainT, class Q, class Qd, class Qdd>
void rnea_derivative_passes(const ChainT& chain, typename ChainT::Data& data,
                            const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot,
                            const Eigen::MatrixBase<Qdd>& qddot) {
  static_assert(std::is_floating_point_v<typename ChainT::Scalar>,
                "softrne: derivatives need a chain of a floating-point scalar");
  prepare_derivatives(chain, data);
  auto& ws = data.derivatives;
  using AD = typename std::decay_t<decltype(ws)>::AD;
  const InertiaRate rate = chain.inertia_rate;
  const int nq = chain.num_coordinates(), n_seg = data.num_segments();

  // The expansion point, in double: what rnea() computes, kept in data.
  compute_kinematics(chain, data, q, qdot);
  rnea_passes(chain, data, qdot, qddot, true, true, data.tau);
  for (int i = 0; i < nq; ++i) {
    ws.q(i) = AD(q(i));
    ws.qdot(i) = AD(qdot(i));
    ws.qddot(i) = AD(qddot(i));
  }

  for (int s = 0; s < n_seg; ++s) {
    int s_offset = 0, s_nq = 0;
    chain.visit_segment(data, s, [&](const auto& seg, const auto&, int, int offset) {
      s_offset = offset;
      s_nq = std::decay_t<decltype(seg)>::nq;
    });
    for (int j = 0; j < s_nq; ++j) {
      const int i = s_offset + j;  // the block: directions (q_i, qdot_i)
      ws.q(i).derivatives() << 1, 0;
      ws.qdot(i).derivatives() << 0, 1;

      // Segment s in AutoDiff: its kinematics and its forward step (its base does not move).
      MotionTangent d_motion;
      ws.chain.visit_segment(ws.data, s, [&](const auto& seg, auto& kin, int, int offset) {
        constexpr int n = std::decay_t<decltype(seg)>::nq;
        seg.calc(segment_entries<n>(ws.q, offset), segment_entries<n>(ws.qdot, offset), kin);
        const auto k = static_cast<std::size_t>(s);
        forward_step(seg, kin, autodiff_constant<AD>(data.motion[k]),
                     segment_entries<n>(ws.qdot, offset), segment_entries<n>(ws.qddot, offset),
                     true, rate, ws.data.motion[k + 1], ws.data.loads[k]);
        d_motion.omega = derivatives_of(ws.data.motion[k + 1].omega);
        d_motion.alpha = derivatives_of(ws.data.motion[k + 1].alpha);
        d_motion.acc = derivatives_of(ws.data.motion[k + 1].acc);
      });
      // The segments after it: their base moves, their kinematics do not.
      chain.forward(data, [&](const auto& seg, const auto& kin, int k, int offset) {
        if (k <= s) return;
        constexpr int n = std::decay_t<decltype(seg)>::nq;
        MotionTangent d_distal;
        forward_tangent_step(seg, kin, data.motion[static_cast<std::size_t>(k)],
                             segment_entries<n>(qdot, offset), rate, d_motion, d_distal,
                             ws.load_tangents[static_cast<std::size_t>(k)]);
        d_motion = d_distal;
      });
      // Backward: the segments after s (loads and wrench move), s itself in AutoDiff, then the
      // segments before it (only the wrench from their children moves).
      WrenchTangent d_wrench;  // zero at the tip
      auto store = [&](const auto& d_tau, int offset) {
        for (Eigen::Index r = 0; r < d_tau.rows(); ++r) {
          data.dtau_dq(offset + r, i) = d_tau(r, 0);
          data.dtau_dqdot(offset + r, i) = d_tau(r, 1);
        }
      };
      auto transmit = [&](bool own_load_moves) {
        return [&, own_load_moves](const auto& seg, const auto& kin, int k, int offset) {
          if (own_load_moves ? k <= s : k >= s) return;
          using Segment = std::decay_t<decltype(seg)>;
          const auto kk = static_cast<std::size_t>(k);
          Eigen::Matrix<double, Segment::nq, kDerivativeBlock> d_tau;
          WrenchTangent d_base;
          backward_tangent_step<Segment>(kin, data.loads[kk],
                                         own_load_moves ? &ws.load_tangents[kk] : nullptr,
                                         d_wrench, rate, d_tau, d_base);
          store(d_tau, offset);
          d_wrench = d_base;
        };
      };
      chain.backward(data, transmit(true));
      ws.chain.visit_segment(ws.data, s, [&](const auto& seg, const auto& kin, int, int offset) {
        constexpr int n = std::decay_t<decltype(seg)>::nq;
        const auto k = static_cast<std::size_t>(s);
        Wrench<AD> distal, base;
        distal.force = with_derivatives<AD>(data.wrench[k + 1].force, d_wrench.force);
        distal.torque = with_derivatives<AD>(data.wrench[k + 1].torque, d_wrench.torque);
        Eigen::Matrix<AD, n, 1> tau;
        backward_step(seg, kin, ws.data.loads[k], distal, rate, tau, base);
        if constexpr (n > 0) {  // (s has coordinates; the others are never visited here)
          Eigen::Matrix<double, n, kDerivativeBlock> d_tau;
          for (int r = 0; r < n; ++r) d_tau.row(r) = tau(r).derivatives().transpose();
          store(d_tau, offset);
        }
        d_wrench.force = derivatives_of(base.force);
        d_wrench.torque = derivatives_of(base.torque);
      });
      chain.backward(data, transmit(false));

      ws.q(i).derivatives().setZero();
      ws.qdot(i).derivatives().setZero();
    }
  }
}

}  // namespace detail

/// \brief Derivatives of the inverse dynamics \f$\tau = M(q)\ddot q + C(q,\dot q)\dot q +
/// G(q)\f$ (rnea()): \f$\partial\tau/\partial q\f$, \f$\partial\tau/\partial\dot q\f$ and
/// \f$\partial\tau/\partial\ddot q = M(q)\f$, each in its own field of data (as Pinocchio's
/// computeRNEADerivatives). Exact (this file's comment: the RNE's tangent, AutoDiff on the
/// perturbed segment only); cost one rnea(), nq one-segment AutoDiff evaluations with O(n)
/// tangent steps each, and mass_matrix(). Allocates nothing for a
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
/// inverse dynamics from the same passes as rnea_derivatives(). If M is not positive
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
