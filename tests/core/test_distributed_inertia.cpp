// The distributed-inertia CC joint (ConstantCurvatureJoint<S, DistributedInertia<NG>>): closed
// form at q = 0, convergence of M, C qdot, G to the continuum of thin disks (an independent
// 2,000-disk midpoint sum with its own kinematics), Euler-Lagrange of the quadrature disks'
// energy on mixed chains (AutoDiff, autodiff_reference.hpp), energy conservation, static == runtime chain, identities
// between the algorithms, the own-body inertia that the articulated-body algorithm uses.
#include "../eigen_malloc_guard.hpp"  // first: before anything includes Eigen
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>

#include <Eigen/Eigenvalues>

#include "softrne/softrne.hpp"
#include "autodiff_reference.hpp"
#include "support.hpp"

namespace core_test_distributed_inertia {

using namespace softrne;
using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

template <class S, int NG = kDefaultGaussPoints>
ConstantCurvatureJoint<S, DistributedInertia<NG>> dist_cc(double mass = 0.8, double h = 0.2,
                                                          double D = 0.2) {
  return softrne_test::paper_cc<S>(mass, h, D).template with_inertia<DistributedInertia<NG>>();
}

// ---------------------------------------------------------------------------------------
// Closed form at q = 0: the disk at fraction s turns by s u and moves sideways by s^2 h u / 2,
// so M_uu = int_0^1 m (s^4 h^2/4 + s^2 D^2/16) ds = m (h^2/20 + D^2/48). Lumped: m (h^2/9 +
// D^2/16) (centre of mass along -h u/3, whole body turning with u).
TEST(DistributedInertia, ClosedFormStraightJoint) {
  for (const auto& hd : {std::pair<double, double>{0.2, 0.2}, {0.3, 0.05}, {0.05, 0.3}}) {
    const double m = 0.8, h = hd.first, D = hd.second;
    Chain<ConstantCurvatureJoint<double, DistributedInertia<>>> cd(dist_cc<double>(m, h, D));
    Chain<ConstantCurvatureJoint<double>> cl(softrne_test::paper_cc<double>(m, h, D));
    auto dd = cd.make_data();
    auto dl = cl.make_data();
    const Eigen::Vector2d q0 = Eigen::Vector2d::Zero();
    const Eigen::Matrix2d Md = mass_matrix(cd, dd, q0), Ml = mass_matrix(cl, dl, q0);
    const double dist = m * (h * h / 20 + D * D / 48), lump = m * (h * h / 9 + D * D / 16);
    EXPECT_LT(std::abs(Md(0, 0) / dist - 1), 1e-12);
    EXPECT_LT(std::abs(Md(1, 1) / dist - 1), 1e-12);
    EXPECT_LT(std::abs(Md(0, 1)), 1e-15 * dist);
    EXPECT_LT(std::abs(Ml(0, 0) / lump - 1), 1e-12);
    EXPECT_LT(std::abs(Ml(1, 1) / lump - 1), 1e-12);
    std::printf("[ info ] h = %.2f, D = %.2f: M_uu distributed %.6e, lumped %.6e (ratio %.3f)\n",
                h, D, Md(0, 0), Ml(0, 0), Ml(0, 0) / Md(0, 0));
  }
}

// ---------------------------------------------------------------------------------------
// Independent continuum reference. A second-order jet in one variable t (value, first and
// second derivative) carries the disks' poses along q(t) = q + t d; with d = e_u, e_v it gives
// the Jacobians, with d = qdot the velocity and (qddot = 0) the acceleration.
struct Jet {
  double a = 0, b = 0, c = 0;  // f, f', f''
};
Jet operator+(Jet x, Jet y) { return {x.a + y.a, x.b + y.b, x.c + y.c}; }
Jet operator-(Jet x, Jet y) { return {x.a - y.a, x.b - y.b, x.c - y.c}; }
Jet operator*(Jet x, Jet y) { return {x.a * y.a, x.a * y.b + x.b * y.a, x.a * y.c + 2 * x.b * y.b + x.c * y.a}; }
Jet operator*(double k, Jet x) { return {k * x.a, k * x.b, k * x.c}; }
Jet inv(Jet x) { return {1 / x.a, -x.b / (x.a * x.a), 2 * x.b * x.b / (x.a * x.a * x.a) - x.c / (x.a * x.a)}; }
Jet operator/(Jet x, Jet y) { return x * inv(y); }
Jet sin(Jet x) { return {std::sin(x.a), std::cos(x.a) * x.b, -std::sin(x.a) * x.b * x.b + std::cos(x.a) * x.c}; }
Jet cos(Jet x) { return {std::cos(x.a), -std::sin(x.a) * x.b, -std::cos(x.a) * x.b * x.b - std::sin(x.a) * x.c}; }
Jet sqrt(Jet x) {
  const double r = std::sqrt(x.a);
  return {r, x.b / (2 * r), x.c / (2 * r) - x.b * x.b / (4 * r * r * r)};
}

// Pose of the disk at arc fraction s along q(t) = q + t d: Rodrigues' rotation by s phi about
// k = (u, v, 0)/phi, position h (sin(s phi)/phi e_z + (1 - cos(s phi))/phi^2 (v, -u, 0)) (the
// integral of the tangent R(sigma w) e_z). Needs phi > 0.
struct DiskJets {
  Jet R[3][3];
  Jet p[3];
};
DiskJets disk_pose(const Eigen::Vector2d& q, const Eigen::Vector2d& d, double s, double h) {
  const Jet u{q(0), d(0), 0}, v{q(1), d(1), 0};
  const Jet phi = sqrt(u * u + v * v);
  const Jet th = s * phi;
  const Jet k[3] = {u / phi, v / phi, Jet{}};
  const Jet ct = cos(th), st = sin(th), vc = Jet{1, 0, 0} - ct;
  DiskJets o;
  const Jet K[3][3] = {{Jet{}, Jet{} - k[2], k[1]}, {k[2], Jet{}, Jet{} - k[0]}, {Jet{} - k[1], k[0], Jet{}}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) o.R[i][j] = (i == j ? ct : Jet{}) + st * K[i][j] + vc * k[i] * k[j];
  o.p[0] = h * (vc / (phi * phi) * v);
  o.p[1] = h * (Jet{} - vc / (phi * phi) * u);
  o.p[2] = h * (st / phi);
  return o;
}
Vector3d vee_skew(const Matrix3d& A) {  // axial vector of the skew part
  return 0.5 * Vector3d(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1));
}

