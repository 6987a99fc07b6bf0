#pragma once
/// \file
/// \brief The derivative of one segment's RNE steps (rnea_steps.hpp's forward_step and
/// backward_step) along one direction of its own coordinates or their rates, with its base's
/// motion held: the tangent steps derivatives.hpp runs on the perturbed segment, in double,
/// from the derivatives of the segment's kinematics (KinematicsTangent).
///
/// ## Where the kinematics' derivatives come from
/// calc_motion() (calc without the inertia) runs once per segment in AutoDiff, seeded along its
/// coordinates q_j only. Along a rate qdot_j nothing needs another evaluation: by the
/// definitions of SegmentKinematics, calc's outputs depend on qdot only through \f$\dot J\dot q
/// = (\sum_k \partial J/\partial q_k\,\dot q_k)\,\dot q\f$ (for J_distal and J_com) and
/// \f$\dot I = \sum_k \partial I/\partial q_k\,\dot q_k\f$, so \f$\partial(\dot J\dot
/// q)/\partial\dot q_j = \dot J e_j + (\partial J/\partial q_j)\dot q\f$ and \f$\partial\dot
/// I/\partial\dot q_j = \partial I/\partial q_j\f$, both from the derivatives along q. The
/// inertia's derivative along q_j is calc's own dinertia_dq[j]; its second derivatives come
/// from the segment's inertia_hessian_times, applied to the distal angular velocity
/// \f$\omega^i\f$, the only vector the steps apply them to. (Until 2026-12-07 calc,
/// forward_step and backward_step ran in AutoDiff once per coordinate, seeded along (q_j,
/// qdot_j): 62k of the 100k instructions of rnea_derivatives on the paper's arm; then the
/// whole calc once per joint, its inertia part 10.5k of 55.6k.)
///
/// ## The tangent steps
/// The product rule on eqs. 11-18 as forward_step and backward_step write them (lumped body;
/// the names below are theirs), base motion (w, dw, a_b) fixed, a prefix d for the derivative:
/// - \f$d\omega = dJ_w\dot q + J_w d\dot q\f$, \f$d\alpha = dJ_w\ddot q + d(\dot J\dot q)_w +
///   w\times d\omega\f$ (base axes); the distal frame's \f$d(R^T x) = dR^T x + R^T dx\f$;
/// - \f$da_e = dw\times dr_e + dJ_v\ddot q + d(\dot J\dot q)_v + w\times(w\times dr_e) +
///   2w\times(dJ_v\dot q + J_v d\dot q)\f$, likewise \f$da_c\f$ with r_c and J_com;
/// - the load \f$f = m a_c\f$, \f$\tau^i = I\alpha^i + \omega^i\times I\omega^i + \dot
///   I\omega^i\f$ (distal axes), turned to base axes by R;
/// - backward: \f$\tau = J_v^T RF + J_w^T RN + J_c^T f + J_w^T\tau_b - \tfrac12\omega^{iT}
///   \partial_k I\,\omega^i\f$ and the base wrench \f$(RF + f;\ RN + r_e\times RF + \tau_b +
///   r_c\times f)\f$, differentiated term by term (\f$\partial_k I\f$ symmetric).
/// The tests hold the derivatives that use these steps to central finite differences and to an
/// AutoDiff pass of the whole RNE (tests/core/test_derivatives.cpp).

