#pragma once
/// \file
/// \brief Massless revolute joint about a unit axis at the base-frame origin.

#include <cmath>

#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/segments/segment_kinematics.hpp"
#include "softrne/spatial/axis_rotation.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {

/// \brief A revolute joint's kinematics: the common record, plus which coordinate axis (if
/// any) it turns about, for the placements' fast path (spatial/axis_rotation.hpp).
template <class Scalar>
struct RevoluteKinematics : SegmentKinematics<Scalar, 1> {
  /// k if the axis is exactly base axis k (0, 1, 2; R then has R(k, k) = 1 and zeros in the
  /// rest of row and column k), -1 for any other axis.
  int coordinate_axis = -1;
};

/// \brief One coordinate q: rotation by q about `axis` (unit, base frame) at the origin; the
/// distal frame origin coincides with the base one. Massless: mass comes from the links
/// around it (formats.md, `revolute_joint`).
template <class Scalar_>
struct RevoluteJoint {
  using Scalar = Scalar_;                 ///< double, long double or an AutoDiff type
  static constexpr int nq = 1;            ///< the joint angle
  static constexpr bool has_body = false; ///< massless
  /// r_base_distal = 0 by construction: placements skip the shift (spatial/frame_placement.hpp;
  /// the conformance suite checks it).
  static constexpr bool zero_translation = true;
  /// The distal frame turns by q about the constant axis J_distal (its angular rows) through
  /// the base origin, a rigid rotation of everything beyond it: the derivatives differentiate
  /// it in closed form, without AutoDiff (algorithms/derivatives.hpp; it takes the axis as unit,
  /// as the robot file must give it).
  static constexpr bool fixed_axis = true;
  using Kinematics = RevoluteKinematics<Scalar>;  ///< what calc() fills
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;    ///< a 3-vector
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;    ///< a 3x3 matrix

  Vector3 axis = Vector3::UnitZ();  ///< rotation axis, unit, in the base frame
  Scalar stiffness{0};  ///< N m/rad
  Scalar damping{0};    ///< N m s/rad
  Scalar mass{0};       ///< always zero; present so every segment answers `mass`

  /// \brief The joint's spring and damper, \f$-k q - d \dot q\f$ (eq. 23's K_spring, K_d).
  /// \param[in] q The joint angle, rad.
  /// \param[in] qdot Its rate, rad/s.
  /// \return The generalised force, N m.
  template <class Q, class Qd>
  Eigen::Matrix<Scalar, 1, 1> passive_force(const Eigen::MatrixBase<Q>& q,
                                            const Eigen::MatrixBase<Qd>& qdot) const {
    return Eigen::Matrix<Scalar, 1, 1>(-(stiffness * q(0) + damping * qdot(0)));
  }

  /// \return 0: no pressure inputs.
  int num_inputs() const { return 0; }

  /// \brief Fills kin for the angle q: the rotation about axis (Rodrigues; about x, y or z
  /// with exact zeros, and kin.coordinate_axis says which), a constant Jacobian (angular part
  /// = axis) and a zero Jacobian rate. Always inlined: small, and called once per joint by
  /// every algorithm (a runtime chain's visit otherwise left it out of line).
  /// \param[in] q The joint angle, rad (the velocity is not needed).
  /// \param[out] kin The segment's kinematics.
  template <class Q, class Qd>
  EIGEN_ALWAYS_INLINE void calc(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>&,
                                Kinematics& kin) const {
    using std::cos;
    using std::sin;
    const Scalar c = cos(q(0)), s = sin(q(0));
    // Constant Jacobian (J_v = 0: the origin does not move); its rate is zero.
    kin.J_distal.template topRows<3>().setZero();
    kin.J_distal.template bottomRows<3>() = axis;
    kin.coordinate_axis = coordinate_axis();
    if (kin.coordinate_axis >= 0) {  // about x, y or z: R turns one plane (i, j)
      detail::with_axis(kin.coordinate_axis, [&](auto k) SOFTRNE_LAMBDA_INLINE {
        constexpr int i = detail::AxisPlane<k()>::I, j = detail::AxisPlane<k()>::J;
        Matrix3& R = kin.R_base_distal;
        R.setIdentity();
        R(i, i) = c;
        R(j, j) = c;
        R(j, i) = s;
        R(i, j) = -s;
      });
      return;
    }
    // Rodrigues, R = I + s K + (1 - c) K^2 with K = [a]x, K^2 = a a^T - |a|^2 I, written per
    // component (no 3x3 product; same formula, so a non-unit axis gives what it gave before).
    const Scalar x = axis(0), y = axis(1), z = axis(2);
    const Scalar t = Scalar(1) - c;
    const Scalar txy = t * x * y, txz = t * x * z, tyz = t * y * z;
    const Scalar sx = s * x, sy = s * y, sz = s * z;
    Matrix3& R = kin.R_base_distal;
    R(0, 0) = Scalar(1) - t * (y * y + z * z);
    R(1, 0) = txy + sz;
    R(2, 0) = txz - sy;
    R(0, 1) = txy - sz;
    R(1, 1) = Scalar(1) - t * (x * x + z * z);
    R(2, 1) = tyz + sx;
    R(0, 2) = txz + sy;
    R(1, 2) = tyz - sx;
    R(2, 2) = Scalar(1) - t * (x * x + y * y);
  }

  /// \return k if axis is exactly the unit vector of base axis k (0, 1, 2), else -1.
  int coordinate_axis() const {
    const Scalar zero(0), one(1);
    if (axis(0) == zero && axis(1) == zero) return axis(2) == one ? 2 : -1;
    if (axis(2) == zero && axis(0) == zero) return axis(1) == one ? 1 : -1;
    if (axis(1) == zero && axis(2) == zero) return axis(0) == one ? 0 : -1;
    return -1;
  }

  /// \brief The same joint in another scalar type.
  /// \tparam NewScalar The new scalar type.
  /// \return A copy with every constant converted.
  template <class NewScalar>
  RevoluteJoint<NewScalar> cast() const {
    RevoluteJoint<NewScalar> j;
    j.axis = axis.template cast<NewScalar>();
    j.stiffness = NewScalar(stiffness);
    j.damping = NewScalar(damping);
    return j;
  }
};

}  // namespace softrne
