// clang-format off
// The malloc guard only defines macros and must precede every Eigen include; the
// headers under test are then the first real includes (they must compile on their own).
#include "../eigen_malloc_guard.hpp"
#include "softrne/sim/eigen_linear_solver.hpp"
#include "softrne/sim/serial_vector_ops.hpp"
// clang-format on

// The two kernels integrate() hands to CVODE in place of SUNDIALS' own: the Newton solver
// (eigen_linear_solver.hpp) and the hot serial-vector operations (serial_vector_ops.hpp).
// References that share no code with them: SUNDIALS' own serial operations and dense solver,
// and Eigen's full-pivoting LU.

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/LU>
#include <gtest/gtest.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>

namespace sim_test_cvode_kernels {

using softrne::sim::detail::make_eigen_dense_solver;
using softrne::sim::detail::use_softrne_vector_ops;

struct Context {
  Context() { SUNContext_Create(nullptr, &ctx); }
  ~Context() { SUNContext_Free(&ctx); }
  SUNContext ctx = nullptr;
};

struct Vector {
  Vector(sunindextype n, SUNContext ctx) : v(N_VNew_Serial(n, ctx)) {}
  ~Vector() { N_VDestroy(v); }
  Eigen::Map<Eigen::VectorXd> map() { return {N_VGetArrayPointer(v), N_VGetLength(v)}; }
  N_Vector v;
};

// Random entries of both signs spanning a few decades, as CVODE's scaled states do.
void fill(Eigen::Map<Eigen::VectorXd> x, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1), e(-3, 2);
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) = u(rng) * std::pow(10.0, e(rng));
}

