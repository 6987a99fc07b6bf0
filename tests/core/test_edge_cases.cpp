// Numerical edge cases of the core, against references that share none of its code:
// the CC arc integrated as an ODE and summed as thin disks at bending angles beyond pi,
// physical identities of the RNE (C(q, qd) qd is quadratic in qd; qd' C qd = qd' Mdot qd / 2
// from finite differences of M; M scales linearly with the masses), very large velocities,
// tiny and huge masses, and the debug-build checks of API misuse (death tests).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "softrne/softrne.hpp"
#include "support.hpp"

namespace core_test_edge_cases {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::VectorXd;
using softrne::ConstantCurvatureJoint;
using softrne::DynamicChain;
using softrne::RevoluteJoint;
using softrne::RigidLink;
using CC = ConstantCurvatureJoint<double>;
using Link = RigidLink<double>;

CC make_cc(double mass = 0.8, double height = 0.2, double diameter = 0.15) {
  CC j;
  j.mass = mass;
  j.height = height;
  j.diameter = diameter;
  j.stiffness << 30, 25;
  j.damping << 2, 1.5;
  return j;
}

Link make_link(double mass = 1.5, double length = 0.15) {
  Link l;
  l.mass = mass;
  l.length = length;
  l.com << 0.01, -0.02, length / 2;
  // Inertia proportional to the mass (principal moments 0.0052, 0.0050, 0.0048 at 1.5 kg).
  l.inertia << 0.0052, 0.0003, -0.0001, 0.0003, 0.0050, 0.0002, -0.0001, 0.0002, 0.0048;
  l.inertia *= mass / 1.5;
  return l;
}

RevoluteJoint<double> make_revolute() {
  RevoluteJoint<double> r;
  r.axis = Vector3d(0.3, -0.2, 1.0).normalized();
  r.stiffness = 0.5;
  r.damping = 0.1;
  return r;
}

/// Hybrid arm: CC, link, CC, link, revolute, link; every mass multiplied by `mass_scale`
/// (`link_scale` additionally for the links).
DynamicChain<double> hybrid_arm(double mass_scale = 1.0, double link_scale = 1.0) {
  DynamicChain<double> c;
  c.add(make_cc(0.8 * mass_scale), "joint1");
  c.add(make_link(1.5 * mass_scale * link_scale), "link1");
  c.add(make_cc(0.6 * mass_scale, 0.18, 0.12), "joint2");
  c.add(make_link(1.0 * mass_scale * link_scale, 0.1), "link2");
  c.add(make_revolute(), "wrist");
  c.add(make_link(0.3 * mass_scale * link_scale, 0.05), "link3");
  c.gravity << 0.0, 0.0, 9.81;
  return c;
}

// --- independent references for the CC arc --------------------------------------------

// dR/dl = R [kappa]x, dp/dl = R e_z with constant body-frame curvature kappa = (u, v, 0)/h:
// exact rotation increments (Rodrigues via Eigen::AngleAxis) and Simpson on each step.
void integrate_arc(const Vector2d& q, double h, int n, Matrix3d& R, Vector3d& p) {
  const Vector3d kappa = Vector3d(q(0), q(1), 0) / h;
  const Vector3d axis = kappa.norm() > 0 ? kappa.normalized() : Vector3d::UnitX();
  const double dl = h / n;
  const Matrix3d dR = Eigen::AngleAxisd(kappa.norm() * dl, axis).toRotationMatrix();
  const Matrix3d dR_half = Eigen::AngleAxisd(kappa.norm() * dl / 2, axis).toRotationMatrix();
  R.setIdentity();
  p.setZero();
  for (int i = 0; i < n; ++i) {
    p += dl / 6 * (R.col(2) + 4 * (R * dR_half).col(2) + (R * dR).col(2));
    R = R * dR;
  }
}

// Centre of mass of the arc by the midpoint rule over n points, the points found by
// walking the arc as above (Simpson on each step of length h/n, starting half a step in).
Vector3d arc_com(const Vector2d& q, double h, int n) {
  const Vector3d kappa = Vector3d(q(0), q(1), 0) / h;
  const Vector3d axis = kappa.norm() > 0 ? kappa.normalized() : Vector3d::UnitX();
  const double dl = h / n;
  auto rot = [&](double l) { return Eigen::AngleAxisd(kappa.norm() * l, axis).toRotationMatrix(); };
  const Matrix3d dR = rot(dl), dR_half = rot(dl / 2);
  // First midpoint: the arc of length dl/2 (Simpson with its own midpoint at dl/4).
  Matrix3d R = dR_half;
  Vector3d p = dl / 12 * (Vector3d::UnitZ() + 4 * rot(dl / 4).col(2) + R.col(2));
  Vector3d sum = Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    sum += p;
    p += dl / 6 * (R.col(2) + 4 * (R * dR_half).col(2) + (R * dR).col(2));
    R = R * dR;
  }
  return sum / n;
}

