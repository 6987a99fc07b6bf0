#pragma once
/// \file
/// \brief The tangents of the two RNE steps (rnea_steps.hpp) with respect to the motion and the
/// wrenches they receive, the segment's own kinematics held fixed: the linear maps that carry
/// a perturbation of one segment's coordinates through the rest of the chain
/// (derivatives.hpp).
///
/// A block of kDerivativeBlock directions is a 3 x kDerivativeBlock matrix per vector
/// (column k: the derivative along direction k; the types are in derivative_workspace.hpp).
/// Derived from forward_step and backward_step term by term (product rule on eqs. 11-18 with
/// the base motion and the children's wrench as the only variables; the velocity products are
/// quadratic in the base's omega, everything else linear):
/// - forward: \f$\delta\omega_e = \delta\omega\f$,
///   \f$\delta\alpha_e = \delta\alpha + \delta\omega\times\omega_{rel}\f$,
///   \f$\delta a_e = \delta a + \delta\alpha\times r + \delta\omega\times(\omega\times r) +
///   \omega\times(\delta\omega\times r) + 2\,\delta\omega\times v_{rel}\f$, then into distal
///   axes; a lumped body's load the same way with its centre of mass, and
///   \f$\delta(I\alpha + \omega\times I\omega + \dot I\omega) = I\delta\alpha +
///   ([\omega]_\times I - [I\omega]_\times + \dot I)\delta\omega\f$ in distal axes; each
///   sub-body of a distributed joint likewise with its own Jacobians;
/// - backward: the children's wrench rotated and shifted, the body's load added, and the
///   coordinates' forces \f$J^T\f$ of both, with
///   \f$\delta(-\tfrac12\omega^T\partial_k I\,\omega) = -\omega^T\partial_k I\,\delta\omega\f$.
/// The tests (tests/core/test_derivatives.cpp) hold the result to central finite differences
/// and to an AutoDiff pass of the whole RNE.

#include <type_traits>

#include <Eigen/Core>

