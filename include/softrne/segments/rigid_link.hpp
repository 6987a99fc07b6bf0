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
  using Scalar = Scalar_;
  static constexpr int nq = 0;
  static constexpr bool has_body = true;
  using Kinematics = SegmentKinematics<Scalar, nq>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;

  Scalar mass{1};
  Scalar length{0};
  Vector3 com = Vector3::Zero();
  Matrix3 inertia = Matrix3::Zero();  ///< about the centre of mass, in the link frame

  int num_inputs() const { return 0; }

  template <class Q, class Qd>
  Eigen::Matrix<Scalar, 0, 1> passive_force(const Eigen::MatrixBase<Q>&,
                                            const Eigen::MatrixBase<Qd>&) const {
    return {};
  }

  /// The kinematics do not depend on q: calc only writes the constant fields.
  template <class Q, class Qd>
  void calc(const Eigen::MatrixBase<Q>&, const Eigen::MatrixBase<Qd>&, Kinematics& kin) const {
    kin.R_base_distal.setIdentity();
    kin.r_base_distal = Vector3(Scalar(0), Scalar(0), length);
    kin.r_base_com = com;
    kin.inertia_com = inertia;
  }

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
