#pragma once
// Test helpers shared by the core tests: random states, AutoDiff types, example chains.

#include <algorithm>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "softrne/softrne.hpp"

/// The tests against AutoDiff references (Euler-Lagrange of the energies, derivatives of
/// aba): ON in the Release tests, OFF in .ci/run's sanitizer build (tests/CMakeLists.txt), where
/// each AutoDiff instantiation of the whole chain costs minutes of compile time and runs the
/// algorithms' source again with another scalar, which the double tests already run there.
#ifndef SOFTRNE_TEST_AUTODIFF_REFERENCES
#define SOFTRNE_TEST_AUTODIFF_REFERENCES 1
#endif

namespace softrne_test {

using AD = Eigen::AutoDiffScalar<Eigen::VectorXd>;
/// Fixed-size derivatives: constants get zero derivatives, so mixed expressions stay coherent.
template <int NV>
using ADN = Eigen::AutoDiffScalar<Eigen::Matrix<double, NV, 1>>;
using Eigen::VectorXd;

/// The AutoDiff type of the Euler-Lagrange references: 12 directions per pass (a 6-coordinate
/// chain's q and qd in one), any number of variables in several (chunked_gradients). One type
/// for every chain size: each AutoDiff type instantiates the whole chain anew (a second one,
/// for a 100-segment chain's 200 variables, cost 50 s of compiler time in each build).
using ADL = ADN<12>;

/// Gradients (m x x.size()) of the m scalars that f(x, out) writes to out[0..m), by
/// forward-mode AutoDiff in chunks of ADT's fixed number of directions (ForwardDiff.jl's
/// chunk mode): pass c seeds variables [c NV, (c + 1) NV) and leaves the others constant.
template <class ADT, class F>
Eigen::MatrixXd chunked_gradients(const VectorXd& x, int m, F&& f) {
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

/// dT/dq, dT/dqd, dV/dq at (q, qd) of the energies T and V that
/// energies(chain_ad, q, qd, T, V) computes on `chain_ad`, a chain cast to an AutoDiff scalar
/// with fixed-size derivatives (ADL).
template <class Energies, class ChainAD>
void lagrangian_gradients(const Energies& energies, const ChainAD& chain_ad, const VectorXd& q, const VectorXd& qd,
                          VectorXd& dT_dq, VectorXd& dT_dqd, VectorXd& dV_dq) {
  using ADT = typename ChainAD::Scalar;
  using QV = Eigen::Matrix<ADT, Eigen::Dynamic, 1>;
  const int n = static_cast<int>(q.size());
  VectorXd x(2 * n);
  x << q, qd;
  const Eigen::MatrixXd g = chunked_gradients<ADT>(x, 2, [&](const QV& xa, ADT* TV) {
    energies(chain_ad, QV(xa.head(n)), QV(xa.tail(n)), TV[0], TV[1]);
  });
  dT_dq = g.row(0).head(n).transpose();
  dT_dqd = g.row(0).tail(n).transpose();
  dV_dq = g.row(1).head(n).transpose();
}

/// The Euler-Lagrange generalised forces tau = d/dt(dT/dqd) - dT/dq + dV/dq of those energies;
/// AutoDiff gives the partials exactly, d/dt is an 8th-order central difference along
/// q(t) = q + t qd + t^2/2 qdd.
template <class Energies, class ChainAD>
VectorXd euler_lagrange(const Energies& energies, const ChainAD& chain_ad, const VectorXd& q, const VectorXd& qd,
                        const VectorXd& qdd) {
  VectorXd dTq, dTqd, dVq;
  lagrangian_gradients(energies, chain_ad, q, qd, dTq, dTqd, dVq);
  const double c[4] = {4.0 / 5, -1.0 / 5, 4.0 / 105, -1.0 / 280};
  const double h = 2e-3;
  VectorXd ddt = VectorXd::Zero(q.size());
  for (int k = 1; k <= 4; ++k) {
    for (int sgn : {1, -1}) {
      const double t = sgn * k * h;
      VectorXd a, b, e;
      lagrangian_gradients(energies, chain_ad, VectorXd(q + t * qd + 0.5 * t * t * qdd), VectorXd(qd + t * qdd), a,
                           b, e);
      ddt += sgn * c[k - 1] * b / h;
    }
  }
  return ddt - dTq + dVq;
}

/// Seeded uniform random vector in [-scale, scale].
inline VectorXd random_vector(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> d(-scale, scale);
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = d(rng);
  return v;
}

/// Active AutoDiff vector: entry i has derivative e_{offset+i} out of `total`.
template <class ADT = AD>
Eigen::Matrix<ADT, Eigen::Dynamic, 1> make_active(const VectorXd& x, int offset, int total) {
  Eigen::Matrix<ADT, Eigen::Dynamic, 1> a(x.size());
  for (int i = 0; i < x.size(); ++i) a(i) = ADT(x(i), total, offset + i);
  return a;
}

template <class S>
softrne::ConstantCurvatureJoint<S> paper_cc(double mass = 0.8, double h = 0.2, double D = 0.2) {
  softrne::ConstantCurvatureJoint<S> cc;
  cc.mass = S(mass);
  cc.height = S(h);
  cc.diameter = S(D);
  cc.stiffness << S(30), S(25);
  cc.damping << S(2), S(1.5);
  return cc;
}

template <class S>
softrne::RigidLink<S> paper_link(double mass = 1.5, double length = 0.15) {
  softrne::RigidLink<S> l;
  l.mass = S(mass);
  l.length = S(length);
  l.com << S(0.01), S(-0.02), S(length / 2);
  l.inertia << S(0.0052), S(0.0003), S(-0.0001), S(0.0003), S(0.0050), S(0.0002), S(-0.0001),
      S(0.0002), S(0.0048);
  return l;
}

template <class S>
softrne::RevoluteJoint<S> revolute(double ax, double ay, double az, double k = 0.5, double d = 0.1) {
  softrne::RevoluteJoint<S> r;
  r.axis = Eigen::Vector3d(ax, ay, az).normalized().cast<S>();
  r.stiffness = S(k);
  r.damping = S(d);
  return r;
}

/// The paper's arm: three CC joints, each followed by a rigid link, hanging (gravity +z).
inline softrne::DynamicChain<double> paper_arm() {
  softrne::DynamicChain<double> c;
  for (int j = 0; j < 3; ++j) {
    c.add(paper_cc<double>(0.8, 0.2, 0.2), "joint" + std::to_string(j + 1));
    c.add(paper_link<double>(j == 2 ? 0.4 : 1.5, j == 2 ? 0.05 : 0.15),
          "link" + std::to_string(j + 1));
  }
  c.gravity << 0.0, 0.0, 9.81;
  return c;
}

/// Max |a - b| / max(1, |b|_inf).
inline double rel_err(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace softrne_test