#include "softrne/algorithms/rnea_steps.hpp"
#include "softrne/chain/derivative_workspace.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {
namespace detail {

/// \brief \f$\partial/\partial\omega\f$ of \f$\omega\times(\omega\times r) + 2\omega\times v\f$
/// at \f$\omega\f$ (the velocity-product terms of a point's acceleration, eqs. 14-15):
/// \f$-[\omega\times r]_\times - [\omega]_\times[r]_\times - 2[v]_\times\f$, with
/// \f$[\omega]_\times[r]_\times = r\omega^T - (\omega\cdot r)I\f$.
EIGEN_ALWAYS_INLINE Eigen::Matrix3d point_velocity_terms_jacobian(const Eigen::Vector3d& w,
                                                                  const Eigen::Vector3d& r,
                                                                  const Eigen::Vector3d& v) {
  const Eigen::Vector3d c = w.cross(r) + 2.0 * v;
  Eigen::Matrix3d m = -skew(c);
  m.noalias() -= r * w.transpose();
  m.diagonal().array() += w.dot(r);
  return m;
}

/// \brief Tangent of forward_step (velocity terms on) with respect to the base motion, the
/// segment's kinematics, qdot and qddot held fixed.
/// \param[in] base The base frame's motion at the expansion point.
/// \param[in] d_base Its derivatives.
/// \param[out] d_distal The distal frame's motion derivatives.
/// \param[out] d_load The body load's derivatives (what backward_tangent_step reads).
template <class Segment, class Qd>
void forward_tangent_step(const Segment& seg, const typename Segment::Kinematics& kin,
                          const FrameMotion<double>& base, const Eigen::MatrixBase<Qd>& qdot,
                          InertiaRate inertia_rate, const MotionTangent& d_base,
                          MotionTangent& d_distal, LoadTangent& d_load) {
  using Vector3 = Eigen::Vector3d;
  constexpr int nq = Segment::nq;
  constexpr bool turns = !has_identity_rotation<Segment>::value;
  constexpr bool shifts = !has_zero_translation<Segment>::value;
  const Vector3& w = base.omega;
  Vector3 w_rel = Vector3::Zero(), v_rel = Vector3::Zero();
  if constexpr (nq > 0) {
    w_rel.noalias() = kin.J_distal.template bottomRows<3>() * qdot;
    if constexpr (shifts) v_rel.noalias() = kin.J_distal.template topRows<3>() * qdot;
  }
  const Tangent3 alpha_e = d_base.alpha - skew(w_rel) * d_base.omega;
  Tangent3 acc_e = d_base.acc;
  if constexpr (shifts) {
    const Vector3& r = kin.r_base_distal;
    acc_e.noalias() -= skew(r) * d_base.alpha;
    acc_e.noalias() += point_velocity_terms_jacobian(w, r, v_rel) * d_base.omega;
  }
  if constexpr (turns) {
    const auto Rt = kin.R_base_distal.transpose();
    d_distal.omega.noalias() = Rt * d_base.omega;
    d_distal.alpha.noalias() = Rt * alpha_e;
    d_distal.acc.noalias() = Rt * acc_e;
  } else {
    d_distal.omega = d_base.omega;
    d_distal.alpha = alpha_e;
    d_distal.acc = acc_e;
  }

  if constexpr (Segment::has_body && num_sub_bodies<Segment> == 0) {
    const Vector3& r_c = kin.r_base_com;
    Vector3 v_c = Vector3::Zero();
    if constexpr (nq > 0) v_c.noalias() = kin.J_com * qdot;
    Tangent3 acc_c = d_base.acc;
    acc_c.noalias() -= skew(r_c) * d_base.alpha;
    acc_c.noalias() += point_velocity_terms_jacobian(w, r_c, v_c) * d_base.omega;
    d_load.force = seg.mass * acc_c;
    // The distal frame's omega at the expansion point (forward_step's distal.omega).
    const Vector3 omega = w + w_rel;
    const Vector3 w_d = turns ? Vector3(kin.R_base_distal.transpose() * omega) : omega;
    const auto& I = kin.inertia_com;
    const Vector3 h = I * w_d;  // the angular momentum, evaluated once
    Eigen::Matrix3d K = skew(w_d) * I - skew(h);
    if constexpr (nq > 0)
      if (inertia_rate == InertiaRate::Consistent) K += kin.inertia_rate;
    Tangent3 torque = I * d_distal.alpha;
    torque.noalias() += K * d_distal.omega;
    if constexpr (turns)
      d_load.torque.noalias() = kin.R_base_distal * torque;
    else
      d_load.torque = torque;
    d_load.omega_distal = d_distal.omega;
  } else if constexpr (num_sub_bodies<Segment> > 0) {
    d_load.force.setZero();
    d_load.torque.setZero();
    d_load.tau_sub_bodies.setZero();
    for (const auto& b : kin.sub_bodies) {
      const Vector3& r = b.r_base_body;
      const Vector3 w_rel_b = b.J_w * qdot, v_rel_b = b.J_v * qdot;
      const Vector3 omega_b = w + w_rel_b;
      const Tangent3 alpha_b = d_base.alpha - skew(w_rel_b) * d_base.omega;
      Tangent3 acc_b = d_base.acc;
      acc_b.noalias() -= skew(r) * d_base.alpha;
      acc_b.noalias() += point_velocity_terms_jacobian(w, r, v_rel_b) * d_base.omega;
      Tangent3 torque_b = b.inertia * alpha_b;
      const Vector3 h_b = b.inertia * omega_b;
      torque_b.noalias() += (skew(omega_b) * b.inertia - skew(h_b)) * d_base.omega;
      const Tangent3 f = b.mass * acc_b;
      d_load.force += f;
      d_load.torque += torque_b;
      d_load.torque.noalias() += skew(r) * f;
      d_load.tau_sub_bodies.template topRows<nq>().noalias() += b.J_v.transpose() * f;
      d_load.tau_sub_bodies.template topRows<nq>().noalias() += b.J_w.transpose() * torque_b;
    }
  }
}

/// \brief Tangent of backward_step with respect to the children's wrench and the segment's
/// own load, its kinematics held fixed.
/// \param[in] load The body load at the expansion point (omega_distal).
/// \param[in] d_load Its derivatives, or null if the load does not move (segments before
///   the perturbed one).
/// \param[in] d_distal The derivatives of the children's wrench (distal origin, distal axes).
/// \param[out] d_tau The segment's generalised forces' derivatives (nq x block).
/// \param[out] d_base The derivatives of the wrench at the base (base origin, base axes).
template <class Segment, class DTau>
void backward_tangent_step(const typename Segment::Kinematics& kin,
                           const BodyLoad<double>& load, const LoadTangent* d_load,
                           const WrenchTangent& d_distal, InertiaRate inertia_rate,
                           Eigen::MatrixBase<DTau>& d_tau, WrenchTangent& d_base) {
  constexpr int nq = Segment::nq;
  constexpr bool turns = !has_identity_rotation<Segment>::value;
  constexpr bool shifts = !has_zero_translation<Segment>::value;
  Tangent3 F, N;
  if constexpr (turns) {
    F.noalias() = kin.R_base_distal * d_distal.force;
    N.noalias() = kin.R_base_distal * d_distal.torque;
  } else {
    F = d_distal.force;
    N = d_distal.torque;
  }
  if constexpr (nq > 0) {
    d_tau.noalias() = kin.J_distal.template bottomRows<3>().transpose() * N;
    if constexpr (shifts) d_tau.noalias() += kin.J_distal.template topRows<3>().transpose() * F;
    if (d_load) {
      if constexpr (num_sub_bodies<Segment> > 0) {
        d_tau += d_load->tau_sub_bodies.template topRows<nq>();
      } else if constexpr (Segment::has_body) {
        d_tau.noalias() += kin.J_com.transpose() * d_load->force;
        d_tau.noalias() += kin.J_distal.template bottomRows<3>().transpose() * d_load->torque;
        if (inertia_rate == InertiaRate::Consistent)
          for (int k = 0; k < nq; ++k)
            d_tau.row(k).noalias() -=
                (kin.dinertia_dq[static_cast<std::size_t>(k)] * load.omega_distal).transpose() *
                d_load->omega_distal;
      }
    }
  }
  d_base.force = F;
  d_base.torque = N;
  if constexpr (shifts) d_base.torque.noalias() += skew(kin.r_base_distal) * F;
  if (d_load) {
    if constexpr (num_sub_bodies<Segment> > 0) {
      d_base.force += d_load->force;
      d_base.torque += d_load->torque;  // about the base origin already
    } else if constexpr (Segment::has_body) {
      d_base.force += d_load->force;
      d_base.torque += d_load->torque;
      d_base.torque.noalias() += skew(kin.r_base_com) * d_load->force;
    }
  }
}

}  // namespace detail
}  // namespace softrne
