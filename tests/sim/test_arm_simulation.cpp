// Arm simulation (simulate_arm, ArmSystem) against independent references:
//  - static equilibrium without gravity: q = K^-1 K_prs p in closed form;
//  - small oscillations: the linearisation x' = A x at q = 0 with M(0) from a hand-written
//    kinetic energy, solved through the eigen-decomposition of A (mode frequencies/decays);
//  - the bundled arm against a fixed-step RK4 written here on ArmDynamics<double>;
//  - the AutoDiff Jacobians against central finite differences, including the equilibrium
//    q = qdot = 0, p = 0 (where Eigen's triangular solve once dropped AutoDiff derivatives).
#include <cmath>
#include <complex>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "softrne/algorithms/mass_matrix.hpp"
#include "softrne/arm/arm_dynamics.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_spec.hpp"
#include "softrne/signals/pchip.hpp"
#include "softrne/sim/arm_simulation.hpp"
#include "test_arms.hpp"

#if __has_include(<nlohmann/json.hpp>)
#include "softrne/io/robot_json.hpp"
#define SOFTRNE_TEST_HAS_JSON 1
#endif

namespace sim_test_arm_simulation {

using softrne::test::link;
using softrne::test::three_joint_arm;

using Eigen::MatrixXd;
using Eigen::VectorXd;
using softrne::ArmDescription;
using softrne::build_arm;
using softrne::io::RobotSpec;
using softrne::sim::ArmSimulation;
using softrne::sim::ArmSimulationOptions;
using softrne::sim::ArmSystem;
using softrne::sim::simulate_arm;
using JM = ArmSimulationOptions::JacobianMethod;
using PI = ArmSimulationOptions::PressureInterpolation;

// ---- robots built in code -------------------------------------------------------------

/// CC joint, link, CC joint, link; gravity as given.
RobotSpec two_joint_arm(const Eigen::Vector3d& gravity, double damping_scale = 1.0) {
  using softrne::io::make_cc_joint;
  RobotSpec s;
  s.name = "test arm";
  s.gravity = gravity;
  s.segments.push_back(make_cc_joint("joint1", 0.8, 0.2, 0.2, 0.06, 0.03, Eigen::Vector2d(40, 33),
                                     damping_scale * Eigen::Vector2d(3.0, 2.5)));
  s.segments.push_back(link("link1", 1.2, 0.15, 0.07, 0.004, 0.003));
  s.segments.push_back(make_cc_joint("joint2", 0.6, 0.18, 0.16, 0.05, 0.028,
                                     Eigen::Vector2d(22, 18),
                                     damping_scale * Eigen::Vector2d(1.2, 1.0)));
  s.segments.push_back(link("link2", 0.4, 0.05, 0.025, 0.0004, 0.0005));
  return s;
}

/// Diagonal K_spring, K_d and the block-diagonal K_prs of an arm of CC joints.
struct JointMatrices {
  MatrixXd K, D, Kprs;
};
JointMatrices joint_matrices(const ArmDescription& d) {
  JointMatrices m{MatrixXd::Zero(d.nq, d.nq), MatrixXd::Zero(d.nq, d.nq),
                  MatrixXd::Zero(d.nq, d.num_inputs)};
  for (const auto& j : d.joints)
    for (int k = 0; k < j.nq; ++k) {
      m.K(j.q_offset + k, j.q_offset + k) = j.stiffness(k);
      m.D(j.q_offset + k, j.q_offset + k) = j.damping(k);
      for (int c = 0; c < j.num_inputs; ++c)
        m.Kprs(j.q_offset + k, j.input_offset + c) = j.pressure_to_torque(k, c);
    }
  return m;
}

ArmSimulationOptions tight_options() {
  ArmSimulationOptions o;
  o.cvode.rtol = 1e-11;
  o.cvode.atol = 1e-13;
  o.cvode.max_steps = 2000000;
  o.velocity_atol_factor = 1.0;
  return o;
}

// ---- 1. static equilibrium without gravity ---------------------------------------------

TEST(ArmSimulation, StaticEquilibriumWithoutGravityIsKInverseKprsP) {
  const ArmDescription d = build_arm(two_joint_arm(Eigen::Vector3d::Zero(), 4.0));
  const JointMatrices m = joint_matrices(d);
  VectorXd p(d.num_inputs);
  p << 120e3, 20e3, 35e3, 90e3,  // joint 1: (u, v) torques of opposite signs
      10e3, 80e3, 70e3, 5e3;
  // Closed form (K diagonal): q = K^-1 K_prs p, here a few tenths of a radian.
  const VectorXd q_star = m.Kprs * p;
  VectorXd q_expected(d.nq);
  for (int i = 0; i < d.nq; ++i) q_expected(i) = q_star(i) / m.K(i, i);
  ASSERT_GT(q_expected.cwiseAbs().minCoeff(), 0.05);
  ASSERT_LT(q_expected.cwiseAbs().maxCoeff(), 1.0);

  // The right-hand side vanishes there: at rest, with C qdot = G = 0, M qddot = K_prs p - K q.
  const VectorXd t = VectorXd::LinSpaced(401, 0.0, 40.0);
  const MatrixXd P = p.transpose().replicate(t.size(), 1);
  ArmSystem sys(d, t, P, PI::pchip);
  VectorXd x(d.num_states()), xdot(d.num_states());
  x << q_expected, VectorXd::Zero(d.nq);
  ASSERT_TRUE(sys.rhs(3.0, x, xdot));
  EXPECT_LT(xdot.cwiseAbs().maxCoeff(), 1e-12);

  // Simulated from rest at q = 0 until the transient (slowest decay ~ 2/s) has died out.
  const ArmSimulation sim = simulate_arm(d, t, P, VectorXd::Zero(d.nq), tight_options());
  ASSERT_TRUE(sim.ok()) << sim.result.message;
  const VectorXd q_end = sim.angles.bottomRows(1).transpose();
  const VectorXd v_end = sim.states.bottomRows(1).rightCols(d.nq).transpose();
  std::printf("[   info   ] |q_end - K^-1 Kprs p| = %.2e rad, |qdot_end| = %.2e rad/s\n",
              (q_end - q_expected).cwiseAbs().maxCoeff(), v_end.cwiseAbs().maxCoeff());
  EXPECT_LT((q_end - q_expected).cwiseAbs().maxCoeff(), 1e-8)
      << "simulated " << q_end.transpose() << "\nexpected  " << q_expected.transpose();
  EXPECT_LT(v_end.cwiseAbs().maxCoeff(), 1e-8);
}

// ---- 2. small oscillations against the linearisation -----------------------------------

/// A body of the arm at q = 0 in the plane of the u coordinates (rotation about x): mass,
/// inertia about its centre of mass (about x), and per coordinate u_i the centre of mass's
/// lever (|velocity| per unit rate) and the body's angular rate. Straight arm, everything on
/// the z axis, so the v plane is the same and u/v do not couple.
struct PlanarBody {
  double mass, inertia;
  std::vector<double> lever, rate;
};

/// M(0) of the u (= v) plane from T = 1/2 sum_b (m_b |v_b|^2 + I_b w_b^2).
MatrixXd planar_mass_matrix(const std::vector<PlanarBody>& bodies, int n) {
  MatrixXd M = MatrixXd::Zero(n, n);
  for (const auto& b : bodies)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        M(i, j) += b.mass * b.lever[i] * b.lever[j] + b.inertia * b.rate[i] * b.rate[j];
  return M;
}

/// A CC joint straight along z: its centre of mass (height h/2) moves h/6 per unit bending
/// rate, its distal origin h/2; about its centre of mass it is a stack of thin disks,
/// I = m (D^2/16 + h^2/12) (paper eqs. 19-22 at q = 0).
double cc_inertia(double m, double h, double D) {
  return m * (D * D / 16 + h * h / 12);
}

/// x(t) = Re(V exp(Lambda t) V^-1 x0) for x' = A x: the modes of the linearisation.
struct ModalSolution {
  Eigen::VectorXcd lambda;
  Eigen::MatrixXcd V, Vinv;
  explicit ModalSolution(const MatrixXd& A) {
    Eigen::EigenSolver<MatrixXd> es(A);
    lambda = es.eigenvalues();
    V = es.eigenvectors();
    Vinv = V.inverse();
  }
  VectorXd at(double t, const VectorXd& x0) const {
    const Eigen::VectorXcd c = Vinv * x0.cast<std::complex<double>>();
    Eigen::VectorXcd e(c.size());
    for (Eigen::Index k = 0; k < c.size(); ++k) e(k) = std::exp(lambda(k) * t) * c(k);
    return (V * e).real();
  }
};

/// Simulates a small displacement eps * dir from rest (no gravity, no pressure) and compares
/// with the modal solution of A = [[0, I], [-M^-1 K, -M^-1 D]].
void check_small_oscillations(const RobotSpec& spec, const MatrixXd& M, double t_end,
                              const VectorXd& dir) {
  const ArmDescription d = build_arm(spec);
  const JointMatrices m = joint_matrices(d);
  const int n = d.nq;
  MatrixXd A = MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = -M.ldlt().solve(m.K);
  A.bottomRightCorner(n, n) = -M.ldlt().solve(m.D);
  const ModalSolution modes(A);
  for (Eigen::Index k = 0; k < modes.lambda.size(); ++k) {
    // Every mode oscillates (damped, not overdamped) and is resolved over the run.
    EXPECT_GT(std::abs(modes.lambda(k).imag()), 1.0) << "mode " << k << ": " << modes.lambda(k);
    EXPECT_LT(modes.lambda(k).real(), 0.0);
  }

  const double eps = 1e-6;  // nonlinear terms are O(eps) relative
  const VectorXd t = VectorXd::LinSpaced(static_cast<Eigen::Index>(t_end / 0.002) + 1, 0.0, t_end);
  const MatrixXd P = MatrixXd::Zero(t.size(), d.num_inputs);
  ArmSimulationOptions o = tight_options();
  o.cvode.rtol = 1e-12;
  o.cvode.atol = 1e-10 * eps;
  const ArmSimulation sim = simulate_arm(d, t, P, eps * dir, o);
  ASSERT_TRUE(sim.ok()) << sim.result.message;
  VectorXd x0 = VectorXd::Zero(2 * n);
  x0.head(n) = eps * dir;
  double worst = 0, peak = 0;
  for (Eigen::Index r = 0; r < t.size(); ++r) {
    const VectorXd lin = modes.at(t(r), x0);
    worst = std::max(worst, (sim.states.row(r).transpose() - lin).cwiseAbs().maxCoeff());
    peak = std::max(peak, lin.head(n).cwiseAbs().maxCoeff());
  }
  std::printf("[   info   ] max |x_sim - x_lin| / eps = %.2e; modes:", worst / eps);
  for (Eigen::Index k = 0; k < modes.lambda.size(); k += 2)
    std::printf(" %.3g%+.3gi", modes.lambda(k).real(), modes.lambda(k).imag());
  std::printf("\n");
  EXPECT_LT(worst / eps, 1e-4) << "max |x_sim - x_lin| / eps over " << t.size() << " samples";
  EXPECT_GT(peak / eps, 0.5);
}

TEST(ArmSimulation, SingleCCJointOscillatesWithTheModesOfItsLinearisation) {
  RobotSpec s;
  s.name = "one CC joint";
  s.segments.push_back(softrne::io::make_cc_joint("joint1", 0.8, 0.2, 0.2, 0.06, 0.03,
                                                  Eigen::Vector2d(3.0, 2.0),
                                                  Eigen::Vector2d(0.004, 0.003)));
  const double m = 0.8, h = 0.2, D = 0.2;
  // M(0) = m (h/6)^2 + m (D^2/16 + h^2/12) for u and v alike.
  const double Muu = m * h * h / 36 + cc_inertia(m, h, D);
  const MatrixXd M = Muu * MatrixXd::Identity(2, 2);
  {  // The library agrees with the closed form (a sanity check of the reference itself).
    const ArmDescription d = build_arm(s);
    auto chain = d.make_chain<double>();
    auto data = chain.make_data();
    const MatrixXd M_lib = softrne::mass_matrix(chain, data, VectorXd::Zero(2));
    EXPECT_LT((M_lib - M).cwiseAbs().maxCoeff(), 1e-14 * Muu);
  }
  check_small_oscillations(s, M, 2.0, Eigen::Vector2d(1.0, -0.6));
}

TEST(ArmSimulation, TwoJointArmOscillatesWithTheModesOfItsLinearisation) {
  const RobotSpec s = two_joint_arm(Eigen::Vector3d::Zero(), 0.05);
  const double m1 = 0.8, h1 = 0.2, D1 = 0.2, ml1 = 1.2, L1 = 0.15, c1 = 0.07, Il1 = 0.004;
  const double m2 = 0.6, h2 = 0.18, D2 = 0.16, ml2 = 0.4, c2 = 0.025, Il2 = 0.0004;
  // Levers per unit rate of (u1, u2): a point at height z above the distal origin of joint 1
  // moves h1/2 + z per unit u1 (the distal origin moves h1/2, then rigid rotation).
  const std::vector<PlanarBody> bodies = {
      {m1, cc_inertia(m1, h1, D1), {h1 / 6, 0}, {1, 0}},
      {ml1, Il1, {h1 / 2 + c1, 0}, {1, 0}},
      {m2, cc_inertia(m2, h2, D2), {h1 / 2 + L1 + h2 / 2, h2 / 6}, {1, 1}},
      {ml2, Il2, {h1 / 2 + L1 + h2 + c2, h2 / 2 + c2}, {1, 1}},
  };
  const MatrixXd Mp = planar_mass_matrix(bodies, 2);
  MatrixXd M = MatrixXd::Zero(4, 4);  // coordinates u1, v1, u2, v2
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      M(2 * i, 2 * j) = Mp(i, j);
      M(2 * i + 1, 2 * j + 1) = Mp(i, j);
    }
  {
    const ArmDescription d = build_arm(s);
    auto chain = d.make_chain<double>();
    auto data = chain.make_data();
    const MatrixXd M_lib = softrne::mass_matrix(chain, data, VectorXd::Zero(4));
    EXPECT_LT((M_lib - M).cwiseAbs().maxCoeff(), 1e-13 * M.cwiseAbs().maxCoeff());
  }
  check_small_oscillations(s, M, 3.0, Eigen::Vector4d(0.8, -0.5, -1.0, 0.7));
}

