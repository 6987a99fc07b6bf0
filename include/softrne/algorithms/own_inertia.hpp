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
/// Segments with several sub-bodies (a distributed-inertia CC segment) overload
/// `detail::own_body_inertia` for their type (one_body_inertia below is one body), declared in
/// their own header so that it is visible (through segment_list.hpp) before the definitions of
/// algorithms/articulated_body.hpp; the generic function refuses kinematics with sub-bodies.

#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "softrne/algorithms/mass_matrix.hpp"
#include "softrne/algorithms/rnea_steps.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {

/// \brief Own bodies of one segment, about its base-frame origin, base axes, ordering
/// (linear; angular); see the file comment.
template <class Scalar, int NQ>
struct OwnBodyInertia {
  Eigen::Matrix<Scalar, 6, 6> spatial;   // own bodies' rigid spatial inertia about the base origin, base axes, (linear; angular): wrench (f; n_O) = spatial * (a_O; alpha) for motion rigid with the base frame
  Eigen::Matrix<Scalar, 6, NQ> coupling; // column k: wrench about the base origin the own bodies need for qddot = e_k with the base at rest
  Eigen::Matrix<Scalar, NQ, NQ> joint;   // their joint-space inertia  sum_b S_b^T I_b S_b
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

namespace detail {

/// Kinematics records that list rigid sub-bodies (`sub_bodies`).
template <class Kin, class = void>
struct has_sub_bodies : std::false_type {};
template <class Kin>
struct has_sub_bodies<Kin, std::void_t<decltype(std::declval<const Kin&>().sub_bodies)>>
    : std::true_type {};

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

/// \brief The lumped own body of a segment with `has_body` (CC joint, rigid link): mass
/// seg.mass at kin.r_base_com, inertia \f$R I_c R^T\f$ about it (I_c = kin.inertia_com in
/// distal axes, eq. 19), centre of mass moving with J_com (not with the distal frame: eq. 9)
/// and turning with the angular rows of J_distal.
template <class Segment>
void own_body_inertia(const Segment& seg, const typename Segment::Kinematics& kin,
                      OwnBodyInertia<typename Segment::Scalar, Segment::nq>& out) {
  static_assert(Segment::has_body, "own_body_inertia: the segment has no body");
  using Scalar = typename Segment::Scalar;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  constexpr int n = Segment::nq;
  // The lumped fields of a kinematics record with sub-bodies are not its inertia: such a
  // segment must bring its own overload (declared before articulated_body.hpp's definitions).
  static_assert(!has_sub_bodies<typename Segment::Kinematics>::value,
                "own_body_inertia: a segment made of sub-bodies needs its own overload");
  // Inertia about the centre of mass in base axes (eq. 18 turns I_c alpha_distal by R).
  Matrix3 I_c;
  if constexpr (has_identity_rotation<Segment>::value)
    I_c = kin.inertia_com;
  else
    I_c = rotate_symmetric(kin.R_base_distal, kin.inertia_com);
  one_body_inertia<Scalar, n>(seg.mass, kin.r_base_com, I_c, kin.J_com,
                              kin.J_distal.template bottomRows<3>(), out);
}

}  // namespace detail
}  // namespace softrne
