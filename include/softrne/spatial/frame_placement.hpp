#pragma once
/// \file
/// \brief A segment's distal frame placed in its base frame, and what the recursions move
/// across it: directions, points' accelerations, wrenches, rigid and articulated inertias.
///
/// \f$p_{base} = R\,p_{distal} + r\f$ (R = SegmentKinematics::R_base_distal, r =
/// r_base_distal). Segments whose R is the identity by construction (rigid links) or whose r
/// is zero by construction (revolute joints) say so in their own type (`identity_rotation`,
/// `zero_translation`; detail::placement_of reads them), and the placement skips
/// the product or the shift: the shortcuts live here, once, instead of at each site of
/// rnea_steps.hpp, mass_matrix.hpp and articulated_body.hpp (as Pinocchio's transform types
/// carry their own fast paths). With the flags on, every operation is the plain formula; the
/// shortcuts give bit-identical results (a product by the identity, a zero cross product).
/// A segment whose R may turn about a coordinate axis (a revolute joint about x, y or z) says
/// which in its kinematics (`coordinate_axis`), and the products with R skip its zeros
/// (spatial/axis_rotation.hpp): vectors bit-identical, inertias equal to rounding.
///
/// Conventions (those of the RNE's backward step, eqs. 16-17): a wrench (f; n) is a force and
/// a torque about a point; an inertia is kept as mass m, first moment h (about the origin)
/// and the 3x3 inertia about the origin, or as an articulated inertia in 3x3 blocks
/// [A B; B^T C] acting on (linear acceleration of the origin; angular acceleration).

#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "softrne/chain/motion.hpp"
#include "softrne/config.hpp"
#include "softrne/spatial/axis_rotation.hpp"
#include "softrne/spatial/inertia_transforms.hpp"