bool is_rotation(const Matrix3d& R, double tol) {
  return (R.transpose() * R - Matrix3d::Identity()).norm() < tol &&
         std::abs(R.determinant() - 1.0) < tol;
}

const std::vector<double> kBeyondPi = {M_PI + 1e-9, 4.0, 6.0, 2 * M_PI, 10.0, 25.0};
const std::vector<double> kDirections = {0.0, 0.7, 2.0, -2.5};

TEST(EdgeCases, CCJointBeyondPiMatchesIntegratedArc) {
  const CC j = make_cc();
  for (double phi : kBeyondPi) {
    for (double dir : kDirections) {
      SCOPED_TRACE("phi " + std::to_string(phi) + " dir " + std::to_string(dir));
      const Vector2d q(phi * std::cos(dir), phi * std::sin(dir));
      const Vector2d qd(0.8, -1.3);
      CC::Kinematics k;
      j.calc(q, qd, k);
      EXPECT_TRUE(
          k.R_base_distal.allFinite() && k.r_base_distal.allFinite() && k.r_base_com.allFinite() &&
          k.J_distal.allFinite() && k.Jdot_qdot_distal.allFinite() && k.J_com.allFinite() &&
          k.Jdot_qdot_com.allFinite() && k.inertia_com.allFinite() && k.inertia_rate.allFinite() &&
          k.dinertia_dq[0].allFinite() && k.dinertia_dq[1].allFinite());
      EXPECT_TRUE(is_rotation(k.R_base_distal, 1e-12));
      Matrix3d R;
      Vector3d p;
      integrate_arc(q, j.height, 4000, R, p);
      EXPECT_LT((k.R_base_distal - R).norm(), 1e-11);
      EXPECT_LT((k.r_base_distal - p).norm() / j.height, 1e-10);
      // The chord is never longer than the arc; past 2 pi the arc has closed on itself.
      EXPECT_LE(k.r_base_distal.norm(), j.height * (1 + 1e-12));
      // Centre of mass of the arc (midpoint rule, Richardson-extrapolated).
      const Vector3d c1 = arc_com(q, j.height, 1000), c2 = arc_com(q, j.height, 2000);
      EXPECT_LT((k.r_base_com - (4 * c2 - c1) / 3).norm() / j.height, 1e-8);
      // Inertia about the COM: symmetric positive definite.
      EXPECT_LT((k.inertia_com - k.inertia_com.transpose()).norm(), 1e-14 * k.inertia_com.norm());
      const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(k.inertia_com);
      EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
    }
  }
}

