#pragma once
/// \file
/// \brief Rigid link: a body fixed to its base frame, distal frame translated along z.

#include <Eigen/Core>

#include "softrne/segments/segment_kinematics.hpp"

namespace softrne {

/// \brief A rigid body fixed to the previous segment's distal frame (formats.md, `rigid_link`):
/// centre of mass `com` and inertia about it in that frame; its distal frame is translated by
/// (0, 0, length), not rotated. No coordinates, so its Jacobians are empty (paper eq. 10).
template <class Scalar_>
struct RigidLink {
  using Scalar = Scalar_;                 ///< double, long double or an AutoDiff type
  static constexpr int nq = 0;            ///< no coordinates
  static constexpr bool has_body = true;  ///< it carries mass
  /// R_base_distal is the identity by construction: placements skip the product
  /// (spatial/frame_placement.hpp; the conformance suite checks it).
  static constexpr bool identity_rotation = true;
  using Kinematics = SegmentKinematics<Scalar, nq>;  ///< what calc() fills
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;       ///< a 3-vector
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;       ///< a 3x3 matrix

  Scalar mass{1};                 ///< m, kg
  Scalar length{0};               ///< distal frame at (0, 0, length) in the base frame, m
  Vector3 com = Vector3::Zero();  ///< centre of mass in the link (base) frame, m
  Matrix3 inertia = Matrix3::Zero();  ///< about the centre of mass, in the link frame

  /// \return 0: no pressure inputs.
  int num_inputs() const { return 0; }

  /// \brief No coordinates, so no spring or damper force.
  /// \return An empty vector.
  template <class Q, class Qd>
  Eigen::Matrix<Scalar, 0, 1> passive_force(const Eigen::MatrixBase<Q>&,
                                            const Eigen::MatrixBase<Qd>&) const {
    return {};
  }

  /// \brief The kinematics do not depend on q: calc only writes the constant fields (the
  /// relative motion is zero, eq. 10).
  /// \param[out] kin The segment's kinematics.
  template <class Q, class Qd>
  void calc(const Eigen::MatrixBase<Q>&, const Eigen::MatrixBase<Qd>&, Kinematics& kin) const {
    kin.R_base_distal.setIdentity();
    kin.r_base_distal = Vector3(Scalar(0), Scalar(0), length);
    kin.r_base_com = com;
    kin.inertia_com = inertia;
  }

  /// \brief The same link in another scalar type.
  /// \tparam NewScalar The new scalar type.
  /// \return A copy with every constant converted.
  template <class NewScalar>
  RigidLink<NewScalar> cast() const {
    RigidLink<NewScalar> l;
    l.mass = NewScalar(mass);
    l.length = NewScalar(length);
    l.com = com.template cast<NewScalar>();
    l.inertia = inertia.template cast<NewScalar>();
    return l;
  }
};

}  // namespace softrne
