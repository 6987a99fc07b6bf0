// Derivatives of the dynamics (algorithms/derivatives.hpp): rnea_derivatives and
// aba_derivatives on random hybrid chains (lumped and distributed CC joints, revolute joints,
// rigid links) against
//   - central finite differences of rnea / forward_dynamics / aba in double (no AutoDiff;
//     4th-order stencil);
//   - an AutoDiff evaluation that shares neither the seeding nor the assembly: the chain cast
//     to a dynamic-size AutoDiff scalar, all of (q, qdot[, tau]) active in one pass, through
//     rnea and through forward_dynamics (its Cholesky differentiated, not M^-1 assembled);
// on random states, at phi = 0 exactly and on both sides of the CC functions' series
// switches (cc_functions.hpp); both chain kinds (a compile-time chain against the same
// runtime chain); the size errors of a runtime chain; no heap allocation (static chain, and a
// runtime chain after its first call), with the guard's positive control. And the one claim of
// segment_tangent.hpp the RNE tests see only through the whole: the rate directions derived
// from calc seeded along q equal calc seeded along the rates.
#include "../eigen_malloc_guard.hpp"  // first: before anything includes Eigen
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "softrne/algorithms/derivatives.hpp"
#include "softrne/algorithms/mass_matrix.hpp"
#include "autodiff_reference.hpp"
#include "support.hpp"

