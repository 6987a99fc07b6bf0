// Linearisation for control (linearisation.hpp, ArmJacobian) against independent references:
//  - A = df/dx and B = df/dp against central finite differences of ArmDynamics<double>::rhs
//    (the simulator's right-hand side) at random states of an arm with effects that have
//    states of their own (actuator_lag, viscoelastic) and effects that change the pressures;
//  - one zero-order-hold step x1 = x* + Ad dx0 + Bd dp + cd around an equilibrium
//    (static_equilibrium: every state's rate vanishes there, the effects' states included) against
//    CVODE (ArmSystem, tight tolerances) over one sample with constant pressures: the
//    difference is second order in the deviation (halving it quarters the difference).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "softrne/arm/arm_dynamics.hpp"
#include "softrne/arm/equilibrium.hpp"
#include "softrne/sim/arm_simulation.hpp"
#include "softrne/sim/linearisation.hpp"
#include "test_arms.hpp"

namespace sim_test_linearisation {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using softrne::ArmDescription;
using softrne::sim::JacobianMethod;

/// The bundled arm's layout with effects that have states (actuator_lag: one per chamber of
/// joints 1 and 3; viscoelastic: one per coordinate of joint 2) and effects on the pressures
/// and forces without states.
ArmDescription arm_with_state_effects() {
  softrne::io::RobotSpec spec = softrne::test::three_joint_arm();
  spec.effects = {
      {"actuator_lag", {"joint1", "joint3"}, {{"T", 0.05}}, ""},
      {"viscoelastic", {"joint2"}, {{"k", 8.0}, {"tau", 0.3}}, ""},
      {"chamber_gain", {"joint2"}, {{"gain", 0.8}}, ""},
      {"stiffening", {"joint1"}, {{"beta", 0.8}}, ""},
      {"payload", {}, {{"mass", 0.2}}, ""},
  };
  return softrne::build_arm(spec);
}

/// d f / d [x, p] by central differences of ArmDynamics<double>::rhs, column by column.
MatrixXd central_differences(const ArmDescription& d, const VectorXd& x, const VectorXd& p) {
  softrne::ArmDynamics<double> f(d);
  const int n = d.num_states(), m = d.num_inputs;
  MatrixXd J(n, n + m);
  VectorXd fp(n), fm(n);
  for (int j = 0; j < n + m; ++j) {
    VectorXd xp = x, xm = x, pp = p, pm = p;
    double& up = j < n ? xp(j) : pp(j - n);
    double& um = j < n ? xm(j) : pm(j - n);
    const double h = 1e-6 * std::max(1.0, std::abs(up));
    up += h;
    um -= h;
    f.rhs(xp, pp, fp);
    f.rhs(xm, pm, fm);
    J.col(j) = (fp - fm) / (2 * h);
  }
  return J;
}

VectorXd random_state(const ArmDescription& d, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  VectorXd x(d.num_states());
  for (int i = 0; i < d.nq; ++i) x(i) = 0.8 * U(rng);
  for (int i = d.nq; i < 2 * d.nq; ++i) x(i) = 3.0 * U(rng);
  // Effect states: lagged pressures (Pa) first, then the viscoelastic angles (rad).
  const int lag = d.effect_state_size(0);
  for (int i = 0; i < lag; ++i) x(2 * d.nq + i) = 75e3 + 75e3 * U(rng);
  for (int i = 2 * d.nq + lag; i < d.num_states(); ++i) x(i) = 0.8 * U(rng);
  return x;
}

TEST(Linearisation, ABMatchCentralDifferencesOfTheRightHandSideAtRandomStates) {
  const ArmDescription d = arm_with_state_effects();
  ASSERT_EQ(d.num_states(), 12 + 8 + 2);
  const int n = d.num_states();
  softrne::sim::ArmJacobian jac(d);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    const VectorXd x = random_state(d, rng);
    VectorXd p(d.num_inputs);
    for (Eigen::Index i = 0; i < p.size(); ++i) p(i) = 75e3 + 75e3 * U(rng);
    const MatrixXd J_fd = central_differences(d, x, p);
    for (JacobianMethod method : {JacobianMethod::inverse_dynamics, JacobianMethod::forward_dynamics}) {
      jac.set_method(method);
      const softrne::sim::Linearisation lin = softrne::sim::linearise(jac, x, p);
      MatrixXd J(n, n + d.num_inputs);
      J << lin.A, lin.B;
      // Row by row relative to the row's largest entry: the rows differ by orders of
      // magnitude (1/s for the angles, 1/(s^2 Pa) for the pressures' effect on the
      // accelerations, 1/s for the lagged pressures).
      double worst = 0;
      for (int i = 0; i < n; ++i) {
        const double scale = std::max(1e-300, J_fd.row(i).cwiseAbs().maxCoeff());
        worst = std::max(worst, (J.row(i) - J_fd.row(i)).cwiseAbs().maxCoeff() / scale);
      }
      std::printf("[   info   ] trial %d (%s): max row-relative |[A B] - FD| = %.1e\n", trial,
                  method == JacobianMethod::inverse_dynamics ? "inverse" : "forward", worst);
      EXPECT_LT(worst, 1e-7) << "trial " << trial;
      // The pressures act: B is not zero in the acceleration and lag rows.
      EXPECT_GT(lin.B.middleRows(d.nq, d.nq).cwiseAbs().maxCoeff(), 1e-4);
      EXPECT_GT(lin.B.middleRows(2 * d.nq, d.effect_state_size(0)).cwiseAbs().maxCoeff(), 1.0);
    }
  }
}

