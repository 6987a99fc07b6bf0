// Several recordings that start in motion (issue 19 items 1-2): the initial-rate estimate
// against a closed form and its noise against theory; stacking against the parts; a fit on
// logs cut out of one long run (made by one simulate_arm call from rest, not by the stacked
// per-recording path that fits them) recovers the truth.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "softrne/fit/arm_fit.hpp"
#include "softrne/io/recordings.hpp"
#include "softrne/signals/initial_rate.hpp"
#include "synthetic_arm.hpp"

namespace fit_test_recordings {

using namespace softrne;

TEST(InitialRate, ExactOnAQuadraticAndItsNoiseAsTheLeastSquaresTheorySays) {
  // A quadratic is fitted exactly whatever the sampling: the slope at t0 is b + 2 c t0.
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(30, 3.0, 3.0 + 29 * 0.02);
  Eigen::MatrixXd y(30, 2);
  for (Eigen::Index i = 0; i < 30; ++i) {
    y(i, 0) = 0.3 - 1.7 * t(i) + 0.45 * t(i) * t(i);
    y(i, 1) = -2.0 + 0.2 * t(i);
  }
  const Eigen::VectorXd r = signals::initial_rate(t, y, 9);
  EXPECT_NEAR(r(0), -1.7 + 2 * 0.45 * 3.0, 1e-10);
  EXPECT_NEAR(r(1), 0.2, 1e-11);
  // White noise sigma through 9 samples at 100 Hz: the standard deviation of the slope is
  // sigma sqrt((A^T A)^-1)_11, 0.1421 rad/s for sigma 3e-3 (computed independently with numpy).
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 3e-3);
  const Eigen::VectorXd tn = Eigen::VectorXd::LinSpaced(9, 0.0, 0.08);
  double sum2 = 0;
  const int trials = 4000;
  for (int k = 0; k < trials; ++k) {
    Eigen::MatrixXd yn(9, 1);
    for (Eigen::Index i = 0; i < 9; ++i) yn(i, 0) = noise(rng);
    const double s = signals::initial_rate(tn, yn, 9)(0);
    sum2 += s * s;
  }
  EXPECT_NEAR(std::sqrt(sum2 / trials), 0.1421, 0.1421 * 0.05);  // 4000 trials: 1.1 % std
  EXPECT_THROW(signals::initial_rate(t.head(2), y.topRows(2)), std::invalid_argument);
}

io::Dataset part(double t0, int n, int cols, const std::string& name) {
  io::Dataset d;
  d.t = Eigen::VectorXd::LinSpaced(n, t0, t0 + 0.01 * (n - 1));
  d.pressures = Eigen::MatrixXd::Random(n, 4);
  d.angles = Eigen::MatrixXd::Random(n, cols);
  d.has_angles = true;
  d.source = name;
  return d;
}

TEST(Recordings, StackedTimesIncreaseAndEachRecordingComesBackAsRead) {
  // The second file's clock starts before the first one's ends (separate logs): stacked, it
  // starts one interval after.
  const std::vector<io::Dataset> parts{part(5.0, 40, 4, "a.csv"), part(1.0, 25, 4, "b.csv"), part(0.0, 30, 4, "c.csv")};
  const io::Dataset s = io::stack_recordings(parts);
  ASSERT_EQ(s.recordings.size(), 3u);
  EXPECT_EQ(s.t.size(), 95);
  EXPECT_EQ(s.source, "a.csv + b.csv + c.csv");
  for (Eigen::Index i = 1; i < s.t.size(); ++i) EXPECT_GT(s.t(i), s.t(i - 1)) << i;
  EXPECT_NEAR(s.t(40) - s.t(39), 0.01, 1e-12);
  for (std::size_t k = 0; k < 3; ++k) {
    const io::Dataset back = io::recording(s, k);
    EXPECT_EQ(back.source, parts[k].source);
    EXPECT_NEAR((back.t - parts[k].t).cwiseAbs().maxCoeff(), 0.0, 1e-12);
    EXPECT_EQ(back.pressures, parts[k].pressures);
    EXPECT_EQ(back.angles, parts[k].angles);
  }
  // One recording stays a plain data set (from rest, no list): one-file behaviour is unchanged.
  EXPECT_TRUE(io::stack_recordings({parts[0]}).recordings.empty());
  io::Dataset other = part(0.0, 10, 3, "d.csv");
  EXPECT_THROW(io::stack_recordings({parts[0], other}), std::invalid_argument);
}

/// Logs cut out of one long noise-free run of `truth` (one simulate_arm call from rest), each
/// starting `offset` s after a pressure step, so that every log starts in motion; its own
/// clock starts at 0; sensor noise added afterwards.
struct CutLogs {
  std::vector<io::Dataset> logs;
  std::vector<Eigen::VectorXd> true_rates;  // measured-space rates at each log's first sample
};
CutLogs cut_logs(const ArmDescription& truth, unsigned seed, int offset_rows) {
  const int n = 2000;  // 20 s at 100 Hz
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) * 0.01);
  const Eigen::MatrixXd p = softrne_test::random_steps(t, truth.num_inputs, 1.0, seed);
  sim::ArmSimulationOptions o;
  o.cvode.rtol = 1e-10;
  o.cvode.atol = 1e-11;
  const sim::ArmSimulation run = sim::simulate_arm(truth, t, p, Eigen::VectorXd::Zero(truth.nq), o);
  EXPECT_TRUE(run.ok()) << run.result.message;
  CutLogs out;
  std::mt19937 rng(seed + 7);
  std::normal_distribution<double> na(0.0, 0.003);
  const int steps[] = {200, 600, 1100, 1500};  // pressure steps at 2, 6, 11 and 15 s
  for (int k = 0; k < 4; ++k) {
    const int a = steps[k] + offset_rows, rows = 300;
    io::Dataset d;
    d.t = t.segment(a, rows).array() - t(a);
    d.pressures = p.middleRows(a, rows);
    d.angles = run.angles.middleRows(a, rows);
    for (Eigen::Index i = 0; i < d.angles.size(); ++i) d.angles.data()[i] += na(rng);
    d.has_angles = true;
    d.angle_names = truth.coordinate_names;
    d.pressure_names = truth.pressure_names;
    d.source = "log" + std::to_string(k) + ".csv";
    out.logs.push_back(d);
    out.true_rates.push_back(run.states.row(a).segment(truth.nq, truth.nq).transpose());  // no sensor gain here
  }
  return out;
}

