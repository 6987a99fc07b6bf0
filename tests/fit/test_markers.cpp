// Motion-capture markers (issue 19 item 3): the robot file's markers and the data columns,
// marker positions against the paper's closed form of one CC joint (eqs. 2-4), the capture
// frame's closed-form fit, and a fit from markers alone, in a rotated and shifted capture frame
// with 1 mm noise, that recovers stiffness, damping and the frame within their standard errors.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "softrne/arm/markers.hpp"
#include "softrne/fit/arm_fit.hpp"
#include "softrne/io/recordings.hpp"
#include "softrne/io/robot_json.hpp"
#include "../sanitizer_build.hpp"
#include "synthetic_arm.hpp"

namespace fit_test_markers {

using namespace softrne;

io::RobotSpec with_markers(io::RobotSpec s) {
  s.markers.push_back({"elbow", "link1", Eigen::Vector3d(0.02, 0.0, 0.0)});
  s.markers.push_back({"tip", "link2", Eigen::Vector3d(0.0, 0.01, 0.05)});
  return s;
}

TEST(Markers, RobotFileRoundTripAndOneLineErrors) {
  const io::RobotSpec s = with_markers(softrne_test::two_joint_spec());
  const io::RobotSpec back = io::parse_robot_json(io::to_json(s).dump(), "m.json");
  ASSERT_EQ(back.markers.size(), 2u);
  EXPECT_EQ(back.markers[1].name, "tip");
  EXPECT_EQ(back.markers[1].segment, "link2");
  EXPECT_EQ(back.markers[1].offset, s.markers[1].offset);
  auto error_of = [&](const std::string& markers) {
    nlohmann::json j = io::to_json(s);
    j["markers"] = nlohmann::json::parse(markers);
    try {
      io::parse_robot_json(j.dump(), "m.json");
    } catch (const io::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of(R"([{"name": "tip", "segment": "nowhere", "offset": [0, 0, 0]}])")
                .find("markers[0] 'tip': field 'segment'"), std::string::npos)
      << error_of(R"([{"name": "tip", "segment": "nowhere", "offset": [0, 0, 0]}])");
  EXPECT_NE(error_of(R"([{"name": "2tip", "segment": "link1", "offset": [0, 0, 0]}])").find("field 'name'"),
            std::string::npos);
  EXPECT_NE(error_of(R"([{"name": "a", "segment": "link1", "offset": [0, 0, 0]},
                         {"name": "a", "segment": "link2", "offset": [0, 0, 0]}])").find("duplicate marker"),
            std::string::npos);
  EXPECT_NE(error_of(R"([{"name": "a", "segment": "link1", "offset": [0, 0]}])").find("offset"), std::string::npos);
  EXPECT_NE(error_of(R"([{"name": "a", "segment": "link1", "offset": [0, 0, 0], "colour": 1}])").find("colour"),
            std::string::npos);
}

TEST(Markers, DataColumnsStandInForAnglesAndComeAllOrNone) {
  const io::RobotSpec s = with_markers(softrne_test::two_joint_spec());
  std::string head = "t", row0 = "0", row1 = "0.01";
  for (const auto& p : io::pressure_column_names(s)) head += "," + p, row0 += ",0", row1 += ",0";
  for (const auto& m : io::marker_column_names(s)) head += "," + m, row0 += ",0.5", row1 += ",0.25";
  const io::Dataset d = io::parse_dataset(head + "\n" + row0 + "\n" + row1 + "\n", "m.csv", s, true);
  EXPECT_TRUE(d.has_markers);
  EXPECT_FALSE(d.has_angles);
  ASSERT_EQ(d.markers.cols(), 6);
  EXPECT_EQ(d.markers(1, 5), 0.25);
  // Without the marker columns the angles are required; a partial marker set is refused.
  std::string bare = "t";
  for (const auto& p : io::pressure_column_names(s)) bare += "," + p;
  EXPECT_THROW(io::parse_dataset(bare + "\n0,0,0,0,0,0,0,0,0\n0.01,0,0,0,0,0,0,0,0\n", "m.csv", s, true),
               io::InputError);
  try {
    io::parse_dataset(bare + ",tip_x,tip_y,tip_z\n0,0,0,0,0,0,0,0,0,1,2,3\n0.01,0,0,0,0,0,0,0,0,1,2,3\n", "m.csv", s,
                      false);
    ADD_FAILURE() << "a partial marker set was accepted";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("elbow_x"), std::string::npos) << e.what();
  }
}