// ---- 3. the bundled arm against an RK4 written here -------------------------------------

#ifdef SOFTRNE_TEST_HAS_JSON
/// Classical RK4 on ArmDynamics<double> with the PCHIP pressures, n steps per sample interval
/// (so no step straddles a sample, where the interpolant's second derivative jumps).
MatrixXd rk4_reference(const ArmDescription& d, const VectorXd& t, const MatrixXd& P,
                       const VectorXd& x0, int substeps) {
  softrne::ArmDynamics<double> f(d);
  softrne::signals::PchipSignal u(t, P);
  VectorXd p(d.num_inputs);
  const int ns = d.num_states();
  auto rhs = [&](double tt, const VectorXd& x, VectorXd& xd) {
    u.value(tt, p);
    f.rhs(x, p, xd);
  };
  MatrixXd out(t.size(), ns);
  VectorXd x = x0, k1(ns), k2(ns), k3(ns), k4(ns);
  out.row(0) = x.transpose();
  for (Eigen::Index i = 0; i + 1 < t.size(); ++i) {
    const double h = (t(i + 1) - t(i)) / substeps;
    for (int s = 0; s < substeps; ++s) {
      const double tt = t(i) + s * h;
      rhs(tt, x, k1);
      rhs(tt + h / 2, x + h / 2 * k1, k2);
      rhs(tt + h / 2, x + h / 2 * k2, k3);
      rhs(tt + h, x + h * k3, k4);
      x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    out.row(i + 1) = x.transpose();
  }
  return out;
}

TEST(ArmSimulation, BundledArmMatchesAnIndependentRK4) {
  const std::string dir = std::string(SOFTRNE_DATA_DIR) + "/arm-a-1";
  const RobotSpec robot = softrne::io::read_robot_json(dir + "/robot.json");
  const ArmDescription d = build_arm(robot);
  const softrne::io::Dataset data = softrne::io::read_dataset(dir + "/test.csv", robot, true);
  Eigen::Index rows = 0;
  while (rows < data.t.size() && data.t(rows) <= data.t(0) + 2.0 + 1e-9) ++rows;
  ASSERT_GE(rows, 150);
  const VectorXd t = data.t.head(rows);
  const MatrixXd P = data.pressures.topRows(rows);
  const VectorXd q0 = data.angles.row(0).transpose();
  const VectorXd x0 = softrne::initial_state(d, q0, P.row(0).transpose());

  const MatrixXd ref = rk4_reference(d, t, P, x0, 32);
  const MatrixXd ref_fine = rk4_reference(d, t, P, x0, 64);
  const double ref_error = (ref - ref_fine).leftCols(d.nq).cwiseAbs().maxCoeff();
  EXPECT_LT(ref_error, 1e-8) << "the RK4 reference itself has not converged";

  const ArmSimulation sim = simulate_arm(d, t, P, q0, tight_options());
  ASSERT_TRUE(sim.ok()) << sim.result.message;
  const double diff = (sim.angles - ref_fine.leftCols(d.nq)).cwiseAbs().maxCoeff();
  std::printf("[   info   ] CVODE vs RK4: %.2e rad (RK4 32 vs 64 substeps: %.2e rad)\n", diff,
              ref_error);
  EXPECT_LT(diff, 1e-6) << "CVODE vs RK4, max over " << rows << " samples and " << d.nq
                        << " angles (RK4 self-consistency " << ref_error << ")";
  // The angles move (the comparison is not trivial).
  EXPECT_GT((ref_fine.leftCols(d.nq).bottomRows(1) - ref_fine.leftCols(d.nq).topRows(1))
                .cwiseAbs()
                .maxCoeff(),
            0.05);

  // The default (sensible, looser) tolerances stay well below the angle sensors' 3e-3 rad.
  const ArmSimulation def = simulate_arm(d, t, P, q0);
  ASSERT_TRUE(def.ok()) << def.result.message;
  const double def_diff = (def.angles - ref_fine.leftCols(d.nq)).cwiseAbs().maxCoeff();
  std::printf("[   info   ] default tolerances vs RK4: %.2e rad\n", def_diff);
  EXPECT_LT(def_diff, 1e-3);
}
#else
TEST(ArmSimulation, BundledArmMatchesAnIndependentRK4) {
  GTEST_SKIP() << "nlohmann/json.hpp not found: cannot read robot.json";
}
#endif

// ---- 4. AutoDiff Jacobians vs central finite differences --------------------------------

MatrixXd central_differences(ArmSystem& sys, double t, const VectorXd& x) {
  const int n = sys.size();
  MatrixXd J(n, n);
  VectorXd fp(n), fm(n);
  for (int j = 0; j < n; ++j) {
    const double h = 1e-6 * std::max(1.0, std::abs(x(j)));
    VectorXd xp = x, xm = x;
    xp(j) += h;
    xm(j) -= h;
    EXPECT_TRUE(sys.rhs(t, xp, fp));
    EXPECT_TRUE(sys.rhs(t, xm, fm));
    J.col(j) = (fp - fm) / (2 * h);
  }
  return J;
}

void check_jacobians(ArmSystem& sys, double t, const VectorXd& x, const std::string& where) {
  const int n = sys.size();
  VectorXd f(n);
  ASSERT_TRUE(sys.rhs(t, x, f));
  const MatrixXd J_fd = central_differences(sys, t, x);
  const double scale = std::max(1.0, J_fd.cwiseAbs().maxCoeff());
  MatrixXd J_inv = MatrixXd::Constant(n, n, 7.0), J_fwd = MatrixXd::Zero(n, n);  // J_inv: junk in
  sys.set_jacobian_method(JM::inverse_dynamics);
  ASSERT_TRUE(sys.jacobian(t, x, f, J_inv));
  sys.set_jacobian_method(JM::forward_dynamics);
  ASSERT_TRUE(sys.jacobian(t, x, f, J_fwd));
  std::printf(
      "[   info   ] %s: |J_ad - J_fd| / max|J| = %.1e (inverse), %.1e (forward); "
      "AD inverse vs forward %.1e\n",
      where.c_str(), (J_inv - J_fd).cwiseAbs().maxCoeff() / scale,
      (J_fwd - J_fd).cwiseAbs().maxCoeff() / scale, (J_inv - J_fwd).cwiseAbs().maxCoeff() / scale);
  EXPECT_LT((J_inv - J_fd).cwiseAbs().maxCoeff(), 1e-7 * scale) << where << " (inverse dynamics)";
  EXPECT_LT((J_fwd - J_fd).cwiseAbs().maxCoeff(), 1e-7 * scale) << where << " (forward dynamics)";
  EXPECT_LT((J_inv - J_fwd).cwiseAbs().maxCoeff(), 1e-11 * scale) << where << " (two AutoDiffs)";
}

TEST(ArmSystem, AutoDiffJacobianMatchesFiniteDifferencesAtRandomStates) {
  RobotSpec spec = three_joint_arm();
  // Effects with and without states of their own (actuator_lag adds one per chamber).
  softrne::io::EffectSpec lag{"actuator_lag", {"joint1", "joint3"}, {{"T", 0.05}}, ""};
  softrne::io::EffectSpec stiff{"stiffening", {"joint2"}, {{"beta", 0.8}}, ""};
  softrne::io::EffectSpec quad{
      "quadratic_damping", {"joint1", "joint2", "joint3"}, {{"c2", 0.3}}, ""};
  softrne::io::EffectSpec prs{"pressure_stiffening", {"joint1"}, {{"gamma", 2e-6}}, ""};
  softrne::io::EffectSpec mis{"chamber_misalignment", {"joint2"}, {{"psi", 0.2}}, ""};
  softrne::io::EffectSpec tip{"payload", {}, {{"mass", 0.3}}, ""};
  spec.effects = {lag, stiff, quad, prs, mis, tip};
  const ArmDescription d = build_arm(spec);
  ASSERT_EQ(d.num_states(), 12 + 8);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const VectorXd t = VectorXd::LinSpaced(101, 0.0, 1.0);
  MatrixXd P(t.size(), d.num_inputs);
  for (Eigen::Index i = 0; i < P.size(); ++i) P(i) = 75e3 + 75e3 * U(rng);
  ArmSystem sys(d, t, P, PI::pchip);
  for (int trial = 0; trial < 6; ++trial) {
    VectorXd x(d.num_states());
    for (int i = 0; i < d.nq; ++i) x(i) = 0.8 * U(rng);
    for (int i = d.nq; i < 2 * d.nq; ++i) x(i) = 3.0 * U(rng);
    for (int i = 2 * d.nq; i < d.num_states(); ++i) x(i) = 75e3 + 75e3 * U(rng);
    check_jacobians(sys, 0.37 + 0.1 * trial, x, "random state " + std::to_string(trial));
  }
}

TEST(ArmSystem, AutoDiffJacobianMatchesFiniteDifferencesAtTheEquilibrium) {
  // Exactly q = qdot = 0 with zero pressures: the hanging arm at rest, qddot = 0 exactly.
  // Regression: Eigen's triangular solve skipped right-hand sides whose value was exactly
  // zero and dropped their AutoDiff derivatives, which zeroed the acceleration rows of J.
  const ArmDescription d = build_arm(three_joint_arm());
  const VectorXd t = VectorXd::LinSpaced(11, 0.0, 0.1);
  const MatrixXd P = MatrixXd::Zero(t.size(), d.num_inputs);
  ArmSystem sys(d, t, P, PI::pchip);
  const VectorXd x = VectorXd::Zero(d.num_states());
  VectorXd f(d.num_states());
  ASSERT_TRUE(sys.rhs(0.05, x, f));
  EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-14);
  check_jacobians(sys, 0.05, x, "q = qdot = 0, p = 0");
  // The acceleration rows are not zero: the springs pull back.
  MatrixXd J = MatrixXd::Zero(d.num_states(), d.num_states());
  sys.set_jacobian_method(JM::inverse_dynamics);
  ASSERT_TRUE(sys.jacobian(0.05, x, f, J));
  EXPECT_GT(J.bottomLeftCorner(d.nq, d.nq).diagonal().cwiseAbs().minCoeff(), 1.0);
}

