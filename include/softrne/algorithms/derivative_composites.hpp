#pragma once
/// \file
/// \brief What the rest of the chain does with a perturbation of one frame's motion, in world
/// quantities (Pinocchio's computeRNEADerivatives works the same way for rigid joints): the
/// linear maps that let derivatives.hpp carry the perturbation of one segment's coordinates to
/// every other row of \f$\partial\tau\f$ in O(1) per row.
///
/// ## Derivation
/// Spatial vectors about the world origin, (linear; angular) (spatial/spatial_algebra.hpp).
/// Every body m of the model (a segment's lumped body, or one sub-body of a distributed CC
/// joint) has a twist \f$v_m = V_b + J_m\dot q\f$ (V_b: its segment's base frame; J_m the
/// world Jacobian of its centre and its angular velocity), a spatial inertia \f$Y_m\f$, and
/// the d'Alembert wrench of the RNE (eqs. 16-18) \f$f_m = Y_m a_m + v_m\times^* Y_m v_m +
/// \dot I_m\omega_m\f$ (the last: InertiaRate::Consistent, a lumped CC body), a_m its
/// spatial acceleration. A coordinate's force is \f$\tau_k = \sum_m J_{k,m}^T f_m\f$
/// (\f$-\tfrac12\omega^T\partial_k I\,\omega\f$ for its own lumped CC body) over the bodies
/// it moves. All of this is covariant: moving everything rigidly moves \f$f_m\f$ with it and
/// leaves \f$\tau\f$ alone.
///
/// Perturb one frame F (a segment's distal frame) by a twist \f$\xi\f$ of its pose and
/// \f$\delta V, \delta A\f$ of its twist and spatial acceleration, the coordinates beyond it
/// fixed. Only the non-rigid parts \f$\Delta V = \delta V - \xi\times V\f$ and \f$\Delta A =
/// \delta A - \xi\times A\f$ (the derivatives of F's motion in its own axes, carried to the
/// world) change anything, and for every body m beyond F (V_F, v_m at the expansion point):
/// \f$\Delta v_m = \Delta V\f$ and \f$\Delta a_m = \Delta A + \Delta V\times(v_m - V_F)\f$.
/// With \f$D_m = \partial f_m/\partial v_m - Y_m[v_m\times] = [\,\cdot\times^* Y_m v_m] +
/// [v_m\times^*]Y_m - Y_m[v_m\times] + \dot I_m\f$:
/// - the wrench of everything beyond F changes by \f$\xi\times^* F + Y_{crb}\tilde a +
///   D_{crb}\Delta V\f$, with \f$\tilde a = \Delta A + V_F\times\Delta V\f$ and the composites
///   \f$Y_{crb} = \sum Y_m\f$, \f$D_{crb} = \sum D_m\f$ over those bodies (the frame's
///   SubtreeComposite);
/// - a coordinate k beyond F changes by \f$P_k\tilde a + R_k\Delta V\f$, with
///   \f$P_k = \sum_m J_{k,m}^T Y_m\f$ and \f$R_k = \sum_m J_{k,m}^T D_m + E_k\f$ (E_k: the
///   \f$-\omega^T\partial_k I\f$ of its own lumped CC body) over the bodies it moves; neither
///   depends on F, so one pass fills them for all perturbations (ws.sensitivity).
/// A coordinate before F sees only the wrench its segment transmits: \f$\delta\tau_k =
/// J_k^T\delta F\f$ (J_k: its distal frame's world Jacobian).
///
/// The tests (tests/core/test_derivatives.cpp) hold the result to central finite differences
/// and to an AutoDiff pass of the whole RNE.

#include <type_traits>

#include <Eigen/Core>

#include "softrne/algorithms/kinematics.hpp"
#include "softrne/algorithms/rnea_steps.hpp"
#include "softrne/chain/derivative_workspace.hpp"
#include "softrne/spatial/inertia_transforms.hpp"
#include "softrne/spatial/spatial_algebra.hpp"

