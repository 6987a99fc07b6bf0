#pragma once
/// \file
/// \brief Segments whose own mass is several rigid sub-bodies (the quadrature disks of a
/// distributed-inertia CC segment): their kinematics record and their composite inertia.

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

/// \brief The own sub-bodies of one segment as the composite-inertia sweeps see them, about
/// the segment's base origin, base axes.
template <class Scalar, int NQ>
struct SubBodyInertia {
  Scalar mass{0};
  Eigen::Matrix<Scalar, 3, 1> first_moment;     ///< \f$\sum_b m_b r_b\f$
  Eigen::Matrix<Scalar, 3, 3> inertia_origin;   ///< \f$\sum_b I_b - m_b [r_b]_\times^2\f$
  Eigen::Matrix<Scalar, 3, NQ> force;           ///< column k: \f$\sum_b m_b J_{v,b,k}\f$
  Eigen::Matrix<Scalar, 3, NQ> torque;          ///< column k: about the base origin
  Eigen::Matrix<Scalar, NQ, NQ> joint;          ///< \f$\sum_b m_b J_v^T J_v + J_w^T I_b J_w\f$
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief Sums the sub-bodies: rigid composite (mass, first moment, inertia about the base
/// origin), the d'Alembert wrench about the base origin for qddot = e_k (base at rest, no
/// velocity), and the joint-space inertia (each pair once: exactly symmetric).
template <class Scalar, int NQ, int NB>
void sub_body_inertia(const MultiBodyKinematics<Scalar, NQ, NB>& kin,
                      SubBodyInertia<Scalar, NQ>& out) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  out.mass = Scalar(0);
  out.first_moment.setZero();
  out.inertia_origin.setZero();
  out.force.setZero();
  out.torque.setZero();
  out.joint.setZero();
  for (const auto& b : kin.sub_bodies) {
    const Vector3& r = b.r_base_body;
    out.mass += b.mass;
    out.first_moment += b.mass * r;
    // I_b - m [r]x^2 = I_b + m (|r|^2 1 - r r^T)
    const Scalar rr = r.squaredNorm();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        out.inertia_origin(i, j) += b.inertia(i, j) - b.mass * r(i) * r(j) + (i == j ? b.mass * rr : Scalar(0));
    for (int k = 0; k < NQ; ++k) {
      const Vector3 f = b.mass * b.J_v.col(k);
      const Vector3 t = b.inertia * b.J_w.col(k);
      out.force.col(k) += f;
      out.torque.col(k) += t + r.cross(f);
      for (int j = 0; j <= k; ++j) out.joint(j, k) += b.J_v.col(j).dot(f) + b.J_w.col(j).dot(t);
    }
  }
  for (int k = 0; k < NQ; ++k)
    for (int j = 0; j < k; ++j) out.joint(k, j) = out.joint(j, k);
}

}  // namespace detail
}  // namespace softrne