namespace core_test_derivatives {

using namespace softrne;
using Eigen::MatrixXd;
using Eigen::VectorXd;
using softrne_test::random_cc;
using softrne_test::random_link;
using softrne_test::random_rev;
using softrne_test::random_vector;
using softrne_test::rel_err;
using CC = ConstantCurvatureJoint<double>;
using CCDist = ConstantCurvatureJoint<double, DistributedInertia<>>;
using Link = RigidLink<double>;
using Rev = RevoluteJoint<double>;

enum Kind { kCC, kLink, kRev, kCCDist };

DynamicChain<double> make_chain(const std::vector<Kind>& kinds, std::mt19937& rng) {
  DynamicChain<double> c;
  for (Kind k : kinds) {
    if (k == kCC) c.add(random_cc(rng));
    if (k == kCCDist) c.add(random_cc<DistributedInertia<>>(rng));
    if (k == kLink) c.add(random_link(rng));
    if (k == kRev) c.add(random_rev(rng));
  }
  c.gravity = Eigen::Vector3d(softrne_test::uniform(rng, -1, 1), softrne_test::uniform(rng, -1, 1),
                              softrne_test::uniform(rng, -1, 1))
                  .normalized() *
              9.81;
  return c;
}

/// Random hybrid chains: every kind in each, shuffled (at most two revolute joints in a row,
/// no bare revolute joint at the tip: M stays well conditioned).
std::vector<DynamicChain<double>> random_chains(std::mt19937& rng) {
  std::vector<DynamicChain<double>> out;
  out.push_back(softrne_test::paper_arm());
  for (int c = 0; c < 5; ++c) {
    std::vector<Kind> k = {kCC, kCCDist, kRev, kLink, kCC, kLink};
    std::shuffle(k.begin(), k.end(), rng);
    for (std::size_t i = 1; i < k.size(); ++i)
      if (k[i] == kRev && k[i - 1] == kRev) std::swap(k[i], k.back());
    if (k.back() == kRev) std::swap(k.back(), k.front());
    out.push_back(make_chain(k, rng));
    if (c == 4) out.back().inertia_rate = InertiaRate::PaperFrozen;
  }
  return out;
}

/// q with every CC joint's (u, v) at bending angle phi in direction dir (others random).
VectorXd bent(const DynamicChain<double>& chain, VectorXd q, double phi, double dir) {
  for (int i = 0; i < chain.num_segments(); ++i)
    if (std::visit([](const auto& s) { return std::decay_t<decltype(s)>::nq == 2; }, chain.segment(i))) {
      q(chain.q_offset(i)) = phi * std::cos(dir);
      q(chain.q_offset(i) + 1) = phi * std::sin(dir);
    }
  return q;
}

/// phi = 0 and the doubles next to each series switch (cc_functions.hpp; the lumped inertia
/// also evaluates the functions at 4 phi^2, hence the halves).
std::vector<double> special_angles() {
  std::vector<double> a = {0.0};
  const double sw = std::sqrt(detail::kCCSeriesSwitch), swd = std::sqrt(detail::kCCDiffSwitch);
  for (double s : {sw, swd, sw / 2, swd / 2}) {
    a.push_back(std::nextafter(s, 0.0));
    a.push_back(std::nextafter(s, 10.0));
  }
  return a;
}

/// d f / d x(j) of a vector function by the 4th-order central difference, column j.
template <class F>
MatrixXd finite_difference(const VectorXd& x, double h, F&& f) {
  const int n = static_cast<int>(x.size());
  MatrixXd J;
  for (int j = 0; j < n; ++j) {
    auto at = [&](double t) {
      VectorXd y = x;
      y(j) += t;
      return VectorXd(f(y));
    };
    const VectorXd d = (8.0 * (at(h) - at(-h)) - (at(2 * h) - at(-2 * h))) / (12.0 * h);
    if (j == 0) J.resize(d.size(), n);
    J.col(j) = d;
  }
  return J;
}

constexpr double kFdStep = 1e-3;
// Worst relative errors met (printed): rnea 8e-12, aba 1.5e-9 (its FD divides rounding
// errors of a solve by the step).
constexpr double kFdTolRnea = 1e-9;
constexpr double kFdTolAba = 1e-8;

struct Worst {
  double fd = 0, ad = 0;
  void print(const char* what) const {
    std::printf("[ info ] %s: worst relative error against finite differences %.1e, against "
                "AutoDiff %.1e\n", what, fd, ad);
  }
};

/// rnea_derivatives at (q, qd, qdd) against FD (kFdTolRnea) and, if built, one dynamic-size
/// AutoDiff pass of rnea (1e-9); d tau/d qddot against FD in qddot and mass_matrix() (1e-12).
void check_rnea(const DynamicChain<double>& chain, const VectorXd& q, const VectorXd& qd,
                const VectorXd& qdd, Worst& w) {
  auto data = chain.make_data();
  rnea_derivatives(chain, data, q, qd, qdd);
  const MatrixXd dq = data.dtau_dq, dqd = data.dtau_dqdot, M = data.mass_matrix;
  const VectorXd tau = data.tau;
  auto fd_data = chain.make_data();
  EXPECT_LT(rel_err(tau, rnea(chain, fd_data, q, qd, qdd)), 1e-14);
  // d tau/d qddot comes from the derivatives' own composites: the same M as the CRBA's.
  EXPECT_LT(rel_err(M, mass_matrix(chain, fd_data, q)), 1e-12);
  const MatrixXd fq = finite_difference(q, kFdStep, [&](const VectorXd& x) { return rnea(chain, fd_data, x, qd, qdd); });
  const MatrixXd fqd = finite_difference(qd, kFdStep, [&](const VectorXd& x) { return rnea(chain, fd_data, q, x, qdd); });
  const MatrixXd fqdd = finite_difference(qdd, kFdStep, [&](const VectorXd& x) { return rnea(chain, fd_data, q, qd, x); });
  const double e_fd = std::max({rel_err(dq, fq), rel_err(dqd, fqd), rel_err(M, fqdd)});
  EXPECT_LT(e_fd, kFdTolRnea) << "q " << q.transpose() << "\nd tau/dq\n" << dq << "\nFD\n" << fq;
  w.fd = std::max(w.fd, e_fd);
#if SOFTRNE_TEST_AUTODIFF_REFERENCES
  using AD = softrne_test::AD;
  using VAD = Eigen::Matrix<AD, Eigen::Dynamic, 1>;
  const int n = chain.num_coordinates();
  const auto chain_ad = chain.cast<AD>();
  auto data_ad = chain_ad.make_data();
  const VAD tau_ad = rnea(chain_ad, data_ad, softrne_test::make_active(q, 0, 2 * n),
                          softrne_test::make_active(qd, n, 2 * n), VAD(qdd.cast<AD>()));
  MatrixXd J(n, 2 * n);
  for (int i = 0; i < n; ++i) J.row(i) = tau_ad(i).derivatives().transpose();
  const double e_ad = std::max(rel_err(dq, J.leftCols(n)), rel_err(dqd, J.rightCols(n)));
  EXPECT_LT(e_ad, 1e-9);
  w.ad = std::max(w.ad, e_ad);
#endif
}

/// aba_derivatives at (q, qd, tau) against FD of forward_dynamics and of aba (kFdTolAba) and, if
/// built, one dynamic-size AutoDiff pass of forward_dynamics (1e-9); dqddot_dtau M = 1.
void check_aba(const DynamicChain<double>& chain, const VectorXd& q, const VectorXd& qd,
               const VectorXd& tau, Worst& w) {
  const int n = chain.num_coordinates();
  auto data = chain.make_data();
  aba_derivatives(chain, data, q, qd, tau);
  // On the way, what forward_dynamics() leaves (M from the derivatives' composites, so equal
  // to rounding), and the inverse dynamics at qddot* (data.tau) gives tau back.
  auto ref = chain.make_data();
  forward_dynamics(chain, ref, q, qd, tau);
  EXPECT_TRUE(data.nonlinear_forces == ref.nonlinear_forces);
  EXPECT_LT(rel_err(data.mass_matrix, ref.mass_matrix), 1e-13);
  EXPECT_LT(rel_err(data.qddot, ref.qddot), 1e-12);
  EXPECT_LT(rel_err(data.tau, tau), 1e-12);
  const MatrixXd dq = data.dqddot_dq, dqd = data.dqddot_dqdot, dtau = data.dqddot_dtau;
  EXPECT_LT(rel_err(dtau * data.mass_matrix, MatrixXd::Identity(n, n)), 1e-12);
  auto fd_data = chain.make_data();
  const MatrixXd fq = finite_difference(q, kFdStep, [&](const VectorXd& x) { return forward_dynamics(chain, fd_data, x, qd, tau); });
  const MatrixXd fqd = finite_difference(qd, kFdStep, [&](const VectorXd& x) { return aba(chain, fd_data, q, x, tau); });
  const MatrixXd ft = finite_difference(tau, kFdStep, [&](const VectorXd& x) { return aba(chain, fd_data, q, qd, x); });
  const double e_fd = std::max({rel_err(dq, fq), rel_err(dqd, fqd), rel_err(dtau, ft)});
  EXPECT_LT(e_fd, kFdTolAba) << "q " << q.transpose() << "\nd qdd/dq\n" << dq << "\nFD\n" << fq;
  w.fd = std::max(w.fd, e_fd);
#if SOFTRNE_TEST_AUTODIFF_REFERENCES
  using AD = softrne_test::AD;
  using VAD = Eigen::Matrix<AD, Eigen::Dynamic, 1>;
  const auto chain_ad = chain.cast<AD>();
  auto data_ad = chain_ad.make_data();
  const VAD qdd = forward_dynamics(chain_ad, data_ad, softrne_test::make_active(q, 0, 3 * n),
                                   softrne_test::make_active(qd, n, 3 * n),
                                   softrne_test::make_active(tau, 2 * n, 3 * n));
  MatrixXd J(n, 3 * n);
  for (int i = 0; i < n; ++i) J.row(i) = qdd(i).derivatives().transpose();
  const double e_ad = std::max(
      {rel_err(dq, J.leftCols(n)), rel_err(dqd, J.middleCols(n, n)), rel_err(dtau, J.rightCols(n))});
  EXPECT_LT(e_ad, 1e-9);
  w.ad = std::max(w.ad, e_ad);
#endif
}

/// check(chain, q, qd, qdd_or_tau, worst) on 4 random states of each random chain.
template <class Check>
void on_random_states(unsigned seed, const char* what, Check check) {
  std::mt19937 rng(seed);
  Worst w;
  for (const auto& chain : random_chains(rng)) {
    const int n = chain.num_coordinates();
    for (int s = 0; s < 4; ++s)
      check(chain, random_vector(rng, n, 1.5), random_vector(rng, n, 2.0), random_vector(rng, n, 5.0), w);
  }
  w.print(what);
}

/// check(...) with every CC joint at phi = 0 or next to a series switch, in two directions,
/// and at rest in the straight configuration (qdot = 0, phi = 0 exactly).
template <class Check>
void on_special_states(unsigned seed, const char* what, Check check) {
  std::mt19937 rng(seed);
  Worst w;
  for (const auto& chain : random_chains(rng)) {
    const int n = chain.num_coordinates();
    for (double phi : special_angles())
      for (double dir : {0.0, 0.7}) {
        const VectorXd q = bent(chain, random_vector(rng, n, 1.0), phi, dir);
        check(chain, q, random_vector(rng, n, 2.0), random_vector(rng, n, 5.0), w);
      }
    check(chain, bent(chain, VectorXd::Zero(n), 0.0, 0.0), VectorXd::Zero(n), random_vector(rng, n, 5.0), w);
  }
  w.print(what);
}

TEST(RneaDerivatives, RandomHybridChainsAndStates) {
  on_random_states(21, "rnea_derivatives, random states", check_rnea);
}

TEST(RneaDerivatives, AtZeroBendingAndAtTheSeriesSwitches) {
  on_special_states(22, "rnea_derivatives, phi = 0 and series switches", check_rnea);
}

TEST(AbaDerivatives, RandomHybridChainsAndStates) {
  on_random_states(23, "aba_derivatives, random states", check_aba);
}

TEST(AbaDerivatives, AtZeroBendingAndAtTheSeriesSwitches) {
  on_special_states(24, "aba_derivatives, phi = 0 and series switches", check_aba);
}

// ---------------------------------------------------------------------------------------
// The tangent steps' kinematics (segment_tangent.hpp): the directions along qdot_j are derived
// from calc_motion in AutoDiff seeded along q only, the inertia's from calc in double and the
// CC joint's inertia_hessian_times. Here the whole calc is seeded along (q_j, qdot_j) instead,
// its derivatives along qdot_j read directly, and the along-q ones compared too (the inertia's
// second derivatives among them, against AutoDiff of calc's first ones).

TEST(KinematicsTangents, RateDirectionsEqualCalcSeededAlongTheRates) {
  using AD = DerivativeScalar<double>;
  using CCAD = ConstantCurvatureJoint<AD>;
  // Relative to the reference's size (these are 1e-3 to 10; the floor only guards zeros).
  auto rel = [](const MatrixXd& a, const MatrixXd& b) {
    return (a - b).cwiseAbs().maxCoeff() / std::max(b.cwiseAbs().maxCoeff(), 1e-8);
  };
  std::mt19937 rng(26);
  double worst = 0, worst_motion = 0;
  // Random bendings, phi = 0 exactly, and both sides of the series switches (phi^2 = 0.25, 1).
  std::vector<Eigen::Vector2d> qs;
  for (int r = 0; r < 20; ++r) qs.push_back(random_vector(rng, 2, 1.5));
  qs.push_back(Eigen::Vector2d::Zero());
  for (double x : {0.25, 1.0})
    for (double f : {1 - 1e-9, 1 + 1e-9})
      qs.push_back(Eigen::Vector2d(0.6, 0.8) * std::sqrt(x * f));
  for (const Eigen::Vector2d& q : qs) {
    const CC cc = random_cc(rng);
    const CCAD cc_ad = cc.cast<AD>();
    const Eigen::Vector2d qd = random_vector(rng, 2, 2.0);
    CC::Kinematics kin;
    cc.calc(q, qd, kin);
    // As derivatives.hpp seeds it: direction k along q_k.
    Eigen::Matrix<AD, 2, 1> q_ad, qd_ad;
    for (int k = 0; k < 2; ++k) {
      q_ad(k) = AD(q(k), Eigen::Vector2d::Unit(k));
      qd_ad(k) = AD(qd(k), Eigen::Vector2d::Zero());
    }
    CCAD::Kinematics kin_q;
    cc_ad.calc_motion(q_ad, qd_ad, kin_q);
    // The vector the inertia's derivatives are applied to (the distal angular velocity there).
    const Eigen::Vector3d w = random_vector(rng, 3, 2.0);
    detail::InertiaHessianTimes<2> hessian_w;
    cc.inertia_hessian_times(q, kin, w, hessian_w);
    const std::array<Eigen::Vector3d, 2> dI_w = {kin.dinertia_dq[0] * w, kin.dinertia_dq[1] * w};
    for (int j = 0; j < 2; ++j) {
      detail::KinematicsTangent<2> along_q, along_qdot;
      detail::kinematics_tangents<2>(kin_q, kin, &hessian_w, dI_w, qd, j, along_q, along_qdot);
      // The reference: direction 0 along q_j, direction 1 along qdot_j.
      Eigen::Matrix<AD, 2, 1> q_j, qd_j;
      for (int k = 0; k < 2; ++k) {
        q_j(k) = AD(q(k), Eigen::Vector2d::Zero());
        qd_j(k) = AD(qd(k), Eigen::Vector2d::Zero());
      }
      q_j(j).derivatives()(0) = 1;
      qd_j(j).derivatives()(1) = 1;
      CCAD::Kinematics ref;
      cc_ad.calc(q_j, qd_j, ref);
      using detail::derivative_along;
      // The pose, Jacobians, their rates and the first derivative of the inertia: AutoDiff
      // against AutoDiff, to rounding.
      const double e_motion = std::max(
          {rel(along_qdot.Jdq, derivative_along(ref.Jdot_qdot_distal, 1)),
           rel(along_qdot.Jdq_c, derivative_along(ref.Jdot_qdot_com, 1)),
           rel(along_qdot.I_rate_omega, derivative_along(ref.inertia_rate, 1) * w),
           rel(along_q.Jdq, derivative_along(ref.Jdot_qdot_distal, 0)),
           rel(along_q.Jdq_c, derivative_along(ref.Jdot_qdot_com, 0)),
           rel(along_q.R, derivative_along(ref.R_base_distal, 0)),
           rel(along_q.J, derivative_along(ref.J_distal, 0)),
           rel(along_q.J_c, derivative_along(ref.J_com, 0)),
           rel(along_q.I, derivative_along(ref.inertia_com, 0))});
      EXPECT_LT(e_motion, 1e-13) << "q " << q.transpose() << " qdot " << qd.transpose() << " j "
                                 << j;
      // The inertia's second derivatives (inertia_hessian_times, written out; near the series
      // switch its closed form loses about a digit to cancellation).
      const double e_hessian = std::max(
          {rel(along_q.I_rate_omega, derivative_along(ref.inertia_rate, 0) * w),
           rel(along_q.dI_dq_omega[0], derivative_along(ref.dinertia_dq[0], 0) * w),
           rel(along_q.dI_dq_omega[1], derivative_along(ref.dinertia_dq[1], 0) * w)});
      EXPECT_LT(e_hessian, 5e-12) << "q " << q.transpose() << " qdot " << qd.transpose()
                                  << " j " << j;
      const double e = std::max(e_motion, e_hessian);
      worst = std::max(worst, e);
      worst_motion = std::max(worst_motion, e_motion);
      // Nothing else of calc depends on qdot (the claim the derivation rests on).
      EXPECT_EQ(derivative_along(ref.R_base_distal, 1).norm(), 0.0);
      EXPECT_EQ(derivative_along(ref.J_distal, 1).norm(), 0.0);
      EXPECT_EQ(derivative_along(ref.J_com, 1).norm(), 0.0);
      EXPECT_EQ(derivative_along(ref.r_base_com, 1).norm(), 0.0);
      EXPECT_EQ(derivative_along(ref.inertia_com, 1).norm(), 0.0);
      EXPECT_EQ(derivative_along(ref.dinertia_dq[0], 1).norm(), 0.0);
    }
  }
  std::printf("[ info ] kinematics_tangents against calc seeded along the rates: worst relative "
              "error %.1e (%.1e without the inertia's second derivatives)\n",
              worst, worst_motion);
}

// ---------------------------------------------------------------------------------------
// Both chain kinds, errors, allocation

using Static = Chain<CC, Link, Rev, CCDist, Link, Rev, CC>;

Static make_static(std::mt19937& rng) {
  Static s(random_cc(rng), random_link(rng), random_rev(rng), random_cc<DistributedInertia<>>(rng),
           random_link(rng), random_rev(rng), random_cc(rng));
  s.gravity << 0.0, 0.0, 9.81;
  return s;
}

DynamicChain<double> to_dynamic(const Static& s) {
  DynamicChain<double> d;
  std::apply([&](const auto&... seg) { (d.add(seg), ...); }, s.segments);
  d.gravity = s.gravity;
  return d;
}

TEST(Derivatives, StaticChainEqualsRuntimeChain) {
  std::mt19937 rng(25);
  const Static s = make_static(rng);
  const DynamicChain<double> d = to_dynamic(s);
  auto ds = s.make_data();
  auto dd = d.make_data();
  for (int k = 0; k < 5; ++k) {
    const Static::VectorQ q = random_vector(rng, Static::nq, 1.5), qd = random_vector(rng, Static::nq, 2.0),
                          a = random_vector(rng, Static::nq, 5.0);
    rnea_derivatives(s, ds, q, qd, a);
    rnea_derivatives(d, dd, VectorXd(q), VectorXd(qd), VectorXd(a));
    EXPECT_LT(rel_err(ds.dtau_dq, dd.dtau_dq), 1e-13);
    EXPECT_LT(rel_err(ds.dtau_dqdot, dd.dtau_dqdot), 1e-13);
    EXPECT_LT(rel_err(ds.mass_matrix, dd.mass_matrix), 1e-13);
    aba_derivatives(s, ds, q, qd, a);
    aba_derivatives(d, dd, VectorXd(q), VectorXd(qd), VectorXd(a));
    EXPECT_LT(rel_err(ds.dqddot_dq, dd.dqddot_dq), 1e-12);
    EXPECT_LT(rel_err(ds.dqddot_dqdot, dd.dqddot_dqdot), 1e-12);
    EXPECT_LT(rel_err(ds.dqddot_dtau, dd.dqddot_dtau), 1e-12);
  }
  // The chain's constants are read at every call, not when the workspace was made.
  DynamicChain<double> heavier = d;
  std::get<CC>(heavier.segment(0)).mass *= 2;
  auto fresh = heavier.make_data();
  const VectorXd q = VectorXd::Constant(Static::nq, 0.3), qd = VectorXd::Constant(Static::nq, 0.5);
  rnea_derivatives(heavier, dd, q, qd, q);
  rnea_derivatives(heavier, fresh, q, qd, q);
  EXPECT_EQ(dd.dtau_dq, fresh.dtau_dq);
  EXPECT_EQ(dd.dtau_dqdot, fresh.dtau_dqdot);
}

TEST(Derivatives, RuntimeChainSizeErrors) {
  const auto arm = softrne_test::paper_arm();
  auto data = arm.make_data();
  const VectorXd ok = VectorXd::Zero(6), bad = VectorXd::Zero(3);
  try {
    rnea_derivatives(arm, data, bad, ok, ok);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "softrne::rnea_derivatives: q has 3 entries; the chain has 6 coordinates");
  }
  EXPECT_THROW(rnea_derivatives(arm, data, ok, ok, bad), std::invalid_argument);
  EXPECT_THROW(aba_derivatives(arm, data, ok, bad, ok), std::invalid_argument);
  try {
    aba_derivatives(arm, data, ok, ok, bad);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "softrne::aba_derivatives: tau has 3 entries; the chain has 6 coordinates");
  }
  auto other = softrne_test::paper_arm();
  other.add(Link{});
  auto other_data = other.make_data();
  EXPECT_THROW(rnea_derivatives(arm, other_data, ok, ok, ok), std::invalid_argument);
}

