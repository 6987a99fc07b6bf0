// The closed loop's parts against references that do not share their code: the noise
// estimate against the known sigma of generated noise, the residual analysis against signals
// built to correlate with one feature, the folds against their definition, the candidate list
// against the effects' own scope tables, and the screen against the exact gain of a linear
// measurement effect.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <set>

#include "softrne/algorithms/mass_matrix.hpp"
#include "softrne/fit/loop.hpp"
#include "softrne/io/recordings.hpp"
#include "synthetic_arm.hpp"

namespace {

using namespace softrne;

TEST(NoiseFloor, RecoversSigmaOfWhiteNoiseOnASmoothSignal) {
  std::mt19937 rng(3);
  const int n = 6000;
  for (double sigma : {0.001, 0.003, 0.01}) {
    std::normal_distribution<double> noise(0.0, sigma);
    Eigen::MatrixXd y(n, 2);
    for (int i = 0; i < n; ++i) {
      const double t = 0.01 * i;
      y(i, 0) = 0.4 * std::sin(2.1 * t) + noise(rng);
      y(i, 1) = 0.3 * std::tanh(std::sin(0.7 * t) * 4) + noise(rng);
    }
    const Eigen::VectorXd s = fit::estimate_noise_sigma(y);
    // Standard error of a median-based estimate from n samples: ~1.25 sigma / sqrt(n) -> 2 %.
    EXPECT_NEAR(s(0) / sigma, 1.0, 0.06) << sigma;
    EXPECT_NEAR(s(1) / sigma, 1.0, 0.06) << sigma;
  }
  EXPECT_NEAR(fit::noise_floor_median(1.0), 0.6745, 1e-4);
}

TEST(NoiseFloor, PressureStepsDoNotInflateTheEstimate) {
  // A step signal (jumps of 0.5 rad every 200 samples, each smoothed over 3 samples) plus noise:
  // the median ignores the few large third differences at the steps.
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.003);
  Eigen::MatrixXd y(4000, 1);
  double level = 0, target = 0;
  for (int i = 0; i < 4000; ++i) {
    if (i % 200 == 0) target = (i / 200) % 2 ? 0.5 : -0.2;
    level += (target - level) * 0.3;
    y(i, 0) = level + noise(rng);
  }
  EXPECT_NEAR(fit::estimate_noise_sigma(y)(0) / 0.003, 1.0, 0.1);
}

TEST(ResidualAnalysis, NoiseIsAtTheFloorAndASignalAboveIt) {
  const ArmDescription d = build_arm(softrne_test::two_joint_spec());
  const int n = 2000;
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) * 0.01);
  Eigen::MatrixXd sim(n, d.nq), meas(n, d.nq), p = Eigen::MatrixXd::Zero(n, d.num_inputs);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.003);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < d.nq; ++k) {
      sim(i, k) = 0.3 * std::sin((1.0 + k) * t(i));
      meas(i, k) = sim(i, k) + noise(rng);
    }
  const Eigen::VectorXd sigma = Eigen::VectorXd::Constant(d.nq, 0.003);
  const fit::UnexplainedResidual quiet = fit::analyse_residual(d, t, meas, sim, p, sigma);
  EXPECT_FALSE(quiet.above_floor) << quiet.statement;
  for (const auto& c : quiet.coordinates) EXPECT_NEAR(c.ratio, 1.0, 0.1) << c.name;
  // u2 moves as 0.3 sin(3t) and its measured angle carries an error 0.1 qdot = 0.09 cos(3t):
  // far above the floor and along qdot, not q.
  Eigen::MatrixXd meas2 = meas;
  for (int i = 0; i < n; ++i) {
    sim(i, 2) = 0.3 * std::sin(3.0 * t(i));
    meas2(i, 2) = sim(i, 2) + 0.1 * 0.9 * std::cos(3.0 * t(i)) + noise(rng);
  }
  const fit::UnexplainedResidual loud = fit::analyse_residual(d, t, meas2, sim, p, sigma);
  ASSERT_TRUE(loud.above_floor);
  const auto& c = loud.coordinates.at(2);
  EXPECT_GT(c.ratio, 10.0);
  EXPECT_GT(std::abs(c.corr_qdot), 0.95);
  // The measured angle holds the error itself (0.09 of its 0.31 amplitude): r(q) ~ 0.29.
  EXPECT_LT(std::abs(c.corr_q), 0.4);
  EXPECT_GT(c.band_power.at(0) + c.band_power.at(1), 0.95);  // 0.48 Hz
  EXPECT_NE(loud.statement.find("u2"), std::string::npos) << loud.statement;
  EXPECT_NE(loud.statement.find("qdot"), std::string::npos) << loud.statement;
  EXPECT_EQ(loud.statement.find("u1:"), std::string::npos) << loud.statement;
}

