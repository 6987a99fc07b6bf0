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
/// distributed-inertia CC segment, segments/sub_bodies.hpp) sum the same blocks over them:
/// add_body() is the one place the blocks of a body are written. articulated_body.hpp takes
/// all of them from here, mass_matrix.hpp the sub-bodies' (it folds a lumped body into its
/// composite instead, see there).

#include <type_traits>

#include <Eigen/Core>

#include "softrne/algorithms/rnea_steps.hpp"
#include "softrne/segments/sub_bodies.hpp"
#include "softrne/spatial/inertia_transforms.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {

/// \brief Own bodies of one segment, about its base-frame origin, base axes, ordering
/// (linear; angular); see the file comment.
template <class Scalar, int NQ>
struct OwnBodyInertia {
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;  ///< a 3x3 matrix
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;  ///< a 3-vector
  Scalar mass{0};                               ///< \f$\sum_b m_b\f$, kg
  Vector3 first_moment = Vector3::Zero();       ///< \f$h = \sum_b m_b r_b\f$, kg m
  /// \f$I_O = \sum_b I_b - m_b [r_b]_\times^2\f$, about the base origin, kg m^2.
  Matrix3 inertia_origin = Matrix3::Zero();
  /// Column k: the wrench (force; moment about O) the own bodies need for qddot = e_k with the
  /// base at rest.
  Eigen::Matrix<Scalar, 6, NQ> coupling = Eigen::Matrix<Scalar, 6, NQ>::Zero();
  /// Their joint-space inertia \f$\sum_b S_b^T \mathcal I_b S_b\f$ (their share of M).
  Eigen::Matrix<Scalar, NQ, NQ> joint = Eigen::Matrix<Scalar, NQ, NQ>::Zero();

  /// \return The rigid spatial inertia about O: wrench (f; n_O) = spatial() (a_O; alpha) for
  ///   motion rigid with the base frame.
  Eigen::Matrix<Scalar, 6, 6> spatial() const {
    Eigen::Matrix<Scalar, 6, 6> I;
    const Matrix3 H = skew(first_moment);
    I.template topLeftCorner<3, 3>() = mass * Matrix3::Identity();
    I.template topRightCorner<3, 3>() = -H;
    I.template bottomLeftCorner<3, 3>() = H;
    I.template bottomRightCorner<3, 3>() = inertia_origin;
    return I;
  }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

namespace detail {

/// \brief Adds one rigid body to out: mass m, centre c, inertia I_c about its centre in base
/// axes, centre velocity Jacobian Jv and angular Jacobian Jw relative to the base frame. Fills
/// the upper triangle of out.joint only (own_body_inertia mirrors it once at the end).
template <class Scalar, int NQ, class JvT, class JwT>
void add_body(const Scalar& m, const Eigen::Matrix<Scalar, 3, 1>& c,
              const Eigen::Matrix<Scalar, 3, 3>& I_c, const JvT& Jv, const JwT& Jw,
              OwnBodyInertia<Scalar, NQ>& out) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  // Rigid part about O: f = m (a_O + alpha x c), n_O = I_c alpha + c x f.
  out.mass += m;
  out.first_moment += m * c;
  out.inertia_origin += I_c;
  add_shift(out.inertia_origin, c, Vector3(Scalar(0.5) * m * c));  // parallel axis
  if constexpr (NQ > 0) {
    for (int k = 0; k < NQ; ++k) {
      // The body's d'Alembert wrench about O for qddot = e_k (eqs. 16-18 at rest).
      const Vector3 f = m * Jv.col(k);
      const Vector3 t = I_c * Jw.col(k);
      out.coupling.col(k).template head<3>() += f;
      out.coupling.col(k).template tail<3>() += t + c.cross(f);
      // joint(j, k) = J_v,j . m J_v,k + J_w,j . I_c J_w,k, upper triangle.
      for (int j = 0; j <= k; ++j) out.joint(j, k) += Jv.col(j).dot(f) + Jw.col(j).dot(t);
    }
  } else {
    (void)Jv;
    (void)Jw;
  }
}

/// \brief The own body of a segment with `has_body`, from zero. Lumped (CC joint, rigid link):
/// mass seg.mass at kin.r_base_com, inertia \f$R I_c R^T\f$ about it (I_c = kin.inertia_com in
/// distal axes, eq. 19), centre of mass moving with J_com (not with the distal frame: eq. 9)
/// and turning with the angular rows of J_distal. Made of sub-bodies (distributed CC joint):
/// the sum over them, each with its own Jacobians. out.joint is exactly symmetric.
template <class Segment>
void own_body_inertia(const Segment& seg, const typename Segment::Kinematics& kin,
                      OwnBodyInertia<typename Segment::Scalar, Segment::nq>& out) {
  static_assert(Segment::has_body, "own_body_inertia: the segment has no body");
  using Scalar = typename Segment::Scalar;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  constexpr int n = Segment::nq;
  out = OwnBodyInertia<Scalar, n>();
  if constexpr (num_sub_bodies<Segment> > 0) {
    (void)seg;
    for (const auto& b : kin.sub_bodies) add_body<Scalar, n>(b.mass, b.r_base_body, b.inertia, b.J_v, b.J_w, out);
  } else {
    // Inertia about the centre of mass in base axes (eq. 18 turns I_c alpha_distal by R).
    Matrix3 I_c;
    if constexpr (has_identity_rotation<Segment>::value)
      I_c = kin.inertia_com;
    else
      I_c = rotate_symmetric(kin.R_base_distal, kin.inertia_com);
    add_body<Scalar, n>(seg.mass, kin.r_base_com, I_c, kin.J_com, kin.J_distal.template bottomRows<3>(), out);
  }
  if constexpr (n > 1)
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < k; ++j) out.joint(k, j) = out.joint(j, k);
}

}  // namespace detail
}  // namespace softrne
