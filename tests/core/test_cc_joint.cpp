// ConstantCurvatureJoint against references that share none of its code: the arc integrated
// as an ODE along its length, direct sums over thin disks (paper eq. 22 with the parallel-axis
// theorem applied here), central finite differences and Eigen AutoDiff.
#include "../eigen_malloc_guard.hpp"  // first: before anything includes Eigen
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "softrne/segments/constant_curvature_joint.hpp"
#include "autodiff_reference.hpp"
#include "support.hpp"

namespace {

using softrne::ConstantCurvatureJoint;
using softrne_test::AD;
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

// Pose as (p, R) under AutoDiff, for derivative references.
struct AdKin {
  Eigen::Matrix<AD, 3, 3> R;
  Eigen::Matrix<AD, 3, 1> re, rc;
  Eigen::Matrix<AD, 3, 3> I;
};

AdKin calc_ad(const Joint& j, const Eigen::Matrix<AD, 2, 1>& q) {
  const auto ja = j.cast<AD>();
  ConstantCurvatureJoint<AD>::Kinematics k;
  Eigen::Matrix<AD, 2, 1> qd;
  qd.setZero();
  ja.calc(q, qd, k);
  return {k.R_base_distal, k.r_base_distal, k.r_base_com, k.inertia_com};
}

Vector3d vee(const Matrix3d& W) { return Vector3d(W(2, 1), W(0, 2), W(1, 0)); }

// Checks J, dI/dq against AutoDiff of the positions, rotation and inertia, and Jdot qdot
// against the AutoDiff time derivative of J(q + t qdot) qdot.
void check_derivatives(const Joint& j, const Vector2d& q, const Vector2d& qd, double tol,
                       double* worst = nullptr) {
  const Kin k = calc(j, q, qd);
  Eigen::Matrix<AD, 2, 1> qa;
  qa(0) = AD(q(0), 2, 0);
  qa(1) = AD(q(1), 2, 1);
  const AdKin a = calc_ad(j, qa);
  Eigen::Matrix<double, 6, 2> J_ref;
  Eigen::Matrix<double, 3, 2> Jc_ref;
  Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = a.R(r, c).value();
  for (int col = 0; col < 2; ++col) {
    Matrix3d dR, dI;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        dR(r, c) = a.R(r, c).derivatives()(col);
        dI(r, c) = a.I(r, c).derivatives()(col);
      }
    for (int r = 0; r < 3; ++r) {
      J_ref(r, col) = a.re(r).derivatives()(col);
      Jc_ref(r, col) = a.rc(r).derivatives()(col);
    }
    J_ref.block<3, 1>(3, col) = vee(dR * R.transpose());
    const double e = (k.dinertia_dq[static_cast<std::size_t>(col)] - dI).norm() /
                     std::max(1e-300, k.inertia_com.norm());
    EXPECT_LT(e, tol) << "dI/dq" << col << " at " << q.transpose();
    if (worst) *worst = std::max(*worst, e);
  }
  const double eJ = (k.J_distal - J_ref).norm() / std::max(1.0, J_ref.norm());
  const double eJc = (k.J_com - Jc_ref).norm() / std::max(1.0, Jc_ref.norm());
  EXPECT_LT(eJ, tol) << "J_distal at " << q.transpose();
  EXPECT_LT(eJc, tol) << "J_com at " << q.transpose();

  // d/dt [J(q + t qd) qd] at t = 0, by AutoDiff in t.
  const auto ja = j.cast<AD>();
  ConstantCurvatureJoint<AD>::Kinematics kt;
  Eigen::Matrix<AD, 2, 1> qt, qdt;
  for (int i = 0; i < 2; ++i) {
    qt(i) = AD(q(i), Eigen::VectorXd::Constant(1, qd(i)));
    qdt(i) = AD(qd(i), Eigen::VectorXd::Zero(1));
  }
  ja.calc(qt, qdt, kt);
  Eigen::Matrix<double, 6, 1> Jdot_ref;
  Eigen::Matrix<double, 3, 1> Jdotc_ref;
  for (int r = 0; r < 6; ++r) {
    AD s = kt.J_distal(r, 0) * qdt(0) + kt.J_distal(r, 1) * qdt(1);
    Jdot_ref(r) = s.derivatives().size() ? s.derivatives()(0) : 0.0;
  }
  for (int r = 0; r < 3; ++r) {
    AD s = kt.J_com(r, 0) * qdt(0) + kt.J_com(r, 1) * qdt(1);
    Jdotc_ref(r) = s.derivatives().size() ? s.derivatives()(0) : 0.0;
  }
  const double scale = std::max(1.0, qd.squaredNorm());
  EXPECT_LT((k.Jdot_qdot_distal - Jdot_ref).norm() / scale, tol) << "Jdot at " << q.transpose();
  EXPECT_LT((k.Jdot_qdot_com - Jdotc_ref).norm() / scale, tol) << "Jdot_com at " << q.transpose();
  if (worst) *worst = std::max({*worst, eJ, eJc});
}