// ---- options -----------------------------------------------------------------------------

TEST(ArmSimulation, VelocityToleranceScalingOnlyChangesTheTolerances) {
  const ArmDescription d = build_arm(two_joint_arm(Eigen::Vector3d(0, 0, 9.81)));
  const VectorXd t = VectorXd::LinSpaced(201, 0.0, 2.0);
  MatrixXd P(t.size(), d.num_inputs);
  for (Eigen::Index i = 0; i < t.size(); ++i)
    for (int c = 0; c < d.num_inputs; ++c) P(i, c) = 60e3 + 50e3 * std::sin(2.0 * t(i) + c);
  ArmSimulationOptions a = tight_options(), b = tight_options();
  b.velocity_atol_factor = 100.0;
  const ArmSimulation sa = simulate_arm(d, t, P, VectorXd(), a);
  const ArmSimulation sb = simulate_arm(d, t, P, VectorXd(), b);
  ASSERT_TRUE(sa.ok() && sb.ok());
  EXPECT_LT((sa.states - sb.states).cwiseAbs().maxCoeff(), 1e-8);  // states unscaled
  EXPECT_GT(sa.states.rightCols(d.nq).cwiseAbs().maxCoeff(), 0.1);
  // Finite-difference Jacobian (CVODE's) gives the same solution too.
  a.autodiff_jacobian = false;
  const ArmSimulation sc = simulate_arm(d, t, P, VectorXd(), a);
  ASSERT_TRUE(sc.ok());
  EXPECT_LT((sa.states - sc.states).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(ArmSimulation, ReportsProgressAndFailsWithOneLine) {
  const ArmDescription d = build_arm(two_joint_arm(Eigen::Vector3d(0, 0, 9.81)));
  const VectorXd t = VectorXd::LinSpaced(301, 0.0, 3.0);
  MatrixXd P(t.size(), d.num_inputs);
  for (Eigen::Index i = 0; i < t.size(); ++i)
    for (int c = 0; c < d.num_inputs; ++c) P(i, c) = 60e3 + 50e3 * std::sin(5.0 * t(i) + c);
  ArmSimulationOptions o;
  double last = -1;
  int calls = 0;
  o.progress = [&](double tt) {
    ++calls;
    last = tt;
  };
  const ArmSimulation s = simulate_arm(d, t, P, VectorXd(), o);
  ASSERT_TRUE(s.ok());
  EXPECT_GT(calls, 0);
  EXPECT_GT(last, 0.0);
  EXPECT_LE(last, 3.0 + 1e-9);
  o.cvode.max_steps = 5;
  const ArmSimulation f = simulate_arm(d, t, P, VectorXd(), o);
  EXPECT_FALSE(f.ok());
  EXPECT_NE(f.result.message.find("CVODE failed at t = "), std::string::npos) << f.result.message;
  EXPECT_EQ(f.result.message.find('\n'), std::string::npos);
  EXPECT_EQ(f.angles.rows(), f.states.rows());
}

}  // namespace sim_test_arm_simulation