TEST(LoopFolds, PartitionTheSamplesIntoAlternatingBlocks) {
  io::Dataset one;
  one.t = Eigen::VectorXd::LinSpaced(1000, 0.0, 9.99);
  const auto folds = fit::detail::make_folds(one, 4);
  ASSERT_EQ(folds.size(), 2u);
  for (std::size_t i = 0; i < 1000; ++i) {
    EXPECT_NE(folds[0].held_rows[i], folds[1].held_rows[i]) << i;  // each sample held out once
    EXPECT_NE(folds[0].held_rows[i], folds[0].fit_rows[i]) << i;
    EXPECT_EQ(folds[0].held_rows[i], (i / 250) % 2 == 0) << i;
  }
}

TEST(LoopFolds, HoldOutWholeRecordingsBalancedByLength) {
  // Recordings of 500, 100, 300, 200 rows: the longest first to the fold holding out fewer
  // rows: 500 -> fold 0, 300 -> fold 1, 200 -> fold 1, 100 -> fold 0 (600 / 500 rows).
  std::vector<io::Dataset> parts;
  for (int n : {500, 100, 300, 200}) {
    io::Dataset p;
    p.t = Eigen::VectorXd::LinSpaced(n, 0.0, 0.01 * (n - 1));
    p.pressures = Eigen::MatrixXd::Zero(n, 2);
    p.angles = Eigen::MatrixXd::Zero(n, 1);
    p.has_angles = true;
    p.source = "r" + std::to_string(n) + ".csv";
    parts.push_back(p);
  }
  const io::Dataset data = io::stack_recordings(parts);
  ASSERT_EQ(data.recordings.size(), 4u);
  const auto folds = fit::detail::make_folds(data, 4);
  const int expected_fold[] = {0, 0, 1, 1};
  for (std::size_t k = 0; k < 4; ++k) {
    const auto& r = data.recordings[k];
    for (Eigen::Index i = r.first_row; i < r.first_row + r.rows; ++i) {
      const auto row = static_cast<std::size_t>(i);
      EXPECT_EQ(folds[0].held_rows[row], expected_fold[k] == 0) << r.source << " row " << i;
      EXPECT_EQ(folds[1].held_rows[row], expected_fold[k] == 1) << r.source << " row " << i;
      EXPECT_NE(folds[0].fit_rows[row], folds[0].held_rows[row]);
    }
  }
}