namespace softrne {

/// \brief A rigid composite: mass, first moment \f$h = \sum m_b r_b\f$ and inertia about the
/// origin of the frame it is expressed in.
template <class Scalar>
struct RigidInertia {
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;  ///< a 3x3 matrix
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;  ///< a 3-vector
  Scalar mass{0};                                ///< kg
  Vector3 first_moment = Vector3::Zero();        ///< kg m
  Matrix3 inertia = Matrix3::Zero();             ///< about the origin, kg m^2
};

/// \brief A symmetric 6x6 articulated-body inertia [A B; B^T C] in 3x3 blocks (A, C
/// symmetric), acting on (linear acceleration of the origin; angular acceleration).
template <class Scalar>
struct ArticulatedInertia {
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;  ///< a 3x3 matrix
  Matrix3 A = Matrix3::Zero();                   ///< force per linear acceleration
  Matrix3 B = Matrix3::Zero();                   ///< force per angular acceleration
  Matrix3 C = Matrix3::Zero();                   ///< torque per angular acceleration
};

namespace detail {

/// \brief \f$[r]_\times M\f$: r x each column of M (18 multiplications instead of 27).
template <class Scalar>
Eigen::Matrix<Scalar, 3, 3> cross_columns(const Eigen::Matrix<Scalar, 3, 1>& r,
                                          const Eigen::Matrix<Scalar, 3, 3>& M) {
  Eigen::Matrix<Scalar, 3, 3> out;
  for (int j = 0; j < 3; ++j) {
    out(0, j) = r(1) * M(2, j) - r(2) * M(1, j);
    out(1, j) = r(2) * M(0, j) - r(0) * M(2, j);
    out(2, j) = r(0) * M(1, j) - r(1) * M(0, j);
  }
  return out;
}

/// \brief \f$R v\f$ for a 3x3 R, written out and always inlined. The recursions' hot 3x3
/// products must not depend on the compiler's inlining budget for the whole translation
/// unit: with Eigen's product expression, GCC 12 stopped inlining the product's assignment
/// loop in the benchmark binary once this layer added call sites (callgrind: rnea of the
/// paper's arm 7 218 -> 7 498 instructions per call, the products out of line).
template <class Scalar, class V>
EIGEN_ALWAYS_INLINE Eigen::Matrix<Scalar, 3, 1> times(const Eigen::Matrix<Scalar, 3, 3>& R,
                                                      const Eigen::MatrixBase<V>& v) {
  return Eigen::Matrix<Scalar, 3, 1>(R(0, 0) * v(0) + R(0, 1) * v(1) + R(0, 2) * v(2),
                                     R(1, 0) * v(0) + R(1, 1) * v(1) + R(1, 2) * v(2),
                                     R(2, 0) * v(0) + R(2, 1) * v(1) + R(2, 2) * v(2));
}

/// \brief \f$R^T v\f$ for a 3x3 R, written out and always inlined (see times()).
template <class Scalar, class V>
EIGEN_ALWAYS_INLINE Eigen::Matrix<Scalar, 3, 1> transpose_times(const Eigen::Matrix<Scalar, 3, 3>& R,
                                                                const Eigen::MatrixBase<V>& v) {
  return Eigen::Matrix<Scalar, 3, 1>(R(0, 0) * v(0) + R(1, 0) * v(1) + R(2, 0) * v(2),
                                     R(0, 1) * v(0) + R(1, 1) * v(1) + R(2, 1) * v(2),
                                     R(0, 2) * v(0) + R(1, 2) * v(1) + R(2, 2) * v(2));
}

}  // namespace detail

/// \brief The placement (R, r) of a distal frame in its base frame (see the file comment).
/// Holds references to the kinematics it was made from. Its vector operations are always
/// inlined: a placement must cost what the hand-written products cost (see detail::times()).
/// \tparam Turns false if R is the identity by construction.
/// \tparam Shifts false if r is zero by construction.
/// \tparam AxisFastPath true if R may be a rotation about a coordinate axis, given at
///   construction (spatial/axis_rotation.hpp): its products with vectors and inertias then
///   skip R's zeros.
template <class Scalar, bool Turns = true, bool Shifts = true, bool AxisFastPath = false>
class FramePlacement {
 public:
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;  ///< a 3x3 matrix
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;  ///< a 3-vector
  static constexpr bool turns = Turns;          ///< R is not the identity by construction
  static constexpr bool shifts = Shifts;        ///< r is not zero by construction

  /// \param[in] R The distal axes in base axes (kept by reference).
  /// \param[in] r The distal origin in the base frame (kept by reference).
  /// \param[in] coordinate_axis k if R is a rotation about base axis k (0, 1, 2), else -1;
  ///   only read with AxisFastPath.
  FramePlacement(const Matrix3& R, const Vector3& r, int coordinate_axis = -1)
      : R_(R), r_(r), axis_(coordinate_axis) {}

  /// \return R.
  const Matrix3& rotation() const { return R_; }
  /// \return r.
  const Vector3& translation() const { return r_; }

  /// \brief A direction from distal axes into base axes.
  /// \param[in] v A 3-vector in distal axes.
  /// \return R v.
  template <class V>
  EIGEN_ALWAYS_INLINE Vector3 rotate(const Eigen::MatrixBase<V>& v) const {
    if constexpr (AxisFastPath) {
      if (axis_ >= 0)
        return detail::with_axis(axis_, [&](auto k) SOFTRNE_LAMBDA_INLINE {
          return detail::times_about_axis<k()>(R_, v);
        });
    }
    if constexpr (Turns) return detail::times(R_, v); else return v;
  }

  /// \brief A direction from base axes into distal axes.
  /// \param[in] v A 3-vector in base axes.
  /// \return R^T v.
  template <class V>
  EIGEN_ALWAYS_INLINE Vector3 rotate_back(const Eigen::MatrixBase<V>& v) const {
    if constexpr (AxisFastPath) {
      if (axis_ >= 0)
        return detail::with_axis(axis_, [&](auto k) SOFTRNE_LAMBDA_INLINE {
          return detail::times_about_axis<k(), true>(R_, v);
        });
    }
    if constexpr (Turns) return detail::transpose_times(R_, v); else return v;
  }