TEST(EdgeCases, CCJointJacobianBeyondPiMatchesFiniteDifferences) {
  const CC j = make_cc();
  const double eps = 1e-6;
  for (double phi : kBeyondPi) {
    for (double dir : kDirections) {
      SCOPED_TRACE("phi " + std::to_string(phi) + " dir " + std::to_string(dir));
      const Vector2d q(phi * std::cos(dir), phi * std::sin(dir));
      CC::Kinematics k;
      j.calc(q, Vector2d::Zero(), k);
      for (int c = 0; c < 2; ++c) {
        CC::Kinematics kp, km;
        j.calc(q + eps * Vector2d::Unit(c), Vector2d::Zero(), kp);
        j.calc(q - eps * Vector2d::Unit(c), Vector2d::Zero(), km);
        // Linear velocity rows of J_distal (base frame, bottom 3) and the COM Jacobian.
        const Vector3d dr = (kp.r_base_distal - km.r_base_distal) / (2 * eps);
        const Vector3d dcom = (kp.r_base_com - km.r_base_com) / (2 * eps);
        // Angular velocity: vee(dR R^T), in the base frame (top 3 rows).
        const Matrix3d W =
            (kp.R_base_distal - km.R_base_distal) / (2 * eps) * k.R_base_distal.transpose();
        const Vector3d w(W(2, 1), W(0, 2), W(1, 0));
        const Eigen::Matrix<double, 6, 1> col = k.J_distal.col(c);
        const bool ok_order1 =
            (col.head<3>() - w).norm() < 1e-7 && (col.tail<3>() - dr).norm() < 1e-7;
        const bool ok_order2 =
            (col.tail<3>() - w).norm() < 1e-7 && (col.head<3>() - dr).norm() < 1e-7;
        EXPECT_TRUE(ok_order1 || ok_order2) << "J column " << c << ": " << col.transpose()
                                            << " vs w " << w.transpose() << " v " << dr.transpose();
        EXPECT_LT((k.J_com.col(c) - dcom).norm(), 1e-7);
      }
    }
  }
}

/// qd' C(q, qd) qd = qd' Mdot qd / 2 (the kinetic-energy balance, with Mdot from central
/// differences of mass_matrix along qd), and C(q, s qd) qd s = s^2 C(q, qd) qd.
void check_rnea_identities(const DynamicChain<double>& arm, const VectorXd& q, const VectorXd& qd,
                           double tol) {
  auto data = arm.make_data();
  const VectorXd b = softrne::bias(arm, data, q, qd);
  const VectorXd b2 = softrne::bias(arm, data, q, (2.0 * qd).eval());
  ASSERT_TRUE(b.allFinite() && b2.allFinite());
  EXPECT_LT((b2 - 4 * b).norm(), tol * std::max(1.0, b2.norm()));

  const double eps = 1e-6 / std::max(1.0, qd.norm());
  const MatrixXd Mp = softrne::mass_matrix(arm, data, (q + eps * qd).eval());
  const MatrixXd Mm = softrne::mass_matrix(arm, data, (q - eps * qd).eval());
  const MatrixXd Mdot = (Mp - Mm) / (2 * eps);
  const double lhs = qd.dot(b), rhs = 0.5 * qd.dot(Mdot * qd);
  EXPECT_NEAR(lhs, rhs, 1e-6 * std::max(1.0, std::abs(rhs))) << "qd'Cqd " << lhs;

  const VectorXd qdd = VectorXd::LinSpaced(q.size(), -3.0, 2.0);
  const VectorXd tau = softrne::rnea(arm, data, q, qd, qdd);
  const MatrixXd M = softrne::mass_matrix(arm, data, q);
  const VectorXd g = softrne::gravity(arm, data, q);
  ASSERT_TRUE(tau.allFinite() && M.allFinite() && g.allFinite());
  EXPECT_LT((tau - (M * qdd + b + g)).norm(), tol * std::max(1.0, tau.norm()));
  EXPECT_LT((M - M.transpose()).norm(), 1e-12 * M.norm());
  EXPECT_EQ(Eigen::LLT<MatrixXd>(M).info(), Eigen::Success);
}

TEST(EdgeCases, RneaBeyondPi) {
  const auto arm = hybrid_arm();
  const int nq = arm.num_coordinates();
  ASSERT_EQ(nq, 5);
  for (double phi : {4.0, 6.0, 10.0}) {
    for (double dir : kDirections) {
      SCOPED_TRACE("phi " + std::to_string(phi) + " dir " + std::to_string(dir));
      VectorXd q(nq), qd(nq);
      q << phi * std::cos(dir), phi * std::sin(dir), -phi * std::sin(dir), phi * std::cos(dir), phi;
      qd << 1.1, -0.7, 0.4, 2.0, -1.5;
      check_rnea_identities(arm, q, qd, 1e-12);
    }
  }
}