TEST(LoopCandidates, EveryEffectInEveryAllowedScopeOnceAndNothingAlreadyHeld) {
  const ArmDescription d = build_arm(softrne_test::two_joint_spec());
  const std::vector<AnyEffect> c = fit::enumerate_candidates(d);
  std::set<std::string> labels, names;
  for (const AnyEffect& e : c) {
    EXPECT_TRUE(labels.insert(fit::candidate_label(e, d)).second) << fit::candidate_label(e, d);
    names.insert(effect_name(e));
    const auto scopes = effect_scopes(e);
    EXPECT_NE(std::find(scopes.begin(), scopes.end(), effect_base(e).scope), scopes.end());
    for (Eigen::Index k = 0; k < effect_base(e).params.size(); ++k)
      EXPECT_EQ(effect_base(e).params(k), effect_param_bounds(e, static_cast<int>(k), d.segment_mass()).neutral);
  }
  EXPECT_EQ(names.size(), effect_names().size());  // every effect applies to a CC arm
  // Holding stiffening on joint2 removes exactly the stiffening candidates that touch joint2.
  ArmDescription held = d;
  add_effect(held, make_effect_at_neutral("stiffening", d, Scope::PerJoint, {1}));
  int before = 0, after = 0;
  for (const AnyEffect& e : c) before += effect_name(e) == "stiffening";
  for (const AnyEffect& e : fit::enumerate_candidates(held)) {
    if (effect_name(e) != "stiffening") continue;
    ++after;
    for (int j : effect_base(e).joints) EXPECT_NE(j, 1);
  }
  EXPECT_GT(before, after);
  EXPECT_GT(after, 0);
}

TEST(LoopCandidates, OnAnArmOfBothKindsTheSharedScopeIsAlsoTriedOverEachKind) {
  // The two-joint arm with a revolute joint between its CC joints (as random arm 1007,
  // C-L-Rz-C): an effect that acts on both kinds gets three shared candidates, over all its
  // joints and over the two CC joints (one revolute joint: its own per-joint candidate covers
  // it); an effect of the chambers only gets one. Without the revolute joint, one each.
  const ArmDescription cc_only = build_arm(softrne_test::two_joint_spec());
  io::RobotSpec spec = softrne_test::two_joint_spec();
  io::RevoluteJointSpec rz;
  rz.name = "rev1";
  rz.stiffness = 0.1;
  rz.damping = 0.003;
  spec.segments.insert(spec.segments.begin() + 2, rz);
  const ArmDescription mixed = build_arm(spec);
  ASSERT_EQ(mixed.joints.size(), 3u);
  auto shared_joint_sets = [](const ArmDescription& d, const std::string& name) {
    std::set<std::vector<int>> sets;
    for (const AnyEffect& e : fit::enumerate_candidates(d))
      if (effect_name(e) == name && effect_base(e).scope == Scope::Shared) {
        std::vector<int> j = effect_base(e).joints;
        std::sort(j.begin(), j.end());
        EXPECT_TRUE(sets.insert(j).second) << name << ": a shared candidate twice";
      }
    return sets;
  };
  int cc1 = -1, cc2 = -1;
  for (std::size_t j = 0; j < mixed.joints.size(); ++j)
    if (mixed.joints[j].is_cc()) (cc1 < 0 ? cc1 : cc2) = static_cast<int>(j);
  ASSERT_GE(cc2, 0);
  const std::set<std::vector<int>> both{{0, 1, 2}, {cc1, cc2}};
  EXPECT_EQ(shared_joint_sets(mixed, "coulomb_friction"), both);
  EXPECT_EQ(shared_joint_sets(mixed, "sensor_gain"), both);
  EXPECT_EQ(shared_joint_sets(mixed, "pressure_stiffening"), (std::set<std::vector<int>>{{cc1, cc2}}));
  EXPECT_EQ(shared_joint_sets(cc_only, "coulomb_friction"), (std::set<std::vector<int>>{{0, 1}}));
}

