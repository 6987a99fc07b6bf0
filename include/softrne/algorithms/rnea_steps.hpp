#pragma once
/// \file
/// \brief The two step bodies of the recursive Newton-Euler algorithm, written once for every
/// segment type and both kinds of chain.

#include <type_traits>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "softrne/chain/motion.hpp"
#include "softrne/segments/sub_bodies.hpp"
#include "softrne/spatial/frame_placement.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {
namespace detail {

/// \brief Forward step (paper eqs. 11-15) across one segment: from the motion of its base
/// frame to that of its distal frame, and the d'Alembert load of its own body.
/// \param velocity_terms false drops every velocity-product term (used for the columns of M,
/// where qdot = 0 but the kinematics were computed at another qdot).
template <class Segment, class Qd, class Qdd>
void forward_step(const Segment& seg, const typename Segment::Kinematics& kin,
                  const FrameMotion<typename Segment::Scalar>& base,
                  const Eigen::MatrixBase<Qd>& qdot, const Eigen::MatrixBase<Qdd>& qddot,
                  bool velocity_terms, InertiaRate inertia_rate,
                  FrameMotion<typename Segment::Scalar>& distal,
                  BodyLoad<typename Segment::Scalar>& load) {
  using Scalar = typename Segment::Scalar;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  constexpr int nq = Segment::nq;
  const auto& R = kin.R_base_distal;
  const Vector3& r_e = kin.r_base_distal;

  // Relative twist and its rate, in the base frame (eq. 7).
  Vector3 v_rel = Vector3::Zero(), w_rel = Vector3::Zero();
  Vector3 a_rel = Vector3::Zero(), dw_rel = Vector3::Zero();
  constexpr bool turns = !has_identity_rotation<Segment>::value;
  constexpr bool shifts = !has_zero_translation<Segment>::value;  // else J_v = 0 too
  if constexpr (nq > 0) {
    if constexpr (shifts) {
      v_rel = kin.J_distal.template topRows<3>() * qdot;
      a_rel = kin.J_distal.template topRows<3>() * qddot;
    }
    w_rel = kin.J_distal.template bottomRows<3>() * qdot;
    dw_rel = kin.J_distal.template bottomRows<3>() * qddot;
    if (velocity_terms) {
      a_rel += kin.Jdot_qdot_distal.template head<3>();
      dw_rel += kin.Jdot_qdot_distal.template tail<3>();
    }
  }
  const Vector3& w = base.omega;
  const Vector3& dw = base.alpha;
  const Vector3 omega = w + w_rel;                     // eq. 11
  const Vector3 alpha = dw + dw_rel + w.cross(w_rel);  // eq. 12
  // Eq. 15: acceleration of the distal origin (velocity of a point in a rotating frame).
  // Written out here rather than through FramePlacement (spatial/frame_placement.hpp), whose
  // point_acceleration and rotate_back say the same: that version measured 7 326 instead of
  // 7 113 instructions per rnea of the paper's arm (callgrind, GCC 12), the centripetal and
  // Coriolis terms no longer sharing one branch and Eigen's R^T products vectorising better.
  Vector3 acc_e = base.acc;
  if constexpr (shifts) acc_e += dw.cross(r_e);
  acc_e += a_rel;
  if (velocity_terms) {
    if constexpr (shifts && nq > 0)
      acc_e += w.cross(w.cross(r_e)) + Scalar(2) * w.cross(v_rel);
    else if constexpr (shifts)
      acc_e += w.cross(w.cross(r_e));
  }
  if constexpr (turns) {
    distal.omega.noalias() = R.transpose() * omega;
    distal.alpha.noalias() = R.transpose() * alpha;
    distal.acc.noalias() = R.transpose() * acc_e;
  } else {
    distal.omega = omega;
    distal.alpha = alpha;
    distal.acc = acc_e;
  }

  if constexpr (Segment::has_body && num_sub_bodies<Segment> == 0) {
    const Vector3& r_c = kin.r_base_com;
    // Eq. 14 with the centre of mass's own relative velocity and acceleration
    // (the paper writes a_{e,rel} there; it must be a_{c,rel}).
    Vector3 acc_c = base.acc + dw.cross(r_c);
    if constexpr (nq > 0) acc_c += kin.J_com * qddot;
    if (velocity_terms) {
      acc_c += w.cross(w.cross(r_c));
      if constexpr (nq > 0) acc_c += Scalar(2) * w.cross(kin.J_com * qdot) + kin.Jdot_qdot_com;
    }
    load.force = seg.mass * acc_c;  // eq. 16 (gravity is in base.acc)
    // Eq. 18 in the distal frame, plus the rate of the configuration-dependent inertia.
    const auto& I = kin.inertia_com;
    Vector3 torque = times(I, distal.alpha);
    if (velocity_terms) {
      torque += cross3(distal.omega, times(I, distal.omega));
      if constexpr (nq > 0) {
        if (inertia_rate == InertiaRate::Consistent)
          torque += times(kin.inertia_rate, distal.omega);
      }
    }
    if constexpr (turns)
      load.torque = times(R, torque);
    else
      load.torque = torque;
    load.omega_distal = velocity_terms ? distal.omega : Vector3::Zero();
  } else if constexpr (num_sub_bodies<Segment> > 0) {
    // Own mass as rigid sub-bodies (the quadrature disks of a distributed CC joint), each with
    // its own Jacobians relative to the base frame: eqs. 11-12 and 14 for its angular and
    // linear acceleration, eqs. 16 and 18 for its d'Alembert load (constant inertia in its own
    // frame: no inertia-rate terms). The load is summed about the base origin; its projection
    // on the segment's coordinates (backward_step's power-conjugate projection, with each
    // sub-body's own Jacobians) needs nothing from the children, so it is formed here.
    static_assert(nq > 0 && nq <= 3, "sub-body segments need 1 to 3 coordinates");
    Vector3 F = Vector3::Zero(), N = Vector3::Zero();
    Eigen::Matrix<Scalar, nq, 1> tau_b = Eigen::Matrix<Scalar, nq, 1>::Zero();
    for (const auto& b : kin.sub_bodies) {
      const Vector3& r = b.r_base_body;
      Vector3 alpha_b = dw + b.J_w * qddot;
      Vector3 acc_b = base.acc + dw.cross(r) + b.J_v * qddot;
      Vector3 torque_b;
      if (velocity_terms) {
        const Vector3 w_rel_b = b.J_w * qdot;
        const Vector3 v_rel_b = b.J_v * qdot;
        const Vector3 omega_b = w + w_rel_b;
        alpha_b += b.Jdot_qdot_w + w.cross(w_rel_b);
        acc_b += w.cross(w.cross(r)) + Scalar(2) * w.cross(v_rel_b) + b.Jdot_qdot_v;
        torque_b = b.inertia * alpha_b + omega_b.cross(b.inertia * omega_b);
      } else {
        torque_b = b.inertia * alpha_b;
      }
      const Vector3 f = b.mass * acc_b;
      F += f;
      N += torque_b + r.cross(f);
      tau_b.noalias() += b.J_v.transpose() * f;
      tau_b.noalias() += b.J_w.transpose() * torque_b;
    }
    load.force = F;
    load.torque = N;  // about the base origin
    load.omega_distal.setZero();
    load.tau_sub_bodies.setZero();
    load.tau_sub_bodies.template head<nq>() = tau_b;
  }
}

/// \brief Backward step (paper eqs. 16-17): from the wrench that segment i passes on to its
/// children (about its distal origin, distal frame) to the wrench at its base (about the base
/// origin, base frame), and the segment's generalised forces.
///
/// The generalised forces are the power-conjugate projections of the loads: the wrench
/// transmitted to the children through the distal frame's Jacobian, the segment's own body
/// through its centre-of-mass and angular Jacobians. (Taking the x/y torque components at a
/// frame is not the same: the tip of a CC joint moves about half as far as a rigid rotation
/// about its base would move it.)
template <class Segment>
void backward_step(const Segment&, const typename Segment::Kinematics& kin,
                   const BodyLoad<typename Segment::Scalar>& load,
                   const Wrench<typename Segment::Scalar>& distal, InertiaRate inertia_rate,
                   Eigen::Matrix<typename Segment::Scalar, Segment::nq, 1>& tau,
                   Wrench<typename Segment::Scalar>& base) {
  using Scalar = typename Segment::Scalar;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  constexpr int nq = Segment::nq;
  const auto X = placement_of<Segment>(kin);
  // The children's wrench about the distal origin, in base axes.
  const Vector3 F = X.rotate(distal.force);
  const Vector3 N = X.rotate(distal.torque);
  if constexpr (nq > 0) {
    if constexpr (has_zero_translation<Segment>::value) {  // J_v = 0
      tau.noalias() = kin.J_distal.template bottomRows<3>().transpose() * N;
    } else {
      tau.noalias() = kin.J_distal.template topRows<3>().transpose() * F;
      tau.noalias() += kin.J_distal.template bottomRows<3>().transpose() * N;
    }
    if constexpr (num_sub_bodies<Segment> > 0) {
      tau += load.tau_sub_bodies.template head<nq>();
    } else if constexpr (Segment::has_body) {
      tau.noalias() += kin.J_com.transpose() * load.force;
      tau.noalias() += kin.J_distal.template bottomRows<3>().transpose() * load.torque;
      if (inertia_rate == InertiaRate::Consistent) {
        // -dT/dq_k of the rotational energy 1/2 w^T I(q) w.
        for (int k = 0; k < nq; ++k)
          tau(k) -=
              Scalar(0.5) * load.omega_distal.dot(times(
                                kin.dinertia_dq[static_cast<std::size_t>(k)], load.omega_distal));
      }
    }
  }
  base.force = F;
  base.torque = X.shift_torque(N, F);
  if constexpr (num_sub_bodies<Segment> > 0) {
    base.force += load.force;
    base.torque += load.torque;  // already about the base origin
  } else if constexpr (Segment::has_body) {
    base.force += load.force;
    base.torque += load.torque + kin.r_base_com.cross(load.force);
  }
}

}  // namespace detail
}  // namespace softrne
