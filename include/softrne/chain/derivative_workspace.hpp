#pragma once
/// \file
/// \brief Workspace of the derivatives of the dynamics (algorithms/derivatives.hpp): the chain
/// in a forward-mode AutoDiff scalar and that chain's own workspace, and the world composites
/// of the expansion point (algorithms/derivative_composites.hpp), kept in the chains' Data so
/// that rnea_derivatives and aba_derivatives allocate nothing for a compile-time chain.

#include <array>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "softrne/spatial/skew.hpp"

namespace softrne {

/// \brief Derivative directions carried by one AutoDiff evaluation of the derivatives: a
/// coordinate and its rate, (q_i, qdot_i) (algorithms/derivatives.hpp), and the simulator's
/// Jacobian (sim::ArmJacobian; 2 measured fastest there).
inline constexpr int kDerivativeBlock = 2;

/// \brief The forward-mode AutoDiff scalar of the derivatives: a value and kDerivativeBlock
/// fixed-size derivatives (no heap). For double it is the simulator's Jacobian scalar too
/// (sim::ArmSystem::AD), so the runtime chain's segments are instantiated once for both.
template <class Scalar>
using DerivativeScalar = Eigen::AutoDiffScalar<Eigen::Matrix<Scalar, kDerivativeBlock, 1>>;

template <class... Segments>
class Chain;

namespace detail {

/// \brief A block of derivatives of a 3-vector: column k along direction k of the block.
using Tangent3 = Eigen::Matrix<double, 3, kDerivativeBlock>;

/// \brief A frame at the expansion point, in the world (the chain's base frame): its pose, the
/// velocity of its origin, and its twist about the world origin (linear; angular).
struct FrameInWorld {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< orientation
  Eigen::Vector3d p = Eigen::Vector3d::Zero();      ///< origin
  Eigen::Vector3d v = Eigen::Vector3d::Zero();      ///< velocity of the origin
  Eigen::Matrix<double, 6, 1> twist = Eigen::Matrix<double, 6, 1>::Zero();  ///< (v_O; omega)
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief What the bodies from one frame to the tip offer a perturbation of that frame, in the
/// world about the world origin (algorithms/derivative_composites.hpp): their composite spatial
/// inertia \f$Y = \begin{pmatrix} m & -[h]_\times\\ [h]_\times & I_O\end{pmatrix}\f$ and
/// the composite of their velocity terms \f$D = \begin{pmatrix} 0 & -2[p]_\times\\ 0 &
/// X\end{pmatrix}\f$, kept as their blocks.
struct SubtreeComposite {
  double mass = 0;                                         ///< m
  Eigen::Vector3d first_moment = Eigen::Vector3d::Zero();  ///< h = sum of m c
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();       ///< I_O, about the world origin
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();      ///< p = sum of m v_c
  Eigen::Matrix3d velocity = Eigen::Matrix3d::Zero();      ///< X

  /// \brief Y a + D (0; dw), columnwise: the wrench's change for (a~; dV's angular part).
  template <class A, class W>
  EIGEN_ALWAYS_INLINE Eigen::Matrix<double, 6, A::ColsAtCompileTime> apply(
      const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<W>& dw) const {
    Eigen::Matrix<double, 6, A::ColsAtCompileTime> out(6, a.cols());
    for (Eigen::Index j = 0; j < a.cols(); ++j) {
      const Eigen::Vector3d lin = a.col(j).template head<3>(), ang = a.col(j).template tail<3>();
      const Eigen::Vector3d w = dw.col(j);
      out.col(j).template head<3>() =
          mass * lin - cross3(first_moment, ang) - 2.0 * cross3(momentum, w);
      out.col(j).template tail<3>() = cross3(first_moment, lin);
      out.col(j).template tail<3>().noalias() += inertia * ang;
      out.col(j).template tail<3>().noalias() += velocity * w;
    }
    return out;
  }

  /// \brief This += other.
  void add(const SubtreeComposite& other) {
    mass += other.mass;
    first_moment += other.first_moment;
    inertia += other.inertia;
    momentum += other.momentum;
    velocity += other.velocity;
  }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief One T per frame (num_segments + 1): a std::vector for a runtime chain (sized by the
/// first call), a std::array for a compile-time one (no heap).
template <class ChainT, class T>
struct PerFrame {
  using type = std::vector<T, Eigen::aligned_allocator<T>>;
};
template <class... Segments, class T>
struct PerFrame<Chain<Segments...>, T> {
  using type = std::array<T, sizeof...(Segments) + 1>;
};

}  // namespace detail

/// \brief Nothing for a chain whose scalar is not a built-in floating-point type (an AutoDiff
/// chain has no derivative workspace of its own: no derivatives of derivatives).
template <class ChainT, bool = std::is_floating_point_v<typename ChainT::Scalar>>
struct DerivativeWorkspace {};

/// \brief The chain in DerivativeScalar, its workspace, the AutoDiff arguments of one
/// segment's evaluation (algorithms/derivatives.hpp) and the world composites of the
/// expansion point (algorithms/derivative_composites.hpp).
/// derivatives.hpp copies the chain's constants into `chain` at every call (the chain may have
/// changed since), so the workspace never holds stale parameters.
template <class ChainT>
struct DerivativeWorkspace<ChainT, true> {
  using AD = DerivativeScalar<typename ChainT::Scalar>;  ///< the AutoDiff scalar
  /// The chain type in AD (Chain<...> of the same segment types, or DynamicChain<AD>).
  using ChainAD = decltype(std::declval<const ChainT&>().template cast<AD>());
  ChainAD chain;                    ///< the chain's constants in AD (no derivatives)
  typename ChainAD::Data data;      ///< the AD chain's workspace
  typename ChainAD::VectorQ q;      ///< q of one pass, seeded
  typename ChainAD::VectorQ qdot;   ///< qdot of one pass, seeded
  typename ChainAD::VectorQ qddot;  ///< qddot (no derivatives)
  static constexpr int kNq = ChainT::VectorQ::RowsAtCompileTime;  ///< nq or Dynamic
  /// Per frame (frame k: segment k's base; the last: the tip): its pose and velocity...
  typename detail::PerFrame<ChainT, detail::FrameInWorld>::type frames;
  /// ... and the composite of the segments from it to the tip.
  typename detail::PerFrame<ChainT, detail::SubtreeComposite>::type subtrees;
  /// Per coordinate (column), the world Jacobian of its segment's distal frame: its twist
  /// about the world origin for a unit rate.
  Eigen::Matrix<double, 6, kNq> jacobian;
  /// Per coordinate (column), the sensitivities (P | R)^T of its generalised force to a
  /// perturbation of its segment's base: d tau = P a~ + R dV_angular
  /// (derivative_composites.hpp).
  Eigen::Matrix<double, 9, kNq> sensitivity;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

namespace detail {

/// \brief Seeds one AutoDiff pass: out(i) = value(i) with derivative direction
/// `index + i - start` of the pass if that lies in [0, kDerivativeBlock), else none. A vector
/// holding the variables [index, index + size) of a pass over [start, start + kDerivativeBlock)
/// (rnea_derivatives: q at index 0, qdot at nq).
template <class V, class VAD>
void seed_block(const Eigen::MatrixBase<V>& value, int index, int start, VAD& out) {
  for (Eigen::Index i = 0; i < value.size(); ++i) {
    out(i).value() = value(i);
    out(i).derivatives().setZero();
    const Eigen::Index k = index + i - start;
    if (k >= 0 && k < kDerivativeBlock) out(i).derivatives()(k) = 1;
  }
}

}  // namespace detail
}  // namespace softrne