TEST(LoopScreen, PredictsTheExactGainOfAnOffsetAndNoneForAnAbsentEffect) {
  // Data: the declared model plus an angle offset of 0.02 rad on u2 only, without noise, so the
  // truth is in the model class and a measurement offset is exactly linear in its parameter:
  // the Gauss-Newton step recovers it and the held-out residual vanishes (gain 1).
  const ArmDescription declared = build_arm(softrne_test::two_joint_spec());
  AnyEffect off = make_effect_at_neutral("angle_offset", declared, Scope::PerCoordinate, {1});
  effect_base(off).params << 0.02, 0.0;
  ArmDescription truth = declared;
  add_effect(truth, off);
  const io::Dataset data = softrne_test::synthetic_dataset(truth, 4.0, 1.0, 7, 0.0, 0.0);
  const auto folds = fit::detail::make_folds(data, 4);
  sim::ArmSimulationOptions so = fit::ArmFitOptions::default_simulation();
  so.cvode.rtol = 1e-9;
  so.cvode.atol = 1e-10;
  const Eigen::MatrixXd y0 = fit::detail::simulated_angles(declared, data, so);
  ASSERT_GT(y0.size(), 0);
  const std::vector<fit::Candidate> cands =
      fit::expand_secondary_kinds(fit::enumerate_candidates(declared), declared, y0, data, so, 2);
  const auto screen = fit::screen_fold(cands, declared, y0, data, folds[0].fit_rows, folds[0].held_rows, so, 2);
  int offset_joint2 = -1, stiffening = -1;
  for (std::size_t i = 0; i < cands.size(); ++i) {
    const auto& b = effect_base(cands[i].effect);
    if (effect_name(cands[i].effect) == "angle_offset" && b.joints == std::vector<int>{1}) offset_joint2 = static_cast<int>(i);
    if (effect_name(cands[i].effect) == "stiffening" && b.scope == Scope::Shared) stiffening = static_cast<int>(i);
  }
  ASSERT_GE(offset_joint2, 0);
  ASSERT_GE(stiffening, 0);
  EXPECT_GT(screen[static_cast<std::size_t>(offset_joint2)].predicted_gain, 0.97);
  EXPECT_NEAR(screen[static_cast<std::size_t>(offset_joint2)].start(0), 0.02, 1e-3);
  EXPECT_NEAR(screen[static_cast<std::size_t>(offset_joint2)].start(1), 0.0, 1e-3);
  // The best candidate is that one; stiffening can explain at most a little of an offset.
  for (std::size_t i = 0; i < cands.size(); ++i)
    EXPECT_LE(screen[i].predicted_gain, screen[static_cast<std::size_t>(offset_joint2)].predicted_gain + 1e-9)
        << cands[i].label;
  EXPECT_LT(screen[static_cast<std::size_t>(stiffening)].predicted_gain, 0.5);
}

// Three effects on the two-joint arm, for the tests of taking one out or replacing it: two
// with internal states (actuator lag, Dahl hysteresis) around one without (an angle offset),
// so that changing the first moves the others' state slices.
struct ThreeEffects {
  ArmDescription base = build_arm(softrne_test::two_joint_spec());
  AnyEffect lag = make_effect_at_neutral("actuator_lag", base, Scope::Shared);
  AnyEffect offset = make_effect_at_neutral("angle_offset", base, Scope::PerCoordinate, {1});
  AnyEffect dahl = make_effect_at_neutral("hysteresis", base, Scope::Shared);
  ArmDescription all = base;
  ThreeEffects() {
    effect_base(lag).params.setConstant(0.08);
    effect_base(offset).params << 0.02, -0.01;
    effect_base(dahl).params << 0.3, 40.0;
    for (const auto& e : {lag, offset, dahl}) add_effect(all, e);
  }
};

