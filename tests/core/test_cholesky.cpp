// The written-out Cholesky of algorithms/cholesky.hpp (forward_dynamics, aba's articulated
// inertias) against Eigen's LLT and the matrix inverse, and the reason it is written out:
// AutoDiff derivatives survive right-hand-side entries whose value is exactly zero.
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <gtest/gtest.h>
#include <unsupported/Eigen/AutoDiff>

#include "softrne/algorithms/articulated_body.hpp"
#include "softrne/algorithms/cholesky.hpp"

namespace core_test_cholesky {

using Eigen::MatrixXd;
using Eigen::VectorXd;

MatrixXd random_spd(int n, std::mt19937& rng) {
  std::normal_distribution<double> g;
  MatrixXd B(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) B(i, j) = g(rng);
  return B * B.transpose() + 0.1 * MatrixXd::Identity(n, n);
}

// Sizes 1-12 take the written-out dot products, 16 and up the column products.
TEST(Cholesky, SolvesAsEigensLltForSizesOneToTwelveAndLarger) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  for (int n : {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 15, 16, 17, 30, 31, 64}) {
    const MatrixXd A = random_spd(n, rng);
    VectorXd b(n);
    for (int i = 0; i < n; ++i) b(i) = g(rng);
    const VectorXd expected = A.llt().solve(b);
    MatrixXd F = A;
    VectorXd x = b;
    ASSERT_TRUE(softrne::detail::cholesky_solve_in_place(F, x)) << n;
    EXPECT_LT((x - expected).norm(), 1e-12 * (1 + expected.norm()) * A.norm()) << n;
    // The factor is Eigen's L (lower triangle); the strict upper triangle is untouched.
    const MatrixXd L = A.llt().matrixL();
    EXPECT_LT((MatrixXd(F.triangularView<Eigen::Lower>()) - L).norm(), 1e-12 * L.norm()) << n;
    EXPECT_EQ(MatrixXd(F.triangularView<Eigen::StrictlyUpper>()),
              MatrixXd(A.triangularView<Eigen::StrictlyUpper>()));
  }
}

TEST(Cholesky, RefusesAMatrixThatIsNotPositiveDefiniteAndLeavesTheRightHandSide) {
  MatrixXd A(2, 2);
  A << 1, 2, 2, 1;  // eigenvalues 3, -1
  VectorXd b(2);
  b << 1, 2;
  EXPECT_FALSE(softrne::detail::cholesky_solve_in_place(A, b));
  EXPECT_EQ(b, VectorXd((VectorXd(2) << 1, 2).finished()));
  // The same through the column products (n >= 16): a negative diagonal entry.
  std::mt19937 rng(9);
  MatrixXd big = random_spd(20, rng);
  big(13, 13) = -1.0;
  VectorXd c = VectorXd::Ones(20);
  EXPECT_FALSE(softrne::detail::cholesky_solve_in_place(big, c));
  EXPECT_EQ(c, VectorXd::Ones(20));
}

// x = A^-1 b with b = 0 exactly but db != 0: x = 0 and dx = A^-1 db. Eigen's triangular
// solvers skip the zero entries of b and return dx = 0.
TEST(Cholesky, KeepsAutoDiffDerivativesOfExactlyZeroRightHandSides) {
  using AD = Eigen::AutoDiffScalar<Eigen::VectorXd>;
  std::mt19937 rng(3);
  const int n = 4;
  const MatrixXd A = random_spd(n, rng);
  Eigen::Matrix<AD, Eigen::Dynamic, Eigen::Dynamic> Aad = A.cast<AD>();
  Eigen::Matrix<AD, Eigen::Dynamic, 1> b(n);
  for (int i = 0; i < n; ++i) b(i) = AD(0.0, VectorXd::Unit(n, i));  // db/ds = I
  ASSERT_TRUE(softrne::detail::cholesky_solve_in_place(Aad, b));
  MatrixXd dx(n, n);
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(b(i).value(), 0.0);
    dx.row(i) = b(i).derivatives().transpose();
  }
  EXPECT_LT((dx - A.inverse()).norm(), 1e-12 * A.inverse().norm());
}

// The inverse from the factor (aba_derivatives' M^-1) against Eigen's LU inverse, for sizes
// around the chains benchmarked (6, 30), into a dynamic and a fixed-size matrix; both
// triangles written and exactly symmetric.
TEST(Cholesky, InverseFromTheFactorIsTheInverse) {
  std::mt19937 rng(5);
  for (int n : {1, 2, 3, 6, 7, 17, 30, 31}) {
    const MatrixXd A = random_spd(n, rng);
    MatrixXd L = A;
    ASSERT_TRUE(softrne::detail::cholesky_factor_in_place(L)) << n;
    L.triangularView<Eigen::StrictlyUpper>().setConstant(42.0);  // not read
    MatrixXd inverse = MatrixXd::Constant(n, n, -7.0);
    softrne::detail::cholesky_inverse_factored(L, inverse);
    const MatrixXd expected = A.inverse();
    EXPECT_LT((inverse - expected).norm(), 1e-12 * expected.norm() * A.norm()) << n;
    EXPECT_EQ(inverse, MatrixXd(inverse.transpose())) << n;
  }
  const MatrixXd A = random_spd(30, rng);
  Eigen::Matrix<double, 30, 30> L = A, inverse;
  ASSERT_TRUE(softrne::detail::cholesky_factor_in_place(L));
  softrne::detail::cholesky_inverse_factored(L, inverse);
  EXPECT_LT((MatrixXd(inverse) - A.inverse()).norm(), 1e-12 * A.inverse().norm() * A.norm());
}

// aba's inverse of a segment's articulated inertia: closed forms for n = 1, 2, the Cholesky
// above for larger blocks; only the leading n x n block of the output is written.
template <int n>
void check_invert_spd_small(std::mt19937& rng) {
  const MatrixXd D = random_spd(n, rng);
  Eigen::Matrix<double, n, n> Df = D;
  Eigen::Matrix<double, 6, 6> out = Eigen::Matrix<double, 6, 6>::Constant(42.0);
  ASSERT_TRUE(softrne::detail::invert_spd_small<n>(Df, out));
  EXPECT_LT((MatrixXd(out.template topLeftCorner<n, n>()) - D.inverse()).norm(),
            1e-12 * D.inverse().norm())
      << n;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      if (i >= n || j >= n) {
        EXPECT_EQ(out(i, j), 42.0);
      }
    }
  Eigen::Matrix<double, n, n> indefinite = -Df;
  EXPECT_FALSE(softrne::detail::invert_spd_small<n>(indefinite, out));
}

TEST(Cholesky, InvertSpdSmallIsTheInverseForBlocksOfOneToFive) {
  std::mt19937 rng(11);
  check_invert_spd_small<1>(rng);
  check_invert_spd_small<2>(rng);
  check_invert_spd_small<3>(rng);
  check_invert_spd_small<4>(rng);
  check_invert_spd_small<5>(rng);
}

}  // namespace core_test_cholesky