struct StartErrors {
  double worst_rate = 0, fastest = 0;  // rad/s
  signals::ErrorStats rest, moving;
};
StartErrors start_errors(const ArmDescription& truth, int offset_rows) {
  const CutLogs cut = cut_logs(truth, 3, offset_rows);
  io::Dataset data = io::stack_recordings(cut.logs);
  const sim::ArmSimulationOptions so = fit::ArmFitOptions::default_simulation();
  StartErrors out;
  // At rest at each first sample (the one-file assumption).
  const sim::ArmSimulation at_rest = fit::simulate_dataset(truth, data, so);
  EXPECT_TRUE(at_rest.ok()) << at_rest.result.message;
  io::estimate_initial_rates(data);
  for (std::size_t k = 0; k < 4; ++k) {
    out.worst_rate = std::max(out.worst_rate, (data.recordings[k].initial_rates - cut.true_rates[k]).cwiseAbs().maxCoeff());
    out.fastest = std::max(out.fastest, cut.true_rates[k].cwiseAbs().maxCoeff());
  }
  const sim::ArmSimulation moving = fit::simulate_dataset(truth, data, so);
  EXPECT_TRUE(moving.ok()) << moving.result.message;
  out.rest = signals::error_stats(at_rest.angles, data.angles, truth.coordinate_names);
  out.moving = signals::error_stats(moving.angles, data.angles, truth.coordinate_names);
  std::printf("[ info ] true model on 4 logs cut %.2f s after a pressure step: mean / max error from rest "
              "%.4f / %.4f rad, from the estimated rates %.4f / %.4f rad; worst rate error %.3f rad/s (fastest "
              "start %.2f rad/s)\n", 0.01 * offset_rows, out.rest.total.mean, out.rest.total.max,
              out.moving.total.mean, out.moving.total.max, out.worst_rate, out.fastest);
  // Each recording is simulated on its own: the stacked simulation's rows of log 2 equal a
  // simulation of log 2 alone.
  const io::Dataset log2 = io::recording(data, 2);
  const sim::ArmSimulation alone = fit::simulate_dataset(truth, log2, so);
  const auto& r2 = data.recordings[2];
  EXPECT_EQ(alone.angles, moving.angles.middleRows(r2.first_row, r2.rows));
  return out;
}

TEST(Recordings, LogsThatStartInMotionSimulateFromTheirEstimatedRates) {
  const ArmDescription truth = build_arm(softrne_test::two_joint_spec());
  // Cut 0.4 s after a step, where the motion is smooth over the estimate's 9 samples: the rate
  // error is the noise's (InitialRate test: sigma 0.142 rad/s; 8 estimates, all within 4
  // sigma) and the true model explains the data to the sensor noise (mean |N(0, 0.003)| =
  // 0.0024 rad), but not from rest.
  const StartErrors smooth = start_errors(truth, 40);
  EXPECT_GT(smooth.fastest, 0.3);  // the logs do start in motion
  EXPECT_LT(smooth.worst_rate, 4 * 0.1421);
  EXPECT_LT(smooth.moving.total.mean, 0.0026);
  EXPECT_GT(smooth.rest.total.max, 2 * smooth.moving.total.max);
  // Cut 0.05 s after a step (the chambers still filling, the arm at up to 7 rad/s and its
  // acceleration changing fast): the quadratic's bias dominates (0.49 rad/s here), which
  // a start at rest still does far worse than. Fitting the initial rates as nuisance
  // parameters would remove it (not built: docs/formats.md, --initial-motion).
  const StartErrors fast = start_errors(truth, 5);
  EXPECT_GT(fast.fastest, 3.0);
  EXPECT_GT(fast.rest.total.max, 3 * fast.moving.total.max);
  EXPECT_LT(fast.moving.total.mean, 0.0030);
}

TEST(Recordings, AFitOnLogsThatStartInMotionRecoversStiffnessAndDamping) {
  const ArmDescription truth = build_arm(softrne_test::two_joint_spec());
  io::Dataset data = io::stack_recordings(cut_logs(truth, 5, 5).logs);
  io::estimate_initial_rates(data);
  const ArmDescription start = softrne_test::perturbed(truth, 1.6, 0.6);
  const fit::ArmFitResult r = fit::fit_arm(start, data);
  for (std::size_t j = 0; j < truth.joints.size(); ++j)
    for (int k = 0; k < 2; ++k) {
      EXPECT_NEAR(r.fitted.joints[j].stiffness(k) / truth.joints[j].stiffness(k), 1.0, 0.03)
          << "stiffness joint " << j << " axis " << k;
      EXPECT_NEAR(r.fitted.joints[j].damping(k) / truth.joints[j].damping(k), 1.0, 0.10)
          << "damping joint " << j << " axis " << k;
    }
  EXPECT_LT(r.stats.total.mean, 0.0027);
  std::printf("[ info ] fit on 4 logs cut in motion: %d simulations, %.1f s, train mean error %.4f rad\n",
              r.simulations, r.wall_seconds, r.stats.total.mean);
}

}  // namespace fit_test_recordings