// `got` (made from `all`) has the effects of `expected`, in their order, with the same state
// slices and the same simulation to the last bit; and it moves differently from `all`.
void expect_the_arm_built_directly(const ArmDescription& got, const ArmDescription& expected,
                                   const ArmDescription& all) {
  ASSERT_EQ(got.effects.size(), expected.effects.size());
  for (std::size_t k = 0; k < got.effects.size(); ++k)
    EXPECT_EQ(effect_name(got.effects[k]), effect_name(expected.effects[k]));
  EXPECT_EQ(got.num_effect_states, expected.num_effect_states);
  EXPECT_EQ(got.effect_state_offsets, expected.effect_state_offsets);
  const io::Dataset data = softrne_test::synthetic_dataset(all, 3.0, 0.7, 5u);
  sim::ArmSimulationOptions o;
  const Eigen::MatrixXd a = fit::detail::simulated_angles(got, data, o);
  const Eigen::MatrixXd b = fit::detail::simulated_angles(expected, data, o);
  ASSERT_GT(a.size(), 0);
  EXPECT_EQ((a - b).cwiseAbs().maxCoeff(), 0.0);
  // Positive control: the change did change the motion.
  const Eigen::MatrixXd c = fit::detail::simulated_angles(all, data, o);
  EXPECT_GT((a - c).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(LoopParts, WithoutEffectIsTheArmBuiltWithoutIt) {
  // Reference: the arm built directly with the other effects, in their order.
  const ThreeEffects t;
  ArmDescription expected = t.base;
  for (const auto& e : {t.offset, t.dahl}) add_effect(expected, e);
  const ArmDescription got = fit::detail::without_effect(t.all, 0);
  EXPECT_LT(got.num_effect_states, t.all.num_effect_states);
  expect_the_arm_built_directly(got, expected, t.all);
}

TEST(LoopParts, WithEffectReplacedIsTheArmBuiltWithTheReplacementInItsPlace) {
  // Reference: the arm built directly with the replacement at the same place. The replaced
  // effect (actuator lag) has internal states and its replacement (Coulomb friction) none.
  const ThreeEffects t;
  auto coulomb = make_effect_at_neutral("coulomb_friction", t.base, Scope::Shared);
  effect_base(coulomb).params << 0.2;
  ArmDescription expected = t.base;
  for (const auto& e : {coulomb, t.offset, t.dahl}) add_effect(expected, e);
  const ArmDescription got = fit::detail::with_effect_replaced(t.all, 0, coulomb);
  EXPECT_EQ(effect_name(got.effects.at(0)), "coulomb_friction");
  EXPECT_LT(got.num_effect_states, t.all.num_effect_states);
  expect_the_arm_built_directly(got, expected, t.all);
}

TEST(LoopParts, DistributeInertiaSwitchesLumpedCcJointsOnly) {
  ArmDescription d = build_arm(softrne_test::two_joint_spec());
  ASSERT_TRUE(fit::detail::distribute_cc_inertia(d));
  int cc = 0;
  for (const auto& seg : d.spec.segments)
    if (const auto* j = std::get_if<io::CCJointSpec>(&seg)) {
      ++cc;
      EXPECT_EQ(j->inertia_model, "distributed");
    }
  EXPECT_EQ(cc, 2);
  EXPECT_FALSE(fit::detail::distribute_cc_inertia(d));  // nothing left to switch
  // The chain it builds has the distributed joints: a different mass matrix at a bent pose.
  const ArmDescription lumped = build_arm(softrne_test::two_joint_spec());
  auto cl = lumped.make_chain<double>();
  auto cd = d.make_chain<double>();
  auto dl = cl.make_data();
  auto dd = cd.make_data();
  Eigen::VectorXd q(4);
  q << 0.4, -0.2, 0.3, 0.1;
  const Eigen::MatrixXd ml = softrne::mass_matrix(cl, dl, q);
  const Eigen::MatrixXd md = softrne::mass_matrix(cd, dd, q);
  EXPECT_GT((ml - md).cwiseAbs().maxCoeff(), 1e-6 * ml.cwiseAbs().maxCoeff());
}

}  // namespace

// The confirmation slots go to distinct effects first, then to second scopes, in screen order,
// and never to a candidate predicted below the threshold (random arm 1039: two scopes each of
// two effects took all four slots before the rule and the true effect, fifth, got none).
TEST(LoopConfirmation, DistinctEffectsFirstThenSecondScopes) {
  using softrne::fit::detail::confirmation_picks;
  const std::vector<std::string> names = {"chamber_gain", "sensor_gain", "chamber_gain",
                                          "sensor_gain",  "mass_scale",  "payload",
                                          "mass_scale",   "angle_offset"};
  const std::vector<double> gains = {0.62, 0.60, 0.58, 0.55, 0.45, 0.30, 0.20, 0.005};
  EXPECT_EQ(confirmation_picks(names, gains, 4, 0.01), (std::vector<std::size_t>{0, 1, 4, 5}));
  // With slots left after every effect's best scope: the second scopes, in screen order.
  EXPECT_EQ(confirmation_picks(names, gains, 6, 0.01), (std::vector<std::size_t>{0, 1, 4, 5, 2, 3}));
  EXPECT_EQ(confirmation_picks(names, gains, 20, 0.01),
            (std::vector<std::size_t>{0, 1, 4, 5, 2, 3, 6}));  // never a third scope, nor < 1 %
  EXPECT_EQ(confirmation_picks(names, gains, 20, 0.50), (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_TRUE(confirmation_picks(names, gains, 0, 0.01).empty());
  EXPECT_TRUE(confirmation_picks({}, {}, 4, 0.01).empty());
}

// The winner: the largest mean held-out gain among the passing candidates, unless one with
// fewer parameters leaves a held-out error within the margin of the winner's (written out
// here: remaining errors 0.60 vs 0.62 are within 5 %, 0.60 vs 0.64 are not).
TEST(LoopSelection, LargestGainUnlessAParsimoniousOneIsWithinTheMargin) {
  using softrne::fit::detail::pick_winner;
  const std::vector<double> cv = {0.40, 0.38, 0.36, 0.90};
  const std::vector<Eigen::Index> n = {4, 1, 1, 1};
  EXPECT_EQ(pick_winner({0, 1, 2}, cv, n, 0.05), 1);  // 1 - 0.38 = 0.62 <= 0.60 * 1.05
  EXPECT_EQ(pick_winner({0, 2}, cv, n, 0.05), 0);     // 0.64 > 0.63
  EXPECT_EQ(pick_winner({0}, cv, n, 0.05), 0);
  EXPECT_EQ(pick_winner({3, 0}, cv, n, 0.05), 3);  // not in the list: never chosen
  EXPECT_EQ(pick_winner({}, cv, n, 0.05), -1);
}

// Gains are measured against the folds' current models: when a fold's model gets better (the
// base refitted from a candidate's refit without its effect), a candidate's gain there shrinks
// to what the effect itself explains, and a failed refit never gains.
TEST(LoopSelection, GainsAreMeasuredAgainstTheFoldsCurrentModels) {
  using softrne::fit::detail::Fold;
  using softrne::fit::detail::FoldTrial;
  using softrne::fit::detail::measured_gains;
  std::vector<Fold> folds(2);
  folds[0].held_rms = 0.010;
  folds[1].held_rms = 0.004;
  std::vector<FoldTrial> trials(2);
  for (auto& t : trials) t.angles = Eigen::MatrixXd::Zero(3, 2);
  trials[0].held_rms = 0.009;
  trials[1].held_rms = 0.003;
  std::vector<double> g = measured_gains(trials, folds);
  ASSERT_EQ(g.size(), 2u);
  EXPECT_NEAR(g[0], 0.10, 1e-15);
  EXPECT_NEAR(g[1], 0.25, 1e-15);
  folds[1].held_rms = 0.0031;  // a better base model in fold 2: the effect explains 3 % there
  g = measured_gains(trials, folds);
  EXPECT_NEAR(g[1], 1.0 - 0.003 / 0.0031, 1e-15);
  EXPECT_LT(g[1], 0.05);
  trials[0].angles.resize(0, 0);  // a failed refit
  EXPECT_EQ(measured_gains(trials, folds)[0], -std::numeric_limits<double>::infinity());
}
