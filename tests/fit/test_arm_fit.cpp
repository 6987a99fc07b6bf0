// fit_arm against data the library made from known parameters (plus sensor noise).
#include <gtest/gtest.h>

#include "softrne/fit/arm_fit.hpp"
#include "synthetic_arm.hpp"

namespace fit_test_arm_fit {

using namespace softrne;

TEST(ArmFit, RecoversStiffnessAndDampingFromNoisyData) {
  const ArmDescription truth = build_arm(softrne_test::two_joint_spec());
  const io::Dataset data = softrne_test::synthetic_dataset(truth, 10.0, 2.0, 7);
  // Starting guesses off by factors between 0.5 and 2.
  ArmDescription start = truth;
  const double kf[] = {0.5, 2.0, 1.6, 0.6}, df[] = {2.0, 0.5, 0.7, 1.8};
  for (std::size_t j = 0; j < start.joints.size(); ++j)
    for (int k = 0; k < 2; ++k) {
      start.joints[j].stiffness(k) *= kf[2 * j + static_cast<std::size_t>(k)];
      start.joints[j].damping(k) *= df[2 * j + static_cast<std::size_t>(k)];
    }
  const fit::ArmFitResult r = fit::fit_arm(start, data);
  for (std::size_t j = 0; j < truth.joints.size(); ++j)
    for (int k = 0; k < 2; ++k) {
      const double K = r.fitted.joints[j].stiffness(k), K0 = truth.joints[j].stiffness(k);
      const double D = r.fitted.joints[j].damping(k), D0 = truth.joints[j].damping(k);
      EXPECT_NEAR(K / K0, 1.0, 0.02) << "stiffness joint " << j << " axis " << k;
      EXPECT_NEAR(D / D0, 1.0, 0.10) << "damping joint " << j << " axis " << k;
    }
  // The error left is the sensor noise (0.003 rad, mean |N(0, s)| = 0.8 s).
  EXPECT_LT(r.stats.total.mean, 0.004);
  EXPECT_TRUE(std::all_of(r.fit.identifiable.begin(), r.fit.identifiable.end(), [](bool b) { return b; }));
  std::printf("[ info ] fit: %d simulations, %.1f s, train mean error %.4f rad\n", r.simulations, r.wall_seconds,
              r.stats.total.mean);
}

// simulate_dataset integrates no looser than the model's effects need (effect_max_atol):
// with a Coulomb friction, a caller's atol 1e-3 gives exactly the run at Coulomb's 1e-6.
TEST(ArmFit, SimulationsOfAModelWithCoulombFrictionUseItsTolerance) {
  ArmDescription arm = build_arm(softrne_test::two_joint_spec());
  const io::Dataset data = softrne_test::synthetic_dataset(arm, 2.0, 2.0, 5);
  sim::ArmSimulationOptions loose;
  loose.cvode.atol = 1e-3;
  sim::ArmSimulationOptions tight = loose;
  tight.cvode.atol = CoulombFriction::max_atol;
  const Eigen::VectorXd q0 = data.angles.row(0).transpose();
  auto direct = [&](const ArmDescription& d, const sim::ArmSimulationOptions& o) {
    return sim::simulate_arm(d, data.t, data.pressures, q0, o).angles;
  };
  // Without the effect the caller's tolerance holds (and differs from the tight run).
  EXPECT_EQ(fit::simulate_dataset(arm, data, loose).angles, direct(arm, loose));
  EXPECT_NE(direct(arm, loose), direct(arm, tight));
  AnyEffect e = make_effect_at_neutral("coulomb_friction", arm, Scope::Shared);
  effect_base(e).params.setConstant(0.05);
  add_effect(arm, e);
  EXPECT_EQ(fit::simulate_dataset(arm, data, loose).angles, direct(arm, tight));
  EXPECT_EQ(effect_max_atol(AnyEffect(Hysteresis{})), std::numeric_limits<double>::infinity());
}

TEST(ArmFit, BadDataIsRefusedWithAClearMessage) {
  const ArmDescription arm = build_arm(softrne_test::two_joint_spec());
  io::Dataset d = softrne_test::synthetic_dataset(arm, 1.0, 0.5, 3);
  {
    io::Dataset no_angles = d;
    no_angles.has_angles = false;
    no_angles.angles.resize(d.t.size(), 0);
    EXPECT_THROW(fit::fit_arm(arm, no_angles), std::invalid_argument);
  }
  {
    io::Dataset few_angles = d;
    few_angles.angles = d.angles.leftCols(2);
    EXPECT_THROW(fit::fit_arm(arm, few_angles), std::invalid_argument);
  }
  {
    io::Dataset shorty = d;
    shorty.t = d.t.head(5);
    shorty.angles = d.angles.topRows(5);
    shorty.pressures = d.pressures.topRows(5);
    try {
      fit::fit_arm(arm, shorty);
      FAIL() << "a 5-sample data set was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("too short"), std::string::npos) << e.what();
    }
  }
  {
    io::Dataset still = d;
    still.pressures.setConstant(1000.0);
    still.angles.setZero();
    try {
      fit::fit_arm(arm, still);
      FAIL() << "constant data was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("not identifiable"), std::string::npos) << e.what();
    }
  }
}

}  // namespace fit_test_arm_fit
