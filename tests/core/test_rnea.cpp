// The generic RNE against the Euler-Lagrange equations of the lumped energy, differentiated
// with AutoDiff (autodiff_reference.hpp, SOFTRNE_TEST_AUTODIFF_REFERENCES); cross-identities
// between rnea, gravity, bias and mass_matrix; static chain == runtime chain; closed-form
// statics; no heap allocation.
#include "../eigen_malloc_guard.hpp"  // first: before anything includes Eigen
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>

#include "softrne/softrne.hpp"
#include "autodiff_reference.hpp"
#include "support.hpp"

namespace core_test_rnea {

using namespace softrne;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

DynamicChain<double> cc_only() {
  DynamicChain<double> c;
  c.add(softrne_test::paper_cc<double>(0.8, 0.2, 0.2), "j1");
  c.add(softrne_test::paper_cc<double>(0.5, 0.15, 0.12), "j2");
  c.add(softrne_test::paper_cc<double>(0.3, 0.1, 0.1), "j3");
  c.gravity << 0.3, -1.0, 9.81;
  return c;
}

DynamicChain<double> hybrid() {
  DynamicChain<double> c;
  c.add(softrne_test::revolute<double>(0, 0, 1), "yaw");
  c.add(softrne_test::paper_link<double>(1.0, 0.1), "l0");
  c.add(softrne_test::paper_cc<double>(0.8, 0.2, 0.2), "j1");
  c.add(softrne_test::paper_link<double>(1.5, 0.15), "l1");
  c.add(softrne_test::revolute<double>(1, 0.2, 0), "elbow");
  c.add(softrne_test::paper_link<double>(0.7, 0.2), "l2");
  c.add(softrne_test::paper_cc<double>(0.4, 0.12, 0.1), "j2");
  c.add(softrne_test::paper_link<double>(0.3, 0.05), "tip");
  c.gravity << 0.0, 0.0, -9.81;
  return c;
}

#if SOFTRNE_TEST_AUTODIFF_REFERENCES
DynamicChain<double> long_chain(int n_cc) {
  DynamicChain<double> c;
  for (int i = 0; i < n_cc; ++i) {
    c.add(softrne_test::paper_cc<double>(0.1, 0.05, 0.04), "j" + std::to_string(i));
    c.add(softrne_test::paper_link<double>(0.05, 0.02), "l" + std::to_string(i));
  }
  c.gravity << 0.0, 0.0, 9.81;
  return c;
}

using softrne_test::check_against_lagrangian;
TEST(RneaLagrangian, CcOnlyChain) { check_against_lagrangian(cc_only(), 100, 1.6, 11); }
TEST(RneaLagrangian, PaperArm) { check_against_lagrangian(softrne_test::paper_arm(), 100, 1.6, 12); }
TEST(RneaLagrangian, HybridWithRevoluteJoints) { check_against_lagrangian(hybrid(), 100, 1.6, 13); }
TEST(RneaLagrangian, LongChain100Segments) { check_against_lagrangian(long_chain(50), 3, 0.3, 14); }

TEST(RneaLagrangian, PaperFrozenInertiaIsNotLagrangian) {
  // The paper's eq. 18 drops dI/dt: it must differ from Euler-Lagrange at speed (and agree
  // at rest, where the dropped terms vanish).
  auto chain = softrne_test::paper_arm();
  chain.inertia_rate = InertiaRate::PaperFrozen;
  auto data = chain.make_data();
  const auto chain_ad = softrne_test::paper_arm().cast<softrne_test::ADL>();
  std::mt19937 rng(15);
  const VectorXd q = softrne_test::random_vector(rng, 6, 1.0);
  const VectorXd qd = softrne_test::random_vector(rng, 6, 2.0);
  const VectorXd qdd = softrne_test::random_vector(rng, 6, 5.0);
  const VectorXd ref = softrne_test::euler_lagrange(chain_ad, q, qd, qdd);
  EXPECT_GT((rnea(chain, data, q, qd, qdd) - ref).norm() / ref.norm(), 1e-6);
  const VectorXd z = VectorXd::Zero(6);
  const VectorXd ref_at_rest = softrne_test::euler_lagrange(chain_ad, q, z, qdd);
  EXPECT_LT((rnea(chain, data, q, z, qdd) - ref_at_rest).norm(), 1e-9);
}
#else
TEST(RneaLagrangian, InTheReleaseTestsOnly) {
  GTEST_SKIP() << "AutoDiff references are not built here (SOFTRNE_TEST_AUTODIFF_REFERENCES=OFF)";
}
#endif

TEST(RneaIdentities, GravityBiasMassMatrix) {
  for (const auto& chain : {cc_only(), softrne_test::paper_arm(), hybrid()}) {
    auto data = chain.make_data();
#if SOFTRNE_TEST_AUTODIFF_REFERENCES
    const auto chain_ad = chain.cast<softrne_test::ADL>();
#endif
    const int n = chain.num_coordinates();
    std::mt19937 rng(21);
    for (int s = 0; s < 20; ++s) {
      const VectorXd q = softrne_test::random_vector(rng, n, 1.6);
      const VectorXd qd = softrne_test::random_vector(rng, n, 2.0);
      const VectorXd qdd = softrne_test::random_vector(rng, n, 5.0);
      const VectorXd z = VectorXd::Zero(n);
      const VectorXd G = gravity(chain, data, q);
      EXPECT_LT(softrne_test::rel_err(rnea(chain, data, q, z, z), G), 1e-14);
      const VectorXd Cqd = bias(chain, data, q, qd);
      EXPECT_LT(softrne_test::rel_err(rnea(chain, data, q, qd, z) - G, Cqd), 1e-13);
      EXPECT_LT(softrne_test::rel_err(bias(chain, data, q, qd, true), G + Cqd), 1e-13);
      const MatrixXd M = mass_matrix(chain, data, q);
      EXPECT_LT(softrne_test::rel_err(M, M.transpose()), 1e-14);
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatrixXd>(M).eigenvalues().minCoeff(), 0.0);
      EXPECT_LT(softrne_test::rel_err(rnea(chain, data, q, qd, qdd), M * qdd + Cqd + G), 1e-13);
      mass_matrix_and_bias(chain, data, q, qd);
      EXPECT_LT(softrne_test::rel_err(data.mass_matrix, M), 1e-15);
      EXPECT_LT(softrne_test::rel_err(data.nonlinear_forces, Cqd + G), 1e-13);
#if SOFTRNE_TEST_AUTODIFF_REFERENCES
      // G = dV/dq.
      VectorXd a, b, dV;
      softrne_test::lagrangian_gradients(chain_ad, q, qd, a, b, dV);
      EXPECT_LT(softrne_test::rel_err(G, dV), 1e-12);
#endif
      // qd^T (dM/dt - 2C) qd = 0 with dM/dt by a central difference along qd.
      const double eps = 1e-6;
      const MatrixXd Mp = mass_matrix(chain, data, VectorXd(q + eps * qd));
      const MatrixXd Mm = mass_matrix(chain, data, VectorXd(q - eps * qd));
      const double skew = qd.dot((Mp - Mm) / (2 * eps) * qd) - 2 * qd.dot(Cqd);
      EXPECT_LT(std::abs(skew), 1e-7 * std::max(1.0, std::abs(qd.dot(Cqd))));
    }
  }
}

