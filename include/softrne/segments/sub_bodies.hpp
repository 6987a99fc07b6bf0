#pragma once
/// \file
/// \brief Segments whose own mass is several rigid sub-bodies (the quadrature disks of a
/// distributed-inertia CC segment): their kinematics record. Their inertia as the algorithms
/// see it is algorithms/own_inertia.hpp's.

#include <array>
#include <cstddef>

#include <Eigen/Core>

#include "softrne/segments/segment_kinematics.hpp"

namespace softrne {

/// \brief One rigid sub-body of a segment, in the segment's base frame: mass, pose, inertia
/// about its own centre, and the Jacobians of its centre's velocity and of its angular velocity
/// relative to the base frame (with their time derivatives along qdot).
template <class Scalar, int NQ>
struct SubBodyKinematics {
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;  ///< a 3x3 matrix
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;  ///< a 3-vector
  Scalar mass{0};                              ///< kg
  Matrix3 R_base_body = Matrix3::Identity();   ///< the sub-body's orientation
  Vector3 r_base_body = Vector3::Zero();       ///< its centre

  /// About the sub-body's centre, in base axes (\f$R I_{body} R^T\f$).
  Matrix3 inertia = Matrix3::Zero();
  Eigen::Matrix<Scalar, 3, NQ> J_v = Eigen::Matrix<Scalar, 3, NQ>::Zero();  ///< of its centre
  Eigen::Matrix<Scalar, 3, NQ> J_w = Eigen::Matrix<Scalar, 3, NQ>::Zero();  ///< angular
  Vector3 Jdot_qdot_v = Vector3::Zero();  ///< \f$\dot J_v\dot q\f$
  Vector3 Jdot_qdot_w = Vector3::Zero();  ///< \f$\dot J_\omega\dot q\f$
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief Kinematics of a segment whose own mass is NB rigid sub-bodies. The distal-frame
/// fields of the base record are filled as usual; r_base_com, J_com and Jdot_qdot_com hold the
/// mass-weighted mean of the sub-bodies; the lumped inertia fields (inertia_com, dinertia_dq,
/// inertia_rate) stay zero: the algorithms use the sub-bodies instead.
template <class Scalar, int NQ, int NB>
struct MultiBodyKinematics : SegmentKinematics<Scalar, NQ> {
  static_assert(NB > 0, "MultiBodyKinematics needs at least one sub-body");
  static constexpr int num_sub_bodies = NB;  ///< how many sub-bodies

  /// The sub-bodies (for a DistributedInertia CC joint: the quadrature disks).
  std::array<SubBodyKinematics<Scalar, NQ>, static_cast<std::size_t>(NB)> sub_bodies;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

namespace detail {

/// Number of rigid sub-bodies a segment's own mass is made of (0: one lumped body, if any).
template <class Segment>
constexpr int num_sub_bodies = Segment::Kinematics::num_sub_bodies;

}  // namespace detail
}  // namespace softrne