TEST(Linearisation, ArmSystemJacobianIsTheStateJacobian) {
  // One source of truth: the simulator's Jacobian is ArmJacobian's A at the interpolated
  // pressures.
  const ArmDescription d = arm_with_state_effects();
  std::mt19937 rng(3);
  const VectorXd x = random_state(d, rng);
  const VectorXd t = VectorXd::LinSpaced(3, 0.0, 1.0);
  const MatrixXd P = MatrixXd::Constant(3, d.num_inputs, 40e3);
  softrne::sim::ArmSystem sys(d, t, P, softrne::sim::ArmSimulationOptions::PressureInterpolation::linear);
  MatrixXd J(d.num_states(), d.num_states());
  VectorXd f(d.num_states());
  ASSERT_TRUE(sys.rhs(0.5, x, f));
  ASSERT_TRUE(sys.jacobian(0.5, x, f, J));
  const softrne::sim::Linearisation lin = softrne::sim::linearise(d, x, P.row(0).transpose());
  EXPECT_EQ((J - lin.A).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((f - lin.f).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Linearisation, OneZeroOrderHoldStepMatchesTheSimulatorAroundAnEquilibrium) {
  const ArmDescription d = arm_with_state_effects();
  const int n = d.num_states(), m = d.num_inputs;
  VectorXd p_eq(m);
  const double pattern[4] = {60e3, 10e3, 35e3, 20e3};  // bends u and v of every joint
  for (int i = 0; i < m; ++i) p_eq(i) = pattern[i % 4];
  // static_equilibrium solves for the angles only; every state's rate must vanish, so this
  // also checks that it holds the effects' states at rest at the answer (the viscoelastic
  // branch relaxed where the arm is, not where Newton started).
  const VectorXd x_eq = softrne::rest_state(d, softrne::static_equilibrium(d, p_eq), p_eq);
  softrne::ArmDynamics<double> f(d);
  VectorXd f_eq(n);
  f.rhs(x_eq, p_eq, f_eq);
  ASSERT_LT(f_eq.cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_GT(x_eq.head(d.nq).cwiseAbs().maxCoeff(), 0.1);  // the pressures bend the arm

  const double h = 0.01;  // one control period
  const softrne::sim::DiscreteLinearisation dl =
      softrne::sim::discretise_zoh(softrne::sim::linearise(d, x_eq, p_eq), h);
  EXPECT_LT(dl.cd.cwiseAbs().maxCoeff(), 1e-12);

  // A deviation of every state and input: angles, rates, lagged pressures, viscoelastic angles.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  VectorXd dx(n), dp(m);
  for (int i = 0; i < d.nq; ++i) dx(i) = 2e-3 * U(rng);
  for (int i = d.nq; i < 2 * d.nq; ++i) dx(i) = 2e-2 * U(rng);
  const int lag = d.effect_state_size(0);
  for (int i = 2 * d.nq; i < 2 * d.nq + lag; ++i) dx(i) = 300 * U(rng);
  for (int i = 2 * d.nq + lag; i < n; ++i) dx(i) = 2e-3 * U(rng);
  for (int i = 0; i < m; ++i) dp(i) = 1e3 * U(rng);

  softrne::sim::CvodeOptions copt;
  copt.rtol = 1e-12;
  copt.atol = 1e-12;
  double err[2], moved[2];
  for (int s = 0; s < 2; ++s) {
    const double eps = s == 0 ? 1.0 : 0.5;
    const VectorXd t = (VectorXd(2) << 0.0, h).finished();
    const MatrixXd P = (p_eq + eps * dp).transpose().replicate(2, 1);
    softrne::sim::ArmSystem sys(d, t, P,
                                softrne::sim::ArmSimulationOptions::PressureInterpolation::zero_order_hold);
    const softrne::sim::SimulationResult r = softrne::sim::integrate(sys, VectorXd(x_eq + eps * dx), t, {}, copt);
    ASSERT_TRUE(r.ok) << r.message;
    const VectorXd x1_sim = r.x.row(1).transpose();
    const VectorXd x1_lin = x_eq + dl.Ad * (eps * dx) + dl.Bd * (eps * dp) + dl.cd;
    // Relative to how far the state moved over the sample, component-wise scaled by dx.
    const VectorXd scale = dx.cwiseAbs().cwiseMax(1e-12);
    err[s] = ((x1_sim - x1_lin).cwiseQuotient(scale)).cwiseAbs().maxCoeff() / eps;
    moved[s] = ((x1_sim - x_eq).cwiseQuotient(scale)).cwiseAbs().maxCoeff() / eps;
    std::printf("[   info   ] deviation x%.1f: |x1_sim - x1_lin| = %.2e, the step moved %.2e (in dx)\n",
                eps, err[s] * eps, moved[s] * eps);
    EXPECT_GT(moved[s], 0.1);  // the step is not trivial
  }
  // First order exact: the difference is the nonlinearity, 1e-4 of the motion and second order
  // in the deviation.
  EXPECT_LT(err[0], 1e-3 * moved[0]);
  const double ratio = err[0] / err[1];  // (err/eps) halves with eps
  std::printf("[   info   ] halving the deviation divides the difference by %.2f (4: second order)\n",
              2 * ratio);
  EXPECT_GT(2 * ratio, 3.5);
  EXPECT_LT(2 * ratio, 4.5);
}

TEST(Linearisation, DiscretisationMatchesAClosedFormOfADoubleIntegrator) {
  // x = [position, velocity], u a force per mass: Ad = [[1, h], [0, 1]], Bd = [h^2/2, h],
  // and a constant drift f* = [0, a] gives cd = [a h^2 / 2, a h].
  softrne::sim::Linearisation lin;
  lin.A = (MatrixXd(2, 2) << 0, 1, 0, 0).finished();
  lin.B = (MatrixXd(2, 1) << 0, 1).finished();
  lin.f = (VectorXd(2) << 0, 0.3).finished();
  const double h = 0.02;
  const softrne::sim::DiscreteLinearisation dl = softrne::sim::discretise_zoh(lin, h);
  EXPECT_NEAR(dl.Ad(0, 1), h, 1e-15);
  EXPECT_NEAR(dl.Ad(0, 0), 1, 1e-15);
  EXPECT_NEAR(dl.Bd(0, 0), h * h / 2, 1e-16);
  EXPECT_NEAR(dl.Bd(1, 0), h, 1e-15);
  EXPECT_NEAR(dl.cd(0), 0.3 * h * h / 2, 1e-16);
  EXPECT_NEAR(dl.cd(1), 0.3 * h, 1e-15);
}

TEST(Linearisation, BadArgumentsGiveAClearError) {
  const ArmDescription d = softrne::build_arm(softrne::test::three_joint_arm());
  try {
    softrne::sim::linearise(d, VectorXd::Zero(3), VectorXd::Zero(d.num_inputs));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("12 states"), std::string::npos) << e.what();
  }
  softrne::sim::Linearisation lin = softrne::sim::linearise(d, VectorXd::Zero(12), VectorXd::Zero(12));
  EXPECT_THROW(softrne::sim::discretise_zoh(lin, 0.0), std::invalid_argument);
  EXPECT_THROW(softrne::sim::discretise_zoh(lin, std::nan("")), std::invalid_argument);
}

}  // namespace sim_test_linearisation
