// spatial/frame_placement.hpp against the 6x6 Pluecker transforms written out here, finite
// differences of a rotating frame, and its own general formulas (the compile-time shortcuts
// must give the same bits).
#include "softrne/spatial/frame_placement.hpp"  // first: the header compiles on its own

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>

#include <Eigen/Geometry>

#include "softrne/spatial/skew.hpp"

namespace {

using softrne::ArticulatedInertia;
using softrne::FramePlacement;
using softrne::RigidInertia;
using softrne::Wrench;
using Matrix3 = Eigen::Matrix3d;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector3 = Eigen::Vector3d;
using Vector6 = Eigen::Matrix<double, 6, 1>;

Matrix3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

Vector3 random_vector(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Vector3(g(rng), g(rng), g(rng));
}

Matrix3 random_symmetric(std::mt19937& rng) {
  const Matrix3 A = Matrix3::NullaryExpr([&] { return std::normal_distribution<double>()(rng); });
  return A + A.transpose();
}

// One random articulated inertia (symmetric blocks) moved to the base by two placements.
template <class PlacementX, class PlacementY>
std::pair<ArticulatedInertia<double>, ArticulatedInertia<double>> to_base_by_both(
    const PlacementX& X, const PlacementY& Y, std::mt19937& rng) {
  ArticulatedInertia<double> p, q;
  p.A = q.A = random_symmetric(rng);
  p.B = q.B = random_symmetric(rng);
  p.C = q.C = random_symmetric(rng);
  X.to_base(p);
  Y.to_base(q);
  return {p, q};
}

// Wrenches (f; n about the origin), linear first: the distal frame's wrench in the base frame
// is X_f w with X_f = [R 0; [r]x R  R].
Matrix6 force_transform(const Matrix3& R, const Vector3& r) {
  Matrix6 X = Matrix6::Zero();
  X.topLeftCorner<3, 3>() = R;
  X.bottomLeftCorner<3, 3>() = softrne::skew(r) * R;
  X.bottomRightCorner<3, 3>() = R;
  return X;
}

double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}

TEST(FramePlacement, WrenchMatchesPlueckerForceTransform) {
  std::mt19937 rng(1);
  for (int s = 0; s < 20; ++s) {
    const Matrix3 R = random_rotation(rng);
    const Vector3 r = random_vector(rng);
    const FramePlacement<double> X(R, r);
    Wrench<double> w;
    w.force = random_vector(rng);
    w.torque = random_vector(rng);
    const Wrench<double> b = X.shift_to_base(X.rotate(w));
    Vector6 got, w6;
    got << b.force, b.torque;
    w6 << w.force, w.torque;
    EXPECT_LT(rel(got, force_transform(R, r) * w6), 1e-15);
    EXPECT_LT(rel(X.rotate_back(X.rotate(w.force)), w.force), 1e-15);
  }
}

TEST(FramePlacement, InertiasMatchPlueckerCongruence) {
  std::mt19937 rng(2);
  for (int s = 0; s < 20; ++s) {
    const Matrix3 R = random_rotation(rng);
    const Vector3 r = random_vector(rng);
    const FramePlacement<double> X(R, r);
    const Matrix6 Xf = force_transform(R, r);

    // An articulated inertia [A B; B^T C] (any symmetric 6x6): I_base = X_f I X_f^T.
    ArticulatedInertia<double> IA;
    IA.A = random_symmetric(rng);
    IA.B = Matrix3::NullaryExpr([&] { return std::normal_distribution<double>()(rng); });
    IA.C = random_symmetric(rng);
    Matrix6 I6;
    I6 << IA.A, IA.B, IA.B.transpose(), IA.C;
    X.to_base(IA);
    Matrix6 got;
    got << IA.A, IA.B, IA.B.transpose(), IA.C;
    EXPECT_LT(rel(got, Xf * I6 * Xf.transpose()), 1e-14);
    EXPECT_EQ(IA.C, IA.C.transpose());

    // A rigid inertia (m, h, I_O) as [m 1, -[h]x; [h]x, I_O]: the same congruence.
    RigidInertia<double> RI;
    RI.mass = 1.5;
    RI.first_moment = random_vector(rng);
    RI.inertia = random_symmetric(rng);
    auto six = [](const RigidInertia<double>& I) {
      Matrix6 M;
      M << I.mass * Matrix3::Identity(), -softrne::skew(I.first_moment), softrne::skew(I.first_moment),
          I.inertia;
      return M;
    };
    const Matrix6 before = six(RI);
    X.rotate(RI);
    X.shift_to_base(RI);
    EXPECT_LT(rel(six(RI), Xf * before * Xf.transpose()), 1e-14);
  }
}

// The acceleration of a point fixed in a frame whose origin accelerates by a and which turns
// by exp([omega t + alpha t^2 / 2]x): second central difference of its position at t = 0.
TEST(FramePlacement, PointAccelerationMatchesFiniteDifferences) {
  std::mt19937 rng(3);
  for (int s = 0; s < 20; ++s) {
    const Vector3 a = random_vector(rng), w = random_vector(rng), dw = random_vector(rng);
    const Vector3 r = random_vector(rng);
    const Matrix3 R = random_rotation(rng);
    const FramePlacement<double> X(R, r);
    auto position = [&](double t) {
      const Vector3 phi = w * t + 0.5 * dw * t * t;
      const Matrix3 E = phi.norm() > 0 ? Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix()
                                       : Matrix3::Identity();
      return Vector3(0.5 * a * t * t + E * r);
    };
    const double h = 1e-4;
    const Vector3 fd = (position(h) - 2 * position(0) + position(-h)) / (h * h);
    EXPECT_LT(rel(X.point_acceleration(a, w, dw, true), fd), 1e-6);
    EXPECT_EQ(X.point_acceleration(a, dw), X.point_acceleration(a, w, dw, false));
  }
}