namespace softrne {
namespace detail {

/// \brief true for a segment that declares `static constexpr bool fixed_axis = true` (a
/// RevoluteJoint): one coordinate, no body, no translation, and a rigid rotation about the
/// constant axis of J_distal. Its coordinate moves everything beyond its base rigidly by the
/// twist S = its world Jacobian, so its derivatives need no AutoDiff (derivatives.hpp).
template <class Segment, class = void>
struct is_fixed_axis_joint : std::false_type {};
template <class Segment>
struct is_fixed_axis_joint<Segment, std::void_t<decltype(Segment::fixed_axis)>>
    : std::bool_constant<Segment::fixed_axis && Segment::nq == 1 && !Segment::has_body &&
                         has_zero_translation<Segment>::value> {};

/// \brief A segment's distal frame in the world from its base frame (at the expansion point),
/// and the world Jacobian of the distal frame's twist (6 x nq, columns of its coordinates).
/// \param[in] motion_distal The distal frame's motion in its own axes (the RNE's; its omega is
///   read).
template <class Segment, class Qd, class JacobianT>
void world_frame_step(const typename Segment::Kinematics& kin, const FrameInWorld& base,
                      const FrameMotion<double>& motion_distal, const Eigen::MatrixBase<Qd>& qdot,
                      FrameInWorld& distal, JacobianT&& jacobian) {
  constexpr int nq = Segment::nq;
  if constexpr (has_identity_rotation<Segment>::value)
    distal.R = base.R;
  else
    distal.R.noalias() = base.R * kin.R_base_distal;
  distal.p = base.p;
  if constexpr (!has_zero_translation<Segment>::value)
    distal.p.noalias() += base.R * kin.r_base_distal;
  const Eigen::Vector3d w = distal.R * motion_distal.omega;
  distal.v = base.v;
  if constexpr (!has_zero_translation<Segment>::value) {
    distal.v += cross3(base.twist.template tail<3>(), distal.p - base.p);
    if constexpr (nq > 0) {
      const Eigen::Vector3d v_rel = kin.J_distal.template topRows<3>() * qdot;
      distal.v.noalias() += base.R * v_rel;
    }
  }
  if constexpr (nq > 0) {
    // (R J_v + p x R J_w; R J_w): the twist about the world origin.
    jacobian.template bottomRows<3>().noalias() = base.R * kin.J_distal.template bottomRows<3>();
    if constexpr (has_zero_translation<Segment>::value)
      jacobian.template topRows<3>().setZero();
    else
      jacobian.template topRows<3>().noalias() = base.R * kin.J_distal.template topRows<3>();
    for (int j = 0; j < nq; ++j)
      jacobian.col(j).template head<3>() += cross3(distal.p, jacobian.col(j).template tail<3>());
  } else {
    (void)qdot;
    (void)jacobian;
  }
  distal.twist.template head<3>() = distal.v + cross3(distal.p, w);
  distal.twist.template tail<3>() = w;
}

/// \brief A frame's spatial acceleration about the world origin, \f$(a - \alpha\times p -
/// \omega\times v;\ \alpha)\f$ in world axes (gravity in it, as in the RNE's accelerations),
/// from its pose and twist in the world and the RNE's motion in its own axes. Apart from
/// world_frame_step because the frames and composites do not depend on the accelerations
/// (aba_derivatives forms M from them before it knows qddot).
inline Vector6d spatial_acceleration(const FrameInWorld& frame,
                                     const FrameMotion<double>& motion) {
  Vector6d a;
  a.tail<3>() = frame.R * motion.alpha;
  a.head<3>() = frame.R * motion.acc;
  a.head<3>() += cross3(frame.p, a.tail<3>()) - cross3(frame.twist.tail<3>(), frame.v);
  return a;
}

/// \brief The sensitivities (P | R)^T (9 x nq) that the bodies of `c` give coordinates moving
/// them all with the world Jacobian J (6 x nq): \f$(Y J;\ D^T J)\f$, D's zero linear columns
/// dropped.
template <int NQ, class JacobianT>
Eigen::Matrix<double, 9, NQ> sensitivity_of(const SubtreeComposite& c, const JacobianT& J) {
  Eigen::Matrix<double, 9, NQ> out;
  for (int j = 0; j < NQ; ++j) {
    const Eigen::Vector3d lin = J.col(j).template head<3>(), ang = J.col(j).template tail<3>();
    // Y J_j (Y is symmetric), then D^T J_j = 2 p x lin + X^T ang.
    out.col(j).template head<3>() = c.mass * lin - cross3(c.first_moment, ang);
    out.col(j).template segment<3>(3) = cross3(c.first_moment, lin);
    out.col(j).template segment<3>(3).noalias() += c.inertia * ang;
    out.col(j).template tail<3>() = 2.0 * cross3(c.momentum, lin);
    out.col(j).template tail<3>().noalias() += c.velocity.transpose() * ang;
  }
  return out;
}

/// \brief A segment's own bodies (the file comment): their composite (Y, D) into `own`, their
/// share of the segment's sensitivities ((P | R)^T, 9 x nq) into `cols` and of its block of
/// the mass matrix (\f$\sum_m J_m^T Y_m J_m\f$) into `joint`, all from zero.
/// \param[in] load The body load of the RNE at the expansion point (its omega_distal).
template <class Segment, class Qd>
void own_body_composite(const Segment& seg, const typename Segment::Kinematics& kin,
                        const BodyLoad<double>& load, const FrameInWorld& base,
                        const FrameInWorld& distal, const Eigen::MatrixBase<Qd>& qdot,
                        InertiaRate inertia_rate, SubtreeComposite& own,
                        Eigen::Matrix<double, 9, Segment::nq>& cols,
                        Eigen::Matrix<double, Segment::nq, Segment::nq>& joint) {
  using Matrix3 = Eigen::Matrix3d;
  using Vector3 = Eigen::Vector3d;
  constexpr int nq = Segment::nq;
  own = SubtreeComposite{};
  if constexpr (nq > 0) {
    cols.setZero();
    joint.setZero();
  }
  // One rigid body: mass m, centre c_base (base axes), inertia I_c about it (world axes),
  // Jacobians of its centre and angular velocity (base axes), and the rate of its inertia
  // (world axes) if it has one.
  auto add_body = [&](double m, const Vector3& c_base, const Matrix3& I_c, const auto& Jv,
                      const auto& Jw, const Matrix3* rate) {
    SubtreeComposite b;
    const Vector3 c = base.p + base.R * c_base;
    b.mass = m;
    b.first_moment = m * c;
    b.inertia = I_c;
    add_shift(b.inertia, c, Vector3(0.5 * b.first_moment));  // I_O = I_c - m [c]^2
    Vector6d v = base.twist;
    Eigen::Matrix<double, 6, nq> J;
    if constexpr (nq > 0) {
      J.template bottomRows<3>().noalias() = base.R * Jw;
      J.template topRows<3>().noalias() = base.R * Jv;
      for (int j = 0; j < nq; ++j)
        J.col(j).template head<3>() += cross3(c, J.col(j).template tail<3>());
      v.noalias() += J * qdot;
    } else {
      (void)Jv;
      (void)Jw;
    }
    // D (file comment) in closed form: with the momentum p = m v_c and the angular momentum
    // L = I_O w + h x v_O, D = (0, -2[p]; 0, X), X = -[L] + [w] I_O - I_O [w] - [v_O][h] -
    // [h][v_O] (+ I-dot): its linear columns vanish. [a][b] + [b][a] = a b^T + b a^T - 2 a.b 1.
    const Vector3 w = v.tail<3>(), v_O = v.head<3>();
    b.momentum = m * v_O + cross3(w, b.first_moment);
    const Vector3 L = b.inertia * w + cross3(b.first_moment, v_O);
    const Matrix3 WI = skew(w) * b.inertia;
    b.velocity = WI + WI.transpose() - skew(L);
    b.velocity.noalias() -= v_O * b.first_moment.transpose() + b.first_moment * v_O.transpose();
    b.velocity.diagonal().array() += 2.0 * v_O.dot(b.first_moment);
    if (rate) b.velocity += *rate;
    if constexpr (nq > 0) {
      const Eigen::Matrix<double, 9, nq> c_b = sensitivity_of<nq>(b, J);
      cols += c_b;
      joint.noalias() += c_b.template topRows<6>().transpose() * J;
    }
    own.add(b);
  };
  if constexpr (num_sub_bodies<Segment> > 0) {
    (void)seg;
    (void)load;
    (void)distal;
    (void)inertia_rate;
    for (const auto& b : kin.sub_bodies)
      add_body(b.mass, b.r_base_body, rotate_symmetric(base.R, b.inertia), b.J_v, b.J_w, nullptr);
  } else if constexpr (Segment::has_body) {
    const bool rate = nq > 0 && inertia_rate == InertiaRate::Consistent;
    Matrix3 rate_world;
    if (rate) rate_world = rotate_symmetric(distal.R, kin.inertia_rate);
    add_body(seg.mass, kin.r_base_com, rotate_symmetric(distal.R, kin.inertia_com), kin.J_com,
             kin.J_distal.template bottomRows<3>(), rate ? &rate_world : nullptr);
    // E_k: d/dV of -1/2 w^T dI/dq_k w (backward_step), through the angular part.
    if constexpr (nq > 0)
      if (rate)
        for (int k = 0; k < nq; ++k)
          cols.col(k).template tail<3>() -=
              distal.R * (kin.dinertia_dq[static_cast<std::size_t>(k)] * load.omega_distal);
  } else {
    (void)seg;
    (void)kin;
    (void)load;
    (void)distal;
    (void)inertia_rate;
  }
}

/// \brief At the expansion point the RNE left in data (kinematics, and the angular velocities of
/// its motions and loads: none of this depends on qddot): every frame in the world
/// (ws.frames), every frame's SubtreeComposite (ws.subtrees), and every coordinate's Jacobian
/// and sensitivities (ws.jacobian, ws.sensitivity). O(n). With `mass`,
/// also the mass matrix from the same composites (as Pinocchio's computeRNEADerivatives fills
/// M): \f$M_{kj} = P_k J_j\f$ for j in an earlier segment than k (\f$\partial\tau_k/\partial\ddot
/// q_j\f$: a unit \f$\ddot q_j\f$ is \f$\Delta A = J_j\f$), and a segment's own block
/// \f$\sum_m J_m^T Y_m J_m + J^T Y_{crb} J\f$ (its own bodies, then everything beyond it).
/// O(nq^2).
template <class ChainT, class Qd>
void compute_derivative_composites(const ChainT& chain, typename ChainT::Data& data,
                                   const Eigen::MatrixBase<Qd>& qdot,
                                   typename ChainT::MatrixQ* mass) {
  auto& ws = data.derivatives;
  const InertiaRate rate = chain.inertia_rate;
  ws.frames[0] = FrameInWorld{};  // the world: at rest
  chain.forward(data, [&](const auto& seg, const auto& kin, int k, int offset) {
    using Segment = std::decay_t<decltype(seg)>;
    constexpr int n = Segment::nq;
    const auto kk = static_cast<std::size_t>(k);
    world_frame_step<Segment>(kin, ws.frames[kk], data.motion[kk + 1],
                              segment_entries<n>(qdot, offset), ws.frames[kk + 1],
                              ws.jacobian.template middleCols<n>(offset));
  });
  const auto n_seg = static_cast<std::size_t>(data.num_segments());
  ws.subtrees[n_seg] = SubtreeComposite{};
  chain.backward(data, [&](const auto& seg, const auto& kin, int k, int offset) {
    using Segment = std::decay_t<decltype(seg)>;
    constexpr int n = Segment::nq;
    const auto kk = static_cast<std::size_t>(k);
    const SubtreeComposite& beyond = ws.subtrees[kk + 1];
    SubtreeComposite own;
    Eigen::Matrix<double, 9, n> cols;
    Eigen::Matrix<double, n, n> joint;
    own_body_composite(seg, kin, data.loads[kk], ws.frames[kk], ws.frames[kk + 1],
                       segment_entries<n>(qdot, offset), rate, own, cols, joint);
    if constexpr (n > 0) {
      const Eigen::Matrix<double, 6, n> J = ws.jacobian.template middleCols<n>(offset);
      const Eigen::Matrix<double, 9, n> c_beyond = sensitivity_of<n>(beyond, J);
      ws.sensitivity.template middleCols<n>(offset) = cols + c_beyond;
      if (mass) {
        joint.noalias() += c_beyond.template topRows<6>().transpose() * J;
        mass->template block<n, n>(offset, offset) = joint;
      }
    }
    ws.subtrees[kk] = beyond;
    ws.subtrees[kk].add(own);
  });
  if (!mass) return;
  chain.forward(data, [&](const auto& seg, const auto&, int, int offset) {
    constexpr int n = std::decay_t<decltype(seg)>::nq;
    for (int r = offset; r < offset + n; ++r)
      for (int j = 0; j < offset; ++j)
        (*mass)(j, r) = (*mass)(r, j) =
            ws.sensitivity.col(r).template head<6>().dot(ws.jacobian.col(j));
  });
}

}  // namespace detail
}  // namespace softrne
