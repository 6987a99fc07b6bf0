// The O(n) articulated-body forward dynamics (algorithms/articulated_body.hpp) against the
// dense solve (forward_dynamics: M from mass_matrix, Cholesky) on random hybrid chains of
// 1..100 segments and compile-time chains; own_body_inertia against the mass matrix and an
// independent construction; AutoDiff derivatives against M^-1; no heap allocation.
#include "../eigen_malloc_guard.hpp"  // first: before anything includes Eigen
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "softrne/softrne.hpp"
#include "autodiff_reference.hpp"
#include "support.hpp"

namespace core_test_articulated_body {

using namespace softrne;
using softrne_test::rel_err;
using Eigen::MatrixXd;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;
using CC = ConstantCurvatureJoint<double>;
using Link = RigidLink<double>;
using Rev = RevoluteJoint<double>;

enum Kind { kCC = 0, kLink = 1, kRev = 2 };

using softrne_test::random_cc;
using softrne_test::random_link;
using softrne_test::random_rev;
using softrne_test::uniform;

DynamicChain<double> make_chain(const std::vector<int>& kinds, std::mt19937& rng) {
  DynamicChain<double> c;
  for (int k : kinds) {
    if (k == kCC) c.add(random_cc(rng));
    if (k == kLink) c.add(random_link(rng));
    if (k == kRev) c.add(random_rev(rng));
  }
  const Vector3d g(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
  c.gravity = g.normalized() * 9.81;
  return c;
}

/// n random segment types. Consecutive revolute joints turn about one point, so runs are
/// capped at two (more than three would make M singular, three nearly so for close axes);
/// the tip is never a bare revolute joint (nothing would move beyond it: M singular).
std::vector<int> random_kinds(int n, std::mt19937& rng, int first = -1) {
  std::vector<int> k(static_cast<std::size_t>(n));
  for (auto& x : k) x = std::uniform_int_distribution<int>(0, 2)(rng);
  if (first >= 0) k.front() = first;
  for (std::size_t i = 2; i < k.size(); ++i)
    if (k[i] == kRev && k[i - 1] == kRev && k[i - 2] == kRev) k[i] = i % 2 ? kCC : kLink;
  if (k.back() == kRev) k.back() = n % 2 ? kCC : kLink;
  return k;
}

/// Worst case over random states of the forward error rel_err(aba, forward_dynamics) and of
/// aba's backward error |M a - (tau - b)| / (|M| |a| + |tau - b|) (inf norms; M and b from
/// the dense path), and the largest 2-norm condition number of M met.
struct Errors {
  double forward = 0, backward = 0, cond = 0;
};

template <class ChainT>
Errors aba_vs_dense(const ChainT& chain, std::mt19937& rng, int states, double qscale = 1.5) {
  auto d1 = chain.make_data();
  auto d2 = chain.make_data();
  const int nq = chain.num_coordinates();
  Errors e;
  for (int s = 0; s < states; ++s) {
    typename ChainT::VectorQ q = softrne_test::random_vector(rng, nq, qscale);
    typename ChainT::VectorQ qd = softrne_test::random_vector(rng, nq, 2.0);
    typename ChainT::VectorQ tau = softrne_test::random_vector(rng, nq, 5.0);
    const VectorXd a = aba(chain, d1, q, qd, tau);
    const VectorXd b = forward_dynamics(chain, d2, q, qd, tau);
    EXPECT_TRUE(a.allFinite());
    EXPECT_TRUE(b.allFinite());
    e.forward = std::max(e.forward, rel_err(a, b));
    const MatrixXd M = d2.mass_matrix;
    const VectorXd r = tau - d2.nonlinear_forces;
    const double Mn = M.cwiseAbs().rowwise().sum().maxCoeff();
    e.backward = std::max(e.backward, (M * a - r).cwiseAbs().maxCoeff() /
                                          (Mn * a.cwiseAbs().maxCoeff() + r.cwiseAbs().maxCoeff()));
    const VectorXd ev = Eigen::SelfAdjointEigenSolver<MatrixXd>(M).eigenvalues();
    e.cond = std::max(e.cond, ev(nq - 1) / ev(0));
  }
  return e;
}

/// 1e-9 relative, loosened only where M itself is ill-conditioned beyond 1e6 (long random
/// chains): there both solves are backward stable and their difference is ~ cond(M) eps
/// (checked against a long-double solve while writing this test: aba and dense were equally
/// far from it).
void expect_agree(const Errors& e, const std::string& what) {
  EXPECT_LT(e.forward, 1e-9 * std::max(1.0, e.cond * 1e-6)) << what << " cond " << e.cond;
  EXPECT_LT(e.backward, 1e-14) << what;
}

std::string kinds_name(const std::vector<int>& k) {
  std::string s;
  for (int x : k) s += "CLR"[x];
  return s;
}

// ---------------------------------------------------------------------------------------
// aba == dense

TEST(ArticulatedBody, EverySequenceOfOneToThreeSegments) {
  std::mt19937 rng(1);
  double worst = 0;
  for (int n = 1; n <= 3; ++n) {
    int combos = 1;
    for (int i = 0; i < n; ++i) combos *= 3;
    for (int code = 0; code < combos; ++code) {
      std::vector<int> kinds;
      for (int i = 0, c = code; i < n; ++i, c /= 3) kinds.push_back(c % 3);
      const auto chain = make_chain(kinds, rng);
      if (chain.num_coordinates() == 0) {  // only rigid links: nothing to solve
        auto data = chain.make_data();
        EXPECT_EQ(aba(chain, data, VectorXd(0), VectorXd(0), VectorXd(0)).size(), 0);
        continue;
      }
      if (kinds.back() == kRev) {
        // Nothing beyond the tip joint: M and D are singular; both report NaN.
        auto d1 = chain.make_data(), d2 = chain.make_data();
        const int nq = chain.num_coordinates();
        const VectorXd q = softrne_test::random_vector(rng, nq, 1.0);
        EXPECT_TRUE(aba(chain, d1, q, q, q).hasNaN()) << kinds_name(kinds);
        EXPECT_TRUE(forward_dynamics(chain, d2, q, q, q).hasNaN()) << kinds_name(kinds);
        continue;
      }
      const Errors e = aba_vs_dense(chain, rng, 10);
      EXPECT_LT(e.forward, 1e-9) << kinds_name(kinds);
      EXPECT_LT(e.backward, 1e-14) << kinds_name(kinds);
      worst = std::max(worst, e.forward);
    }
  }
  std::printf("[ info ] all sequences of 1..3 segments: max rel err %.2e\n", worst);
}

TEST(ArticulatedBody, RandomChainsUpTo100Segments) {
  std::mt19937 rng(2);
  for (int n : {1, 2, 3, 5, 10, 30, 100}) {
    Errors worst;
    for (int first : {kCC, kLink, kRev}) {
      const auto kinds = random_kinds(n, rng, first);
      const auto chain = make_chain(kinds, rng);
      if (chain.num_coordinates() == 0) continue;
      const Errors e = aba_vs_dense(chain, rng, n >= 30 ? 4 : 20);
      expect_agree(e, "n=" + std::to_string(n) + " " + kinds_name(kinds));
      if (n <= 30) {
        EXPECT_LT(e.forward, 1e-9);
      }
      worst.forward = std::max(worst.forward, e.forward);
      worst.backward = std::max(worst.backward, e.backward);
      worst.cond = std::max(worst.cond, e.cond);
    }
    std::printf("[ info ] n=%3d random hybrid chains: max rel err %.2e, backward err %.2e, "
                "cond(M) <= %.1e\n",
                n, worst.forward, worst.backward, worst.cond);
  }
}

TEST(ArticulatedBody, LongArmsOfThePapersSegmentsStrict) {
  // 5..50 x [CC joint + rigid link] of the paper's dimensions (up to 100 segments): cond(M)
  // stays below ~1e7 here, and 1e-9 holds without any loosening.
  std::mt19937 rng(12);
  for (int pairs : {5, 15, 50}) {
    DynamicChain<double> chain;
    for (int j = 0; j < pairs; ++j) {
      chain.add(softrne_test::paper_cc<double>());
      chain.add(softrne_test::paper_link<double>());
    }
    chain.gravity << 0.0, 0.0, 9.81;
    const Errors e = aba_vs_dense(chain, rng, 8);
    EXPECT_LT(e.forward, 1e-9) << 2 * pairs << " segments";
    EXPECT_LT(e.backward, 1e-14) << 2 * pairs << " segments";
    std::printf("[ info ] %3d segments (CC + link): max rel err %.2e, cond(M) <= %.1e\n",
                2 * pairs, e.forward, e.cond);
  }
}

TEST(ArticulatedBody, CcOnlyAndRevoluteRunsAndPaperFrozen) {
  std::mt19937 rng(3);
  // Consecutive CC joints with no link between them, a run of revolute joints, the frozen
  // inertia rate of the paper (only b changes).
  for (const std::vector<int>& kinds :
       {std::vector<int>{kCC, kCC, kCC, kCC}, std::vector<int>{kRev, kRev, kRev, kLink},
        std::vector<int>{kLink, kRev, kRev, kCC, kRev, kRev, kRev, kLink, kCC}}) {
    auto chain = make_chain(kinds, rng);
    EXPECT_LT(aba_vs_dense(chain, rng, 20).forward, 1e-9) << kinds_name(kinds);
    chain.inertia_rate = InertiaRate::PaperFrozen;
    EXPECT_LT(aba_vs_dense(chain, rng, 20).forward, 1e-9) << kinds_name(kinds) << " frozen";
  }
}

TEST(ArticulatedBody, BundledArmAtZeroAndBeyondPi) {
  std::mt19937 rng(4);
  const auto arm = softrne_test::paper_arm();
  EXPECT_LT(aba_vs_dense(arm, rng, 50).forward, 1e-9);
  auto d1 = arm.make_data(), d2 = arm.make_data();
  const VectorXd qd = softrne_test::random_vector(rng, 6, 2.0);
  const VectorXd tau = softrne_test::random_vector(rng, 6, 5.0);
  const VectorXd zero = VectorXd::Zero(6);
  // q = 0 exactly (the CC functions' removable singularity), at rest and moving.
  EXPECT_LT(rel_err(aba(arm, d1, zero, zero, tau), forward_dynamics(arm, d2, zero, zero, tau)),
            1e-12);
  EXPECT_LT(rel_err(aba(arm, d1, zero, qd, tau), forward_dynamics(arm, d2, zero, qd, tau)), 1e-12);
  // phi = sqrt(u^2 + v^2) > pi in every joint.
  VectorXd q(6);
  q << 2.5, 2.5, -3.0, 1.2, 0.4, -3.3;
  const VectorXd a = aba(arm, d1, q, qd, tau);
  EXPECT_TRUE(a.allFinite());
  EXPECT_LT(rel_err(a, forward_dynamics(arm, d2, q, qd, tau)), 1e-9);
  // A mixed chain at q = 0.
  const auto chain = make_chain({kRev, kCC, kLink, kRev, kRev, kCC, kLink}, rng);
  auto d3 = chain.make_data(), d4 = chain.make_data();
  const int nq = chain.num_coordinates();
  const VectorXd z = VectorXd::Zero(nq), t = softrne_test::random_vector(rng, nq, 5.0);
  EXPECT_LT(rel_err(aba(chain, d3, z, z, t), forward_dynamics(chain, d4, z, z, t)), 1e-12);
}

TEST(ArticulatedBody, StaticChainEqualsDenseAndRuntimeChain) {
  std::mt19937 rng(5);
  using Mixed = Chain<Rev, CC, Link, Rev, Rev, Link, CC, Link>;
  Mixed mixed(random_rev(rng), random_cc(rng), random_link(rng), random_rev(rng), random_rev(rng),
              random_link(rng), random_cc(rng), random_link(rng));
  mixed.gravity << 1.0, -2.0, 9.0;
  EXPECT_LT(aba_vs_dense(mixed, rng, 20).forward, 1e-9);
  // The bundled arm's shape, compile-time, against the runtime chain.
  const auto dyn = softrne_test::paper_arm();
  using Arm = Chain<CC, Link, CC, Link, CC, Link>;
  Arm arm(std::get<CC>(dyn.segment(0)), std::get<Link>(dyn.segment(1)),
          std::get<CC>(dyn.segment(2)), std::get<Link>(dyn.segment(3)),
          std::get<CC>(dyn.segment(4)), std::get<Link>(dyn.segment(5)));
  arm.gravity = dyn.gravity;
  EXPECT_LT(aba_vs_dense(arm, rng, 20).forward, 1e-9);
  auto ds = arm.make_data();
  auto dd = dyn.make_data();
  for (int s = 0; s < 10; ++s) {
    const Arm::VectorQ q = softrne_test::random_vector(rng, 6, 1.5);
    const Arm::VectorQ qd = softrne_test::random_vector(rng, 6, 2.0);
    const Arm::VectorQ tau = softrne_test::random_vector(rng, 6, 5.0);
    const VectorXd a = aba(arm, ds, q, qd, tau);
    const VectorXd b = aba(dyn, dd, VectorXd(q), VectorXd(qd), VectorXd(tau));
    EXPECT_LT(rel_err(a, b), 1e-13);
  }
}

// ---------------------------------------------------------------------------------------
// The own body

TEST(OwnBodyInertia, JointEqualsMassMatrixOfOneSegment) {
  std::mt19937 rng(6);
  for (int s = 0; s < 20; ++s) {
    Chain<CC> one(random_cc(rng));
    auto data = one.make_data();
    Eigen::Vector2d q = softrne_test::random_vector(rng, 2, s == 0 ? 0.0 : 2.5);
    const Eigen::Matrix2d M = mass_matrix(one, data, q);
    OwnBodyInertia<double, 2> own;
    detail::own_body_inertia(std::get<0>(one.segments), std::get<0>(data.kinematics), own);
    EXPECT_LT(rel_err(own.joint, M), 1e-14);
  }
}

TEST(OwnBodyInertia, SpatialAndCouplingAgainstIndependentConstruction) {
  std::mt19937 rng(7);
  for (int s = 0; s < 10; ++s) {
    // CC joint (turning body, moving centre of mass) and rigid link (full inertia, off-axis).
    const CC cc = random_cc(rng);
    CC::Kinematics kc;
    Eigen::Vector2d q = softrne_test::random_vector(rng, 2, 1.5);
    cc.calc(q, Eigen::Vector2d::Zero(), kc);
    OwnBodyInertia<double, 2> oc;
    detail::own_body_inertia(cc, kc, oc);
    const Link link = random_link(rng);
    Link::Kinematics kl;
    link.calc(Eigen::Matrix<double, 0, 1>(), Eigen::Matrix<double, 0, 1>(), kl);
    OwnBodyInertia<double, 0> ol;
    detail::own_body_inertia(link, kl, ol);

    // Wrench of a rigid body for unit motions of the base, by Newton-Euler with cross products:
    // f = m (a + alpha x c), n_O = I alpha + c x f with I = R I_c R^T.
    auto check_spatial = [](double m, const Vector3d& c, const Matrix3d& I,
                            const Eigen::Matrix<double, 6, 6>& spatial) {
      Eigen::Matrix<double, 6, 6> ref;
      for (int k = 0; k < 6; ++k) {
        Vector3d a = Vector3d::Zero(), alpha = Vector3d::Zero();
        if (k < 3) a(k) = 1; else alpha(k - 3) = 1;
        const Vector3d f = m * (a + alpha.cross(c));
        ref.col(k) << f, I * alpha + c.cross(f);
      }
      EXPECT_LT(rel_err(spatial, ref), 1e-15);
    };
    const Matrix3d R = kc.R_base_distal;
    check_spatial(cc.mass, kc.r_base_com, R * kc.inertia_com * R.transpose(), oc.spatial());
    check_spatial(link.mass, link.com, link.inertia, ol.spatial());

    // Coupling column k = the RNE's wrench at the base of a lone segment for qddot = e_k at
    // rest without gravity (backward_step of the body's d'Alembert load).
    Chain<CC> one(cc);
    one.gravity.setZero();
    auto data = one.make_data();
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d e = Eigen::Vector2d::Zero();
      e(k) = 1;
      rnea(one, data, q, Eigen::Vector2d::Zero(), e);
      Eigen::Matrix<double, 6, 1> w;
      w << data.wrench[0].force, data.wrench[0].torque;
      EXPECT_LT(rel_err(oc.coupling.col(k), w), 1e-14);
    }
  }
}

TEST(OwnBodyInertia, BodyRigidWithTheDistalFrameWouldBeWrong) {
  // A lone bent CC joint: its own body's joint inertia (S_b^T I S_b, centre of mass along
  // dr_c/dq) is M, and aba equals the dense solve. Had the body been treated as rigid with
  // the distal frame (S_b = S_e, Featherstone's ABA as is), D would differ from M by far more
  // than the tolerance, so the aba == dense checks above would fail.
  std::mt19937 rng(8);
  Chain<CC> one(softrne_test::paper_cc<double>());
  auto data = one.make_data();
  auto dense = one.make_data();
  const Eigen::Vector2d q(0.9, -0.6), qd(1.0, 0.5), tau(0.3, -0.2);
  const Eigen::Vector2d a = aba(one, data, q, qd, tau);
  EXPECT_LT(rel_err(a, forward_dynamics(one, dense, q, qd, tau)), 1e-13);
  const Eigen::Matrix2d M = dense.mass_matrix;
  // The rigid-with-distal-frame alternative: S_e = X^{-1} J_distal, D_rigid = S_e^T I S_e.
  const auto& kin = std::get<0>(data.kinematics);
  OwnBodyInertia<double, 2> own;
  detail::own_body_inertia(std::get<0>(one.segments), kin, own);
  Eigen::Matrix<double, 6, 2> Se = kin.J_distal;
  for (int k = 0; k < 2; ++k)
    Se.col(k).head<3>() += kin.r_base_distal.cross(kin.J_distal.col(k).tail<3>());
  const Eigen::Matrix2d D_rigid = Se.transpose() * own.spatial() * Se;
  const double rigid_err = rel_err(D_rigid / M.norm(), M / M.norm());
  std::printf("[ info ] lone CC joint: |D_rigid - M| / |M| = %.3f (aba uses J_com: M exactly)\n",
              rigid_err);
  EXPECT_GT(rigid_err, 1e-2);
  const Eigen::Vector2d a_rigid = D_rigid.ldlt().solve(tau - dense.nonlinear_forces);
  EXPECT_GT(rel_err(a_rigid, a), 1e-2);
}

// ---------------------------------------------------------------------------------------
// AutoDiff
#if SOFTRNE_TEST_AUTODIFF_REFERENCES

/// d(qddot)/d(tau) of aba (AutoDiff, tau active) against M^-1; and d(qddot)/d(q, qdot, tau)
/// of aba against that of forward_dynamics.
void check_autodiff(const DynamicChain<double>& chain, const VectorXd& q, const VectorXd& qd,
                    const VectorXd& tau) {
  const int nq = chain.num_coordinates();
  const auto chain_ad = chain.cast<softrne_test::AD>();
  auto data_ad = chain_ad.make_data();
  using AD = softrne_test::AD;
  using VAD = Eigen::Matrix<AD, Eigen::Dynamic, 1>;
  const VAD q_p = q.cast<AD>(), qd_p = qd.cast<AD>();
  const VAD tau_a = softrne_test::make_active(tau, 0, nq);
  const VAD qdd = aba(chain_ad, data_ad, q_p, qd_p, tau_a);
  MatrixXd dqdd_dtau = MatrixXd::Zero(nq, nq);
  for (int i = 0; i < nq; ++i)
    if (qdd(i).derivatives().size() > 0) dqdd_dtau.row(i) = qdd(i).derivatives().transpose();
  auto data = chain.make_data();
  const MatrixXd M = mass_matrix(chain, data, q);
  const MatrixXd Minv = M.ldlt().solve(MatrixXd::Identity(nq, nq));
  const double e_tau = rel_err(dqdd_dtau, Minv);
  EXPECT_LT(e_tau, 1e-9);

  const int nv = 3 * nq;
  const VAD q_a = softrne_test::make_active(q, 0, nv), qd_a = softrne_test::make_active(qd, nq, nv),
            t_a = softrne_test::make_active(tau, 2 * nq, nv);
  auto d1 = chain_ad.make_data(), d2 = chain_ad.make_data();
  const VAD x = aba(chain_ad, d1, q_a, qd_a, t_a);
  const VAD y = forward_dynamics(chain_ad, d2, q_a, qd_a, t_a);
  MatrixXd Jx(nq, nv), Jy(nq, nv);
  for (int i = 0; i < nq; ++i) {
    Jx.row(i) = x(i).derivatives().transpose();
    Jy.row(i) = y(i).derivatives().transpose();
  }
  const double e_all = rel_err(Jx, Jy);
  EXPECT_LT(e_all, 1e-9);
  std::printf("[ info ] AutoDiff, %d segments: |d qdd/d tau - M^-1| %.1e, "
              "|d qdd/d(q, qdot, tau) aba - dense| %.1e\n",
              chain.num_segments(), e_tau, e_all);
}

TEST(ArticulatedBodyAutoDiff, DerivativeByTauIsInverseMassMatrix) {
  std::mt19937 rng(9);
  const auto arm = softrne_test::paper_arm();
  check_autodiff(arm, softrne_test::random_vector(rng, 6, 1.5),
                 softrne_test::random_vector(rng, 6, 2.0),
                 softrne_test::random_vector(rng, 6, 5.0));
  const auto mixed = make_chain({kCC, kRev, kRev, kLink, kCC, kLink, kRev, kCC}, rng);
  const int nq = mixed.num_coordinates();
  check_autodiff(mixed, softrne_test::random_vector(rng, nq, 1.5),
                 softrne_test::random_vector(rng, nq, 2.0),
                 softrne_test::random_vector(rng, nq, 5.0));
}

TEST(ArticulatedBodyAutoDiff, AtAnEquilibrium) {
  // qdot = 0 and tau = G(q): qddot = 0 exactly, its derivatives are not.
  std::mt19937 rng(10);
  const DynamicChain<double> chains[] = {softrne_test::paper_arm(),
                                         make_chain({kRev, kCC, kLink, kRev, kCC}, rng)};
  for (const auto& chain : chains) {
    const int nq = chain.num_coordinates();
    const VectorXd q = softrne_test::random_vector(rng, nq, 1.0), zero = VectorXd::Zero(nq);
    auto data = chain.make_data();
    const VectorXd G = gravity(chain, data, q);
    EXPECT_LT(aba(chain, data, q, zero, G).cwiseAbs().maxCoeff(), 1e-12);
    check_autodiff(chain, q, zero, G);
    check_autodiff(chain, zero, zero, VectorXd(gravity(chain, data, zero)));
  }
}

#else
TEST(ArticulatedBodyAutoDiff, InTheReleaseTestsOnly) {
  GTEST_SKIP() << "AutoDiff references are not built here (SOFTRNE_TEST_AUTODIFF_REFERENCES=OFF)";
}
#endif

// ---------------------------------------------------------------------------------------
// Allocation

TEST(ArticulatedBodyAllocation, NoHeapAllocation) {
  std::mt19937 rng(11);
  Chain<CC, Link, CC, Link, Rev, Link> arm(random_cc(rng), random_link(rng), random_cc(rng),
                                           random_link(rng), random_rev(rng), random_link(rng));
  auto ds = arm.make_data();
  Eigen::Matrix<double, 5, 1> q, qd, tau;
  q << 0.1, 0.2, -0.3, 0.4, 0.5;
  qd << 1, 2, 3, -1, -2;
  tau << 0.5, -0.5, 0.2, 0.1, 0.0;
  const auto dyn = make_chain({kCC, kLink, kRev, kRev, kLink, kCC}, rng);
  auto dd = dyn.make_data();
  const VectorXd qx = VectorXd::Constant(6, 0.3), qdx = VectorXd::Constant(6, -0.5),
                 tx = VectorXd::Ones(6);
  const long eigen_failures_before = softrne_test::eigen_assert_failures;
  Eigen::internal::set_is_malloc_allowed(false);
  aba(arm, ds, q, qd, tau);
  aba(dyn, dd, qx, qdx, tx);
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_EQ(softrne_test::eigen_assert_failures, eigen_failures_before)
      << "heap allocation where forbidden";
  EXPECT_TRUE(ds.qddot.allFinite() && dd.qddot.allFinite());
}

}  // namespace core_test_articulated_body