struct Continuum {
  Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
  Eigen::Vector2d Cqd = Eigen::Vector2d::Zero(), G = Eigen::Vector2d::Zero();
};

// M, C qdot, G of one CC joint on a fixed base, as the midpoint sum over n disks.
Continuum midpoint_sum(int n, double m, double h, double D, const Eigen::Vector2d& q,
                       const Eigen::Vector2d& qd, const Vector3d& g) {
  Continuum c;
  const Matrix3d I_disk = Vector3d(D * D / 16, D * D / 16, D * D / 8).asDiagonal();
  for (int i = 0; i < n; ++i) {
    const double s = (i + 0.5) / n, dm = m / n;
    Eigen::Matrix<double, 3, 2> Jv, Jw;
    for (int k = 0; k < 2; ++k) {
      const DiskJets e = disk_pose(q, Eigen::Vector2d::Unit(k), s, h);
      Matrix3d R, Rd;
      for (int a = 0; a < 3; ++a) {
        Jv(a, k) = e.p[a].b;
        for (int b = 0; b < 3; ++b) R(a, b) = e.R[a][b].a, Rd(a, b) = e.R[a][b].b;
      }
      Jw.col(k) = vee_skew(Rd * R.transpose());
    }
    const DiskJets e = disk_pose(q, qd, s, h);
    Matrix3d R, Rd, Rdd;
    Vector3d acc;
    for (int a = 0; a < 3; ++a) {
      acc(a) = e.p[a].c;
      for (int b = 0; b < 3; ++b) R(a, b) = e.R[a][b].a, Rd(a, b) = e.R[a][b].b, Rdd(a, b) = e.R[a][b].c;
    }
    const Vector3d w = vee_skew(Rd * R.transpose()), alpha = vee_skew(Rdd * R.transpose());
    const Matrix3d I = dm * R * I_disk * R.transpose();
    c.M += dm * Jv.transpose() * Jv + Jw.transpose() * I * Jw;
    c.Cqd += dm * Jv.transpose() * acc + Jw.transpose() * (I * alpha + w.cross(I * w));
    c.G -= dm * Jv.transpose() * g;
  }
  return c;
}

