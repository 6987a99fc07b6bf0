#pragma once
/// \file
/// \brief Derivatives of the dynamics: \f$\partial\tau/\partial(q,\dot q,\ddot q)\f$ of the
/// inverse dynamics (rnea) and \f$\partial\ddot q/\partial(q,\dot q,\tau)\f$ of the forward
/// dynamics (eq. 23), as Pinocchio's computeRNEADerivatives and computeABADerivatives.
///
/// ## Method: AutoDiff on the perturbed segment, world composites for the rest
/// The directions come in blocks of two, (q_i, qdot_i) for each coordinate i of a segment s,
/// and a block changes the RNE in three ways that are handled apart:
/// - **segment s itself** changes its kinematics (pose, Jacobians, their rates, its
///   configuration-dependent inertia and every series below the CC functions' switches): its
///   `calc` runs in forward-mode AutoDiff (DerivativeScalar), the very code rnea() runs, on
///   that segment alone. For a lumped CC joint (segment_tangent.hpp's has_tangent_steps) calc
///   runs once, seeded along its coordinates, and the tangent steps of segment_tangent.hpp
///   carry the result through its forward and backward step in double (its rates' directions
///   follow from the same evaluation); any other segment runs calc, `forward_step` and
///   `backward_step` in AutoDiff once per coordinate, seeded along (q_i, qdot_i);
/// - **the coordinates after s** see their base's motion change: with the sensitivity rows of
///   derivative_composites.hpp (one O(n) pass for all blocks, in world quantities as
///   Pinocchio's computeRNEADerivatives) each such row costs one 9-vector product;
/// - **the coordinates before s** see only the wrench s passes back: one 6-vector product each
///   with their world Jacobian; and s's own rows take the children's wrench from the
///   subtree's composite inertias (derivative_composites.hpp) into its backward step (its
///   tangent, or the step in AutoDiff).
/// So nq blocks cost one AutoDiff evaluation of calc_motion per lumped CC joint (of calc and
/// both steps per coordinate for other segments) plus O(nq) short products each.
/// Until 2026-12-07 the rest of the chain was walked segment by segment in local axes for
/// every block (3 x 2 tangent steps, O(n) each, 2.2-8x Pinocchio); docs/performance.md has
/// both. Exact to rounding (no step size), at phi = 0 and across the series switches, for
/// every segment type: a new one is differentiated as soon as it has calc (the composites read
/// only the fields every segment's kinematics have). The lumped CC joint's inertia has its
/// second derivatives written out (ConstantCurvatureJoint::inertia_hessian_times, since
/// 2026-12-07, in place of calc_inertia in AutoDiff: 9 % fewer instructions for the whole of
/// rnea_derivatives on the paper's arm); its calc_motion in AutoDiff (pose, Jacobians and
/// their rates) is what is left of AutoDiff on the lumped arm (a tenth of rnea_derivatives'
/// instructions there, docs/performance.md). Written out, it would need \f$\partial
/// J/\partial q\f$ and \f$\partial\dot J\dot q/\partial q\f$ (third derivatives of the g_k)
/// with their series below the switch.
///
/// ## Forward dynamics
/// From \f$M(q)\ddot q = \tau - b(q,\dot q)\f$ with \f$\mathrm{ID}(q,\dot q,\ddot q) = M\ddot q +
/// b\f$: \f$\partial\ddot q/\partial x = -M^{-1}\,\partial\mathrm{ID}/\partial x\f$ at the
/// solution \f$\ddot q^*\f$ for x = q, qdot, and \f$\partial\ddot q/\partial\tau = M^{-1}\f$.
/// aba_derivatives computes \f$\ddot q^*\f$ as forward_dynamics() does, but takes M from the
/// composites the partials need anyway (they depend on q and qdot only, so they come first):
/// one mass-matrix pass fewer (8 % of its instructions on the paper's arm, 15 % on a 6-joint
/// revolute chain; docs/performance.md). The partials of ID then come from the same passes as
/// rnea_derivatives.

#include <limits>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>

#include <Eigen/Core>