TEST(ConstantCurvatureJoint, JacobiansMatchAutoDiff) {
  const Joint j = joint();
  std::mt19937 rng(4);
  double worst = 0;
  for (int i = 0; i < 200; ++i) {
    const Vector2d q = softrne_test::random_vector(rng, 2, 2.5);
    const Vector2d qd = softrne_test::random_vector(rng, 2, 3.0);
    check_derivatives(j, q, qd, 1e-12, &worst);
  }
  std::printf("[ info ] worst relative Jacobian/dI error vs AutoDiff: %.2e\n", worst);
}

TEST(ConstantCurvatureJoint, JacobiansMatchCentralDifferences) {
  const Joint j = joint();
  std::mt19937 rng(5);
  for (int i = 0; i < 50; ++i) {
    const Vector2d q = softrne_test::random_vector(rng, 2, 2.5);
    const Vector2d qd = softrne_test::random_vector(rng, 2, 3.0);
    const Kin k = calc(j, q, qd);
    const double eps = 1e-6;
    // J qdot must equal the numerically differentiated pose along qdot.
    const Kin kp = calc(j, q + eps * qd), km = calc(j, q - eps * qd);
    const Vector3d v_fd = (kp.r_base_distal - km.r_base_distal) / (2 * eps);
    const Vector3d w_fd = vee((kp.R_base_distal - km.R_base_distal) / (2 * eps) * k.R_base_distal.transpose());
    const Vector3d vc_fd = (kp.r_base_com - km.r_base_com) / (2 * eps);
    EXPECT_LT((k.J_distal.topRows<3>() * qd - v_fd).norm(), 1e-7 * std::max(1.0, v_fd.norm()));
    EXPECT_LT((k.J_distal.bottomRows<3>() * qd - w_fd).norm(), 1e-7 * std::max(1.0, w_fd.norm()));
    EXPECT_LT((k.J_com * qd - vc_fd).norm(), 1e-7 * std::max(1.0, vc_fd.norm()));
    // d/dt (J qdot) at fixed qdot equals Jdot qdot.
    const Kin kp2 = calc(j, q + eps * qd, qd), km2 = calc(j, q - eps * qd, qd);
    const Eigen::Matrix<double, 6, 1> dJ = (kp2.J_distal * qd - km2.J_distal * qd) / (2 * eps);
    EXPECT_LT((k.Jdot_qdot_distal - dJ).norm(), 1e-7 * std::max(1.0, dJ.norm()));
    const Matrix3d dI = (kp.inertia_com - km.inertia_com) / (2 * eps);
    EXPECT_LT((k.inertia_rate - dI).norm(), 1e-7 * std::max(1e-3, dI.norm()));
  }
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
      check_derivatives(j, q, qd, 1e-12);
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

TEST(ConstantCurvatureJoint, LongDoubleAgreesWithDouble) {
  const Joint j = joint();
  const auto jl = j.cast<long double>();
  std::mt19937 rng(6);
  for (int i = 0; i < 50; ++i) {
    const Vector2d q = softrne_test::random_vector(rng, 2, 2.5), qd = softrne_test::random_vector(rng, 2, 2);
    const Kin k = calc(j, q, qd);
    ConstantCurvatureJoint<long double>::Kinematics kl;
    jl.calc(q.cast<long double>(), qd.cast<long double>(), kl);
    EXPECT_LT((k.J_distal - kl.J_distal.cast<double>()).norm(), 1e-14);
    EXPECT_LT((k.inertia_com - kl.inertia_com.cast<double>()).norm(), 1e-15);
    EXPECT_LT((k.Jdot_qdot_distal - kl.Jdot_qdot_distal.cast<double>()).norm(), 1e-13);
  }
}

TEST(ConstantCurvatureJoint, CalcDoesNotAllocate) {
  const Joint j = joint();
  Kin k;
  const Vector2d q(0.3, -0.4), qd(1.0, 2.0);
  const long eigen_failures_before = softrne_test::eigen_assert_failures;
  Eigen::internal::set_is_malloc_allowed(false);
  j.calc(q, qd, k);
  j.calc(Vector2d(1.5, 0.2), qd, k);
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_EQ(softrne_test::eigen_assert_failures, eigen_failures_before)
      << "heap allocation where forbidden";
}

TEST(ConstantCurvatureJoint, PressureMapIsEquation24) {
  const Joint j = joint();
  const double dA = 0.06 * M_PI * 0.03 * 0.03;
  Eigen::Vector4d p(1e5, 2e4, 3e4, 7e4);
  const Vector2d tau = j.actuation(p);
  EXPECT_NEAR(tau(0), dA * (p(0) - p(1)), 1e-12);
  EXPECT_NEAR(tau(1), dA * (p(2) - p(3)), 1e-12);
}

SOFTRNE_MALLOC_GUARD_POSITIVE_CONTROL()

}  // namespace