// The 2,000-disk midpoint sum, Richardson-extrapolated with the 1,000-disk sum (midpoint
// error ~ 1/n^2: the extrapolation leaves ~1/n^4, far below 1e-12 relative).
Continuum continuum(double m, double h, double D, const Eigen::Vector2d& q,
                    const Eigen::Vector2d& qd, const Vector3d& g) {
  const Continuum a = midpoint_sum(2000, m, h, D, q, qd, g), b = midpoint_sum(1000, m, h, D, q, qd, g);
  Continuum c;
  c.M = (4 * a.M - b.M) / 3;
  c.Cqd = (4 * a.Cqd - b.Cqd) / 3;
  c.G = (4 * a.G - b.G) / 3;
  return c;
}

template <int NG>
Continuum quadrature(double m, double h, double D, const Eigen::Vector2d& q,
                     const Eigen::Vector2d& qd, const Vector3d& g) {
  Chain<ConstantCurvatureJoint<double, DistributedInertia<NG>>> c(dist_cc<double, NG>(m, h, D));
  c.gravity = g;
  auto d = c.make_data();
  Continuum r;
  r.M = mass_matrix(c, d, q);
  r.Cqd = bias(c, d, q, qd);
  r.G = gravity(c, d, q);
  return r;
}

struct Errors {
  double M = 0, C = 0, G = 0;
};

template <int... NG>
void convergence_table(std::integer_sequence<int, NG...>, double q_scale, Errors* out) {
  std::mt19937 rng(7);
  const double m = 0.8, h = 0.2, D = 0.2;
  const Vector3d g(0.3, -1.0, 9.81);
  for (int trial = 0; trial < 12; ++trial) {
    const Eigen::Vector2d q = softrne_test::random_vector(rng, 2, q_scale);
    const Eigen::Vector2d qd = softrne_test::random_vector(rng, 2, 3.0);
    const Continuum ref = continuum(m, h, D, q, qd, g);
    int i = 0;
    (([&] {
       const Continuum c = quadrature<NG>(m, h, D, q, qd, g);
       Errors& e = out[i++];
       e.M = std::max(e.M, (c.M - ref.M).norm() / ref.M.norm());
       e.C = std::max(e.C, (c.Cqd - ref.Cqd).norm() / ref.Cqd.norm());
       e.G = std::max(e.G, (c.G - ref.G).norm() / ref.G.norm());
     }()),
     ...);
  }
}