#include "softrne/algorithms/bias.hpp"
#include "softrne/algorithms/cholesky.hpp"
#include "softrne/algorithms/derivative_composites.hpp"
#include "softrne/algorithms/forward_dynamics.hpp"
#include "softrne/algorithms/rnea.hpp"
#include "softrne/algorithms/segment_tangent.hpp"
#include "softrne/chain/derivative_workspace.hpp"
#include "softrne/chain/dynamic_chain.hpp"
#include "softrne/chain/static_chain.hpp"

namespace softrne {
namespace detail {

/// \brief Nothing to prepare for a compile-time chain: its workspace is fixed-size, and the
/// AutoDiff copy of a segment is made when it is evaluated (segment_to_autodiff).
template <class... Segments>
void prepare_derivatives(const Chain<Segments...>&, typename Chain<Segments...>::Data&) {}

/// \brief The first call (or a chain of another layout) builds the AD chain, its workspace and
/// the outputs (allocates once); later calls check the layout only. The constants of a
/// segment are copied when it is evaluated (segment_to_autodiff).
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
          same = std::holds_alternative<SegAD>(ws.chain.segment(i));
        },
        chain.segment(i));
  const int nq = chain.num_coordinates();
  if (!same) {
    ws.chain = chain.template cast<AD>();
    ws.data = ws.chain.make_data();
    ws.q.resize(nq);
    ws.qdot.resize(nq);
    ws.qddot.resize(nq);
    ws.frames.resize(static_cast<std::size_t>(chain.num_segments() + 1));
    ws.subtrees.resize(static_cast<std::size_t>(chain.num_segments() + 1));
    ws.jacobian.resize(6, nq);
    ws.sensitivity.resize(9, nq);
  }
  for (auto* m :
       {&data.dtau_dq, &data.dtau_dqdot, &data.dqddot_dq, &data.dqddot_dqdot, &data.dqddot_dtau})
    m->resize(nq, nq);  // no-op after the first call
}

