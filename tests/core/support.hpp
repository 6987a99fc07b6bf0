#pragma once
// Test helpers shared by the core tests: random states, example segments and chains, errors.
// The AutoDiff references are in autodiff_reference.hpp.

#include <algorithm>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "softrne/softrne.hpp"

namespace softrne_test {

using Eigen::VectorXd;

/// Seeded uniform random vector in [-scale, scale].
inline VectorXd random_vector(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> d(-scale, scale);
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = d(rng);
  return v;
}

template <class S>
softrne::ConstantCurvatureJoint<S> paper_cc(double mass = 0.8, double h = 0.2, double D = 0.2) {
  softrne::ConstantCurvatureJoint<S> cc;
  cc.mass = S(mass);
  cc.height = S(h);
  cc.diameter = S(D);
  cc.stiffness << S(30), S(25);
  cc.damping << S(2), S(1.5);
  return cc;
}

template <class S>
softrne::RigidLink<S> paper_link(double mass = 1.5, double length = 0.15) {
  softrne::RigidLink<S> l;
  l.mass = S(mass);
  l.length = S(length);
  l.com << S(0.01), S(-0.02), S(length / 2);
  l.inertia << S(0.0052), S(0.0003), S(-0.0001), S(0.0003), S(0.0050), S(0.0002), S(-0.0001),
      S(0.0002), S(0.0048);
  return l;
}

template <class S>
softrne::RevoluteJoint<S> revolute(double ax, double ay, double az, double k = 0.5, double d = 0.1) {
  softrne::RevoluteJoint<S> r;
  r.axis = Eigen::Vector3d(ax, ay, az).normalized().cast<S>();
  r.stiffness = S(k);
  r.damping = S(d);
  return r;
}

/// The paper's arm: three CC joints, each followed by a rigid link, hanging (gravity +z).
inline softrne::DynamicChain<double> paper_arm() {
  softrne::DynamicChain<double> c;
  for (int j = 0; j < 3; ++j) {
    c.add(paper_cc<double>(0.8, 0.2, 0.2), "joint" + std::to_string(j + 1));
    c.add(paper_link<double>(j == 2 ? 0.4 : 1.5, j == 2 ? 0.05 : 0.15),
          "link" + std::to_string(j + 1));
  }
  c.gravity << 0.0, 0.0, 9.81;
  return c;
}

/// Uniform random number in [lo, hi].
inline double uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

/// A CC joint of random mass and dimensions (any inertia model).
template <class Inertia = softrne::LumpedInertia>
softrne::ConstantCurvatureJoint<double, Inertia> random_cc(std::mt19937& rng) {
  softrne::ConstantCurvatureJoint<double, Inertia> c;
  c.mass = uniform(rng, 0.2, 1.5);
  c.height = uniform(rng, 0.08, 0.3);
  c.diameter = uniform(rng, 0.04, 0.25);
  return c;
}

/// A rigid link with a full inertia tensor and its centre of mass off the axis.
inline softrne::RigidLink<double> random_link(std::mt19937& rng) {
  softrne::RigidLink<double> l;
  l.mass = uniform(rng, 0.1, 2.0);
  l.length = uniform(rng, 0.02, 0.3);
  l.com = Eigen::Vector3d(uniform(rng, -0.05, 0.05), uniform(rng, -0.05, 0.05), uniform(rng, 0, l.length));
  Eigen::Matrix3d A;
  for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = uniform(rng, -0.05, 0.05);
  l.inertia = l.mass * (A * A.transpose() + 1e-3 * Eigen::Matrix3d::Identity());
  return l;
}

/// A revolute joint about a random axis.
inline softrne::RevoluteJoint<double> random_rev(std::mt19937& rng) {
  softrne::RevoluteJoint<double> r;
  r.axis = Eigen::Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)).normalized();
  return r;
}

/// Max |a - b| / max(1, |b|_inf).
inline double rel_err(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace softrne_test