TEST(DistributedInertia, ConvergenceToContinuum) {
  // Sanity of the reference itself: at a small bend (its closed forms lose digits to
  // cancellation at tiny ones) it approaches the q = 0 closed form (M changes as phi^2).
  {
    const Continuum r = continuum(0.8, 0.2, 0.2, Eigen::Vector2d(1e-3, 0), Eigen::Vector2d::Zero(),
                                  Vector3d::Zero());
    EXPECT_LT(std::abs(r.M(0, 0) / (0.8 * (0.04 / 20 + 0.04 / 48)) - 1), 1e-5);
  }
  using Points = std::integer_sequence<int, 1, 2, 3, 4, 5, 6, 7, 8, 10, 12>;
  const int ng[] = {1, 2, 3, 4, 5, 6, 7, 8, 10, 12};
  for (double q_scale : {0.7, 1.4, 2.2}) {
    Errors e[10];
    convergence_table(Points{}, q_scale, e);
    std::printf("[ info ] |u|, |v| <= %.1f (phi <= %.2f): max relative error vs the continuum\n",
                q_scale, q_scale * std::sqrt(2.0));
    std::printf("[ info ]   NG      M         C qdot    G\n");
    for (int i = 0; i < 10; ++i) {
      std::printf("[ info ]   %2d  %.2e  %.2e  %.2e\n", ng[i], e[i].M, e[i].C, e[i].G);
      if (ng[i] == kDefaultGaussPoints && q_scale <= 1.4) {
        EXPECT_LT(e[i].M, 1e-8);
        EXPECT_LT(e[i].C, 1e-8);
        EXPECT_LT(e[i].G, 1e-8);
      }
      if (ng[i] == kDefaultGaussPoints + 1) {  // one more point: up to phi = pi
        EXPECT_LT(e[i].M, 1e-8);
        EXPECT_LT(e[i].C, 1e-8);
        EXPECT_LT(e[i].G, 1e-8);
      }
      if (ng[i] == 12) {
        EXPECT_LT(e[i].M, 1e-11);
        EXPECT_LT(e[i].C, 1e-11);
        EXPECT_LT(e[i].G, 1e-11);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// The disks' inertia is eq. 20 (D^2/16 (1, 1, 2) in the disk's frame, times its mass) rotated
// with the disk. Their Jacobians and rates against AutoDiff and finite differences:
// tests/segments/test_segment_conformance.cpp.
TEST(DistributedInertia, DiskInertiaIsEquation20) {
  const auto j = dist_cc<double>();
  std::mt19937 rng(3);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector2d q = softrne_test::random_vector(rng, 2, trial < 5 ? 1e-3 : 2.0);
    const Eigen::Vector2d qd = softrne_test::random_vector(rng, 2, 2.0);
    decltype(j)::Kinematics k;
    j.calc(q, qd, k);
    for (const auto& B : k.sub_bodies) {
      const Matrix3d& R = B.R_base_body;
      const Matrix3d Ib = R * Vector3d(1, 1, 2).asDiagonal() * R.transpose() * B.mass * 0.04 / 16;
      worst = std::max(worst, (B.inertia - Ib).norm() / Ib.norm());
    }
  }
  EXPECT_LT(worst, 1e-13);
}

// ---------------------------------------------------------------------------------------
// Euler-Lagrange of the quadrature disks' energy (plus the lumped bodies of the other
// segments), differentiated with AutoDiff (autodiff_reference.hpp, as tests/core/test_rnea.cpp
// does for the lumped chain).

// Distributed CC joints mixed with links, a revolute joint and a lumped CC joint.
DynamicChain<double> mixed() {
  DynamicChain<double> c;
  c.add(dist_cc<double>(0.8, 0.2, 0.2), "j1");
  c.add(softrne_test::paper_link<double>(1.5, 0.15), "l1");
  c.add(softrne_test::revolute<double>(1, 0.2, 0), "elbow");
  c.add(softrne_test::paper_link<double>(0.7, 0.2), "l2");
  c.add(softrne_test::paper_cc<double>(0.5, 0.15, 0.12), "j2");  // lumped
  c.add(softrne_test::paper_link<double>(0.4, 0.05), "l3");
  c.add(dist_cc<double>(0.3, 0.1, 0.1), "j3");
  c.add(softrne_test::paper_link<double>(0.1, 0.03), "tip");
  c.gravity << 0.3, -1.0, 9.81;
  return c;
}

DynamicChain<double> dist_only() {
  DynamicChain<double> c;
  c.add(dist_cc<double>(0.8, 0.2, 0.2), "j1");
  c.add(dist_cc<double>(0.5, 0.15, 0.12), "j2");
  c.add(dist_cc<double>(0.3, 0.1, 0.1), "j3");
  c.gravity << 0.0, 0.0, -9.81;
  return c;
}

#if SOFTRNE_TEST_AUTODIFF_REFERENCES
using softrne_test::check_against_lagrangian;
TEST(DistributedLagrangian, DistributedOnly) { check_against_lagrangian(dist_only(), 40, 1.6, 41); }
TEST(DistributedLagrangian, MixedChain) { check_against_lagrangian(mixed(), 40, 1.6, 42); }
#else
TEST(DistributedLagrangian, InTheReleaseTestsOnly) {
  GTEST_SKIP() << "AutoDiff references are not built here (SOFTRNE_TEST_AUTODIFF_REFERENCES=OFF)";
}
#endif
TEST(DistributedLagrangian, InertiaRateOptionIsIrrelevant) {
  // The disks are rigid: PaperFrozen changes only the lumped joint.
  auto a = dist_only();
  auto b = dist_only();
  b.inertia_rate = InertiaRate::PaperFrozen;
  auto da = a.make_data(), db = b.make_data();
  std::mt19937 rng(43);
  const VectorXd q = softrne_test::random_vector(rng, 6, 1.0), qd = softrne_test::random_vector(rng, 6, 2.0),
                 qdd = softrne_test::random_vector(rng, 6, 2.0);
  EXPECT_EQ(rnea(a, da, q, qd, qdd), rnea(b, db, q, qd, qdd));
}

// ---------------------------------------------------------------------------------------
TEST(DistributedIdentities, GravityBiasMassMatrixForwardDynamics) {
  for (const auto& chain : {mixed(), dist_only()}) {
    auto data = chain.make_data();
    const int n = chain.num_coordinates();
    std::mt19937 rng(51);
    double worst_fd = 0;
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
      EXPECT_EQ(M, M.transpose());
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatrixXd>(M).eigenvalues().minCoeff(), 0.0);
      // M from the composite-inertia sweep against the RNE's columns.
      EXPECT_LT(softrne_test::rel_err(rnea(chain, data, q, qd, qdd), M * qdd + Cqd + G), 1e-13);
      const VectorXd tau = rnea(chain, data, q, qd, qdd);
      const VectorXd qdd2 = forward_dynamics(chain, data, q, qd, tau);
      worst_fd = std::max(worst_fd, softrne_test::rel_err(qdd2, qdd));
      // qd^T (dM/dt - 2C) qd = 0.
      const double eps = 1e-6;
      const MatrixXd Mp = mass_matrix(chain, data, VectorXd(q + eps * qd));
      const MatrixXd Mm = mass_matrix(chain, data, VectorXd(q - eps * qd));
      const double sk = qd.dot((Mp - Mm) / (2 * eps) * qd) - 2 * qd.dot(Cqd);
      EXPECT_LT(std::abs(sk), 1e-7 * std::max(1.0, std::abs(qd.dot(Cqd))));
    }
    EXPECT_LT(worst_fd, 1e-10);
  }
}

TEST(DistributedIdentities, StaticChainEqualsRuntimeChain) {
  using DCC = ConstantCurvatureJoint<double, DistributedInertia<>>;
  using CC = ConstantCurvatureJoint<double>;
  using RL = RigidLink<double>;
  using RJ = RevoluteJoint<double>;
  Chain<DCC, RL, RJ, RL, CC, RL, DCC, RL> st(
      dist_cc<double>(0.8, 0.2, 0.2), softrne_test::paper_link<double>(1.5, 0.15),
      softrne_test::revolute<double>(1, 0.2, 0), softrne_test::paper_link<double>(0.7, 0.2),
      softrne_test::paper_cc<double>(0.5, 0.15, 0.12), softrne_test::paper_link<double>(0.4, 0.05),
      dist_cc<double>(0.3, 0.1, 0.1), softrne_test::paper_link<double>(0.1, 0.03));
  st.gravity << 0.3, -1.0, 9.81;
  const auto dyn = mixed();
  static_assert(decltype(st)::nq == 7);
  auto sd = st.make_data();
  auto dd = dyn.make_data();
  std::mt19937 rng(61);
  for (int s = 0; s < 30; ++s) {
    const VectorXd q = softrne_test::random_vector(rng, 7, 2.0);
    const VectorXd qd = softrne_test::random_vector(rng, 7, 2.0);
    const VectorXd qdd = softrne_test::random_vector(rng, 7, 5.0);
    const Eigen::Matrix<double, 7, 1> qs = q, qds = qd, qdds = qdd;
    EXPECT_EQ(VectorXd(rnea(st, sd, qs, qds, qdds)), rnea(dyn, dd, q, qd, qdd));
    EXPECT_EQ(MatrixXd(mass_matrix(st, sd, qs)), mass_matrix(dyn, dd, q));
    EXPECT_EQ(VectorXd(forward_dynamics(st, sd, qs, qds, qdds)), forward_dynamics(dyn, dd, q, qd, qdd));
  }
}

// The lumped and distributed models share the distal-frame kinematics and the total mass and
// centre of mass (to quadrature accuracy); they differ in M.
TEST(DistributedIdentities, SameKinematicsAndGravityOnRigidPayload) {
  const auto jl = softrne_test::paper_cc<double>();
  const auto jd = dist_cc<double>();
  std::mt19937 rng(71);
  for (int s = 0; s < 20; ++s) {
    const Eigen::Vector2d q = softrne_test::random_vector(rng, 2, 1.4), qd = softrne_test::random_vector(rng, 2, 2.0);
    decltype(jl)::Kinematics kl;
    decltype(jd)::Kinematics kd;
    jl.calc(q, qd, kl);
    jd.calc(q, qd, kd);
    EXPECT_EQ(kl.R_base_distal, kd.R_base_distal);
    EXPECT_EQ(kl.J_distal, kd.J_distal);
    EXPECT_EQ(kl.Jdot_qdot_distal, kd.Jdot_qdot_distal);
    EXPECT_LT((kl.r_base_com - kd.r_base_com).norm(), 1e-12);
    EXPECT_LT((kl.J_com - kd.J_com).norm(), 1e-12);
    EXPECT_LT((kl.Jdot_qdot_com - kd.Jdot_qdot_com).norm(), 1e-11);
  }
}

// ---------------------------------------------------------------------------------------
// A free arm (springs, no damping, no pressure) conserves T + V_gravity + V_spring.
TEST(DistributedEnergy, FreeMotionConservesEnergy) {
  using DCC = ConstantCurvatureJoint<double, DistributedInertia<>>;
  using RL = RigidLink<double>;
  Chain<DCC, RL, DCC, RL> arm(dist_cc<double>(0.8, 0.2, 0.2), softrne_test::paper_link<double>(0.3, 0.1),
                              dist_cc<double>(0.4, 0.15, 0.15), softrne_test::paper_link<double>(0.1, 0.05));
  arm.gravity << 0.0, 0.0, 9.81;
  using VQ = decltype(arm)::VectorQ;
  const VQ k = (VQ() << 4.0, 5.0, 2.0, 2.5).finished();
  auto data = arm.make_data();
  auto energy = [&](const VQ& q, const VQ& qd) {
    double T, V;
    softrne_test::energies(arm, q, qd, T, V);
    return T + V + 0.5 * q.dot(k.cwiseProduct(q));
  };
  auto accel = [&](const VQ& q, const VQ& qd) {
    const VQ tau = -k.cwiseProduct(q);
    return VQ(forward_dynamics(arm, data, q, qd, tau));
  };
  VQ q = (VQ() << 0.9, -0.6, 1.2, 0.4).finished(), qd = (VQ() << 0.0, 2.0, -3.0, 1.0).finished();
  const double E0 = energy(q, qd);
  double T0, V0;
  softrne_test::energies(arm, q, qd, T0, V0);
  const double dt = 2e-4;
  double drift = 0, max_speed = 0;
  for (int step = 0; step < 15000; ++step) {  // 3 s, RK4
    const VQ a1 = accel(q, qd);
    const VQ a2 = accel(q + 0.5 * dt * qd, qd + 0.5 * dt * a1);
    const VQ a3 = accel(q + 0.5 * dt * (qd + 0.5 * dt * a1), qd + 0.5 * dt * a2);
    const VQ a4 = accel(q + dt * (qd + 0.5 * dt * a2), qd + dt * a3);
    q += dt * qd + dt * dt / 6 * (a1 + a2 + a3);
    qd += dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    if (step % 100 == 99) {
      drift = std::max(drift, std::abs(energy(q, qd) - E0));
      max_speed = std::max(max_speed, qd.cwiseAbs().maxCoeff());
    }
  }
  // T from the disks equals 1/2 qd^T M qd.
  double T, V;
  softrne_test::energies(arm, q, qd, T, V);
  EXPECT_LT(std::abs(T - 0.5 * qd.dot(mass_matrix(arm, data, q) * qd)), 1e-13 * std::max(1.0, T));
  std::printf("[ info ] 3 s free motion (max |qd| %.2f rad/s, T0 %.3f J): max |E - E0| = %.2e J\n",
              max_speed, T0, drift);
  EXPECT_GT(max_speed, 1.0);
  EXPECT_LT(drift, 1e-9);
}

// ---------------------------------------------------------------------------------------
// The own-body inertia the articulated-body algorithm uses (algorithms/own_inertia.hpp)
// resolves to the disks' overload and agrees with the RNE.
TEST(DistributedOwnInertia, MatchesRneOfSingleSegment) {
  using DCC = ConstantCurvatureJoint<double, DistributedInertia<>>;
  Chain<DCC> c(dist_cc<double>());
  auto data = c.make_data();
  std::mt19937 rng(81);
  for (int s = 0; s < 10; ++s) {
    const Eigen::Vector2d q = softrne_test::random_vector(rng, 2, 1.5);
    const Eigen::Vector2d z = Eigen::Vector2d::Zero();
    const Eigen::Matrix2d M = mass_matrix(c, data, q);
    OwnBodyInertia<double, 2> own;
    detail::own_body_inertia(std::get<0>(c.segments), std::get<0>(data.kinematics), own);
    EXPECT_LT((own.joint - M).norm(), 1e-15 * M.norm());
    c.gravity.setZero();
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector2d e = Eigen::Vector2d::Unit(k);
      detail::rnea_passes(c, data, z, e, false, false, data.tau);
      Eigen::Matrix<double, 6, 1> w;
      w << data.wrench[0].force, data.wrench[0].torque;
      EXPECT_LT((own.coupling.col(k) - w).norm(), 1e-14 * std::max(1.0, w.norm()));
    }
    // Rigid base acceleration a0 (gravity -a0): the wrench is spatial * (a0; 0).
    const Vector3d a0(0.4, -2.0, 7.0);
    c.gravity = -a0;
    detail::rnea_passes(c, data, z, z, true, false, data.tau);
    Eigen::Matrix<double, 6, 1> w, m;
    w << data.wrench[0].force, data.wrench[0].torque;
    m << a0, Vector3d::Zero();
    EXPECT_LT((own.spatial() * m - w).norm(), 1e-13 * w.norm());
  }
}