/// \brief Segment s's constants into the AD chain (the chain may have changed since the last
/// call, so this runs before every AutoDiff evaluation of s).
template <class ChainAD, class... Segments, std::size_t... I>
void segment_to_autodiff(const Chain<Segments...>& chain, ChainAD& chain_ad, int s,
                         std::index_sequence<I...>) {
  using AD = typename ChainAD::Scalar;
  ((static_cast<int>(I) == s
        ? void(std::get<I>(chain_ad.segments) = std::get<I>(chain.segments).template cast<AD>())
        : void()),
   ...);
}
template <class ChainAD, class... Segments>
void segment_to_autodiff(const Chain<Segments...>& chain, ChainAD& chain_ad, int s) {
  segment_to_autodiff(chain, chain_ad, s, std::index_sequence_for<Segments...>{});
}
template <class ChainAD, class Scalar>
void segment_to_autodiff(const DynamicChain<Scalar>& chain, ChainAD& chain_ad, int s) {
  using AD = typename ChainAD::Scalar;
  std::visit(
      [&](const auto& seg) {
        using SegAD = decltype(seg.template cast<AD>());
        std::get<SegAD>(chain_ad.segment(s)) = seg.template cast<AD>();
      },
      chain.segment(s));
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

/// \brief Column i of \f$\partial\tau/\partial q\f$ and \f$\partial\tau/\partial\dot q\f$ for
/// the coordinates from `first` on: their sensitivities (ws.sensitivity) to x = (a~; dV's
/// angular part), one column per direction of the block (derivative_composites.hpp).
template <class Data, class X>
void store_coordinates_after(Data& data, int i, int first, const X& x) {
  const auto& sensitivity = data.derivatives.sensitivity;
  for (int r = first; r < static_cast<int>(data.dtau_dq.rows()); ++r) {
    data.dtau_dq(r, i) = sensitivity.col(r).dot(x.col(0));
    data.dtau_dqdot(r, i) = sensitivity.col(r).dot(x.col(1));
  }
}

/// \brief The same for the coordinates before `end`: their world Jacobians (ws.jacobian)
/// against the change dF of the wrench they transmit (world, about the world origin).
template <class Data, class F>
void store_coordinates_before(Data& data, int i, int end, const F& dF) {
  const auto& jacobian = data.derivatives.jacobian;
  for (int r = 0; r < end; ++r) {
    data.dtau_dq(r, i) = jacobian.col(r).dot(dF.col(0));
    data.dtau_dqdot(r, i) = jacobian.col(r).dot(dF.col(1));
  }
}

/// \brief The columns (q_i, qdot_i) of \f$\partial\tau\f$ for the coordinate i of a fixed-axis
/// joint s (is_fixed_axis_joint), in closed form from the composites (as Pinocchio's
/// computeRNEADerivatives for its revolute joints). With S its world Jacobian, V_b and A_b its
/// base's twist and spatial acceleration (derivative_composites.hpp's notation):
/// - q_i turns everything from s on rigidly by S about a base that does not move:
///   \f$\Delta V = V_b\times S\f$, \f$\Delta A = A_b\times S\f$ at the base, so the rows from s on
///   change by \f$P\tilde a + R\Delta V\f$, and the rows before s by \f$J^T\delta F\f$ with the
///   whole change of the wrench s passes back, \f$\delta F = S\times^* F_s + Y_{crb}\tilde a +
///   D_{crb}\Delta V\f$;
/// - qdot_i adds S to the twist beyond it and \f$V_b\times S\f$ to its spatial acceleration
///   (\f$\dot S = V\times S\f$): \f$\Delta V = S\f$, \f$\tilde a = 2 V_b\times S\f$, the same rows
///   (s's own included: it has no body, so its row is its children's wrench through S).
template <class Data>
void fixed_axis_derivatives(Data& data, int s, int i) {
  const auto& ws = data.derivatives;
  const auto k = static_cast<std::size_t>(s);
  const FrameInWorld& base = ws.frames[k];
  const Vector6d S = ws.jacobian.col(i);
  const Vector6d& V = base.twist;
  Eigen::Matrix<double, 6, kDerivativeBlock> dV;
  dV.col(0) = cross_motion(V, S);
  dV.col(1) = S;
  Eigen::Matrix<double, 9, kDerivativeBlock> x;  // (a~; dV's angular part)
  x.template topRows<6>().col(0) =
      cross_motion(spatial_acceleration(base, data.motion[k]), S) + cross_motion(V, dV.col(0));
  x.template topRows<6>().col(1) = 2.0 * dV.col(0);
  x.template bottomRows<3>() = dV.template bottomRows<3>();
  store_coordinates_after(data, i, i, x);
  if (i > 0) {
    const SubtreeComposite& from_s = ws.subtrees[k];
    Eigen::Matrix<double, 6, kDerivativeBlock> dF =
        from_s.apply(x.template topRows<6>(), x.template bottomRows<3>());
    Vector6d F;
    F << data.wrench[k].force, data.wrench[k].torque;
    dF.col(0) += cross_force(S, force_to_world(base.R, base.p, F));
    store_coordinates_before(data, i, i, dF);
  }
}

/// \brief The change (dV, dA) of segment s's distal twist and spatial acceleration in its own
/// axes, one column per direction of block i, to the rows of the coordinates from `first` on
/// (store_coordinates_after) and to the change of the wrench the children pass to s (returned,
/// in s's distal axes about its origin).
template <class Data>
Eigen::Matrix<double, 6, kDerivativeBlock> distal_change_to_children(
    Data& data, int s, int i, int first, const Eigen::Matrix<double, 6, kDerivativeBlock>& dV,
    const Eigen::Matrix<double, 6, kDerivativeBlock>& dA) {
  const auto& ws = data.derivatives;
  const auto k = static_cast<std::size_t>(s);
  const FrameInWorld& distal = ws.frames[k + 1];
  // In the world, and a~ = dA + V x dV (derivative_composites.hpp).
  const Eigen::Matrix<double, 6, kDerivativeBlock> delta_V =
      motion_to_world(distal.R, distal.p, dV);
  Eigen::Matrix<double, 9, kDerivativeBlock> x;  // (a~; dV's angular part)
  x.template topRows<6>() = motion_to_world(distal.R, distal.p, dA);
  for (int c = 0; c < kDerivativeBlock; ++c)
    x.template topRows<6>().col(c) += cross_motion(distal.twist, delta_V.col(c));
  x.template bottomRows<3>() = delta_V.template bottomRows<3>();
  store_coordinates_after(data, i, first, x);
  // The wrench of everything after s.
  const Eigen::Matrix<double, 6, kDerivativeBlock> d_children =
      ws.subtrees[k + 1].apply(x.template topRows<6>(), x.template bottomRows<3>());
  return force_to_local(distal.R, distal.p, d_children);
}

/// \brief The columns (q_i, qdot_i) of \f$\partial\tau\f$ for the coordinates of a segment s
/// with tangent steps (segment_tangent.hpp: a lumped CC joint): its calc_motion() once in
/// AutoDiff along its coordinates and its inertia_hessian_times() in double, then per
/// coordinate the tangent steps in double, the rows after s and before s as for any segment
/// (the file comment).
template <class ChainT, class Segment, class Q, class Qd, class Qdd>
void tangent_step_derivatives(const ChainT& chain, typename ChainT::Data& data, int s, int offset,
                              const Segment& seg, const typename Segment::Kinematics& kin,
                              const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot,
                              const Eigen::MatrixBase<Qdd>& qddot) {
  static_assert(has_tangent_steps<Segment, kDerivativeBlock>);
  auto& ws = data.derivatives;
  using AD = typename std::decay_t<decltype(ws)>::AD;
  const InertiaRate rate = chain.inertia_rate;
  const auto k = static_cast<std::size_t>(s);
  constexpr int n = Segment::nq;
  using SegmentAD = decltype(seg.template cast<AD>());
  // calc_motion() in AutoDiff, direction j along q_j; the inertia's second derivatives in
  // double (only InertiaRate::Consistent reads them).
  segment_to_autodiff(chain, ws.chain, s);
  for (int j = 0; j < n; ++j) ws.q(offset + j).derivatives() = AD::DerType::Unit(j);
  const typename SegmentAD::Kinematics* kin_ad = nullptr;
  ws.chain.visit_segment(ws.data, s, [&](const auto& seg_ad, auto& kin_s, int, int) {
    if constexpr (std::is_same_v<std::decay_t<decltype(seg_ad)>, SegmentAD>) {
      seg_ad.calc_motion(segment_entries<n>(ws.q, offset), segment_entries<n>(ws.qdot, offset),
                         kin_s);
      kin_ad = &kin_s;
    }
  });
  for (int j = 0; j < n; ++j) ws.q(offset + j).derivatives().setZero();
  SOFTRNE_ASSERT(kin_ad != nullptr, "the AutoDiff chain's segment has another type");
  const bool consistent = rate == InertiaRate::Consistent;
  InertiaHessianTimes<n> hessian_omega;
  if (consistent)
    seg.inertia_hessian_times(segment_entries<n>(q, offset), kin, data.motion[k + 1].omega,
                              hessian_omega);

  const auto qd = segment_entries<n>(qdot, offset);
  const auto qdd = segment_entries<n>(qddot, offset);
  const FrameInWorld& base = ws.frames[k];
  const FrameMotion<double>& base_motion = data.motion[k];
  const FrameMotion<double>& distal_motion = data.motion[k + 1];
  const auto& R = kin.R_base_distal;
  // The distal origin's velocity in base axes, and both twists in distal axes.
  Eigen::Vector3d v =
      transpose_times(base.R, base.v) + cross3(base_motion.omega, kin.r_base_distal);
  v.noalias() += kin.J_distal.template topRows<3>() * qd;
  const Eigen::Vector3d v_d = transpose_times(R, v);
  const Eigen::Vector3d& w_d = distal_motion.omega;
  const TangentPoint<n> point =
      tangent_point<Segment>(kin, distal_motion, data.loads[k], data.wrench[k + 1]);
  for (int j = 0; j < n; ++j) {
    const int i = offset + j;  // the block: column 0 along q_i, column 1 along qdot_i
    KinematicsTangent<n> t[kDerivativeBlock];
    kinematics_tangents<n>(*kin_ad, kin, consistent ? &hessian_omega : nullptr, point.dI_omega,
                           qd, j, t[0], t[1]);
    FrameMotion<double> d_distal[kDerivativeBlock];
    BodyLoad<double> d_load[kDerivativeBlock];
    Eigen::Matrix<double, 6, kDerivativeBlock> dV, dA;
    auto forward = [&](auto along_rate) {
      constexpr bool kRate = decltype(along_rate)::value;
      constexpr int c = kRate ? 1 : 0;
      tangent_forward_step<kRate>(seg, kin, base_motion, qd, qdd, rate, distal_motion, point, t[c],
                                  d_distal[c], d_load[c]);
      // (dv; dw) and (da - dw x v - w x dv; dalpha), distal axes, as the AutoDiff path
      // (autodiff_segment_derivatives) forms them.
      Eigen::Vector3d dv;
      if constexpr (kRate) {
        dv = transpose_times(R, kin.J_distal.template topRows<3>().col(j));
      } else {
        Eigen::Vector3d dv_base = cross3(base_motion.omega, t[c].r_e);
        dv_base.noalias() += t[c].J.template topRows<3>() * qd;
        dv = transpose_times(t[c].R, v) + transpose_times(R, dv_base);
      }
      const Eigen::Vector3d& dw = d_distal[c].omega;
      dV.col(c) << dv, dw;
      dA.col(c) << d_distal[c].acc + cross3(v_d, dw) - cross3(w_d, dv), d_distal[c].alpha;
    };
    forward(std::false_type{});
    forward(std::true_type{});
    const Eigen::Matrix<double, 6, kDerivativeBlock> d_local =
        distal_change_to_children(data, s, i, offset + n, dV, dA);
    Eigen::Matrix<double, 6, kDerivativeBlock> d_base;
    auto backward = [&](auto along_rate) {
      constexpr bool kRate = decltype(along_rate)::value;
      constexpr int c = kRate ? 1 : 0;
      Wrench<double> d_children, d_base_c;
      d_children.force = d_local.col(c).template head<3>();
      d_children.torque = d_local.col(c).template tail<3>();
      Eigen::Matrix<double, n, 1> d_tau;
      tangent_backward_step<kRate, Segment>(kin, data.loads[k], point, d_children, d_load[c], rate,
                                            t[c], d_tau, d_base_c);
      (kRate ? data.dtau_dqdot : data.dtau_dq).template block<n, 1>(offset, i) = d_tau;
      d_base.col(c) << d_base_c.force, d_base_c.torque;
    };
    backward(std::false_type{});
    backward(std::true_type{});
    // The coordinates before s: the wrench their segments transmit.
    if (offset > 0)
      store_coordinates_before(data, i, offset, force_to_world(base.R, base.p, d_base));
  }
}

/// \brief The columns (q_i, qdot_i) of \f$\partial\tau\f$ for the NQ coordinates of any other
/// segment s (the file comment): per coordinate, its calc, forward_step and backward_step in
/// AutoDiff along (q_i, qdot_i).
template <int NQ, class ChainT>
void autodiff_segment_derivatives(const ChainT& chain, typename ChainT::Data& data, int s,
                                  int s_offset) {
  auto& ws = data.derivatives;
  using AD = typename std::decay_t<decltype(ws)>::AD;
  const InertiaRate rate = chain.inertia_rate;
  const auto& frames = ws.frames;
  const auto k = static_cast<std::size_t>(s);
  const int s_end = s_offset + NQ;
  const FrameInWorld& base = frames[k];
  const FrameInWorld& distal = frames[k + 1];
  const Eigen::Vector3d& w_d = data.motion[k + 1].omega;  // distal axes
  const Eigen::Vector3d v_d = distal.R.transpose() * distal.v;
  const Eigen::Vector3d v_b = base.R.transpose() * base.v;
  for (int j = 0; j < NQ; ++j) {
    const int i = s_offset + j;  // the block: directions (q_i, qdot_i)
    ws.q(i).derivatives() << 1, 0;
    ws.qdot(i).derivatives() << 0, 1;

    // Segment s in AutoDiff: its kinematics and its forward step (its base does not move).
    if (j == 0) segment_to_autodiff(chain, ws.chain, s);
    // The distal frame's twist and spatial acceleration in its own axes, derived: (dv; dw)
    // and (da - dw x v - w x dv; dalpha) (a spatial acceleration is a - w x v at the origin).
    Eigen::Matrix<double, 6, kDerivativeBlock> dV, dA;
    ws.chain.visit_segment(ws.data, s, [&](const auto& seg, auto& kin, int, int offset) {
      constexpr int n = std::decay_t<decltype(seg)>::nq;
      seg.calc(segment_entries<n>(ws.q, offset), segment_entries<n>(ws.qdot, offset), kin);
      forward_step(seg, kin, autodiff_constant<AD>(data.motion[k]),
                   segment_entries<n>(ws.qdot, offset), segment_entries<n>(ws.qddot, offset), true,
                   rate, ws.data.motion[k + 1], ws.data.loads[k]);
      Eigen::Matrix<AD, 3, 1> v = v_b.template cast<AD>();
      v += data.motion[k].omega.template cast<AD>().cross(kin.r_base_distal);
      if constexpr (n > 0)
        v += kin.J_distal.template topRows<3>() * segment_entries<n>(ws.qdot, offset);
      const Tangent3 dv =
          derivatives_of(Eigen::Matrix<AD, 3, 1>(kin.R_base_distal.transpose() * v));
      const Tangent3 dw = derivatives_of(ws.data.motion[k + 1].omega);
      dV.template topRows<3>() = dv;
      dV.template bottomRows<3>() = dw;
      dA.template topRows<3>() = derivatives_of(ws.data.motion[k + 1].acc);
      dA.template topRows<3>().noalias() += skew(v_d) * dw;
      dA.template topRows<3>().noalias() -= skew(w_d) * dv;
      dA.template bottomRows<3>() = derivatives_of(ws.data.motion[k + 1].alpha);
    });
    const Eigen::Matrix<double, 6, kDerivativeBlock> d_local =
        distal_change_to_children(data, s, i, s_end, dV, dA);
    // Segment s itself in AutoDiff, backward.
    Eigen::Matrix<double, 6, kDerivativeBlock> d_base;
    ws.chain.visit_segment(ws.data, s, [&](const auto& seg, const auto& kin, int, int) {
      constexpr int n = std::decay_t<decltype(seg)>::nq;
      Wrench<AD> children, base_wrench;
      children.force =
          with_derivatives<AD>(data.wrench[k + 1].force, d_local.template topRows<3>());
      children.torque =
          with_derivatives<AD>(data.wrench[k + 1].torque, d_local.template bottomRows<3>());
      Eigen::Matrix<AD, n, 1> tau;
      backward_step(seg, kin, ws.data.loads[k], children, rate, tau, base_wrench);
      if constexpr (n > 0) {  // (s has coordinates; the others are never visited here)
        for (int r = 0; r < n; ++r) {
          data.dtau_dq(s_offset + r, i) = tau(r).derivatives()(0);
          data.dtau_dqdot(s_offset + r, i) = tau(r).derivatives()(1);
        }
      }
      d_base.template topRows<3>() = derivatives_of(base_wrench.force);
      d_base.template bottomRows<3>() = derivatives_of(base_wrench.torque);
    });
    // The coordinates before s: the wrench their segments transmit.
    if (s_offset > 0)
      store_coordinates_before(data, i, s_offset, force_to_world(base.R, base.p, d_base));

    ws.q(i).derivatives().setZero();
    ws.qdot(i).derivatives().setZero();
  }
}

/// \brief \f$\partial\tau/\partial q\f$ and \f$\partial\tau/\partial\dot q\f$ of the RNE at
/// (q, qdot, qddot) into data.dtau_dq and data.dtau_dqdot (the file comment: one block
/// (q_i, qdot_i) per coordinate, AutoDiff on the coordinate's own segment, the composites of
/// derivative_composites.hpp elsewhere), once data holds the RNE at that point
/// (compute_kinematics, then rnea_passes with qddot: kinematics, motions, loads, wrenches) and
/// the composites (compute_derivative_composites) and the workspace is prepared
/// (prepare_derivatives).
template <class ChainT, class Q, class Qd, class Qdd>
void derivative_columns(const ChainT& chain, typename ChainT::Data& data,
                        const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot,
                        const Eigen::MatrixBase<Qdd>& qddot) {
  static_assert(std::is_floating_point_v<typename ChainT::Scalar>,
                "softrne: derivatives need a chain of a floating-point scalar");
  auto& ws = data.derivatives;
  using AD = typename std::decay_t<decltype(ws)>::AD;
  const int nq = chain.num_coordinates(), n_seg = data.num_segments();
  for (int i = 0; i < nq; ++i) {
    ws.q(i) = AD(q(i));
    ws.qdot(i) = AD(qdot(i));
    ws.qddot(i) = AD(qddot(i));
  }
  for (int s = 0; s < n_seg; ++s)
    chain.visit_segment(data, s, [&](const auto& seg, const auto& kin, int, int offset) {
      using Segment = std::decay_t<decltype(seg)>;
      if constexpr (is_fixed_axis_joint<Segment>::value)
        fixed_axis_derivatives(data, s, offset);
      else if constexpr (has_tangent_steps<Segment, kDerivativeBlock>)
        tangent_step_derivatives(chain, data, s, offset, seg, kin, q, qdot, qddot);
      else if constexpr (Segment::nq > 0)
        autodiff_segment_derivatives<Segment::nq>(chain, data, s, offset);
      // (a segment without coordinates, a rigid link, has no columns)
    });
}

/// \brief \f$\partial\tau/\partial q\f$ and \f$\partial\tau/\partial\dot q\f$ of the RNE at
/// (q, qdot, qddot) into data.dtau_dq and data.dtau_dqdot, from nothing: the RNE at that
/// point (tau into data.tau; kinematics, motions, loads and wrenches kept in data), the
/// composites, with `with_mass_matrix` \f$\partial\tau/\partial\ddot q = M\f$ from them into
/// data.mass_matrix, then derivative_columns().
template <class ChainT, class Q, class Qd, class Qdd>
void rnea_derivative_passes(const ChainT& chain, typename ChainT::Data& data,
                            const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot,
                            const Eigen::MatrixBase<Qdd>& qddot, bool with_mass_matrix) {
  prepare_derivatives(chain, data);
  compute_kinematics(chain, data, q, qdot);
  rnea_passes(chain, data, qdot, qddot, true, true, data.tau);
  compute_derivative_composites(chain, data, qdot, with_mass_matrix ? &data.mass_matrix : nullptr);
  derivative_columns(chain, data, q, qdot, qddot);
}

}  // namespace detail