TEST(RneaIdentities, StaticChainEqualsRuntimeChain) {
  using CC = ConstantCurvatureJoint<double>;
  using RL = RigidLink<double>;
  using RJ = RevoluteJoint<double>;
  Chain<RJ, RL, CC, RL, RJ, RL, CC, RL> st(
      softrne_test::revolute<double>(0, 0, 1), softrne_test::paper_link<double>(1.0, 0.1),
      softrne_test::paper_cc<double>(0.8, 0.2, 0.2), softrne_test::paper_link<double>(1.5, 0.15),
      softrne_test::revolute<double>(1, 0.2, 0), softrne_test::paper_link<double>(0.7, 0.2),
      softrne_test::paper_cc<double>(0.4, 0.12, 0.1), softrne_test::paper_link<double>(0.3, 0.05));
  st.gravity << 0.0, 0.0, -9.81;
  const auto dyn = hybrid();
  static_assert(decltype(st)::nq == 6);
  auto sd = st.make_data();
  auto dd = dyn.make_data();
  std::mt19937 rng(31);
  for (int s = 0; s < 50; ++s) {
    const VectorXd q = softrne_test::random_vector(rng, 6, 2.0);
    const VectorXd qd = softrne_test::random_vector(rng, 6, 2.0);
    const VectorXd qdd = softrne_test::random_vector(rng, 6, 5.0);
    const Eigen::Matrix<double, 6, 1> qs = q, qds = qd, qdds = qdd;
    EXPECT_EQ(VectorXd(rnea(st, sd, qs, qds, qdds)), rnea(dyn, dd, q, qd, qdd));
    EXPECT_EQ(MatrixXd(mass_matrix(st, sd, qs)), mass_matrix(dyn, dd, q));
  }
}