// The articulated-body algorithm (articulated_body.hpp) on chains with distributed joints,
// through the overload above, against the Cholesky forward dynamics.
TEST(DistributedOwnInertia, ArticulatedBodyMatchesForwardDynamics) {
  for (const auto& chain : {mixed(), dist_only()}) {
    auto data = chain.make_data();
    const int n = chain.num_coordinates();
    std::mt19937 rng(91);
    double worst = 0;
    for (int s = 0; s < 20; ++s) {
      const VectorXd q = softrne_test::random_vector(rng, n, 1.6);
      const VectorXd qd = softrne_test::random_vector(rng, n, 2.0);
      const VectorXd tau = softrne_test::random_vector(rng, n, 3.0);
      const VectorXd a = forward_dynamics(chain, data, q, qd, tau);
      const VectorXd b = aba(chain, data, q, qd, tau);
      worst = std::max(worst, softrne_test::rel_err(b, a));
    }
    std::printf("[ info ] aba vs forward_dynamics, %d coordinates: worst %.2e\n", n, worst);
    EXPECT_LT(worst, 1e-11);
  }
}

TEST(DistributedAllocation, RuntimeChainAlgorithmsDoNotAllocateAfterMakeData) {
  const auto chain = mixed();
  auto data = chain.make_data();
  const VectorXd q = VectorXd::Constant(7, 0.3), qd = VectorXd::Constant(7, -0.5),
                 qdd = VectorXd::Ones(7);
  const long eigen_failures_before = softrne_test::eigen_assert_failures;
  Eigen::internal::set_is_malloc_allowed(false);
  rnea(chain, data, q, qd, qdd);
  gravity(chain, data, q);
  bias(chain, data, q, qd);
  mass_matrix(chain, data, q);
  forward_dynamics(chain, data, q, qd, qdd);
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_EQ(softrne_test::eigen_assert_failures, eigen_failures_before)
      << "heap allocation where forbidden";
}

}  // namespace core_test_distributed_inertia
