// ConstantCurvatureJoint against references that share none of its code: the arc integrated
// as an ODE along its length, direct sums over thin disks (paper eq. 22 with the parallel-axis
// theorem applied here), closed forms. Its Jacobians and rates against AutoDiff and finite
// differences, its scalar casts and calc's allocations are checked with every other segment
// type in tests/segments/test_segment_conformance.cpp.
#include "../eigen_malloc_guard.hpp"  // first: before anything includes Eigen
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "softrne/segments/constant_curvature_joint.hpp"
#include "support.hpp"

namespace core_test_cc_joint {

using softrne::ConstantCurvatureJoint;
using Joint = ConstantCurvatureJoint<double>;
using Kin = Joint::Kinematics;
using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

Joint joint() { return softrne_test::paper_cc<double>(0.8, 0.2, 0.15); }

Kin calc(const Joint& j, const Vector2d& q, const Vector2d& qd = Vector2d::Zero()) {
  Kin k;
  j.calc(q, qd, k);
  return k;
}

// Rotation about a unit axis (independent Rodrigues).
Matrix3d axis_angle(const Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

// Integrates the arc as an ODE in arc length: dR/dl = R [kappa]x, dp/dl = R e_z with the
// constant body-frame curvature kappa = (u, v, 0)/h. Classical RK4 with n steps.
void integrate_arc(const Vector2d& q, double h, int n, Matrix3d& R, Vector3d& p) {
  const Vector3d kappa = Vector3d(q(0), q(1), 0) / h;
  const double dl = h / n;
  R.setIdentity();
  p.setZero();
  // Exact rotation increment per step keeps R on SO(3); position by Simpson on each step.
  const Matrix3d dR = axis_angle(kappa.norm() > 0 ? kappa.normalized() : Vector3d::UnitX(),
                                 kappa.norm() * dl);
  const Matrix3d dR_half = axis_angle(kappa.norm() > 0 ? kappa.normalized() : Vector3d::UnitX(),
                                      kappa.norm() * dl / 2);
  for (int i = 0; i < n; ++i) {
    const Vector3d t0 = R.col(2), tm = (R * dR_half).col(2), t1 = (R * dR).col(2);
    p += dl / 6 * (t0 + 4 * tm + t1);
    R = R * dR;
  }
}

// Centre of mass and inertia about it (base frame) by summing n thin disks at their
// midpoints, paper eqs. 20-22 written out here.
void disk_sum(const Joint& j, const Vector2d& q, int n, Vector3d& com, Matrix3d& I) {
  const double phi = q.norm();
  const double h = j.height, m = j.mass, D = j.diameter;
  const Vector3d k = phi > 0 ? Vector3d(q(0) / phi, q(1) / phi, 0) : Vector3d::UnitX();
  const Matrix3d I_disk = Vector3d(0.25, 0.25, 0.5).asDiagonal() * (D / 2) * (D / 2);
  com.setZero();
  Matrix3d I_o = Matrix3d::Zero();  // about the base origin
  for (int i = 0; i < n; ++i) {
    const double l = (i + 0.5) * h / n;
    const double th = phi * l / h;
    Vector3d p;
    if (phi > 0) {
      const double rho = h / phi;
      p = Vector3d(rho * (1 - std::cos(th)) * k(1), -rho * (1 - std::cos(th)) * k(0),
                   rho * std::sin(th));
    } else {
      p = Vector3d(0, 0, l);
    }
    const Matrix3d Rd = axis_angle(k, th);
    const double dm = m / n;
    com += dm * p;
    I_o += dm * (Rd * I_disk * Rd.transpose() + (p.squaredNorm() * Matrix3d::Identity() - p * p.transpose()));
  }
  com /= m;
  I = I_o - m * (com.squaredNorm() * Matrix3d::Identity() - com * com.transpose());
}

TEST(ConstantCurvatureJoint, RotationIsProperAndMatchesElementaryRotations) {
  const Joint j = joint();
  std::mt19937 rng(1);
  for (int i = 0; i < 200; ++i) {
    const Vector2d q = softrne_test::random_vector(rng, 2, 3.0);
    const Matrix3d R = calc(j, q).R_base_distal;
    EXPECT_LT((R.transpose() * R - Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
  }
  for (double a : {-2.0, -0.3, 1e-9, 0.7, 3.0}) {
    EXPECT_LT((calc(j, Vector2d(a, 0)).R_base_distal - axis_angle(Vector3d::UnitX(), a)).norm(), 1e-15);
    EXPECT_LT((calc(j, Vector2d(0, a)).R_base_distal - axis_angle(Vector3d::UnitY(), a)).norm(), 1e-15);
  }
}

TEST(ConstantCurvatureJoint, DistalPoseMatchesIntegratedArc) {
  const Joint j = joint();
  std::mt19937 rng(2);
  double worst = 0;
  for (int i = 0; i < 50; ++i) {
    const Vector2d q = softrne_test::random_vector(rng, 2, 2.2);
    Matrix3d R;
    Vector3d p;
    integrate_arc(q, j.height, 2000, R, p);
    const Kin k = calc(j, q);
    worst = std::max(worst, (k.r_base_distal - p).norm() / j.height);
    EXPECT_LT((k.R_base_distal - R).norm(), 1e-12);
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(ConstantCurvatureJoint, ComAndInertiaMatchDiskSums) {
  const Joint j = joint();
  std::mt19937 rng(3);
  for (int i = 0; i < 20; ++i) {
    const Vector2d q = i == 0 ? Vector2d(0, 0) : Vector2d(softrne_test::random_vector(rng, 2, 2.2));
    // Richardson extrapolation of the midpoint sums (error ~ n^-2) of 10,000 and 20,000 disks.
    Vector3d c1, c2;
    Matrix3d I1, I2;
    disk_sum(j, q, 10000, c1, I1);
    disk_sum(j, q, 20000, c2, I2);
    const Vector3d com = (4 * c2 - c1) / 3;
    const Matrix3d Ib = (4 * I2 - I1) / 3;
    const Kin k = calc(j, q);
    EXPECT_LT((k.r_base_com - com).norm() / j.height, 1e-12) << q.transpose();
    const Matrix3d I_distal_ref = k.R_base_distal.transpose() * Ib * k.R_base_distal;
    EXPECT_LT((k.inertia_com - I_distal_ref).norm() / Ib.norm(), 1e-11) << q.transpose();
  }
}

TEST(ConstantCurvatureJoint, StraightJointMassMatrixTermClosedForm) {
  // At q = 0 the lumped body gives M_uu = m (h^2/9 + D^2/16) (COM speed h/6 and I_xx).
  const Joint j = joint();
  const Kin k = calc(j, Vector2d::Zero());
  const double Muu = j.mass * k.J_com.col(0).squaredNorm() +
                     k.J_distal.bottomRows<3>().col(0).dot(k.inertia_com * k.J_distal.bottomRows<3>().col(0));
  const double h = j.height, D = j.diameter;
  EXPECT_NEAR(Muu, j.mass * (h * h / 9 + D * D / 16), 1e-15);
}

TEST(ConstantCurvatureJoint, NearSingularConfigurations) {
  const Joint j = joint();
  const double sw = std::sqrt(softrne::detail::kCCSeriesSwitch);
  const double swd = std::sqrt(softrne::detail::kCCDiffSwitch);
  std::vector<double> phis = {0.0, 1e-12, 1e-8, 1e-4, 1e-3, 0.1, sw, swd, 3.0, M_PI - 1e-9, M_PI};
  for (double s : {sw, swd, sw / 2, swd / 2}) {
    phis.push_back(std::nextafter(s, 0.0));
    phis.push_back(std::nextafter(s, 10.0));
  }
  for (double phi : phis) {
    for (double dir : {0.0, 0.7, 2.0}) {
      const Vector2d q(phi * std::cos(dir), phi * std::sin(dir));
      const Vector2d qd(0.8, -1.3);
      const Kin k = calc(j, q, qd);
      Matrix3d R;
      Vector3d p;
      integrate_arc(q, j.height, 400, R, p);
      EXPECT_LT((k.r_base_distal - p).norm() / j.height, 1e-12) << phi;
      EXPECT_LT((k.R_base_distal - R).norm(), 1e-12) << phi;
      EXPECT_TRUE(k.J_distal.allFinite() && k.Jdot_qdot_distal.allFinite() && k.J_com.allFinite() &&
                  k.inertia_com.allFinite() && k.dinertia_dq[0].allFinite());
      // The derivatives at these angles: tests/segments/test_segment_conformance.cpp.
    }
  }
}

TEST(ConstantCurvatureJoint, SwitchPointsAreContinuous) {
  // Values and first derivatives just below and just above each switch agree to 1e-12.
  const Joint j = joint();
  for (double s2 : {softrne::detail::kCCSeriesSwitch, softrne::detail::kCCDiffSwitch,
                    softrne::detail::kCCSeriesSwitch / 4}) {
    const double s = std::sqrt(s2);
    for (double dir : {0.0, 0.4, 1.3}) {
      const Vector2d c(std::cos(dir), std::sin(dir));
      const Vector2d qd(0.5, 0.9);
      const Kin a = calc(j, std::nextafter(s, 0.0) * c, qd);
      const Kin b = calc(j, std::nextafter(s, 10.0) * c, qd);
      auto rel = [](const auto& x, const auto& y) {
        return (x - y).norm() / std::max(1e-300, y.norm());
      };
      EXPECT_LT(rel(a.r_base_distal, b.r_base_distal), 1e-12);
      EXPECT_LT(rel(a.r_base_com, b.r_base_com), 1e-12);
      EXPECT_LT(rel(a.J_distal, b.J_distal), 1e-12);
      EXPECT_LT(rel(a.J_com, b.J_com), 1e-12);
      EXPECT_LT(rel(a.Jdot_qdot_distal, b.Jdot_qdot_distal), 1e-12);
      EXPECT_LT(rel(a.Jdot_qdot_com, b.Jdot_qdot_com), 1e-12);
      EXPECT_LT(rel(a.inertia_com, b.inertia_com), 1e-12);
      EXPECT_LT(rel(a.dinertia_dq[0], b.dinertia_dq[0]), 1e-12);
      EXPECT_LT(rel(a.dinertia_dq[1], b.dinertia_dq[1]), 1e-12);
    }
  }
}

TEST(ConstantCurvatureJoint, PressureMapIsEquation24) {
  const Joint j = joint();
  const double dA = 0.06 * M_PI * 0.03 * 0.03;
  Eigen::Vector4d p(1e5, 2e4, 3e4, 7e4);
  const Vector2d tau = j.actuation(p);
  EXPECT_NEAR(tau(0), dA * (p(0) - p(1)), 1e-12);
  EXPECT_NEAR(tau(1), dA * (p(2) - p(3)), 1e-12);
}

}  // namespace core_test_cc_joint