// mass_matrix() must leave data as compute_kinematics(q, 0) does (distal_placement() and the
// other algorithms read it), and give the M that mass_matrix_and_bias() computes after
// compute_kinematics(), whatever q the data held before. Both chain kinds, and the
// distributed-inertia CC joint (its own sub-body path in the sweep).
template <class ChainT, class VectorT>
void check_mass_matrix_kinematics(const ChainT& chain, std::mt19937& rng) {
  auto data = chain.make_data();
  const int n = chain.num_coordinates();
  for (int s = 0; s < 10; ++s) {
    const VectorT q_before = softrne_test::random_vector(rng, n, 2.0);
    const VectorT q = softrne_test::random_vector(rng, n, 2.0);
    const VectorT qd = softrne_test::random_vector(rng, n, 2.0);
    const VectorT zero = VectorT::Zero(n);
    compute_kinematics(chain, data, q_before, qd);
    const MatrixXd M = mass_matrix(chain, data, q);
    std::vector<Placement<double>> after_mass_matrix;
    for (int i = 0; i < data.num_segments(); ++i)
      after_mass_matrix.push_back(distal_placement(chain, data, i));
    compute_kinematics(chain, data, q, zero);
    for (int i = 0; i < data.num_segments(); ++i) {
      const Placement<double> reference = distal_placement(chain, data, i);
      EXPECT_EQ(after_mass_matrix[static_cast<std::size_t>(i)].R, reference.R);
      EXPECT_EQ(after_mass_matrix[static_cast<std::size_t>(i)].p, reference.p);
    }
    compute_kinematics(chain, data, q_before, qd);
    mass_matrix_and_bias(chain, data, q, qd);
    EXPECT_LT(softrne_test::rel_err(data.mass_matrix, M), 1e-15);
  }
}

TEST(RneaIdentities, MassMatrixLeavesTheKinematicsAtQ) {
  std::mt19937 rng(41);
  DynamicChain<double> dyn = hybrid();
  dyn.add(softrne_test::random_cc<DistributedInertia<>>(rng), "distributed");
  check_mass_matrix_kinematics<DynamicChain<double>, VectorXd>(dyn, rng);
  using CC = ConstantCurvatureJoint<double>;
  using CCD = ConstantCurvatureJoint<double, DistributedInertia<>>;
  using RL = RigidLink<double>;
  using RJ = RevoluteJoint<double>;
  Chain<RJ, RL, CC, RL, CCD, RJ> st(softrne_test::random_rev(rng), softrne_test::random_link(rng),
                                    softrne_test::random_cc(rng), softrne_test::random_link(rng),
                                    softrne_test::random_cc<DistributedInertia<>>(rng),
                                    softrne_test::random_rev(rng));
  st.gravity << 0.0, 0.0, -9.81;
  check_mass_matrix_kinematics<decltype(st), Eigen::Matrix<double, 6, 1>>(st, rng);
}

TEST(RneaClosedForm, SingleJointWithTipMassStaticEquilibrium) {
  // A CC joint with gravity sideways (-y) bending about x only, with a point-like tip mass M:
  // V(u) = g (m r_c,y + M r_e,y), r_e,y = -h (1 - cos u)/u, r_c,y = -h (u - sin u)/u^2, and
  // the equilibrium k u + dV/du = 0 found here by bisection on that scalar equation.
  const double m = 0.8, h = 0.2, M = 0.5, k = 6.0, g = 9.81;
  DynamicChain<double> c;
  auto cc = softrne_test::paper_cc<double>(m, h, 0.2);
  c.add(cc, "j");
  RigidLink<double> tip;
  tip.mass = M;
  tip.inertia = Eigen::Matrix3d::Identity() * 1e-12;
  c.add(tip, "tip");
  c.gravity << 0, -g, 0;
  auto dVdu = [&](double u) {
    const double s = std::sin(u), co = std::cos(u);
    const double drc = -h * ((1 - co) / (u * u) - 2 * (u - s) / (u * u * u));
    const double dre = -h * (s / u - (1 - co) / (u * u));
    return g * (m * drc + M * dre);
  };
  double lo = 0.01, hi = 3.0;
  auto f = [&](double u) { return k * u + dVdu(u); };
  ASSERT_LT(f(lo) * f(hi), 0.0);
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (f(lo) * f(mid) <= 0 ? hi : lo) = mid;
  }
  const double u_star = 0.5 * (lo + hi);
  EXPECT_GT(u_star, 0.1);
  auto data = c.make_data();
  const VectorXd q = (VectorXd(2) << u_star, 0.0).finished();
  const VectorXd G = gravity(c, data, q);
  EXPECT_NEAR(G(0) + k * u_star, 0.0, 1e-12);
  EXPECT_NEAR(G(1), 0.0, 1e-12);
  std::printf("[ info ] equilibrium u* = %.6f rad, residual %.2e N m\n", u_star, G(0) + k * u_star);
}

