#pragma once
// Synthetic data made by the library from a known model (plus sensor noise), for the fit and
// closed-loop tests: the truth is known exactly, so recovery can be checked.

#include <random>
#include <string>

#include "softrne/arm/arm_description.hpp"
#include "softrne/fit/arm_fit.hpp"
#include "softrne/io/robot_spec.hpp"

namespace softrne_test {

/// A hanging arm of two CC joints, each followed by a rigid link (like the paper's, shorter).
inline softrne::io::RobotSpec two_joint_spec() {
  using namespace softrne::io;
  RobotSpec s;
  s.name = "synthetic two-joint arm";
  s.gravity = Eigen::Vector3d(0, 0, 9.81);
  s.segments.push_back(make_cc_joint("joint1", 0.8, 0.2, 0.2, 0.06, 0.03, Eigen::Vector2d(30, 26), Eigen::Vector2d(2.5, 2.0)));
  RigidLinkSpec l1;
  l1.name = "link1";
  l1.mass = 1.0;
  l1.length = 0.15;
  l1.com = Eigen::Vector3d(0, 0, 0.075);
  l1.inertia = Eigen::Vector3d(0.004, 0.004, 0.003).asDiagonal();
  s.segments.push_back(l1);
  s.segments.push_back(make_cc_joint("joint2", 0.6, 0.18, 0.18, 0.05, 0.028, Eigen::Vector2d(18, 15), Eigen::Vector2d(1.2, 1.0)));
  RigidLinkSpec l2 = l1;
  l2.name = "link2";
  l2.mass = 0.4;
  l2.length = 0.05;
  l2.com = Eigen::Vector3d(0, 0, 0.025);
  l2.inertia = Eigen::Vector3d(0.0004, 0.0004, 0.0005).asDiagonal();
  s.segments.push_back(l2);
  return s;
}

/// Random pressure steps (like the paper's training set): every chamber gets a new level
/// between 0 and 150 kPa every `step` seconds, with a 30 ms first-order rise.
inline Eigen::MatrixXd random_steps(const Eigen::VectorXd& t, int channels, double step, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> level(0.0, 150e3);
  Eigen::MatrixXd p(t.size(), channels);
  for (int c = 0; c < channels; ++c) {
    double target = 0, value = 0, next = 0;
    for (Eigen::Index i = 0; i < t.size(); ++i) {
      if (t(i) >= next) {
        target = level(rng);
        next += step;
      }
      const double dt = i > 0 ? t(i) - t(i - 1) : 0.0;
      value += (target - value) * (1 - std::exp(-dt / 0.03));
      p(i, c) = value;
    }
  }
  return p;
}

/// Simulates `truth` under random pressure steps and returns a dataset of what sensors report:
/// angles + N(0, 0.003 rad), pressures + N(0, 300 Pa).
inline softrne::io::Dataset synthetic_dataset(const softrne::ArmDescription& truth, double duration, double step,
                                              unsigned seed, double angle_noise = 0.003, double pressure_noise = 300) {
  softrne::io::Dataset d;
  const int n = static_cast<int>(std::round(duration * 100));
  d.t = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) * 0.01);
  const Eigen::MatrixXd p = random_steps(d.t, truth.num_inputs, step, seed);
  softrne::sim::ArmSimulationOptions o;
  o.cvode.rtol = 1e-8;
  o.cvode.atol = 1e-9;
  const auto s = softrne::sim::simulate_arm(truth, d.t, p, Eigen::VectorXd::Zero(truth.nq), o);
  if (!s.ok()) throw std::runtime_error("synthetic data: " + s.result.message);
  std::mt19937 rng(seed + 1000);
  std::normal_distribution<double> na(0.0, angle_noise), np(0.0, pressure_noise);
  d.angles = s.angles;
  for (Eigen::Index i = 0; i < d.angles.size(); ++i) d.angles.data()[i] += na(rng);
  d.pressures = p;
  for (Eigen::Index i = 0; i < d.pressures.size(); ++i) d.pressures.data()[i] += np(rng);
  d.has_angles = true;
  d.angle_names = truth.coordinate_names;
  d.pressure_names = truth.pressure_names;
  d.source = "synthetic(seed " + std::to_string(seed) + ")";
  return d;
}

/// `base` with its stiffness and damping scaled (a wrong starting guess).
inline softrne::ArmDescription perturbed(softrne::ArmDescription d, double k_factor, double d_factor) {
  for (auto& j : d.joints) {
    j.stiffness *= k_factor;
    j.damping *= d_factor;
  }
  return d;
}

}  // namespace softrne_test