TEST(Markers, PositionsMatchThePapersClosedFormOfACcJoint) {
  // One CC joint with a marker c along its distal z axis. Eqs. 2-4: phi = |(u, v)|,
  // rho = h / phi^2 (v, -u, 0), tip r = (-rho_x s, -rho_y s, |rho| sin phi) with
  // s = cos phi - 1, distal z axis (v~ sin phi, -u~ sin phi, cos phi), u~ = u / phi.
  io::RobotSpec s;
  s.gravity = Eigen::Vector3d(0, 0, 9.81);
  const double h = 0.23, c = 0.04;
  s.segments.push_back(io::make_cc_joint("j", 0.5, h, 0.2, 0.05, 0.02, Eigen::Vector2d(10, 10), Eigen::Vector2d(1, 1)));
  s.markers.push_back({"m", "j", Eigen::Vector3d(0, 0, c)});
  const ArmDescription d = build_arm(s);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> U(-1.2, 1.2);
  double worst = 0;
  for (int k = 0; k < 20; ++k) {
    const double u = U(rng), v = U(rng), phi = std::hypot(u, v);
    const Eigen::Vector3d rho = h / (phi * phi) * Eigen::Vector3d(v, -u, 0);
    const double sg = std::cos(phi) - 1;
    const Eigen::Vector3d r(-rho.x() * sg, -rho.y() * sg, rho.norm() * std::sin(phi));
    const Eigen::Vector3d z(v / phi * std::sin(phi), -u / phi * std::sin(phi), std::cos(phi));
    const Eigen::Vector3d expected = r + c * z;
    Eigen::MatrixXd q(1, 2);
    q << u, v;
    worst = std::max(worst, (marker_positions(d, q).row(0).transpose() - expected).norm());
  }
  EXPECT_LT(worst, 1e-14);
}

TEST(Markers, CaptureFrameIsRecoveredExactlyFromExactPoints) {
  std::mt19937 rng(9);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd base(50, 6);
  for (Eigen::Index i = 0; i < base.size(); ++i) base.data()[i] = 0.3 * n01(rng);
  CaptureFrame truth;
  truth.R = Eigen::AngleAxisd(2.5, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  truth.t = Eigen::Vector3d(1.5, -0.3, 0.8);
  const CaptureFrame f = fit_capture_frame(base, truth.apply(base));
  EXPECT_LT((f.R - truth.R).norm(), 1e-12);
  EXPECT_LT((f.t - truth.t).norm(), 1e-12);
  EXPECT_NEAR(f.R.determinant(), 1.0, 1e-12);  // never a reflection
}

/// Pressures of random steps after 0.5 s at zero: the hanging arm rests straight (q = 0), the
/// equilibrium the fit starts a markers-only recording in.
io::Dataset marker_data(const ArmDescription& truth, const CaptureFrame& frame, double noise, unsigned seed) {
  const int n = 1000;
  io::Dataset d;
  d.t = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) * 0.01);
  Eigen::MatrixXd p = softrne_test::random_steps(d.t, truth.num_inputs, 1.5, seed);
  p.topRows(50).setZero();
  sim::ArmSimulationOptions o;
  o.cvode.rtol = 1e-10;
  o.cvode.atol = 1e-11;
  const sim::ArmSimulation s = sim::simulate_arm(truth, d.t, p, Eigen::VectorXd::Zero(truth.nq), o);
  EXPECT_TRUE(s.ok()) << s.result.message;
  d.markers = frame.apply(marker_positions(truth, s.states));
  std::mt19937 rng(seed + 1);
  std::normal_distribution<double> nm(0.0, noise);
  for (Eigen::Index i = 0; i < d.markers.size(); ++i) d.markers.data()[i] += nm(rng);
  d.has_markers = true;
  d.pressures = p;
  d.angles = Eigen::MatrixXd(n, 0);
  d.pressure_names = truth.pressure_names;
  d.angle_names = truth.coordinate_names;
  d.source = "markers(seed " + std::to_string(seed) + ")";
  return d;
}