#include <array>
#include <cstddef>
#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "softrne/chain/motion.hpp"
#include "softrne/segments/sub_bodies.hpp"
#include "softrne/spatial/frame_placement.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {
namespace detail {

/// \brief The second derivatives of a segment's inertia_com with respect to its coordinates,
/// applied to the distal angular velocity: [i][j] = \f$(\partial^2 I/\partial q_i\partial
/// q_j)\,\omega^i\f$ (distal axes).
template <int NQ>
using InertiaHessianTimes = std::array<std::array<Eigen::Vector3d, static_cast<std::size_t>(NQ)>,
                                       static_cast<std::size_t>(NQ)>;

/// \brief true for a segment with `calc_motion` (calc without the inertia) and
/// `inertia_hessian_times` (the CC joint with LumpedInertia).
template <class Segment, class = void>
struct has_inertia_hessian : std::false_type {};
template <class Segment>
struct has_inertia_hessian<
    Segment, std::void_t<decltype(std::declval<const Segment&>().inertia_hessian_times(
                             std::declval<const Eigen::Matrix<double, Segment::nq, 1>&>(),
                             std::declval<const typename Segment::Kinematics&>(),
                             std::declval<const Eigen::Vector3d&>(),
                             std::declval<InertiaHessianTimes<Segment::nq>&>()))>>
    : std::true_type {};

/// \brief true for a segment whose perturbation derivatives.hpp takes through the tangent steps
/// of this file: one lumped body (no sub-bodies), a rotation and a translation that both move,
/// at most as many coordinates as one AutoDiff evaluation carries, and the second derivatives
/// of its inertia written out (the CC joint with LumpedInertia). Other segments are evaluated
/// in AutoDiff whole.
template <class Segment, int MaxCoordinates>
inline constexpr bool has_tangent_steps =
    Segment::has_body && (num_sub_bodies<Segment> == 0) &&
    !has_identity_rotation<Segment>::value && !has_zero_translation<Segment>::value &&
    Segment::nq >= 1 && Segment::nq <= MaxCoordinates && has_inertia_hessian<Segment>::value;

/// \brief The derivative of a segment's kinematics (SegmentKinematics' fields, same names
/// shortened) along one direction: a coordinate q_j, or a rate qdot_j (`rate` = j). Along a
/// rate only Jdq, Jdq_c, I_rate_omega and rate are set (kinematics_tangents).
template <int NQ>
struct KinematicsTangent {
  using Matrix3 = Eigen::Matrix3d;
  using Vector3 = Eigen::Vector3d;
  Matrix3 R;                                                ///< of R_base_distal
  Vector3 r_e;                                              ///< of r_base_distal
  Vector3 r_c;                                              ///< of r_base_com
  Eigen::Matrix<double, 6, NQ> J;                           ///< of J_distal
  Eigen::Matrix<double, 6, 1> Jdq;                          ///< of Jdot_qdot_distal
  Eigen::Matrix<double, 3, NQ> J_c;                         ///< of J_com
  Vector3 Jdq_c;                                            ///< of Jdot_qdot_com
  Matrix3 I;                                                ///< of inertia_com
  /// Of inertia_rate and of dinertia_dq, times the distal angular velocity omega^i at the
  /// expansion point (the only vector the tangent steps apply them to).
  Vector3 I_rate_omega;
  std::array<Vector3, static_cast<std::size_t>(NQ)> dI_dq_omega;
  int rate = -1;  ///< j along qdot_j (qdot's derivative is e_j there), -1 along a coordinate
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The derivatives of an AutoDiff matrix along direction c, as a double matrix.
template <class M>
Eigen::Matrix<double, M::RowsAtCompileTime, M::ColsAtCompileTime> derivative_along(const M& m,
                                                                                   int c) {
  Eigen::Matrix<double, M::RowsAtCompileTime, M::ColsAtCompileTime> out;
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = 0; i < m.rows(); ++i) out(i, j) = m(i, j).derivatives()(c);
  return out;
}

/// \brief The kinematics' derivatives along q_j and along qdot_j (this file's comment).
/// \param[in] ad The kinematics from calc_motion() in AutoDiff, direction k of its derivatives
///   along q_k (k < NQ), nothing along qdot (its inertia fields are not read).
/// \param[in] kin The same kinematics in double (the expansion point).
/// \param[in] hessian_omega The inertia's second derivatives times omega^i (the segment's
///   inertia_hessian_times), or null: then the tangents of inertia_rate and dinertia_dq are
///   zero (InertiaRate::Neglect does not read them).
/// \param[in] dI_omega dinertia_dq[k] omega^i (TangentPoint).
/// \param[in] qdot The segment's rates at the expansion point.
/// \param[in] j The coordinate.
template <int NQ, class KinAD, class Kin, class Qd>
void kinematics_tangents(const KinAD& ad, const Kin& kin,
                         const InertiaHessianTimes<NQ>* hessian_omega,
                         const std::array<Eigen::Vector3d, static_cast<std::size_t>(NQ)>& dI_omega,
                         const Eigen::MatrixBase<Qd>& qdot, int j, KinematicsTangent<NQ>& along_q,
                         KinematicsTangent<NQ>& along_qdot) {
  const auto jj = static_cast<std::size_t>(j);
  along_q.R = derivative_along(ad.R_base_distal, j);
  along_q.r_e = derivative_along(ad.r_base_distal, j);
  along_q.r_c = derivative_along(ad.r_base_com, j);
  along_q.J = derivative_along(ad.J_distal, j);
  along_q.Jdq = derivative_along(ad.Jdot_qdot_distal, j);
  along_q.J_c = derivative_along(ad.J_com, j);
  along_q.Jdq_c = derivative_along(ad.Jdot_qdot_com, j);
  // The inertia: its first derivative is calc's; inertia_rate = sum_k dI/dq_k qdot_k.
  along_q.I = kin.dinertia_dq[jj];
  along_q.I_rate_omega.setZero();
  for (std::size_t k = 0; k < static_cast<std::size_t>(NQ); ++k) {
    if (hessian_omega) {
      along_q.dI_dq_omega[k] = (*hessian_omega)[jj][k];
      along_q.I_rate_omega += qdot(static_cast<Eigen::Index>(k)) * (*hessian_omega)[jj][k];
    } else {
      along_q.dI_dq_omega[k].setZero();
    }
  }

  // Jdot e_j + (dJ/dq_j) qdot, with Jdot = sum_k (dJ/dq_k) qdot_k.
  Eigen::Matrix<double, 6, 1> Jdot_j = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Vector3d Jdot_c_j = Eigen::Vector3d::Zero();
  for (int k = 0; k < NQ; ++k) {
    for (int r = 0; r < 6; ++r) Jdot_j(r) += ad.J_distal(r, j).derivatives()(k) * qdot(k);
    for (int r = 0; r < 3; ++r) Jdot_c_j(r) += ad.J_com(r, j).derivatives()(k) * qdot(k);
  }
  // Along qdot_j every other derivative is zero; the tangent steps do not read them.
  along_qdot.Jdq.noalias() = Jdot_j + along_q.J * qdot;
  along_qdot.Jdq_c.noalias() = Jdot_c_j + along_q.J_c * qdot;
  along_qdot.I_rate_omega = dI_omega[jj];
  along_qdot.rate = j;
}

/// \brief What the tangent steps of one segment reuse from its expansion point, formed once
/// per segment (tangent_point) for its 2 nq directions.
template <int NQ>
struct TangentPoint {
  using Vector3 = Eigen::Vector3d;
  Vector3 omega, alpha, acc_e;  ///< the distal frame's motion in base axes (R x^i)
  Vector3 I_omega;              ///< I omega^i (distal axes)
  Vector3 torque_distal;        ///< the load's torque in distal axes, R^T tau_b
  Vector3 F_child, N_child;     ///< the children's wrench (distal axes, distal origin)
  Vector3 F, N;                 ///< the same in base axes
  Vector3 N_all;                ///< N + the load's torque (both reach q through J_w)
  std::array<Vector3, static_cast<std::size_t>(NQ)> dI_omega;  ///< dI/dq_k omega^i
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The TangentPoint of a segment from forward_step's outputs (distal, load) and the
/// children's wrench at the expansion point (distal axes, distal origin).
template <class Segment>
TangentPoint<Segment::nq> tangent_point(const typename Segment::Kinematics& kin,
                                        const FrameMotion<double>& distal,
                                        const BodyLoad<double>& load,
                                        const Wrench<double>& children) {
  const auto& R = kin.R_base_distal;
  TangentPoint<Segment::nq> p;
  p.omega = times(R, distal.omega);
  p.alpha = times(R, distal.alpha);
  p.acc_e = times(R, distal.acc);
  p.I_omega = times(kin.inertia_com, distal.omega);
  p.torque_distal = transpose_times(R, load.torque);
  p.F_child = children.force;
  p.N_child = children.torque;
  p.F = times(R, children.force);
  p.N = times(R, children.torque);
  p.N_all = p.N + load.torque;
  for (std::size_t k = 0; k < p.dI_omega.size(); ++k)
    p.dI_omega[k] = times(kin.dinertia_dq[k], load.omega_distal);
  return p;
}

/// \brief The derivative of forward_step (velocity terms on) along t: of the distal frame's
/// motion and of the segment's load; distal and load are forward_step's outputs at the
/// expansion point, p their TangentPoint.
/// \tparam AlongRate t is along a rate qdot_j: only t.Jdq, t.Jdq_c, t.I_rate_omega and t.rate
///   are read (every other derivative of the kinematics is zero there).
template <bool AlongRate, class Segment, class Qd, class Qdd>
void tangent_forward_step(const Segment& seg, const typename Segment::Kinematics& kin,
                          const FrameMotion<double>& base, const Eigen::MatrixBase<Qd>& qdot,
                          const Eigen::MatrixBase<Qdd>& qddot, InertiaRate inertia_rate,
                          const FrameMotion<double>& distal, const TangentPoint<Segment::nq>& p,
                          const KinematicsTangent<Segment::nq>& t, FrameMotion<double>& d_distal,
                          BodyLoad<double>& d_load) {
  static_assert(has_tangent_steps<Segment, Segment::nq>, "a lumped, moving segment only");
  using Vector3 = Eigen::Vector3d;
  const auto& R = kin.R_base_distal;
  const Vector3& w = base.omega;
  const Vector3& dw = base.alpha;

  // Base axes: d omega, d alpha, d a_e, d a_c.
  Vector3 d_omega, d_v_rel, d_v_com;
  if constexpr (AlongRate) {
    d_omega = kin.J_distal.template bottomRows<3>().col(t.rate);
    d_v_rel = kin.J_distal.template topRows<3>().col(t.rate);
    d_v_com = kin.J_com.col(t.rate);
  } else {
    d_omega.noalias() = t.J.template bottomRows<3>() * qdot;
    d_v_rel.noalias() = t.J.template topRows<3>() * qdot;
    d_v_com.noalias() = t.J_c * qdot;
  }
  Vector3 d_alpha = t.Jdq.template tail<3>() + cross3(w, d_omega);
  Vector3 d_acc_e = t.Jdq.template head<3>() + 2.0 * cross3(w, d_v_rel);
  Vector3 d_acc_c = t.Jdq_c + 2.0 * cross3(w, d_v_com);
  if constexpr (!AlongRate) {
    d_alpha.noalias() += t.J.template bottomRows<3>() * qddot;
    d_acc_e += cross3(dw, t.r_e) + cross3(w, cross3(w, t.r_e));
    d_acc_e.noalias() += t.J.template topRows<3>() * qddot;
    d_acc_c += cross3(dw, t.r_c) + cross3(w, cross3(w, t.r_c));
    d_acc_c.noalias() += t.J_c * qddot;
  }

  // Into distal axes: d(R^T x) = dR^T x + R^T dx.
  d_distal.omega = transpose_times(R, d_omega);
  d_distal.alpha = transpose_times(R, d_alpha);
  d_distal.acc = transpose_times(R, d_acc_e);
  if constexpr (!AlongRate) {
    d_distal.omega += transpose_times(t.R, p.omega);
    d_distal.alpha += transpose_times(t.R, p.alpha);
    d_distal.acc += transpose_times(t.R, p.acc_e);
  }

  // The load: f = m a_c; tau^i = I alpha^i + omega^i x I omega^i (+ I-dot omega^i), base axes
  // by R.
  d_load.force = seg.mass * d_acc_c;
  const auto& I = kin.inertia_com;
  const Vector3& om = distal.omega;
  const Vector3& d_om = d_distal.omega;
  Vector3 d_I_om = times(I, d_om);
  if constexpr (!AlongRate) d_I_om += times(t.I, om);
  Vector3 d_torque = times(I, d_distal.alpha) + cross3(d_om, p.I_omega) + cross3(om, d_I_om);
  if constexpr (!AlongRate) d_torque += times(t.I, distal.alpha);
  if (inertia_rate == InertiaRate::Consistent)
    d_torque += t.I_rate_omega + times(kin.inertia_rate, d_om);
  d_load.torque = times(R, d_torque);
  if constexpr (!AlongRate) d_load.torque += times(t.R, p.torque_distal);
  d_load.omega_distal = d_om;
}

/// \brief The derivative of backward_step along t: of the segment's generalised forces and of
/// the wrench at its base (base axes, about the base origin).
/// \param[in] load The load at the expansion point; \param[in] p its TangentPoint (with the
///   children's wrench).
/// \param[in] d_children The derivative of the children's wrench (distal axes, distal origin).
/// \param[in] d_load The load's derivative (tangent_forward_step).
/// \tparam AlongRate As for tangent_forward_step.
template <bool AlongRate, class Segment>
void tangent_backward_step(const typename Segment::Kinematics& kin, const BodyLoad<double>& load,
                           const TangentPoint<Segment::nq>& p, const Wrench<double>& d_children,
                           const BodyLoad<double>& d_load, InertiaRate inertia_rate,
                           const KinematicsTangent<Segment::nq>& t,
                           Eigen::Matrix<double, Segment::nq, 1>& d_tau, Wrench<double>& d_base) {
  static_assert(has_tangent_steps<Segment, Segment::nq>, "a lumped, moving segment only");
  using Vector3 = Eigen::Vector3d;
  constexpr int nq = Segment::nq;
  const auto& R = kin.R_base_distal;
  Vector3 dF = times(R, d_children.force);
  Vector3 dN = times(R, d_children.torque);
  if constexpr (!AlongRate) {
    dF += times(t.R, p.F_child);
    dN += times(t.R, p.N_child);
  }
  const Vector3 dN_all = dN + d_load.torque;  // both through J_w
  d_tau.noalias() = kin.J_distal.template topRows<3>().transpose() * dF;
  d_tau.noalias() += kin.J_distal.template bottomRows<3>().transpose() * dN_all;
  d_tau.noalias() += kin.J_com.transpose() * d_load.force;
  if constexpr (!AlongRate) {
    d_tau.noalias() += t.J.template topRows<3>().transpose() * p.F;
    d_tau.noalias() += t.J.template bottomRows<3>().transpose() * p.N_all;
    d_tau.noalias() += t.J_c.transpose() * load.force;
  }
  if (inertia_rate == InertiaRate::Consistent) {
    const Vector3& om = load.omega_distal;
    const Vector3& d_om = d_load.omega_distal;
    for (int k = 0; k < nq; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      d_tau(k) -= d_om.dot(p.dI_omega[kk]);
      if constexpr (!AlongRate) d_tau(k) -= 0.5 * om.dot(t.dI_dq_omega[kk]);
    }
  }
  d_base.force = dF + d_load.force;
  d_base.torque =
      dN + cross3(kin.r_base_distal, dF) + d_load.torque + cross3(kin.r_base_com, d_load.force);
  if constexpr (!AlongRate) d_base.torque += cross3(t.r_e, p.F) + cross3(t.r_c, load.force);
}

}  // namespace detail
}  // namespace softrne