TEST(EdgeCases, HugeVelocitiesStayFinite) {
  const auto arm = hybrid_arm();
  const int nq = arm.num_coordinates();
  auto data = arm.make_data();
  for (double speed : {1e3, 1e5}) {
    for (double phi : {0.0, 1e-9, 1.0, 4.0}) {
      SCOPED_TRACE("speed " + std::to_string(speed) + " phi " + std::to_string(phi));
      VectorXd q = VectorXd::Constant(nq, phi / std::sqrt(2.0));
      VectorXd qd(nq);
      qd << 1.0, -0.6, 0.8, 0.3, -1.0;
      qd *= speed;
      const VectorXd tau = softrne::rnea(arm, data, q, qd, VectorXd::Zero(nq));
      EXPECT_TRUE(tau.allFinite()) << tau.transpose();
      // Forward dynamics with those velocities: finite accelerations.
      const VectorXd qdd = softrne::forward_dynamics(arm, data, q, qd, VectorXd::Zero(nq));
      EXPECT_TRUE(qdd.allFinite()) << qdd.transpose();
      check_rnea_identities(arm, q, qd, 1e-11);
    }
  }
}

TEST(EdgeCases, TinyAndHugeMassesKeepMPositiveDefinite) {
  const auto unit = hybrid_arm(1.0);
  auto du = unit.make_data();
  VectorXd q(5), qd(5);
  q << 0.4, -0.9, 4.0, 1.0, 0.3;
  qd << 1.0, 2.0, -1.0, 0.5, 3.0;
  const MatrixXd M1 = softrne::mass_matrix(unit, du, q);
  for (double s : {1e-12, 1e-6, 1e6, 1e12}) {
    SCOPED_TRACE("mass scale " + std::to_string(s));
    const auto arm = hybrid_arm(s);
    auto data = arm.make_data();
    const MatrixXd M = softrne::mass_matrix(arm, data, q);
    ASSERT_TRUE(M.allFinite());
    // Every mass and inertia scaled by s: M scales by s exactly (up to rounding).
    EXPECT_LT((M - s * M1).norm(), 1e-12 * s * M1.norm());
    EXPECT_EQ(Eigen::LLT<MatrixXd>(M).info(), Eigen::Success);
    const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(M);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
    const VectorXd qdd = softrne::forward_dynamics(arm, data, q, qd, VectorXd::Zero(5));
    EXPECT_TRUE(qdd.allFinite());
  }
  // Mixed: links 1e6 times heavier or lighter than the joints.
  for (double r : {1e-6, 1e6}) {
    SCOPED_TRACE("link/joint mass ratio " + std::to_string(r));
    const auto arm = hybrid_arm(1.0, r);
    auto data = arm.make_data();
    const MatrixXd M = softrne::mass_matrix(arm, data, q);
    ASSERT_TRUE(M.allFinite());
    EXPECT_LT((M - M.transpose()).norm(), 1e-12 * M.norm());
    EXPECT_EQ(Eigen::LLT<MatrixXd>(M).info(), Eigen::Success);
    EXPECT_TRUE(softrne::forward_dynamics(arm, data, q, qd, VectorXd::Zero(5)).allFinite());
    EXPECT_TRUE(softrne::rnea(arm, data, q, qd, VectorXd::Ones(5)).allFinite());
  }
}

TEST(EdgeCases, StaticChainBeyondPiAgreesWithRuntimeChain) {
  using Arm = softrne::Chain<CC, Link, CC, Link>;
  Arm arm(make_cc(), make_link(), make_cc(0.6, 0.18, 0.12), make_link(1.0, 0.1));
  arm.gravity << 0.0, 0.0, 9.81;
  DynamicChain<double> dyn;
  dyn.add(make_cc());
  dyn.add(make_link());
  dyn.add(make_cc(0.6, 0.18, 0.12));
  dyn.add(make_link(1.0, 0.1));
  dyn.gravity = arm.gravity;
  auto ds = arm.make_data();
  auto dd = dyn.make_data();
  Arm::VectorQ q, qd, qdd;
  q << 6.0, -2.0, 0.5, 9.5;
  qd << 1e3, -2e3, 5e2, 1e3;
  qdd << 1, 2, 3, 4;
  const Arm::VectorQ tau = softrne::rnea(arm, ds, q, qd, qdd);
  const VectorXd tau_dyn = softrne::rnea(dyn, dd, VectorXd(q), VectorXd(qd), VectorXd(qdd));
  ASSERT_TRUE(tau.allFinite());
  EXPECT_LT((tau - tau_dyn).norm(), 1e-12 * tau.norm());
}