double max_rel(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

// Every replaced operation against SUNDIALS' serial implementation of it, for sizes around
// the vector width (1, odd, even) and the arms' 12 states; results in a fresh vector and
// in place (z = x), as CVODE calls them.
TEST(SerialVectorOps, AgreeWithSundialsSerialOperations) {
  Context c;
  std::mt19937 rng(7);
  for (sunindextype n : {1, 3, 12, 17}) {
    Vector x(n, c.ctx), y(n, c.ctx), w(n, c.ctx), ours(n, c.ctx), ref(n, c.ctx);
    use_softrne_vector_ops(ours.v);
    fill(x.map(), rng);
    fill(y.map(), rng);
    fill(w.map(), rng);
    const Eigen::VectorXd x0 = x.map(), y0 = y.map();
    const double a = 0.37, b = -2.5;

    ours.map() = x0;
    N_VLinearSum(a, ours.v, b, y.v, ours.v);  // in place, through the table
    N_VLinearSum_Serial(a, x.v, b, y.v, ref.v);
    EXPECT_LE(max_rel(ours.map(), ref.map()), 1e-15) << n;

    ours.v->ops->nvscale(a, x.v, ours.v);
    N_VScale_Serial(a, x.v, ref.v);
    EXPECT_EQ(Eigen::VectorXd(ours.map()), Eigen::VectorXd(ref.map())) << n;

    ours.v->ops->nvconst(b, ours.v);
    N_VConst_Serial(b, ref.v);
    EXPECT_EQ(Eigen::VectorXd(ours.map()), Eigen::VectorXd(ref.map())) << n;

    // The error weights' operations, exactly SUNDIALS' (one rounding each, or none).
    ours.map() = x0;
    ours.v->ops->nvabs(ours.v, ours.v);  // in place
    N_VAbs_Serial(x.v, ref.v);
    EXPECT_EQ(Eigen::VectorXd(ours.map()), Eigen::VectorXd(ref.map())) << n;
    EXPECT_EQ(Eigen::VectorXd(ours.map()), Eigen::VectorXd(x0.cwiseAbs())) << n;
    ours.v->ops->nvinv(x.v, ours.v);
    N_VInv_Serial(x.v, ref.v);
    EXPECT_EQ(Eigen::VectorXd(ours.map()), Eigen::VectorXd(ref.map())) << n;
    ours.v->ops->nvaddconst(x.v, b, ours.v);
    N_VAddConst_Serial(x.v, b, ref.v);
    EXPECT_EQ(Eigen::VectorXd(ours.map()), Eigen::VectorXd(ref.map())) << n;

    ours.map() = x0;
    const double norm = ours.v->ops->nvwrmsnorm(ours.v, w.v);
    const double norm_ref = N_VWrmsNorm_Serial(x.v, w.v);
    EXPECT_NEAR(norm, norm_ref, 1e-15 * norm_ref) << n;
    EXPECT_NEAR(ours.v->ops->nvwsqrsumlocal(ours.v, w.v), N_VWSqrSumLocal_Serial(x.v, w.v),
                1e-15 * norm_ref * norm_ref * static_cast<double>(n))
        << n;

    // z = c0 X0 + c1 X1 + c2 X2 with z = X0, against the sum of SUNDIALS' linear sums.
    Vector x2(n, c.ctx);
    fill(x2.map(), rng);
    double coef[3] = {1.5, -0.25, 3.0};
    ours.map() = x0;
    N_Vector X[3] = {ours.v, y.v, x2.v};
    ASSERT_EQ(ours.v->ops->nvlinearcombination(3, coef, X, ours.v), 0);
    N_VLinearSum_Serial(coef[0], x.v, coef[1], y.v, ref.v);
    N_VLinearSum_Serial(1.0, ref.v, coef[2], x2.v, ref.v);
    EXPECT_LE(max_rel(ours.map(), ref.map()), 1e-15) << n;

    // Z_k = a_k x + Y_k with Z_k = Y_k.
    Vector z0(n, c.ctx), z1(n, c.ctx);
    z0.map() = y0;
    z1.map() = x2.map();
    double scales[2] = {-0.5, 4.0};
    N_Vector Y[2] = {z0.v, z1.v};
    ASSERT_EQ(ours.v->ops->nvscaleaddmulti(2, scales, x.v, Y, Y), 0);
    N_VLinearSum_Serial(scales[0], x.v, 1.0, y.v, ref.v);
    EXPECT_LE(max_rel(z0.map(), ref.map()), 1e-15) << n;
    N_VLinearSum_Serial(scales[1], x.v, 1.0, x2.v, ref.v);
    EXPECT_LE(max_rel(z1.map(), ref.map()), 1e-15) << n;
  }
}

// CVODE makes its work vectors with N_VClone of the state vector: the table must follow.
TEST(SerialVectorOps, ClonesKeepTheOperations) {
  Context c;
  Vector x(12, c.ctx);
  use_softrne_vector_ops(x.v);
  N_Vector clone = N_VClone(x.v);
  ASSERT_NE(clone, nullptr);
  EXPECT_EQ(clone->ops->nvlinearsum, x.v->ops->nvlinearsum);
  EXPECT_EQ(clone->ops->nvwrmsnorm, x.v->ops->nvwrmsnorm);
  EXPECT_EQ(clone->ops->nvabs, x.v->ops->nvabs);
  EXPECT_NE(clone->ops->nvlinearsum, &N_VLinearSum_Serial);
  N_VDestroy(clone);
}

struct Solver {
  explicit Solver(SUNLinearSolver s) : S(s) {}
  ~Solver() { SUNLinSolFree(S); }
  SUNLinearSolver S;
};

// I - gamma J of a random J, as CVODE forms it; solved in place (x = b) and into another
// vector, against Eigen's full-pivoting LU and SUNDIALS' dense solver.
TEST(EigenDenseSolver, SolvesNewtonSystemsLikeFullPivotingLu) {
  Context c;
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  for (sunindextype n : {1, 2, 12, 20}) {
    SUNMatrix A = SUNDenseMatrix(n, n, c.ctx);
    Eigen::Map<Eigen::MatrixXd> Am(SUNDenseMatrix_Data(A), n, n);
    Am = Eigen::MatrixXd::Identity(n, n);
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = 0; j < n; ++j) Am(i, j) -= 0.7 * g(rng);  // gamma J, pivoting needed
    const Eigen::MatrixXd A0 = Am;
    Vector b(n, c.ctx), x(n, c.ctx), ref(n, c.ctx);
    fill(b.map(), rng);
    const Eigen::VectorXd b0 = b.map();
    const Eigen::VectorXd expected = A0.fullPivLu().solve(b0);

    Solver ours(make_eigen_dense_solver(n, c.ctx));
    ASSERT_NE(ours.S, nullptr);
    EXPECT_EQ(SUNLinSolGetType(ours.S), SUNLINEARSOLVER_DIRECT);
    ASSERT_EQ(SUNLinSolInitialize(ours.S), SUNLS_SUCCESS);
    ASSERT_EQ(SUNLinSolSetup(ours.S, A), SUNLS_SUCCESS);
    EXPECT_EQ(Eigen::MatrixXd(Am), A0) << "setup must not touch A";
    ASSERT_EQ(SUNLinSolSolve(ours.S, A, x.v, b.v, 0.0), SUNLS_SUCCESS);
    const double cond = A0.norm() * A0.inverse().norm();
    EXPECT_LE(max_rel(x.map(), expected), 1e-15 * cond) << n;
    EXPECT_EQ(Eigen::VectorXd(b.map()), b0) << "solve must not touch b";
    ASSERT_EQ(SUNLinSolSolve(ours.S, A, b.v, b.v, 0.0), SUNLS_SUCCESS);  // x = b
    EXPECT_EQ(Eigen::VectorXd(b.map()), Eigen::VectorXd(x.map())) << n;

    // SUNDIALS' dense solver factors A in place: give it a copy.
    SUNMatrix A2 = SUNDenseMatrix(n, n, c.ctx);
    Eigen::Map<Eigen::MatrixXd>(SUNDenseMatrix_Data(A2), n, n) = A0;
    Solver theirs(SUNLinSol_Dense(ref.v, A2, c.ctx));
    ASSERT_EQ(SUNLinSolInitialize(theirs.S), SUNLS_SUCCESS);
    ASSERT_EQ(SUNLinSolSetup(theirs.S, A2), SUNLS_SUCCESS);
    b.map() = b0;
    ASSERT_EQ(SUNLinSolSolve(theirs.S, A2, ref.v, b.v, 0.0), SUNLS_SUCCESS);
    EXPECT_LE(max_rel(x.map(), ref.map()), 1e-15 * cond) << n;
    SUNMatDestroy(A2);
    SUNMatDestroy(A);
  }
}