/// \brief Derivatives of the inverse dynamics \f$\tau = M(q)\ddot q + C(q,\dot q)\dot q +
/// G(q)\f$ (rnea()): \f$\partial\tau/\partial q\f$, \f$\partial\tau/\partial\dot q\f$ and
/// \f$\partial\tau/\partial\ddot q = M(q)\f$, each in its own field of data (as Pinocchio's
/// computeRNEADerivatives). Exact (this file's comment: AutoDiff on the perturbed segment
/// only, world composites for the rest); cost one rnea(), one O(n) composite pass that also
/// gives M (mass_matrix() agrees with it to rounding; the tests hold both to finite
/// differences), and per segment with coordinates one AutoDiff evaluation of a lumped CC
/// joint's kinematics, or one of another segment's calc and steps per coordinate (none for a
/// fixed-axis joint), with O(nq) short products per coordinate. Allocates nothing for a
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
  detail::rnea_derivative_passes(chain, data, q, qdot, qddot, true);
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
///   leaves (data.qddot, data.mass_matrix, data.mass_factor, data.nonlinear_forces; M from
///   the composites, equal to mass_matrix()'s to rounding) and the inverse-dynamics partials at
///   qddot* (data.dtau_dq, data.dtau_dqdot, data.tau).
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
  detail::prepare_derivatives(chain, data);
  // forward_dynamics() but for M, which comes from the composites (they need the velocities
  // only, so they are formed before qddot is known): C qdot + G, M, then qddot*.
  detail::kinematics_and_nonlinear_forces(chain, data, q, qdot);
  detail::compute_derivative_composites(chain, data, qdot, &data.mass_matrix);
  detail::solve_for_qddot(data, tau);
  if (!data.qddot.allFinite()) {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    data.dqddot_dq.setConstant(nan);
    data.dqddot_dqdot.setConstant(nan);
    data.dqddot_dtau.setConstant(nan);
    return;
  }
  // The inverse dynamics' partials at qddot*.
  detail::rnea_passes(chain, data, qdot, data.qddot, true, true, data.tau);
  detail::derivative_columns(chain, data, q, qdot, data.qddot);
  // M^-1 from the factor (cholesky.hpp), then the two products.
  detail::cholesky_inverse_factored(data.mass_factor, data.dqddot_dtau);
  data.dqddot_dq.noalias() = -data.dqddot_dtau * data.dtau_dq;
  data.dqddot_dqdot.noalias() = -data.dqddot_dtau * data.dtau_dqdot;
}

}  // namespace softrne
