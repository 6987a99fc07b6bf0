// The closed loop end to end on data made with known effects (fixed seeds; the broad score on
// random arms is tools/score-loop.py, docs/closing-the-loop.md): it must name each effect with
// its scope, leave effect-free data alone, and never make the held-out error worse.
#include <gtest/gtest.h>

#include <ostream>

#include "softrne/fit/loop.hpp"
#include "../fit/synthetic_arm.hpp"

namespace {

using namespace softrne;

struct Injected {
  std::string name;
  Scope scope;
  std::vector<int> joints;
  std::vector<double> params;
};

struct Case {
  std::string label;
  std::vector<Injected> effects;
  unsigned seed;
  bool distributed_truth = false;  ///< data from distributed-inertia CC joints, declared lumped
};

// The case's label in ctest's and gtest's lines (the default prints the object's bytes).
void PrintTo(const Case& c, std::ostream* os) { *os << c.label; }

ArmDescription truth_of(const ArmDescription& declared, const Case& c) {
  ArmDescription d = declared;
  for (const auto& inj : c.effects) {
    AnyEffect e = make_effect_at_neutral(inj.name, declared, inj.scope, inj.joints);
    for (std::size_t k = 0; k < inj.params.size(); ++k) effect_base(e).params(static_cast<Eigen::Index>(k)) = inj.params[k];
    add_effect(d, e);
  }
  if (c.distributed_truth) fit::detail::distribute_cc_inertia(d);
  return d;
}

std::string describe(const fit::LoopResult& r) {
  std::string s;
  for (std::size_t k = 0; k < r.rounds.size(); ++k)
    for (const auto& c : r.rounds[k]) {
      if (!c.confirmed) continue;
      s += "  round " + std::to_string(k + 1) + " " + c.label + ": predicted";
      for (double g : c.predicted_gains) s += " " + std::to_string(g);
      s += "; held-out";
      for (double g : c.fold_gains) s += " " + std::to_string(g);
      s += c.added ? " (added)\n" : "\n";
    }
  return s;
}

class LoopCase : public ::testing::TestWithParam<Case> {};

TEST_P(LoopCase, NamesTheEffectsWithTheirScopesAndNothingElse) {
  const Case c = GetParam();
  const ArmDescription declared = build_arm(softrne_test::two_joint_spec());
  const ArmDescription truth = truth_of(declared, c);
  const io::Dataset train = softrne_test::synthetic_dataset(truth, 8.0, 1.0, c.seed);
  const io::Dataset test = softrne_test::synthetic_dataset(truth, 8.0, 1.6, c.seed + 50);
  fit::LoopOptions o;
  const fit::LoopResult r = fit::run_loop(softrne_test::perturbed(declared, 1.3, 0.8), train, &test, o);
  const std::string why = describe(r);
  ASSERT_EQ(r.added.size(), c.effects.size()) << why;
  for (const auto& inj : c.effects) {
    bool found = false;
    for (const auto& a : r.added) {
      const EffectBase& b = effect_base(a.effect);
      found = found || (effect_name(a.effect) == inj.name && b.scope == inj.scope && b.joints == inj.joints);
    }
    EXPECT_TRUE(found) << inj.name << " (" << scope_name(inj.scope) << ") not found; loop:\n" << why;
  }
  // Held-out evidence: every added effect lowered the held-out training error in every fold.
  for (const auto& a : r.added)
    for (double g : a.fold_gains) EXPECT_GE(g, o.min_gain) << a.label;
  EXPECT_LE(r.final_test.total.median, r.baseline_test.total.median * 1.02) << why;
  EXPECT_GT(r.noise_floor, 0.6745 * 0.003 * 0.85);
  EXPECT_LT(r.noise_floor, 0.6745 * 0.003 * 1.15);
  if (!c.effects.empty()) {
    // At the noise floor or halved.
    EXPECT_LT(r.final_test.total.median, std::max(0.5 * r.baseline_test.total.median, 1.25 * r.noise_floor)) << why;
  }
  // The inertia model is a structure without parameters; on lumped data it may go either way,
  // on distributed data it must not be replaced by an effect (checked above).
  std::printf("[ info ] %s: inertia model %s (held-out", c.label.c_str(),
              r.inertia.adopted ? "distributed adopted" : "as declared");
  for (double g : r.inertia.fold_gains) std::printf(" %+.1f %%", -100 * g);
  std::printf(")\n");
  std::printf("[ info ] %s: %zu effect(s); test median %.4f -> %.4f rad (floor %.4f); %d simulations, %.0f s\n",
              c.label.c_str(), r.added.size(), r.baseline_test.total.median, r.final_test.total.median,
              r.noise_floor, r.simulations, r.wall_seconds);
}

INSTANTIATE_TEST_SUITE_P(
    Fixed, LoopCase,
    ::testing::Values(Case{"none_seed21", {}, 21u}, Case{"none_seed22", {}, 22u},
                      Case{"none_distributed_truth", {}, 23u, true},
                      Case{"stiffening_joint2", {{"stiffening", Scope::PerJoint, {1}, {4.0}}}, 11u},
                      Case{"coulomb_friction_shared", {{"coulomb_friction", Scope::Shared, {0, 1}, {1.0}}}, 12u},
                      Case{"lag_and_offset",
                           {{"actuator_lag", Scope::Shared, {0, 1}, {0.1}},
                            {"angle_offset", Scope::PerCoordinate, {0}, {0.04, -0.03}}},
                           13u}),
    [](const auto& info) { return info.param.label; });

}  // namespace
