#pragma once
/// \file
/// \brief Workspace of the derivatives of the dynamics (algorithms/derivatives.hpp): the chain
/// in a forward-mode AutoDiff scalar and that chain's own workspace, kept in the chains' Data
/// so that rnea_derivatives and aba_derivatives allocate nothing for a compile-time chain.

#include <array>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

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

/// \brief The derivatives of a frame's motion (FrameMotion) along one block.
struct MotionTangent {
  Tangent3 omega = Tangent3::Zero(), alpha = Tangent3::Zero(), acc = Tangent3::Zero();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The derivatives of a wrench (Wrench) along one block.
struct WrenchTangent {
  Tangent3 force = Tangent3::Zero(), torque = Tangent3::Zero();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The derivatives of a segment's body load (BodyLoad) along one block.
struct LoadTangent {
  Tangent3 force = Tangent3::Zero(), torque = Tangent3::Zero();
  Tangent3 omega_distal = Tangent3::Zero(), tau_sub_bodies = Tangent3::Zero();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief One LoadTangent per segment: a std::vector for a runtime chain (sized by the first
/// call), a std::array for a compile-time one (no heap).
template <class ChainT>
struct LoadTangents {
  using type = std::vector<LoadTangent>;
};
template <class... Segments>
struct LoadTangents<Chain<Segments...>> {
  using type = std::array<LoadTangent, sizeof...(Segments)>;
};

}  // namespace detail

/// \brief Nothing for a chain whose scalar is not a built-in floating-point type (an AutoDiff
/// chain has no derivative workspace of its own: no derivatives of derivatives).
template <class ChainT, bool = std::is_floating_point_v<typename ChainT::Scalar>>
struct DerivativeWorkspace {};

/// \brief The chain in DerivativeScalar, its workspace, the AutoDiff arguments of one
/// segment's evaluation and the per-segment load derivatives (algorithms/derivatives.hpp).
/// derivatives.hpp copies the chain's constants into `chain` at every call (the chain may have
/// changed since), so the workspace never holds stale parameters.
template <class ChainT>
struct DerivativeWorkspace<ChainT, true> {
  using AD = DerivativeScalar<typename ChainT::Scalar>;  ///< the AutoDiff scalar
  /// The chain type in AD (Chain<...> of the same segment types, or DynamicChain<AD>).
  using ChainAD = decltype(std::declval<const ChainT&>().template cast<AD>());
  ChainAD chain;                           ///< the chain's constants in AD (no derivatives)
  typename ChainAD::Data data;             ///< the AD chain's workspace
  typename ChainAD::VectorQ q;             ///< q of one pass, seeded
  typename ChainAD::VectorQ qdot;          ///< qdot of one pass, seeded
  typename ChainAD::VectorQ qddot;         ///< qddot (no derivatives)
  /// Per segment: its body load's derivatives along the block being propagated.
  typename detail::LoadTangents<ChainT>::type load_tangents;
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
