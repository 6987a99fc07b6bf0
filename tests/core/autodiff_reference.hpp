#pragma once
// The AutoDiff references of the core tests, in one place: the AutoDiff types, gradients by
// forward-mode AutoDiff in chunks, and the Euler-Lagrange reference of the dynamics (the
// chain's kinetic and potential energy written out here, tau = d/dt dT/dqd - dT/dq + dV/dq),
// which tests/core/test_rnea.cpp (lumped chains) and test_distributed_inertia.cpp (chains
// with distributed CC joints) check the RNE against.

#include <algorithm>
#include <cstdio>
#include <random>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "softrne/softrne.hpp"
#include "support.hpp"

/// The tests against AutoDiff references of whole chains (Euler-Lagrange of the energies,
/// derivatives of aba): ON in the Release tests, OFF in .ci/run's sanitizer build
/// (tests/CMakeLists.txt), where each AutoDiff instantiation of the whole chain costs minutes of
/// compile time and runs the algorithms' source again with another scalar, which the double
/// tests already run there. With it OFF, each such test file reports one skipped test instead.
#ifndef SOFTRNE_TEST_AUTODIFF_REFERENCES
#define SOFTRNE_TEST_AUTODIFF_REFERENCES 1
#endif

namespace softrne_test {

using AD = Eigen::AutoDiffScalar<Eigen::VectorXd>;
/// Fixed-size derivatives: constants get zero derivatives, so mixed expressions stay coherent.
template <int NV>
using ADN = Eigen::AutoDiffScalar<Eigen::Matrix<double, NV, 1>>;

/// The AutoDiff type of the Euler-Lagrange references: 12 directions per pass (a 6-coordinate
/// chain's q and qd in one), any number of variables in several (chunked_gradients). One type
/// for every chain size: each AutoDiff type instantiates the whole chain anew (a second one,
/// for a 100-segment chain's 200 variables, cost 50 s of compiler time in each build).
using ADL = ADN<12>;

/// Active AutoDiff vector: entry i has derivative e_{offset+i} out of `total`.
template <class ADT = AD>
Eigen::Matrix<ADT, Eigen::Dynamic, 1> make_active(const Eigen::VectorXd& x, int offset, int total) {
  Eigen::Matrix<ADT, Eigen::Dynamic, 1> a(x.size());
  for (int i = 0; i < x.size(); ++i) a(i) = ADT(x(i), total, offset + i);
  return a;
}

/// Gradients (m x x.size()) of the m scalars that f(x, out) writes to out[0..m), by
/// forward-mode AutoDiff in chunks of ADT's fixed number of directions (ForwardDiff.jl's
/// chunk mode): pass c seeds variables [c NV, (c + 1) NV) and leaves the others constant.
template <class ADT, class F>
Eigen::MatrixXd chunked_gradients(const Eigen::VectorXd& x, int m, F&& f) {
  constexpr int NV = ADT::DerType::RowsAtCompileTime;
  static_assert(NV > 0, "chunked_gradients needs fixed-size derivatives");
  const int nx = static_cast<int>(x.size());
  Eigen::MatrixXd g(m, nx);
  std::vector<ADT> out(static_cast<std::size_t>(m));
  Eigen::Matrix<ADT, Eigen::Dynamic, 1> xa(nx);
  for (int c0 = 0; c0 < nx; c0 += NV) {
    for (int i = 0; i < nx; ++i) {
      xa(i).value() = x(i);
      xa(i).derivatives().setZero();
      if (i >= c0 && i < c0 + NV) xa(i).derivatives()(i - c0) = 1.0;
    }
    f(xa, out.data());
    const int w = std::min(NV, nx - c0);
    for (int k = 0; k < m; ++k)
      g.row(k).segment(c0, w) = out[static_cast<std::size_t>(k)].derivatives().head(w).transpose();
  }
  return g;
}

// ---------------------------------------------------------------------------------------
// The Euler-Lagrange reference.

/// Kinetic energy T and gravitational potential V of `chain` at (q, qd), in any scalar,
/// computed here from scratch: the segments give only their own pose, Jacobians and inertia
/// (or those of their sub-bodies, for the distributed CC joint: its quadrature disks); the
/// velocities are propagated in the world frame by this function (no RNE code).
template <class ChainT, class QV>
void energies(const ChainT& chain, const QV& q, const QV& qd, typename ChainT::Scalar& T,
              typename ChainT::Scalar& V) {
  using S = typename ChainT::Scalar;
  using V3 = Eigen::Matrix<S, 3, 1>;
  using M3 = Eigen::Matrix<S, 3, 3>;
  auto data = chain.make_data();
  softrne::compute_kinematics(chain, data, q, qd);
  M3 R = M3::Identity();
  V3 p = V3::Zero(), v = V3::Zero(), w = V3::Zero();
  T = S(0);
  V = S(0);
  chain.forward(data, [&](const auto& seg, const auto& kin, int, int off) {
    using Seg = std::decay_t<decltype(seg)>;
    constexpr int n = Seg::nq;
    V3 v_rel = V3::Zero(), w_rel = V3::Zero();
    if constexpr (n > 0) {
      const auto qds = qd.template segment<n>(off);
      v_rel = kin.J_distal.template topRows<3>() * qds;
      w_rel = kin.J_distal.template bottomRows<3>() * qds;
      if constexpr (softrne::detail::num_sub_bodies<Seg> > 0) {
        for (const auto& b : kin.sub_bodies) {
          const V3 vb = v + w.cross(R * b.r_base_body) + R * (b.J_v * qds);
          const V3 wb = w + R * (b.J_w * qds);
          const M3 Ib = R * b.inertia * R.transpose();
          T += S(0.5) * b.mass * vb.squaredNorm() + S(0.5) * wb.dot(Ib * wb);
          V -= b.mass * chain.gravity.dot(p + R * b.r_base_body);
        }
      } else if constexpr (Seg::has_body) {
        const V3 vc = v + w.cross(R * kin.r_base_com) + R * (kin.J_com * qds);
        const V3 wb = (R * kin.R_base_distal).transpose() * (w + R * w_rel);
        T += S(0.5) * seg.mass * vc.squaredNorm() + S(0.5) * wb.dot(kin.inertia_com * wb);
        V -= seg.mass * chain.gravity.dot(p + R * kin.r_base_com);
      }
    } else if constexpr (Seg::has_body) {
      const V3 vc = v + w.cross(R * kin.r_base_com);
      const V3 wb = (R * kin.R_base_distal).transpose() * w;
      T += S(0.5) * seg.mass * vc.squaredNorm() + S(0.5) * wb.dot(kin.inertia_com * wb);
      V -= seg.mass * chain.gravity.dot(p + R * kin.r_base_com);
    }
    v = v + w.cross(R * kin.r_base_distal) + R * v_rel;
    p = p + R * kin.r_base_distal;
    w = w + R * w_rel;
    R = R * kin.R_base_distal;
  });
}

/// dT/dq, dT/dqd, dV/dq at (q, qd) of the energies above, by AutoDiff on `chain_ad`, a chain
/// cast to an AutoDiff scalar with fixed-size derivatives (ADL).
template <class ChainAD>
void lagrangian_gradients(const ChainAD& chain_ad, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                          Eigen::VectorXd& dT_dq, Eigen::VectorXd& dT_dqd, Eigen::VectorXd& dV_dq) {
  using ADT = typename ChainAD::Scalar;
  using QV = Eigen::Matrix<ADT, Eigen::Dynamic, 1>;
  const int n = static_cast<int>(q.size());
  Eigen::VectorXd x(2 * n);
  x << q, qd;
  const Eigen::MatrixXd g = chunked_gradients<ADT>(x, 2, [&](const QV& xa, ADT* TV) {
    energies(chain_ad, QV(xa.head(n)), QV(xa.tail(n)), TV[0], TV[1]);
  });
  dT_dq = g.row(0).head(n).transpose();
  dT_dqd = g.row(0).tail(n).transpose();
  dV_dq = g.row(1).head(n).transpose();
}

/// The Euler-Lagrange generalised forces tau = d/dt(dT/dqd) - dT/dq + dV/dq; AutoDiff gives
/// the partials exactly, d/dt is an 8th-order central difference along
/// q(t) = q + t qd + t^2/2 qdd.
template <class ChainAD>
Eigen::VectorXd euler_lagrange(const ChainAD& chain_ad, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                               const Eigen::VectorXd& qdd) {
  using Eigen::VectorXd;
  VectorXd dTq, dTqd, dVq;
  lagrangian_gradients(chain_ad, q, qd, dTq, dTqd, dVq);
  const double c[4] = {4.0 / 5, -1.0 / 5, 4.0 / 105, -1.0 / 280};
  const double h = 2e-3;
  VectorXd ddt = VectorXd::Zero(q.size());
  for (int k = 1; k <= 4; ++k) {
    for (int sgn : {1, -1}) {
      const double t = sgn * k * h;
      VectorXd a, b, e;
      lagrangian_gradients(chain_ad, VectorXd(q + t * qd + 0.5 * t * t * qdd), VectorXd(qd + t * qdd), a, b, e);
      ddt += sgn * c[k - 1] * b / h;
    }
  }
  return ddt - dTq + dVq;
}

/// rnea against the Euler-Lagrange reference on `states` random states (|q_i| <= q_scale,
/// |qd_i| <= 2, |qdd_i| <= 5): relative error below 1e-9 in each.
template <class ChainT>
void check_against_lagrangian(const ChainT& chain, int states, double q_scale, unsigned seed) {
  using Eigen::VectorXd;
  const auto chain_ad = chain.template cast<ADL>();
  auto data = chain.make_data();
  std::mt19937 rng(seed);
  const int n = chain.num_coordinates();
  double worst = 0;
  for (int s = 0; s < states; ++s) {
    const VectorXd q = random_vector(rng, n, q_scale);
    const VectorXd qd = random_vector(rng, n, 2.0);
    const VectorXd qdd = random_vector(rng, n, 5.0);
    const VectorXd tau = softrne::rnea(chain, data, q, qd, qdd);
    const VectorXd ref = euler_lagrange(chain_ad, q, qd, qdd);
    const double e = (tau - ref).norm() / std::max(1e-3, ref.norm());
    worst = std::max(worst, e);
    ASSERT_LT(e, 1e-9) << "state " << s << "\nrnea " << tau.transpose() << "\nEL   " << ref.transpose();
  }
  std::printf("[ info ] %d coordinates: worst relative |rnea - Euler-Lagrange| = %.2e\n", n, worst);
}

}  // namespace softrne_test
