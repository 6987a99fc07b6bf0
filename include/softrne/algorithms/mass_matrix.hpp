#pragma once
/// \file
/// \brief Joint-space inertia matrix M(q).

#include <Eigen/Core>

#include "softrne/algorithms/kinematics.hpp"
#include "softrne/algorithms/rnea.hpp"

namespace softrne {
namespace detail {

/// \brief M on the kinematics already in data (any qdot): one RNE pass per coordinate with
/// qddot = e_j and no gravity or velocity terms (section III-D), but the segment kinematics
/// (trigonometry, Jacobians, inertia, the expensive part) are computed once and shared by all
/// columns. Cost: one kinematics pass + nq linear O(n) recursions, O(n nq) in all.
template <class ChainT>
void mass_matrix_passes(const ChainT& chain, typename ChainT::Data& data) {
  const int nq = chain.num_coordinates();
  data.qdot_zero.setZero();
  data.unit.setZero();
  for (int j = 0; j < nq; ++j) {
    data.unit(j) = 1;
    rnea_passes(chain, data, data.qdot_zero, data.unit, false, false);
    data.mass_matrix.col(j) = data.tau;
    data.unit(j) = 0;
  }
}

}  // namespace detail

/// \brief M(q), symmetric positive definite. \return data.mass_matrix
template <class ChainT, class Q>
const typename ChainT::MatrixQ& mass_matrix(const ChainT& chain, typename ChainT::Data& data,
                                            const Eigen::MatrixBase<Q>& q) {
  data.qdot_zero.setZero();
  compute_kinematics(chain, data, q, data.qdot_zero);
  detail::mass_matrix_passes(chain, data);
  return data.mass_matrix;
}

/// \brief M(q) and C(q,qdot) qdot + G(q) from one kinematics evaluation: what forward dynamics
/// needs. Results in data.mass_matrix and data.bias_forces.
template <class ChainT, class Q, class Qd>
void mass_matrix_and_bias(const ChainT& chain, typename ChainT::Data& data,
                          const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot) {
  compute_kinematics(chain, data, q, qdot);
  data.qdot_zero.setZero();
  detail::rnea_passes(chain, data, qdot, data.qdot_zero, true, true);
  data.bias_forces = data.tau;
  detail::mass_matrix_passes(chain, data);
}

}  // namespace softrne