  /// \brief The acceleration of the point at the distal origin, rigid with the base frame
  /// (eq. 15 without the relative terms), base axes.
  /// \param[in] acc The base origin's acceleration (base axes).
  /// \param[in] omega The base frame's angular velocity (base axes).
  /// \param[in] alpha The base frame's angular acceleration (base axes).
  /// \param[in] velocity_terms false drops the centripetal term.
  /// \return acc + alpha x r + omega x (omega x r).
  EIGEN_ALWAYS_INLINE Vector3 point_acceleration(const Vector3& acc, const Vector3& omega, const Vector3& alpha,
                             bool velocity_terms) const {
    if constexpr (Shifts) {
      Vector3 a = acc + alpha.cross(r_);
      if (velocity_terms) a += omega.cross(omega.cross(r_));
      return a;
    } else {
      (void)omega;
      (void)alpha;
      (void)velocity_terms;
      return acc;
    }
  }

  /// \brief The same without velocity terms (the base frame at rest).
  /// \param[in] acc The base origin's acceleration (base axes).
  /// \param[in] alpha The base frame's angular acceleration (base axes).
  /// \return acc + alpha x r.
  EIGEN_ALWAYS_INLINE Vector3 point_acceleration(const Vector3& acc, const Vector3& alpha) const {
    if constexpr (Shifts) return acc + alpha.cross(r_); else { (void)alpha; return acc; }
  }

  /// \brief A torque about the distal origin made about the base origin (base axes).
  /// \param[in] n The torque about the distal origin.
  /// \param[in] f The force applied at the distal origin.
  /// \return n + r x f.
  EIGEN_ALWAYS_INLINE Vector3 shift_torque(const Vector3& n, const Vector3& f) const {
    if constexpr (Shifts) return n + r_.cross(f); else { (void)f; return n; }
  }

  /// \brief A wrench about the distal origin: its axes into the base's (the point stays).
  /// \param[in] w The wrench in distal axes.
  /// \return (R f; R n).
  EIGEN_ALWAYS_INLINE Wrench<Scalar> rotate(const Wrench<Scalar>& w) const {
    return {rotate(w.force), rotate(w.torque)};
  }

  /// \brief A wrench about the distal origin in base axes, about the base origin instead.
  /// \param[in] w The wrench (base axes, about the distal origin).
  /// \return (f; n + r x f).
  EIGEN_ALWAYS_INLINE Wrench<Scalar> shift_to_base(const Wrench<Scalar>& w) const {
    return {w.force, shift_torque(w.torque, w.force)};
  }

  /// \brief A rigid inertia about the distal origin: its axes into the base's (about the same
  /// origin): h -> R h, I -> R I R^T.
  /// \param[in,out] I The inertia, turned in place.
  EIGEN_ALWAYS_INLINE void rotate(RigidInertia<Scalar>& I) const {
    if constexpr (Turns) {
      I.first_moment = rotate(I.first_moment);
      I.inertia = rotate_symmetric(I.inertia);
    }
  }

  /// \brief A symmetric 3x3 tensor from distal axes into base axes.
  /// \param[in] A Symmetric, in distal axes.
  /// \return R A R^T, exactly symmetric.
  EIGEN_ALWAYS_INLINE Matrix3 rotate_symmetric(const Matrix3& A) const {
    if constexpr (AxisFastPath) {
      if (axis_ >= 0)
        return detail::with_axis(axis_, [&](auto k) SOFTRNE_LAMBDA_INLINE {
          return detail::rotate_symmetric_about_axis<k()>(R_, A);
        });
    }
    if constexpr (Turns) return detail::rotate_symmetric(R_, A); else return A;
  }

