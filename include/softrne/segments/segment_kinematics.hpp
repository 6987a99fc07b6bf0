#pragma once
/// \file
/// \brief What one segment hands to the recursive Newton-Euler passes.

#include <array>

#include <Eigen/Core>

namespace softrne {

/// \brief Configuration- and velocity-dependent quantities of one segment, all expressed in
/// the segment's base frame (the parent's distal frame) unless stated otherwise.
///
/// A segment moves its distal frame relative to its base frame through its own coordinates
/// q (NQ of them) and carries at most one lumped body (mass, centre of mass, inertia).
/// Filled by the segment's `calc`; read by the algorithms. Fixed size: no allocation.
template <class Scalar, int NQ>
struct SegmentKinematics {
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;  ///< a 3x3 matrix
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;  ///< a 3-vector
  using Vector6 = Eigen::Matrix<Scalar, 6, 1>;  ///< a 6-vector (linear; angular)

  /// Rigid sub-bodies the own mass is made of (0: one lumped body described below, if any;
  /// see MultiBodyKinematics in sub_bodies.hpp).
  static constexpr int num_sub_bodies = 0;

  /// Orientation of the distal frame in the base frame (paper eq. 2, \f$R^{i-1}_i\f$);
  /// the forward pass maps base-frame vectors to the distal frame with its transpose.
  Matrix3 R_base_distal = Matrix3::Identity();
  Vector3 r_base_distal = Vector3::Zero();  ///< distal-frame origin (eq. 4)
  Vector3 r_base_com = Vector3::Zero();     ///< centre of mass (eq. 9)

  /// Geometric Jacobian of the distal frame: rows 0-2 its origin's linear velocity, rows 3-5
  /// its angular velocity, relative to and in the base frame (eqs. 5-7).
  Eigen::Matrix<Scalar, 6, NQ> J_distal = Eigen::Matrix<Scalar, 6, NQ>::Zero();
  /// \f$\dot J_{distal}\dot q\f$ at the velocity given to calc (eq. 8).
  Vector6 Jdot_qdot_distal = Vector6::Zero();
  /// Linear-velocity Jacobian of the centre of mass, \f$\partial r_c/\partial q\f$.
  Eigen::Matrix<Scalar, 3, NQ> J_com = Eigen::Matrix<Scalar, 3, NQ>::Zero();
  Vector3 Jdot_qdot_com = Vector3::Zero();  ///< \f$\dot J_{com}\dot q\f$ at calc's velocity

  /// Inertia about the centre of mass, in the distal frame (eq. 19); the body is taken to
  /// rotate with the distal frame (the paper's lumped model).
  Matrix3 inertia_com = Matrix3::Zero();
  /// \f$\partial I_c/\partial q_k\f$ in the distal frame (zero for rigid bodies).
  std::array<Matrix3, static_cast<std::size_t>(NQ)> dinertia_dq = zero_matrices();
  /// \f$\dot I_c = \sum_k \partial I_c/\partial q_k\,\dot q_k\f$ at the velocity given to calc.
  Matrix3 inertia_rate = Matrix3::Zero();

  /// \return NQ zero 3x3 matrices (the initial value of dinertia_dq).
  static std::array<Matrix3, static_cast<std::size_t>(NQ)> zero_matrices() {
    std::array<Matrix3, static_cast<std::size_t>(NQ)> a;
    for (auto& m : a) m.setZero();
    return a;
  }

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

}  // namespace softrne