// A singular or non-finite Newton matrix is a recoverable failure (CVODE then retries with
// a smaller step), with the zero pivot's column in lastflag, as SUNLinSol_Dense reports it.
TEST(EigenDenseSolver, SingularAndNonFiniteMatricesAreRecoverableFailures) {
  Context c;
  const sunindextype n = 4;
  SUNMatrix A = SUNDenseMatrix(n, n, c.ctx);
  Eigen::Map<Eigen::MatrixXd> Am(SUNDenseMatrix_Data(A), n, n);
  Solver ours(make_eigen_dense_solver(n, c.ctx));
  Am.setIdentity();
  Am(2, 2) = 0;  // column 3 (1-based) has no pivot
  EXPECT_EQ(SUNLinSolSetup(ours.S, A), SUNLS_LUFACT_FAIL);
  EXPECT_EQ(SUNLinSolLastFlag(ours.S), 3);
  Am.setIdentity();
  Am(1, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(SUNLinSolSetup(ours.S, A), SUNLS_LUFACT_FAIL);
  Am.setIdentity();
  EXPECT_EQ(SUNLinSolSetup(ours.S, A), SUNLS_SUCCESS);
  EXPECT_EQ(SUNLinSolLastFlag(ours.S), 0);
  SUNMatDestroy(A);
}

}  // namespace sim_test_cvode_kernels