// The shortcuts: a placement that knows R = 1 or r = 0 gives the bits of the general one.
TEST(FramePlacement, ShortcutsGiveTheSameBits) {
  std::mt19937 rng(4);
  for (int s = 0; s < 10; ++s) {
    const Matrix3 R = random_rotation(rng), I = Matrix3::Identity();
    const Vector3 r = random_vector(rng), zero = Vector3::Zero();
    const FramePlacement<double> general_no_turn(I, r), general_no_shift(R, zero);
    const FramePlacement<double, false, true> no_turn(I, r);
    const FramePlacement<double, true, false> no_shift(R, zero);
    Wrench<double> w;
    w.force = random_vector(rng);
    w.torque = random_vector(rng);
    const Vector3 a = random_vector(rng), om = random_vector(rng), al = random_vector(rng);
    auto same = [&](const auto& X, const auto& Y) {
      EXPECT_EQ(X.rotate(w.force), Y.rotate(w.force));
      EXPECT_EQ(X.rotate_back(w.force), Y.rotate_back(w.force));
      const Wrench<double> x = X.shift_to_base(X.rotate(w)), y = Y.shift_to_base(Y.rotate(w));
      EXPECT_EQ(x.force, y.force);
      EXPECT_EQ(x.torque, y.torque);
      EXPECT_EQ(X.point_acceleration(a, om, al, true), Y.point_acceleration(a, om, al, true));
      const auto [p, q] = to_base_by_both(X, Y, rng);
      EXPECT_EQ(p.A, q.A);
      EXPECT_EQ(p.B, q.B);
      EXPECT_EQ(p.C, q.C);
      RigidInertia<double> u, v;
      u.mass = v.mass = 2.0;
      u.first_moment = v.first_moment = random_vector(rng);
      u.inertia = v.inertia = random_symmetric(rng);
      X.rotate(u);
      X.shift_to_base(u);
      Y.rotate(v);
      Y.shift_to_base(v);
      EXPECT_EQ(u.first_moment, v.first_moment);
      EXPECT_EQ(u.inertia, v.inertia);
    };
    same(no_turn, general_no_turn);
    same(no_shift, general_no_shift);
  }
}

// The coordinate-axis fast path (spatial/axis_rotation.hpp) against the full products, with R
// written here (not by the revolute joint's code) and checked against Eigen's AngleAxis:
// vectors to the last bit (the skipped terms are products with exact zeros), inertias to
// rounding, and every operation of a placement that takes the path against one that does not.
TEST(FramePlacement, CoordinateAxisFastPathIsTheFullProduct) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-4.0, 4.0);
  for (int s = 0; s < 30; ++s)
    for (int k = 0; k < 3; ++k) {
      // The structure the fast path assumes (exact ones and zeros in row and column k, as
      // RevoluteJoint::calc writes; Eigen's AngleAxis leaves rounding there), checked against
      // Eigen's rotation.
      const double theta = angle(rng);
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      Matrix3 R = Matrix3::Identity();
      R(i, i) = R(j, j) = std::cos(theta);
      R(j, i) = std::sin(theta);
      R(i, j) = -std::sin(theta);
      ASSERT_LT(rel(R, Eigen::AngleAxisd(theta, Vector3::Unit(k)).toRotationMatrix()), 1e-15);
      const Vector3 v = random_vector(rng), zero = Vector3::Zero();
      const Matrix3 A = random_symmetric(rng);
      const FramePlacement<double, true, false> full(R, zero);
      const FramePlacement<double, true, false, true> fast(R, zero, k);
      const FramePlacement<double, true, false, true> not_taken(R, zero, -1);
      EXPECT_EQ(fast.rotate(v), full.rotate(v)) << "axis " << k;
      EXPECT_EQ(fast.rotate_back(v), full.rotate_back(v)) << "axis " << k;
      EXPECT_EQ(not_taken.rotate(v), full.rotate(v));
      EXPECT_EQ(not_taken.rotate_symmetric(A), full.rotate_symmetric(A));
      const Matrix3 B = fast.rotate_symmetric(A);
      EXPECT_LT(rel(B, R * A * R.transpose()), 1e-15) << "axis " << k;
      EXPECT_EQ(B, B.transpose());
      // The placement's inertia operations take the same path.
      RigidInertia<double> u, w;
      u.mass = w.mass = 1.5;
      u.first_moment = w.first_moment = random_vector(rng);
      u.inertia = w.inertia = A;
      fast.rotate(u);
      full.rotate(w);
      EXPECT_EQ(u.first_moment, w.first_moment);
      EXPECT_LT(rel(u.inertia, w.inertia), 1e-15);
      const auto [p, q] = to_base_by_both(fast, full, rng);
      EXPECT_LT(rel(p.A, q.A), 1e-15);
      EXPECT_EQ(p.B, q.B);
      EXPECT_LT(rel(p.C, q.C), 1e-15);
    }
}

}  // namespace