// The README's controller example holds references to the results of rnea, mass_matrix,
// gravity and bias in turn, then runs forward dynamics: each result must still be its own
// (each algorithm writes its own field), equal to the same call on a fresh Data.
TEST(RneaReadme, ControllerExampleKeepsEachResult) {
  using CC = ConstantCurvatureJoint<double>;
  using RL = RigidLink<double>;
  using Arm = Chain<CC, RL, CC, RL>;
  const Arm arm(softrne_test::paper_cc<double>(), softrne_test::paper_link<double>(),
                softrne_test::paper_cc<double>(), softrne_test::paper_link<double>());
  auto data = arm.make_data();
  Arm::VectorQ q, qd, qdd;
  q << 0.3, -0.2, 0.5, 0.1;
  qd << 1.0, -0.5, 0.7, 2.0;
  qdd << 0.4, 0.3, -0.8, 1.2;
  const Arm::VectorQ& tau = rnea(arm, data, q, qd, qdd);
  const Arm::MatrixQ& M = mass_matrix(arm, data, q);
  const Arm::VectorQ& G = gravity(arm, data, q);
  const Arm::VectorQ& Cqd = bias(arm, data, q, qd);
  const Arm::VectorQ u = Arm::VectorQ::Zero();
  const Arm::VectorQ qdd_dense = forward_dynamics(arm, data, q, qd, u);
  const Arm::VectorQ qdd_on = aba(arm, data, q, qd, u);
  auto fresh = [&] { return arm.make_data(); };
  auto d1 = fresh(), d2 = fresh(), d3 = fresh(), d4 = fresh();
  EXPECT_EQ(tau, rnea(arm, d1, q, qd, qdd));
  EXPECT_EQ(M, mass_matrix(arm, d2, q));
  EXPECT_EQ(G, gravity(arm, d3, q));
  EXPECT_EQ(Cqd, bias(arm, d4, q, qd));
  // The three forces differ (the test could not pass if they all held one field), and agree.
  EXPECT_GT((tau - G).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_GT((G - Cqd).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_LT(softrne_test::rel_err(tau, M * qdd + Cqd + G), 1e-13);
  EXPECT_LT(softrne_test::rel_err(qdd_dense, qdd_on), 1e-10);
}

TEST(RneaAllocation, StaticChainAlgorithmsDoNotAllocate) {
  using CC = ConstantCurvatureJoint<double>;
  using RL = RigidLink<double>;
  Chain<CC, RL, CC, RL, CC, RL> arm(softrne_test::paper_cc<double>(), softrne_test::paper_link<double>(),
                                    softrne_test::paper_cc<double>(), softrne_test::paper_link<double>(),
                                    softrne_test::paper_cc<double>(), softrne_test::paper_link<double>());
  auto data = arm.make_data();
  Eigen::Matrix<double, 6, 1> q, qd, qdd;
  q << 0.1, 0.2, -0.3, 0.4, 0.5, -0.6;
  qd << 1, 2, 3, -1, -2, -3;
  qdd.setOnes();
  const long eigen_failures_before = softrne_test::eigen_assert_failures;
  Eigen::internal::set_is_malloc_allowed(false);
  rnea(arm, data, q, qd, qdd);
  gravity(arm, data, q);
  bias(arm, data, q, qd);
  mass_matrix(arm, data, q);
  mass_matrix_and_bias(arm, data, q, qd);
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_EQ(softrne_test::eigen_assert_failures, eigen_failures_before)
      << "heap allocation where forbidden";
}

TEST(RneaAllocation, RuntimeChainAlgorithmsDoNotAllocateAfterMakeData) {
  const auto chain = softrne_test::paper_arm();
  auto data = chain.make_data();
  const VectorXd q = VectorXd::Constant(6, 0.3), qd = VectorXd::Constant(6, -0.5),
                 qdd = VectorXd::Ones(6);
  const long eigen_failures_before = softrne_test::eigen_assert_failures;
  Eigen::internal::set_is_malloc_allowed(false);
  rnea(chain, data, q, qd, qdd);
  mass_matrix_and_bias(chain, data, q, qd);
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_EQ(softrne_test::eigen_assert_failures, eigen_failures_before)
      << "heap allocation where forbidden";
}

}  // namespace core_test_rnea