TEST(Derivatives, NoHeapAllocation) {
  std::mt19937 rng(26);
  const Static s = make_static(rng);
  auto ds = s.make_data();
  const DynamicChain<double> d = to_dynamic(s);
  auto dd = d.make_data();
  const Static::VectorQ q = random_vector(rng, Static::nq, 1.0), qd = random_vector(rng, Static::nq, 2.0),
                        a = random_vector(rng, Static::nq, 5.0);
  const VectorXd qx = q, qdx = qd, ax = a;
  rnea_derivatives(d, dd, qx, qdx, ax);  // a runtime chain sizes its workspace once
  aba_derivatives(d, dd, qx, qdx, ax);
  const long before = softrne_test::eigen_assert_failures;
  Eigen::internal::set_is_malloc_allowed(false);
  rnea_derivatives(s, ds, q, qd, a);
  aba_derivatives(s, ds, q, qd, a);
  rnea_derivatives(d, dd, qx, qdx, ax);
  aba_derivatives(d, dd, qx, qdx, ax);
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_EQ(softrne_test::eigen_assert_failures, before) << "heap allocation where forbidden";
  EXPECT_TRUE(ds.dqddot_dq.allFinite() && dd.dqddot_dq.allFinite());
  EXPECT_GT(ds.dtau_dq.cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace core_test_derivatives
