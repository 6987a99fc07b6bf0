// Control in the loop (simulate_closed_loop) against simulate_arm, which shares neither its
// input handling nor its sampling:
//  - a constant controller equals simulate_arm on those constant pressures;
//  - any controller: its applied pressures, replayed open loop with zero-order hold, give the
//    same states (with an actuator_lag state and an input_delay effect);
//  - a delay of d periods shifts the applied pressures by d samples; clamping; bad
//    controllers and arguments give one-line errors.
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "softrne/sim/arm_simulation.hpp"
#include "softrne/sim/closed_loop.hpp"
#include "test_arms.hpp"

namespace sim_test_closed_loop {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using softrne::ArmDescription;
using softrne::sim::ClosedLoopOptions;
using softrne::sim::ClosedLoopSimulation;
using softrne::sim::ControllerInput;
using softrne::sim::simulate_closed_loop;
using PI = softrne::sim::ArmSimulationOptions::PressureInterpolation;

softrne::sim::ArmSimulationOptions tight() {
  softrne::sim::ArmSimulationOptions o;
  o.cvode.rtol = 1e-11;
  o.cvode.atol = 1e-11;
  o.velocity_atol_factor = 1;  // the rates as tight as the angles
  return o;
}

/// A controller that depends on time only (so that delays compare sample by sample).
Eigen::VectorXd time_pressures(double t, int m) {
  VectorXd p(m);
  for (int i = 0; i < m; ++i) p(i) = 40e3 + 30e3 * std::sin(2.0 * t + 0.7 * i);
  return p;
}

TEST(ClosedLoop, ConstantControllerEqualsSimulateArmOnConstantPressures) {
  const ArmDescription d = softrne::build_arm(softrne::test::three_joint_arm());
  const VectorXd p = time_pressures(0.3, d.num_inputs);
  ClosedLoopOptions opt;
  opt.simulation = tight();
  opt.initial_pressures = p;  // resting under them: the arm starts as simulate_arm's does
  const VectorXd q0 = VectorXd::Constant(d.nq, 0.05);
  const ClosedLoopSimulation cl =
      simulate_closed_loop(d, [&](const ControllerInput&) { return p; }, q0, 1.0, 0.02, opt);
  ASSERT_TRUE(cl.ok()) << cl.result.message;
  ASSERT_EQ(cl.t.size(), 51);
  EXPECT_EQ(cl.result.stats.restarts, 49);  // one per sample inside the run

  const MatrixXd P = p.transpose().replicate(cl.t.size(), 1);
  const softrne::sim::ArmSimulation open = softrne::sim::simulate_arm(d, cl.t, P, q0, tight());
  ASSERT_TRUE(open.ok()) << open.result.message;
  EXPECT_EQ(open.result.stats.restarts, 0);
  // Only the step sequences differ (the loop restarts at every sample): differences at the
  // integration tolerance.
  const double diff = (cl.states - open.states).cwiseAbs().maxCoeff();
  std::printf("[   info   ] constant controller vs simulate_arm: max |dx| = %.1e\n", diff);
  EXPECT_LT(diff, 1e-8);
  EXPECT_LT((cl.angles - open.angles).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GT((cl.angles.bottomRows(1) - cl.angles.topRows(1)).cwiseAbs().maxCoeff(), 0.05);  // it moved
  EXPECT_EQ((cl.pressures - P).cwiseAbs().maxCoeff(), 0.0);
}

TEST(ClosedLoop, AppliedPressuresReplayedOpenLoopGiveTheSameRun) {
  // A state feedback on an arm with an actuator lag (states) and an input delay (0.013 s, not
  // a multiple of the period): both runs integrate the same piecewise-constant input.
  softrne::io::RobotSpec spec = softrne::test::three_joint_arm();
  spec.effects = {{"actuator_lag", {"joint2"}, {{"T", 0.04}}, ""},
                  {"input_delay", {}, {{"delay", 0.013}}, ""}};
  const ArmDescription d = softrne::build_arm(spec);
  ASSERT_NEAR(d.input_delay(), 0.013, 1e-15);
  ClosedLoopOptions opt;
  opt.simulation = tight();
  // simulate_arm starts the lag states at the first applied row; the loop at the pressures
  // the arm rested under. At rest at q = 0 the first command is time_pressures(0): rest there.
  opt.initial_pressures = time_pressures(0.0, d.num_inputs);
  auto controller = [&](const ControllerInput& in) {
    VectorXd p = time_pressures(in.t, d.num_inputs);
    for (int i = 0; i < d.num_inputs; ++i) p(i) -= 2e4 * in.angles(i / 2) + 1e3 * in.velocities(i / 2);
    return p;
  };
  const ClosedLoopSimulation cl = simulate_closed_loop(d, controller, VectorXd(), 0.6, 0.01, opt);
  ASSERT_TRUE(cl.ok()) << cl.result.message;
  EXPECT_EQ((cl.commands - cl.pressures).cwiseAbs().maxCoeff(), 0.0);  // no delay periods
  EXPECT_EQ((cl.pressures.row(0).transpose() - opt.initial_pressures).cwiseAbs().maxCoeff(), 0.0);
  softrne::sim::ArmSimulationOptions zoh = tight();
  zoh.interpolation = PI::zero_order_hold;
  const softrne::sim::ArmSimulation open =
      softrne::sim::simulate_arm(d, cl.t, cl.pressures, VectorXd(), zoh);
  ASSERT_TRUE(open.ok()) << open.result.message;
  // Relative: the lag states are pressures (Pa), the rest radians.
  const double rel = (cl.states - open.states).cwiseAbs().maxCoeff() / cl.states.cwiseAbs().maxCoeff();
  std::printf("[   info   ] replayed open loop: max |dx| / max |x| = %.1e\n", rel);
  EXPECT_LT(rel, 1e-9);
  EXPECT_LT((cl.angles - open.angles).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GT((cl.angles.bottomRows(1) - cl.angles.topRows(1)).cwiseAbs().maxCoeff(), 0.02);
}

TEST(ClosedLoop, ADelayOfDPeriodsShiftsTheAppliedPressuresByDSamples) {
  const ArmDescription d = softrne::build_arm(softrne::test::three_joint_arm());
  const int m = d.num_inputs;
  auto controller = [&](const ControllerInput& in) { return time_pressures(in.t, m); };
  ClosedLoopOptions opt;
  const ClosedLoopSimulation now = simulate_closed_loop(d, controller, VectorXd(), 0.5, 0.01, opt);
  opt.delay_periods = 3;
  opt.initial_pressures = VectorXd::Constant(m, 12e3);
  const ClosedLoopSimulation late = simulate_closed_loop(d, controller, VectorXd(), 0.5, 0.01, opt);
  ASSERT_TRUE(now.ok() && late.ok());
  const Eigen::Index N = now.t.size();
  EXPECT_EQ((late.pressures.bottomRows(N - 3) - now.pressures.topRows(N - 3)).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((late.pressures.topRows(3).array() - 12e3).abs().maxCoeff(), 0.0);
  EXPECT_EQ((late.commands - now.commands).cwiseAbs().maxCoeff(), 0.0);
  // The arm moves later: its angles differ.
  EXPECT_GT((late.angles - now.angles).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(ClosedLoop, PressuresAreClampedToTheRange) {
  const ArmDescription d = softrne::build_arm(softrne::test::three_joint_arm());
  const int m = d.num_inputs;
  ClosedLoopOptions opt;
  opt.p_min = 5e3;
  opt.p_max = 60e3;
  auto controller = [&](const ControllerInput& in) {
    VectorXd p = VectorXd::LinSpaced(m, -50e3, 200e3);
    p(0) = in.k * 1e4;  // crosses the upper limit during the run
    return p;
  };
  const ClosedLoopSimulation cl = simulate_closed_loop(d, controller, VectorXd(), 0.1, 0.01, opt);
  ASSERT_TRUE(cl.ok()) << cl.result.message;
  EXPECT_EQ(cl.pressures.minCoeff(), 5e3);
  EXPECT_EQ(cl.pressures.maxCoeff(), 60e3);
  EXPECT_EQ(cl.commands(3, 0), 30e3);   // inside: unchanged
  EXPECT_EQ(cl.commands(0, 0), 5e3);    // 0 below p_min
  EXPECT_EQ(cl.commands(10, 0), 60e3);  // 100 kPa above p_max
  EXPECT_EQ(cl.commands(0, 1), 5e3);
}

TEST(ClosedLoop, BadControllersAndArgumentsGiveOneLineErrors) {
  const ArmDescription d = softrne::build_arm(softrne::test::three_joint_arm());
  const int m = d.num_inputs;
  auto expect_error = [&](const ClosedLoopSimulation& r, const std::string& what) {
    EXPECT_FALSE(r.ok());
    EXPECT_NE(r.result.message.find(what), std::string::npos) << r.result.message;
    EXPECT_EQ(r.result.message.find('\n'), std::string::npos) << r.result.message;
    EXPECT_EQ(r.states.rows(), r.t.size());
    EXPECT_EQ(r.pressures.rows(), r.t.size());
  };
  // NaN at sample 5: the samples before it are returned.
  const ClosedLoopSimulation nan = simulate_closed_loop(
      d,
      [&](const ControllerInput& in) {
        VectorXd p = VectorXd::Constant(m, 1e4);
        if (in.k == 5) p(2) = std::nan("");
        return p;
      },
      VectorXd(), 0.2, 0.01);
  expect_error(nan, "controller at t = 0.05 s (sample 5) returned a non-finite pressure (p1_2 = nan)");
  EXPECT_EQ(nan.t.size(), 5);
  expect_error(simulate_closed_loop(d, [&](const ControllerInput&) { return VectorXd::Zero(m - 1); },
                                    VectorXd(), 0.2, 0.01),
               "(sample 0) returned 11 pressures; the arm has 12 inputs");
  expect_error(simulate_closed_loop(
                   d,
                   [&](const ControllerInput& in) -> VectorXd {
                     if (in.k == 2) throw std::runtime_error("sensor offline");
                     return VectorXd::Zero(m);
                   },
                   VectorXd(), 0.2, 0.01),
               "(sample 2) threw: sensor offline");
  auto zero = [&](const ControllerInput&) { return VectorXd::Zero(m); };
  expect_error(simulate_closed_loop(d, zero, VectorXd(), 0.2, 0.0), "control_period");
  expect_error(simulate_closed_loop(d, zero, VectorXd(), -1.0, 0.01), "t_end");
  expect_error(simulate_closed_loop(d, zero, VectorXd::Zero(2), 0.2, 0.01), "q0 has 2 angles");
  expect_error(simulate_closed_loop(d, softrne::sim::Controller(), VectorXd(), 0.2, 0.01),
               "no controller");
  ClosedLoopOptions bad;
  bad.p_min = 1e5;
  bad.p_max = 0;
  expect_error(simulate_closed_loop(d, zero, VectorXd(), 0.2, 0.01, bad), "p_min <= p_max");
  bad = ClosedLoopOptions();
  bad.delay_periods = -1;
  expect_error(simulate_closed_loop(d, zero, VectorXd(), 0.2, 0.01, bad), "delay_periods");
  bad = ClosedLoopOptions();
  bad.initial_pressures = VectorXd::Zero(3);
  expect_error(simulate_closed_loop(d, zero, VectorXd(), 0.2, 0.01, bad), "initial_pressures has 3");
}

}  // namespace sim_test_closed_loop
