#pragma once
/// \file
/// \brief Per-segment kinematics for a configuration and velocity, and frame placements.

#include <type_traits>

#include <Eigen/Core>

#include "softrne/config.hpp"

namespace softrne {

/// \brief Calls every segment's `calc(q, qdot)`: rotations, positions, Jacobians, their rates
/// and inertias (paper section III-A). The other algorithms run on what this leaves in data.
template <class ChainT, class Q, class Qd>
void compute_kinematics(const ChainT& chain, typename ChainT::Data& data,
                        const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot) {
  // The Data first: mass_matrix and gravity pass the Data's own zero velocity as qdot, so a
  // Data of another chain would otherwise show up as a wrong-size qdot.
  SOFTRNE_ASSERT(data.tau.size() == chain.num_coordinates(),
                 "this Data was made for another chain (call chain.make_data())");
  SOFTRNE_ASSERT(q.size() == chain.num_coordinates() && qdot.size() == chain.num_coordinates(),
                 "compute_kinematics: q and qdot must have num_coordinates() entries");
  chain.forward(data, [&](const auto& seg, auto& kin, int, int offset) {
    constexpr int n = std::decay_t<decltype(seg)>::nq;
    seg.calc(q.template segment<n>(offset), qdot.template segment<n>(offset), kin);
  });
}

/// \brief Placement of a segment's distal frame in the base frame of the chain.
template <class Scalar>
struct Placement {
  Eigen::Matrix<Scalar, 3, 3> R = Eigen::Matrix<Scalar, 3, 3>::Identity();
  Eigen::Matrix<Scalar, 3, 1> p = Eigen::Matrix<Scalar, 3, 1>::Zero();
};

/// \brief Placement of the distal frame of segment `last` (default: the tip) after
/// `compute_kinematics`.
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
