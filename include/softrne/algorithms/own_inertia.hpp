#pragma once
/// \file
/// \brief The inertia of a segment's own bodies as the articulated-body algorithm sees it.
///
/// A segment's own body need not move rigidly with any frame: a CC joint's centre of mass
/// follows \f$r_c(q)\f$ (eq. 9) while the body turns with the distal frame (eqs. 18-19). What
/// the articulated-body recursion needs from it is the same three blocks a rigid-body joint
/// would give (Featherstone's \f$I_i\f$, \f$I_i S_i\f$, \f$S_i^T I_i S_i\f$), with a "motion
/// subspace" \f$S_b\f$ per sub-body b that is not the distal frame's: column k is the spatial
/// acceleration (at the base origin O, base axes) of body b for \f$\ddot q = e_k\f$ with the
/// base at rest, \f$S_{b,k} = (J_{com,k} - J_{w,k}\times r_c;\; J_{w,k})\f$ (the linear part
/// is the acceleration of the body point that coincides with O). With \f$\mathcal I_b\f$ the
/// body's rigid spatial inertia about O:
/// - spatial = \f$\sum_b \mathcal I_b\f$,
/// - coupling = \f$\sum_b \mathcal I_b S_b\f$; column k = \f$(m J_{com,k};\ I J_{w,k} + r_c
///   \times m J_{com,k})\f$, the body's d'Alembert wrench about O (the RNE's load, eqs.
///   16-18, at zero velocity),
/// - joint = \f$\sum_b S_b^T \mathcal I_b S_b = m J_{com}^T J_{com} + J_w^T I J_w\f$, the
///   body's share of M (what backward_step's power-conjugate projection gives).
///
/// Segments whose own mass is several rigid sub-bodies (the quadrature disks of a
/// distributed-inertia CC segment, segments/sub_bodies.hpp) sum the same blocks over them.

#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "softrne/algorithms/mass_matrix.hpp"
#include "softrne/algorithms/rnea_steps.hpp"
#include "softrne/segments/sub_bodies.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {

/// \brief Own bodies of one segment, about its base-frame origin, base axes, ordering
/// (linear; angular); see the file comment.
template <class Scalar, int NQ>
struct OwnBodyInertia {
  /// Rigid spatial inertia of the own bodies: wrench (f; n_O) = spatial (a_O; alpha) for
  /// motion rigid with the base frame.
  Eigen::Matrix<Scalar, 6, 6> spatial;
  /// Column k: the wrench the own bodies need for qddot = e_k with the base at rest.
  Eigen::Matrix<Scalar, 6, NQ> coupling;
  /// Their joint-space inertia \f$\sum_b S_b^T \mathcal I_b S_b\f$ (their share of M).
  Eigen::Matrix<Scalar, NQ, NQ> joint;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

namespace detail {

/// \brief One rigid body (mass m, centre c, inertia I_c about it in base axes, centre velocity
/// Jacobian Jv and angular Jacobian Jw relative to the base frame) into out.
template <class Scalar, int NQ, class JvT, class JwT>
void one_body_inertia(const Scalar& m, const Eigen::Matrix<Scalar, 3, 1>& c,
                      const Eigen::Matrix<Scalar, 3, 3>& I_c, const JvT& Jv, const JwT& Jw,
                      OwnBodyInertia<Scalar, NQ>& out) {
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  // Rigid spatial inertia about O: f = m (a_O + alpha x c), n_O = I_c alpha + c x f, i.e.
  // [m 1, -m [c]x; m [c]x, I_c - m [c]x^2].
  const Matrix3 mC = m * skew(c);
  out.spatial.template topLeftCorner<3, 3>() = m * Matrix3::Identity();
  out.spatial.template topRightCorner<3, 3>() = -mC;
  out.spatial.template bottomLeftCorner<3, 3>() = mC;
  Matrix3 I_O = I_c;
  add_shift(I_O, c, Vector3(Scalar(0.5) * m * c));  // parallel axis: I_c - m [c]x [c]x
  out.spatial.template bottomRightCorner<3, 3>() = I_O;
  if constexpr (NQ > 0) {
    for (int k = 0; k < NQ; ++k) {
      // The body's d'Alembert wrench about O for qddot = e_k (eqs. 16-18 at rest).
      const Vector3 f = m * Jv.col(k);
      const Vector3 t = I_c * Jw.col(k);
      out.coupling.col(k).template head<3>() = f;
      out.coupling.col(k).template tail<3>() = t + c.cross(f);
      // joint(j, k) = J_v,j . m J_v,k + J_w,j . I_c J_w,k, once per pair (exactly symmetric).
      for (int j = 0; j <= k; ++j) {
        const Scalar s = Jv.col(j).dot(f) + Jw.col(j).dot(t);
        out.joint(j, k) = s;
        out.joint(k, j) = s;
      }
    }
  } else {
    (void)Jv;
    (void)Jw;
  }
}

/// \brief The own body of a segment with `has_body`. Lumped (CC joint, rigid link): mass
/// seg.mass at kin.r_base_com, inertia \f$R I_c R^T\f$ about it (I_c = kin.inertia_com in
/// distal axes, eq. 19), centre of mass moving with J_com (not with the distal frame: eq. 9)
/// and turning with the angular rows of J_distal. Made of sub-bodies (distributed CC joint):
/// the sum over them (sub_body_inertia), each with its own Jacobians.
template <class Segment>
void own_body_inertia(const Segment& seg, const typename Segment::Kinematics& kin,
                      OwnBodyInertia<typename Segment::Scalar, Segment::nq>& out) {
  static_assert(Segment::has_body, "own_body_inertia: the segment has no body");
  using Scalar = typename Segment::Scalar;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  constexpr int n = Segment::nq;
  if constexpr (num_sub_bodies<Segment> > 0) {
    (void)seg;
    SubBodyInertia<Scalar, n> b;
    sub_body_inertia(kin, b);
    const Matrix3 H = skew(b.first_moment);
    out.spatial.template topLeftCorner<3, 3>() = b.mass * Matrix3::Identity();
    out.spatial.template topRightCorner<3, 3>() = -H;
    out.spatial.template bottomLeftCorner<3, 3>() = H;
    out.spatial.template bottomRightCorner<3, 3>() = b.inertia_origin;
    out.coupling.template topRows<3>() = b.force;
    out.coupling.template bottomRows<3>() = b.torque;
    out.joint = b.joint;
  } else {
    // Inertia about the centre of mass in base axes (eq. 18 turns I_c alpha_distal by R).
    Matrix3 I_c;
    if constexpr (has_identity_rotation<Segment>::value)
      I_c = kin.inertia_com;
    else
      I_c = rotate_symmetric(kin.R_base_distal, kin.inertia_com);
    one_body_inertia<Scalar, n>(seg.mass, kin.r_base_com, I_c, kin.J_com,
                                kin.J_distal.template bottomRows<3>(), out);
  }
}

}  // namespace detail
}  // namespace softrne
