#pragma once
/// \file
/// \brief Spatial (6D) vectors about one fixed origin, ordering (linear; angular): the cross
/// products of motions and forces, and the maps between a frame's own axes and the world.
/// Featherstone's notation (Rigid Body Dynamics Algorithms, 2008, ch. 2), in the world-frame
/// form Pinocchio's derivative algorithms use. Only the derivatives of the dynamics
/// (algorithms/derivative_composites.hpp) need them; the RNE itself stays in 3-vectors
/// (rnea_steps.hpp).

#include <Eigen/Core>

#include "softrne/spatial/skew.hpp"

namespace softrne {
namespace detail {

using Vector6d = Eigen::Matrix<double, 6, 1>;  ///< a spatial vector (linear; angular)

/// \brief \f$v \times m\f$ of two motions:
/// \f$(\omega\times m_v + v_O\times m_\omega;\ \omega\times m_\omega)\f$.
EIGEN_ALWAYS_INLINE Vector6d cross_motion(const Vector6d& v, const Vector6d& m) {
  Vector6d out;
  out.head<3>() = cross3(v.tail<3>(), m.head<3>()) + cross3(v.head<3>(), m.tail<3>());
  out.tail<3>() = cross3(v.tail<3>(), m.tail<3>());
  return out;
}

/// \brief \f$v \times^* f\f$ of a motion and a force:
/// \f$(\omega\times f;\ \omega\times n + v_O\times f)\f$.
EIGEN_ALWAYS_INLINE Vector6d cross_force(const Vector6d& v, const Vector6d& f) {
  Vector6d out;
  out.head<3>() = cross3(v.tail<3>(), f.head<3>());
  out.tail<3>() = cross3(v.tail<3>(), f.tail<3>()) + cross3(v.head<3>(), f.head<3>());
  return out;
}

/// \brief A motion given in a frame's own axes about its origin (rotation R, origin p in the
/// world), as seen about the world origin in world axes: \f$(R v + p\times R\omega;\ R\omega)\f$.
/// Columnwise for a 6 x k block.
template <class In>
EIGEN_ALWAYS_INLINE Eigen::Matrix<double, 6, In::ColsAtCompileTime> motion_to_world(
    const Eigen::Matrix3d& R, const Eigen::Vector3d& p, const Eigen::MatrixBase<In>& m) {
  Eigen::Matrix<double, 6, In::ColsAtCompileTime> out(6, m.cols());
  out.template bottomRows<3>().noalias() = R * m.template bottomRows<3>();
  out.template topRows<3>().noalias() = R * m.template topRows<3>();
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    out.col(j).template head<3>() += cross3(p, out.col(j).template tail<3>());
  return out;
}

/// \brief A force (f; n about the frame's origin) in a frame's own axes, as seen about the
/// world origin in world axes: \f$(R f;\ R n + p\times R f)\f$. Columnwise for a 6 x k block.
template <class In>
EIGEN_ALWAYS_INLINE Eigen::Matrix<double, 6, In::ColsAtCompileTime> force_to_world(
    const Eigen::Matrix3d& R, const Eigen::Vector3d& p, const Eigen::MatrixBase<In>& f) {
  Eigen::Matrix<double, 6, In::ColsAtCompileTime> out(6, f.cols());
  out.template topRows<3>().noalias() = R * f.template topRows<3>();
  out.template bottomRows<3>().noalias() = R * f.template bottomRows<3>();
  for (Eigen::Index j = 0; j < f.cols(); ++j)
    out.col(j).template tail<3>() += cross3(p, out.col(j).template head<3>());
  return out;
}

/// \brief The inverse of force_to_world: a world force about the world origin in the frame's
/// axes about its origin, \f$(R^T f;\ R^T(n - p\times f))\f$.
template <class In>
EIGEN_ALWAYS_INLINE Eigen::Matrix<double, 6, In::ColsAtCompileTime> force_to_local(
    const Eigen::Matrix3d& R, const Eigen::Vector3d& p, const Eigen::MatrixBase<In>& f) {
  Eigen::Matrix<double, 6, In::ColsAtCompileTime> out(6, f.cols());
  out.template topRows<3>().noalias() = R.transpose() * f.template topRows<3>();
  Eigen::Matrix<double, 3, In::ColsAtCompileTime> n = f.template bottomRows<3>();
  for (Eigen::Index j = 0; j < f.cols(); ++j)
    n.col(j) -= cross3(p, f.col(j).template head<3>());
  out.template bottomRows<3>().noalias() = R.transpose() * n;
  return out;
}

}  // namespace detail
}  // namespace softrne