// A revolute joint about exactly x, y or z takes the placements' fast path
// (spatial/axis_rotation.hpp): against its twin whose axis is off by 1e-150 (the general
// products, the same physics to far below rounding), every algorithm agrees to rounding,
// on a hybrid chain with axes +-x, +-y, +-z (-e_k takes the general path too).
TEST(EdgeCases, RevoluteAboutCoordinateAxesAgreesWithTheGeneralPath) {
  std::mt19937 rng(17);
  DynamicChain<double> fast, general;
  int fast_paths = 0;
  for (int j = 0; j < 7; ++j) {
    RevoluteJoint<double> r;
    r.axis = Vector3d::Unit(j % 3) * (j == 4 ? -1.0 : 1.0);
    r.stiffness = 0.5;
    r.damping = 0.1;
    RevoluteJoint<double> twin = r;
    twin.axis((j + 1) % 3) = 1e-150;
    EXPECT_EQ(r.coordinate_axis(), j == 4 ? -1 : j % 3);
    EXPECT_EQ(twin.coordinate_axis(), -1);
    fast_paths += r.coordinate_axis() >= 0;
    fast.add(r);
    general.add(twin);
    if (j == 3) {  // a CC joint in the middle
      fast.add(make_cc());
      general.add(make_cc());
    }
    const Link l = make_link(0.5 + 0.2 * j, 0.1 + 0.02 * j);
    fast.add(l);
    general.add(l);
  }
  ASSERT_EQ(fast_paths, 6);
  fast.gravity = general.gravity = Vector3d(0.3, -1.0, 9.81);
  auto df = fast.make_data();
  auto dg = general.make_data();
  const int n = fast.num_coordinates();
  auto random = [&] { return softrne_test::random_vector(rng, n, 2.0); };
  using softrne_test::rel_err;
  for (int s = 0; s < 5; ++s) {
    const VectorXd q = random(), qd = random(), qdd = random(), tau = random();
    EXPECT_LT(rel_err(softrne::rnea(fast, df, q, qd, qdd), softrne::rnea(general, dg, q, qd, qdd)),
              1e-13);
    EXPECT_LT(rel_err(softrne::mass_matrix(fast, df, q), softrne::mass_matrix(general, dg, q)),
              1e-13);
    EXPECT_LT(rel_err(softrne::aba(fast, df, q, qd, tau), softrne::aba(general, dg, q, qd, tau)),
              1e-12);
    EXPECT_LT(rel_err(softrne::forward_dynamics(fast, df, q, qd, tau),
                    softrne::forward_dynamics(general, dg, q, qd, tau)),
              1e-12);
    softrne::aba_derivatives(fast, df, q, qd, tau);
    softrne::aba_derivatives(general, dg, q, qd, tau);
    EXPECT_LT(rel_err(df.dqddot_dq, dg.dqddot_dq), 1e-11);
    EXPECT_LT(rel_err(df.dqddot_dqdot, dg.dqddot_dqdot), 1e-11);
    softrne::rnea_derivatives(fast, df, q, qd, qdd);
    softrne::rnea_derivatives(general, dg, q, qd, qdd);
    EXPECT_LT(rel_err(df.dtau_dq, dg.dtau_dq), 1e-13);
    EXPECT_LT(rel_err(df.dtau_dqdot, dg.dtau_dqdot), 1e-13);
  }
}

// --- misuse of a runtime chain: always-on checks (std::invalid_argument), also in Release --

// The message of `f()`'s std::invalid_argument (fails the test if it throws nothing).
template <class F>
std::string invalid_argument_message(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no std::invalid_argument";
  return {};
}

void expect_contains(const std::string& message, const std::string& part) {
  EXPECT_NE(message.find(part), std::string::npos) << message;
}

