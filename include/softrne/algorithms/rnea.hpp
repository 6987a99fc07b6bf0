#pragma once
/// \file
/// \brief Recursive Newton-Euler inverse dynamics (paper sections III-B and III-C).

#include <type_traits>

#include <Eigen/Core>

#include "softrne/algorithms/kinematics.hpp"
#include "softrne/algorithms/rnea_steps.hpp"

namespace softrne {
namespace detail {

/// \brief The two passes on the kinematics already in data; result in data.tau.
/// \param with_gravity start the forward pass with base acceleration -g.
/// \param velocity_terms keep the velocity-product terms (false for columns of M).
template <class ChainT, class Qd, class Qdd>
void rnea_passes(const ChainT& chain, typename ChainT::Data& data,
                 const Eigen::MatrixBase<Qd>& qdot, const Eigen::MatrixBase<Qdd>& qddot,
                 bool with_gravity, bool velocity_terms, typename ChainT::VectorQ& out) {
  using Scalar = typename ChainT::Scalar;
  auto& base = data.motion[0];
  base.omega.setZero();
  base.alpha.setZero();
  if (with_gravity)
    base.acc = -chain.gravity;
  else
    base.acc.setZero();
  chain.forward(data, [&](const auto& seg, const auto& kin, int i, int offset) {
    constexpr int n = std::decay_t<decltype(seg)>::nq;
    const auto k = static_cast<std::size_t>(i);
    forward_step(seg, kin, data.motion[k], segment_entries<n>(qdot, offset),
                 segment_entries<n>(qddot, offset), velocity_terms, chain.inertia_rate,
                 data.motion[k + 1], data.loads[k]);
  });
  data.wrench[static_cast<std::size_t>(data.num_segments())] = Wrench<Scalar>{};
  chain.backward(data, [&](const auto& seg, const auto& kin, int i, int offset) {
    constexpr int n = std::decay_t<decltype(seg)>::nq;
    const auto k = static_cast<std::size_t>(i);
    Eigen::Matrix<Scalar, n, 1> tau;  // fixed-size, as the step's inputs (segment_entries)
    backward_step(seg, kin, data.loads[k], data.wrench[k + 1], chain.inertia_rate, tau,
                  data.wrench[k]);
    if constexpr (n > 0) out.template segment<n>(offset) = tau;
  });
}

}  // namespace detail

/// \brief Inverse dynamics: the generalised forces \f$\tau = M(q)\ddot q + C(q,\dot q)\dot q +
/// G(q)\f$ of the chain's inertia and gravity (springs, dampers and pressures are not part of
/// it; see forward_dynamics.hpp). Cost: one kinematics pass and two O(n) recursions.
///
/// The forward recursion, base to tip, is the paper's eqs. 11-15 on the relative motion of
/// eqs. 7-8 (a rigid link: eq. 10); the backward recursion, tip to base, is eqs. 16-18 (with
/// the default InertiaRate::Consistent, eq. 18 gains the rate of the configuration-dependent
/// inertia; see rnea_steps.hpp).
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar>.
/// \param[in] chain The model: its segments, gravity (base frame) and inertia_rate.
/// \param[in,out] data Its workspace, made by chain.make_data(); the result goes to data.tau.
/// \param[in] q The coordinates (dim chain.num_coordinates(): u, v per CC joint, the angle
///   of each revolute joint).
/// \param[in] qdot Their rates (dim chain.num_coordinates()).
/// \param[in] qddot The desired accelerations (dim chain.num_coordinates()).
/// \return The generalised forces, stored in data.tau (valid until rnea() runs again on data).
/// \throws std::invalid_argument (DynamicChain only, also in Release) if q, qdot or qddot has
///   another size than the chain or data was made for another chain.
template <class ChainT, class Q, class Qd, class Qdd>
const typename ChainT::VectorQ& rnea(const ChainT& chain, typename ChainT::Data& data,
                                     const Eigen::MatrixBase<Q>& q,
                                     const Eigen::MatrixBase<Qd>& qdot,
                                     const Eigen::MatrixBase<Qdd>& qddot) {
  detail::check_argument(chain, "rnea", "q", q);
  detail::check_argument(chain, "rnea", "qdot", qdot);
  detail::check_argument(chain, "rnea", "qddot", qddot);
  compute_kinematics(chain, data, q, qdot);
  detail::rnea_passes(chain, data, qdot, qddot, true, true, data.tau);
  return data.tau;
}

}  // namespace softrne