/// |fitted - true| / standard error of K, D (8) and of the frame (6) for one data set.
std::vector<double> marker_fit_z_scores(const ArmDescription& truth, const CaptureFrame& frame, unsigned seed,
                                        fit::ArmFitResult& r) {
  const io::Dataset data = marker_data(truth, frame, 1e-3, seed);
  r = fit::fit_arm(softrne_test::perturbed(truth, 1.5, 0.7), data);
  std::vector<double> z;
  EXPECT_EQ(r.fit.std_errors.size(), 8);
  EXPECT_EQ(r.capture_frames.size(), 1u);
  EXPECT_EQ(r.capture_frame_std_errors.size(), 1u);
  if (r.fit.std_errors.size() != 8 || r.capture_frame_std_errors.size() != 1) return z;
  const Eigen::VectorXd& se = r.capture_frame_std_errors[0];
  int k = 0;
  for (std::size_t j = 0; j < truth.joints.size(); ++j)
    for (int a = 0; a < 2; ++a) {
      z.push_back((r.fitted.joints[j].stiffness(a) - truth.joints[j].stiffness(a)) / r.fit.std_errors(k++));
      z.push_back((r.fitted.joints[j].damping(a) - truth.joints[j].damping(a)) / r.fit.std_errors(k++));
    }
  // The frame: the rotation error as a rotation vector, per axis; the translation per axis.
  const Eigen::AngleAxisd dR(r.capture_frames[0].R * frame.R.transpose());
  const Eigen::Vector3d rot_err = dR.angle() * dR.axis(), t_err = r.capture_frames[0].t - frame.t;
  for (int i = 0; i < 3; ++i) z.push_back(rot_err(i) / se(i));
  for (int i = 0; i < 3; ++i) z.push_back(t_err(i) / se(3 + i));
  return z;
}

TEST(Markers, AFitFromMarkersAloneRecoversThePhysicsAndTheCaptureFrame) {
  // Ten data sets (noise seeds and pressure sequences; four under the sanitizers,
  // sanitizer_build.hpp): every error within 4.5 standard errors, and their root mean square
  // near 1, so the standard errors are the errors' size (neither hiding a bias nor inflated);
  // then the noise is all that is left.
  const ArmDescription truth = build_arm(with_markers(softrne_test::two_joint_spec()));
  CaptureFrame frame;
  frame.R = Eigen::AngleAxisd(0.6, Eigen::Vector3d(0.3, 1, -0.2).normalized()).toRotationMatrix();
  frame.t = Eigen::Vector3d(0.8, -0.4, 1.3);
  double sum2 = 0, worst = 0;
  int count = 0;
  fit::ArmFitResult r;
  const unsigned data_sets = softrne_test::kSanitizerBuild ? 4 : 10;
  for (unsigned seed = 21; seed < 21 + data_sets; ++seed) {
    const std::vector<double> z = marker_fit_z_scores(truth, frame, seed, r);
    ASSERT_EQ(z.size(), 14u);
    for (std::size_t i = 0; i < z.size(); ++i) {
      EXPECT_LT(std::abs(z[i]), 4.5) << "seed " << seed << " quantity " << i << " (0-7 K, D; 8-10 rotation; 11-13 "
                                     << "translation)";
      sum2 += z[i] * z[i];
      worst = std::max(worst, std::abs(z[i]));
      ++count;
    }
    // Per marker the distance of N(0, 1 mm) in 3D has mean 2 sqrt(2 / pi) = 1.60 mm.
    ASSERT_EQ(r.marker_stats.names.size(), 2u);
    EXPECT_NEAR(r.marker_stats.total.mean, 1.60, 0.08) << "seed " << seed;
  }
  const double rms = std::sqrt(sum2 / count);
  EXPECT_GT(rms, 0.6);
  EXPECT_LT(rms, 1.6);
  std::printf("[ info ] markers only, %u data sets: errors / standard errors rms %.2f, worst %.2f (%d quantities); "
              "last: %d simulations, %.1f s, marker mean error %.3f mm\n",
              data_sets, rms, worst, count, r.simulations, r.wall_seconds, r.marker_stats.total.mean);
}