  /// \brief A rigid inertia about the distal origin in base axes, about the base origin
  /// instead (parallel axes: its bodies at rho sit at rho + r).
  /// \param[in,out] I The inertia, moved in place.
  EIGEN_ALWAYS_INLINE void shift_to_base(RigidInertia<Scalar>& I) const {
    if constexpr (Shifts) {
      detail::add_shift(I.inertia, r_, Vector3(I.first_moment + Scalar(0.5) * I.mass * r_));
      I.first_moment += I.mass * r_;
    }
  }

  /// \brief An articulated inertia about the distal origin, distal axes, about the base
  /// origin in base axes: \f$X^T I X\f$ with \f$X = [1, -E; 0, 1]\f$, \f$E = [r]_\times\f$ after
  /// the rotation diag(R, R) I diag(R, R)^T. A' = A, B' = B - A E, C' = C + E B + (E B)^T -
  /// E A E; E M is r x each column of M, and A E = -(E A)^T for symmetric A.
  /// \param[in,out] I The articulated inertia, moved in place (A and C stay exactly
  ///   symmetric).
  void to_base(ArticulatedInertia<Scalar>& I) const {
    if constexpr (Turns) {
      I.A = rotate_symmetric(I.A);
      I.C = rotate_symmetric(I.C);
      const Matrix3 BRt = I.B * R_.transpose();
      I.B.noalias() = R_ * BRt;
    }
    if constexpr (Shifts) {
      const Matrix3 EA = detail::cross_columns(r_, I.A);
      const Matrix3 EB = detail::cross_columns(r_, I.B);
      const Matrix3 EAE = detail::cross_columns(r_, Matrix3(-EA.transpose()));
      for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j) {
          const Scalar v = I.C(i, j) + EB(i, j) + EB(j, i) - EAE(i, j);
          I.C(i, j) = v;
          I.C(j, i) = v;
        }
      I.B += EA.transpose();
    }
  }

 private:
  const Matrix3& R_;
  const Vector3& r_;
  int axis_;  // k if R turns about base axis k, else -1 (read with AxisFastPath only)
};

namespace detail {

/// \brief true if Segment declares `static constexpr bool identity_rotation = true`: its distal
/// frame is never rotated relative to its base (R_base_distal is the identity by
/// construction, as for a rigid link), so placements skip multiplying by it.
template <class Segment, class = void>
struct has_identity_rotation : std::false_type {};
template <class Segment>
struct has_identity_rotation<Segment, std::void_t<decltype(Segment::identity_rotation)>>
    : std::bool_constant<Segment::identity_rotation> {};

/// \brief true if Segment declares `static constexpr bool zero_translation = true`: its distal
/// origin is its base origin (r_base_distal = 0 by construction, as for a revolute joint, so
/// the linear rows of J_distal and of Jdot_qdot_distal are zero too).
template <class Segment, class = void>
struct has_zero_translation : std::false_type {};
template <class Segment>
struct has_zero_translation<Segment, std::void_t<decltype(Segment::zero_translation)>>
    : std::bool_constant<Segment::zero_translation> {};

/// \brief true if Segment's kinematics say whether R turns about a coordinate axis (a field
/// `int coordinate_axis`, k or -1, as RevoluteKinematics has): placements then take the fast
/// path of spatial/axis_rotation.hpp when it does.
template <class Segment, class = void>
struct has_coordinate_axis : std::false_type {};
template <class Segment>
struct has_coordinate_axis<
    Segment, std::void_t<decltype(std::declval<typename Segment::Kinematics>().coordinate_axis)>>
    : std::true_type {};

/// \brief The placement of a segment's distal frame in its base frame, with the shortcuts its
/// type declares. Refers to kin.
template <class Segment>
FramePlacement<typename Segment::Scalar, !has_identity_rotation<Segment>::value,
               !has_zero_translation<Segment>::value, has_coordinate_axis<Segment>::value>
placement_of(const typename Segment::Kinematics& kin) {
  if constexpr (has_coordinate_axis<Segment>::value)
    return {kin.R_base_distal, kin.r_base_distal, kin.coordinate_axis};
  else
    return {kin.R_base_distal, kin.r_base_distal};
}

}  // namespace detail

}  // namespace softrne
