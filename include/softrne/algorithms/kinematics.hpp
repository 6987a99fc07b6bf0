#pragma once
/// \file
/// \brief Per-segment kinematics for a configuration and velocity, and frame placements.

#include <type_traits>

#include <Eigen/Core>

#include "softrne/config.hpp"

namespace softrne {

namespace detail {

/// Checks that argument `v` of `algorithm` has one entry per coordinate of the chain: at
/// compile time where both sizes are fixed, else by the chain (always on for DynamicChain,
/// debug only for Chain<...>; see their check_argument).
template <class ChainT, class V>
void check_argument(const ChainT& chain, const char* algorithm, const char* argument,
                    const Eigen::MatrixBase<V>& v) {
  constexpr int fixed = V::SizeAtCompileTime, chain_fixed = ChainT::VectorQ::SizeAtCompileTime;
  static_assert(fixed == Eigen::Dynamic || chain_fixed == Eigen::Dynamic || fixed == chain_fixed,
                "softrne: a fixed-size argument has another size than the chain's nq");
  if constexpr (fixed == Eigen::Dynamic || chain_fixed == Eigen::Dynamic)
    chain.check_argument(algorithm, argument, v.size());
}

/// \brief One segment's entries of a chain-sized vector, as a fixed-size vector of its own.
/// The per-segment functions (`calc`, the RNE steps) then see one argument type per segment
/// type instead of a Block of each chain's vector type and of each caller's expression: they
/// are instantiated once per segment type, not once per (segment type, chain, argument type).
/// It copies nq <= 2 scalars, which the optimiser removes where the step is inlined.
template <int n, class V>
Eigen::Matrix<typename V::Scalar, n, 1> segment_entries(const Eigen::MatrixBase<V>& v,
                                                        int offset) {
  return v.template segment<n>(offset);
}

}  // namespace detail

/// \brief Calls every segment's `calc(q, qdot)`: rotations, positions, Jacobians, their rates
/// and inertias (paper section III-A, eqs. 1-10 and 19). The other algorithms run on what
/// this leaves in data.
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar>.
/// \param[in] chain The model.
/// \param[in,out] data Its workspace; the per-segment results go to data.kinematics.
/// \param[in] q The coordinates (dim chain.num_coordinates()).
/// \param[in] qdot Their rates (dim chain.num_coordinates()).
/// \throws std::invalid_argument (DynamicChain only) if q or qdot has another size than the
///   chain or data was made for another chain.
template <class ChainT, class Q, class Qd>
void compute_kinematics(const ChainT& chain, typename ChainT::Data& data,
                        const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot) {
  // The Data first: mass_matrix and gravity pass the Data's own zero velocity as qdot, so a
  // Data of another chain would otherwise show up as a wrong-size qdot.
  chain.check_data(data);
  detail::check_argument(chain, "compute_kinematics", "q", q);
  detail::check_argument(chain, "compute_kinematics", "qdot", qdot);
  chain.forward(data, [&](const auto& seg, auto& kin, int, int offset) {
    constexpr int n = std::decay_t<decltype(seg)>::nq;
    seg.calc(detail::segment_entries<n>(q, offset), detail::segment_entries<n>(qdot, offset), kin);
  });
}

/// \brief Placement of a segment's distal frame in the base frame of the chain.
template <class Scalar>
struct Placement {
  /// Orientation: the distal frame's axes in base coordinates.
  Eigen::Matrix<Scalar, 3, 3> R = Eigen::Matrix<Scalar, 3, 3>::Identity();
  /// Origin of the distal frame in the base frame.
  Eigen::Matrix<Scalar, 3, 1> p = Eigen::Matrix<Scalar, 3, 1>::Zero();
};

/// \brief Placement of the distal frame of segment `last` (default: the tip) after
/// `compute_kinematics`: the product of the segments' rotations (eq. 2 for a CC joint) and
/// shifts (eq. 4).
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar>.
/// \param[in] chain The model.
/// \param[in] data Its workspace after compute_kinematics() (or any algorithm) at q.
/// \param[in] last Index of the segment whose distal frame is wanted; negative: the tip.
/// \return The frame's orientation and origin in the base frame.
template <class ChainT>
Placement<typename ChainT::Scalar> distal_placement(const ChainT& chain,
                                                    typename ChainT::Data& data, int last = -1) {
  Placement<typename ChainT::Scalar> X;
  if (last < 0) last = data.num_segments() - 1;
  chain.forward(data, [&](const auto&, const auto& kin, int i, int) {
    if (i > last) return;
    X.p += X.R * kin.r_base_distal;
    X.R = X.R * kin.R_base_distal;
  });
  return X;
}

}  // namespace softrne