TEST(EdgeCasesMisuse, DataOfAnotherRuntimeChainThrows) {
  const auto arm = hybrid_arm();
  DynamicChain<double> small;
  small.add(make_cc());
  small.add(make_link());
  auto other = small.make_data();
  const VectorXd z = VectorXd::Zero(arm.num_coordinates());
  const std::string expected = "this Data was made for another chain";
  expect_contains(invalid_argument_message([&] { (void)softrne::rnea(arm, other, z, z, z); }), expected);
  expect_contains(invalid_argument_message([&] { (void)softrne::mass_matrix(arm, other, z); }), expected);
  expect_contains(invalid_argument_message([&] { (void)softrne::gravity(arm, other, z); }), expected);
  expect_contains(invalid_argument_message([&] { (void)softrne::bias(arm, other, z, z); }), expected);
  expect_contains(invalid_argument_message([&] { (void)softrne::aba(arm, other, z, z, z); }), expected);
  DynamicChain<double>::Data empty;
  expect_contains(invalid_argument_message([&] { (void)softrne::rnea(arm, empty, z, z, z); }), expected);
}

// The message names the algorithm, the argument and both sizes, and nothing is read out of
// bounds (this test runs in the Release build and under the sanitizers).
TEST(EdgeCasesMisuse, WrongVectorSizesThrowNamingTheArgumentAndBothSizes) {
  const auto arm = hybrid_arm();
  auto data = arm.make_data();
  const int n = arm.num_coordinates();
  const VectorXd z = VectorXd::Zero(n);
  const VectorXd shorter = VectorXd::Zero(n - 1);
  const VectorXd longer = VectorXd::Zero(n + 1);
  const std::string has = " coordinates", sizes_short = std::to_string(n - 1) + " entries; the chain has " +
                                                          std::to_string(n) + has,
                    sizes_long = std::to_string(n + 1) + " entries; the chain has " + std::to_string(n) + has;
  EXPECT_EQ(invalid_argument_message([&] { (void)softrne::rnea(arm, data, shorter, z, z); }),
            "softrne::rnea: q has " + sizes_short);
  EXPECT_EQ(invalid_argument_message([&] { (void)softrne::rnea(arm, data, z, longer, z); }),
            "softrne::rnea: qdot has " + sizes_long);
  EXPECT_EQ(invalid_argument_message([&] { (void)softrne::rnea(arm, data, z, z, shorter); }),
            "softrne::rnea: qddot has " + sizes_short);
  EXPECT_EQ(invalid_argument_message([&] { (void)softrne::mass_matrix(arm, data, longer); }),
            "softrne::mass_matrix: q has " + sizes_long);
  EXPECT_EQ(invalid_argument_message([&] { (void)softrne::gravity(arm, data, shorter); }),
            "softrne::gravity: q has " + sizes_short);
  EXPECT_EQ(invalid_argument_message([&] { (void)softrne::bias(arm, data, z, VectorXd()); }),
            "softrne::bias: qdot has 0 entries; the chain has " + std::to_string(n) + has);
  EXPECT_EQ(invalid_argument_message([&] { (void)softrne::forward_dynamics(arm, data, z, z, longer); }),
            "softrne::forward_dynamics: tau has " + sizes_long);
  EXPECT_EQ(invalid_argument_message([&] { (void)softrne::aba(arm, data, z, shorter, z); }),
            "softrne::aba: qdot has " + sizes_short);
  EXPECT_EQ(invalid_argument_message([&] { softrne::compute_kinematics(arm, data, longer, z); }),
            "softrne::compute_kinematics: q has " + sizes_long);
  // After a refused call the chain and its Data still work.
  EXPECT_TRUE(softrne::rnea(arm, data, z, z, z).allFinite());
}

// A Data of a chain with the same number of segments and coordinates but other segment
// types passes the size checks; the traversal then finds kinematics of another type.
TEST(EdgeCasesMisuse, DataOfSameSizedChainWithOtherSegmentsThrows) {
  DynamicChain<double> a, b;
  a.add(make_cc());
  a.add(make_link());
  b.add(make_link());
  b.add(make_cc());
  auto data_b = b.make_data();
  const VectorXd z = VectorXd::Zero(2);
  expect_contains(invalid_argument_message([&] { (void)softrne::rnea(a, data_b, z, z, z); }),
                  "this Data was made for another chain (segment 0 has another type");
}

}  // namespace core_test_edge_cases
