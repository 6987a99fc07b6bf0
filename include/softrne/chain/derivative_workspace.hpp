#pragma once
/// \file
/// \brief Workspace of the derivatives of the dynamics (algorithms/derivatives.hpp): the chain
/// in a forward-mode AutoDiff scalar and that chain's own workspace, kept in the chains' Data
/// so that rnea_derivatives and aba_derivatives allocate nothing for a compile-time chain.

#include <type_traits>
#include <utility>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

namespace softrne {

/// \brief Derivative directions carried by one AutoDiff pass of the derivatives
/// (algorithms/derivatives.hpp says why 2).
inline constexpr int kDerivativeBlock = 2;

/// \brief The forward-mode AutoDiff scalar of the derivatives: a value and kDerivativeBlock
/// fixed-size derivatives (no heap). For double it is the simulator's Jacobian scalar too
/// (sim::ArmSystem::AD), so the runtime chain's segments are instantiated once for both.
template <class Scalar>
using DerivativeScalar = Eigen::AutoDiffScalar<Eigen::Matrix<Scalar, kDerivativeBlock, 1>>;

/// \brief Nothing for a chain whose scalar is not a built-in floating-point type (an AutoDiff
/// chain has no derivative workspace of its own: no derivatives of derivatives).
template <class ChainT, bool = std::is_floating_point_v<typename ChainT::Scalar>>
struct DerivativeWorkspace {};

/// \brief The chain in DerivativeScalar, its workspace and the AutoDiff arguments of one pass.
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
