#pragma once
/// \file
/// \brief Per-frame motion and wrench records of the recursive Newton-Euler passes.

#include <Eigen/Core>

namespace softrne {

/// \brief Angular velocity, angular acceleration and linear acceleration of a frame's origin,
/// expressed in that frame (paper eqs. 11, 12, 15). Gravity enters as a base acceleration
/// of \f$-g\f$, so `acc` is the acceleration minus gravity.
template <class Scalar>
struct FrameMotion {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;  ///< a 3-vector of the scalar type
  Vector3 omega = Vector3::Zero();  ///< angular velocity \f$\omega_i^i\f$ (eq. 11)
  Vector3 alpha = Vector3::Zero();  ///< angular acceleration \f$\alpha_i^i\f$ (eq. 12)
  Vector3 acc = Vector3::Zero();    ///< linear acceleration of the origin \f$a_{e,i}^i\f$ (eq. 15)
};

/// \brief A force and a torque about a point, in some frame.
template <class Scalar>
struct Wrench {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;  ///< a 3-vector of the scalar type
  Vector3 force = Vector3::Zero();   ///< force \f$f\f$ (eq. 16)
  Vector3 torque = Vector3::Zero();  ///< torque \f$\tau\f$ about the point (eq. 17)
};

/// \brief The d'Alembert load of one segment's own body, in its base frame: force at the
/// centre of mass (\f$m a_c\f$, eq. 16) and torque about it (eq. 18), plus the body's angular
/// velocity in the distal frame (for the \f$\partial I/\partial q\f$ term).
template <class Scalar>
struct BodyLoad {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;  ///< a 3-vector of the scalar type
  Vector3 force = Vector3::Zero();         ///< \f$m a_c\f$ less gravity (eq. 16)
  Vector3 torque = Vector3::Zero();        ///< \f$\dot H\f$ about the centre of mass (eq. 18)
  Vector3 omega_distal = Vector3::Zero();  ///< the body's angular velocity, distal frame

  /// Segments made of sub-bodies only (distributed-inertia CC joint): `torque` is about the
  /// base origin instead, and the first nq entries here are the sub-bodies' loads projected
  /// on the segment's coordinates with their own Jacobians (omega_distal is unused).
  Vector3 tau_sub_bodies = Vector3::Zero();
};

/// \brief How the rate of change of a CC segment's configuration-dependent inertia enters.
enum class InertiaRate {
  /// Euler-Lagrange of the lumped energy: adds \f$\dot I\omega\f$ to the body torque and
  /// \f$-\tfrac12\omega^T(\partial I/\partial q_k)\omega\f$ on the segment's own coordinates.
  Consistent,
  /// The paper's eq. 18: the segment is frozen rigid at each instant (drops both terms). Not
  /// energy-conserving; kept to reproduce the paper.
  PaperFrozen,
};

}  // namespace softrne
