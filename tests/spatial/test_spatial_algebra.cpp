// spatial/spatial_algebra.hpp (the world-frame spatial vectors of the derivatives) against the
// 6x6 Pluecker matrices written out here (Featherstone, Rigid Body Dynamics Algorithms, 2008,
// ch. 2, in the (linear; angular) order), and against the invariance of power.
#include "softrne/spatial/spatial_algebra.hpp"  // first: the header compiles on its own

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <Eigen/Geometry>

namespace spatial_algebra_test {

using softrne::detail::cross_force;
using softrne::detail::cross_motion;
using softrne::detail::force_to_local;
using softrne::detail::force_to_world;
using softrne::detail::motion_to_world;
using Matrix3 = Eigen::Matrix3d;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector3 = Eigen::Vector3d;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// [a]x, entry by entry (not softrne::skew, which the header itself uses).
Matrix3 hat(const Vector3& a) {
  Matrix3 m;
  m << 0, -a(2), a(1), a(2), 0, -a(0), -a(1), a(0), 0;
  return m;
}

// Motions (v; w): a frame at (R, p) sees its own (v; w) in the world as X_m (v; w).
Matrix6 motion_transform(const Matrix3& R, const Vector3& p) {
  Matrix6 X = Matrix6::Zero();
  X.topLeftCorner<3, 3>() = R;
  X.topRightCorner<3, 3>() = hat(p) * R;
  X.bottomRightCorner<3, 3>() = R;
  return X;
}

// Forces (f; n): X_f = X_m^-T.
Matrix6 force_transform(const Matrix3& R, const Vector3& p) {
  return motion_transform(R, p).inverse().transpose();
}

// crm(v) and crf(v) = -crm(v)^T, for (v; w) ordering.
Matrix6 crm(const Vector6& v) {
  Matrix6 X = Matrix6::Zero();
  X.topLeftCorner<3, 3>() = hat(v.tail<3>());
  X.topRightCorner<3, 3>() = hat(v.head<3>());
  X.bottomRightCorner<3, 3>() = hat(v.tail<3>());
  return X;
}

struct Case {
  Matrix3 R;
  Vector3 p;
};

Case random_case(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return {Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix(),
          Vector3(g(rng), g(rng), g(rng))};
}

double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}

TEST(SpatialAlgebra, TransformsMatchPlueckerMatricesColumnwise) {
  std::mt19937 rng(3);
  for (int s = 0; s < 20; ++s) {
    const Case c = random_case(rng);
    // A fixed-size block of 4 columns and a dynamic one of 3.
    const Eigen::Matrix<double, 6, 4> m = Eigen::Matrix<double, 6, 4>::Random();
    const Eigen::MatrixXd f = Eigen::MatrixXd::Random(6, 3);
    EXPECT_LT(rel(motion_to_world(c.R, c.p, m), motion_transform(c.R, c.p) * m), 1e-14);
    EXPECT_LT(rel(force_to_world(c.R, c.p, f), force_transform(c.R, c.p) * f), 1e-14);
    EXPECT_LT(rel(force_to_local(c.R, c.p, f), force_transform(c.R, c.p).inverse() * f), 1e-14);
    EXPECT_LT(rel(force_to_local(c.R, c.p, force_to_world(c.R, c.p, m)), m), 1e-14);
  }
}

TEST(SpatialAlgebra, PowerIsTheSameInEveryFrame) {
  std::mt19937 rng(4);
  for (int s = 0; s < 20; ++s) {
    const Case c = random_case(rng);
    const Vector6 m = Vector6::Random(), f = Vector6::Random();
    const double local = m.dot(f);
    const double world = motion_to_world(c.R, c.p, m).dot(force_to_world(c.R, c.p, f));
    EXPECT_NEAR(world, local, 1e-14 * (1.0 + c.p.norm()) * m.norm() * f.norm());
  }
}

TEST(SpatialAlgebra, CrossProductsMatchTheirMatrices) {
  for (int s = 0; s < 20; ++s) {
    const Vector6 v = Vector6::Random(), m = Vector6::Random(), f = Vector6::Random();
    EXPECT_LT(rel(cross_motion(v, m), crm(v) * m), 1e-15);
    EXPECT_LT(rel(cross_force(v, f), -crm(v).transpose() * f), 1e-15);
    // v x v = 0, and (v x m) . f = -m . (v x* f).
    EXPECT_LT(cross_motion(v, v).norm(), 1e-15);
    EXPECT_NEAR(cross_motion(v, m).dot(f), -m.dot(cross_force(v, f)), 1e-14);
  }
}

}  // namespace spatial_algebra_test