TEST(Markers, EachRecordingInItsOwnCaptureFrame) {
  // Two logs whose motion-capture frames differ by a half turn (as the ETH trunk's logs do):
  // one frame per recording recovers both and the physics; one shared frame cannot fit them.
  const ArmDescription truth = build_arm(with_markers(softrne_test::two_joint_spec()));
  CaptureFrame a, b;
  a.R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0, 1, 0)).toRotationMatrix();
  a.t = Eigen::Vector3d(0.1, 0.2, 0.3);
  b.R = Eigen::AngleAxisd(3.14159265358979, Eigen::Vector3d(1, 0, 0)).toRotationMatrix() * a.R;
  b.t = Eigen::Vector3d(-0.5, 0.0, 1.0);
  const io::Dataset data = io::stack_recordings({marker_data(truth, a, 1e-3, 41), marker_data(truth, b, 1e-3, 42)});
  fit::ArmFitOptions per;
  per.capture_frame_per_recording = true;
  const fit::ArmFitResult r = fit::fit_arm(softrne_test::perturbed(truth, 1.5, 0.7), data, per);
  ASSERT_EQ(r.capture_frames.size(), 2u);
  ASSERT_EQ(r.capture_frame_std_errors.size(), 2u);
  const CaptureFrame* truth_frames[] = {&a, &b};
  for (std::size_t g = 0; g < 2; ++g) {
    const Eigen::AngleAxisd dR(r.capture_frames[g].R * truth_frames[g]->R.transpose());
    const Eigen::Vector3d rot = dR.angle() * dR.axis(), dt = r.capture_frames[g].t - truth_frames[g]->t;
    for (int i = 0; i < 3; ++i) {
      EXPECT_LT(std::abs(rot(i)), 4.5 * r.capture_frame_std_errors[g](i)) << "frame " << g << " axis " << i;
      EXPECT_LT(std::abs(dt(i)), 4.5 * r.capture_frame_std_errors[g](3 + i)) << "frame " << g << " axis " << i;
    }
  }
  for (std::size_t j = 0; j < truth.joints.size(); ++j)
    for (int k = 0; k < 2; ++k)
      EXPECT_NEAR(r.fitted.joints[j].stiffness(k) / truth.joints[j].stiffness(k), 1.0, 0.02);
  EXPECT_NEAR(r.marker_stats.total.mean, 1.60, 0.08);
  // One shared frame cannot hold two frames a half turn apart whatever the optimiser's budget
  // (the error is structural), so its fit gets one local start of 100 evaluations: the full
  // default budget took 40 % of this test in Release and minutes under the sanitizers.
  fit::ArmFitOptions one_frame;
  one_frame.optimiser.global_evals = 0;
  one_frame.optimiser.multistart_starts = 1;
  one_frame.optimiser.local_evals = 100;
  const fit::ArmFitResult shared = fit::fit_arm(softrne_test::perturbed(truth, 1.5, 0.7), data, one_frame);
  ASSERT_EQ(shared.capture_frames.size(), 1u);
  EXPECT_GT(shared.marker_stats.total.mean, 20 * r.marker_stats.total.mean);
  std::printf("[ info ] two logs in frames a half turn apart: marker mean error %.3f mm with a frame each, %.1f mm "
              "with one shared\n", r.marker_stats.total.mean, shared.marker_stats.total.mean);
}

}  // namespace fit_test_markers
