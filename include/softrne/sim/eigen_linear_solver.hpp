#pragma once
/// \file
/// \brief CVODE's Newton systems solved by Eigen: a SUNLinearSolver of the "direct" kind that
/// factors the dense SUNMatrix \f$I - \gamma J\f$ by Eigen's partial-pivoting LU and solves with
/// that factor, in place of SUNDIALS' own dense solver (SUNLinSol_Dense).
///
/// Why not SUNLinSol_Dense: on the simulator's systems (12 states for the paper's arm) its
/// solve, SUNDlsMat_denseGETRS, cost 4.1k instructions per call, 9.4 % of a whole softrne-sim
/// run (callgrind, Debian's SUNDIALS 6.4 build); Eigen's LU solve of the same system costs a
/// fraction of that (docs/performance.md gives the numbers). Same algorithm (LU with partial
/// pivoting), same matrix and the same contract towards CVODE: setup factors A (recoverable
/// failure SUNLS_LUFACT_FAIL on an exactly singular or non-finite factor, so CVODE retries with
/// a smaller step, as it does for the SUNDIALS solver), solve overwrites x with A^-1 b.
/// Nothing is allocated after make_eigen_dense_solver().
///
/// Why solve by the explicit inverse, formed at setup from the factor (n solves of unit
/// vectors): CVODE sets up far less often than it solves (the Newton matrix is kept up to 100
/// steps, and one Newton iteration per step is the rule: 430 setups and 35.6k solves in the
/// tiled bundled test run), and for the 12-state arm the product \f$A^{-1}b\f$ (Eigen's
/// matrix-vector product) costs 0.68k instructions against 1.4k for the two triangular solves
/// with their short inner loops (callgrind, whole softrne-sim run: the solver 4.7 % of all
/// instructions before, 2.4 % after; written-out column loops took 0.86k). The forward error of
/// either is of order cond(A) times the rounding unit; here A = I - gamma J is close to the
/// identity for the steps CVODE takes, and Newton's iteration only needs a good correction
/// (its residual is evaluated anew each iteration), so the integration's result does not
/// depend on which of the two is used beyond rounding.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/LU>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_linearsolver.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "softrne/config.hpp"

namespace softrne::sim::detail {

/// \brief The solver's state: the factor and the inverse of the last setup.
struct EigenDenseLuContent {
  explicit EigenDenseLuContent(Eigen::Index n) : lu(n), inverse(n, n), scratch(n) {}
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;  ///< P A = L U of the last setup
  Eigen::MatrixXd inverse;                  ///< A^-1 of the last setup, from the factor
  Eigen::VectorXd scratch;                  ///< A^-1 b during a solve
  sunindextype last_flag = 0;               ///< 0, or the 1-based column of a zero pivot
};

/// \brief y = A^-1 b by the factor P A = L U: y = P b, then L y = y (unit diagonal) and
/// U y = y, column by column of the column-major factor. Written out, not Eigen's
/// PartialPivLU::inverse() at setup: that allocates on the heap in the Debug build
/// (Cvode.CallbacksDoNotAllocate failed in the sanitizer build when tried, 2026-12-07), and
/// Eigen's triangular solvers for a runtime-size vector cost 1.6 times these loops.
/// \param[in] c The solver's state after a successful setup.
/// \param[in] b The right-hand side, n entries.
/// \param[out] y The solution, n entries, distinct from b and from the factor.
inline void lu_solve(const EigenDenseLuContent& c, const double* b, double* __restrict y) {
  const Eigen::Index n = c.lu.rows();
  const auto& perm = c.lu.permutationP().indices();
  for (Eigen::Index i = 0; i < n; ++i) y[perm(i)] = b[i];
  const double* __restrict LU = c.lu.matrixLU().data();
  for (Eigen::Index j = 0; j < n; ++j) {  // L y = P b, unit diagonal
    const double yj = y[j];
    const double* col = LU + j * n;
    for (Eigen::Index i = j + 1; i < n; ++i) y[i] -= col[i] * yj;
  }
  for (Eigen::Index j = n - 1; j >= 0; --j) {  // U x = y
    const double* col = LU + j * n;
    const double yj = y[j] / col[j];
    y[j] = yj;
    for (Eigen::Index i = 0; i < j; ++i) y[i] -= col[i] * yj;
  }
}

inline EigenDenseLuContent& eigen_lu_content(SUNLinearSolver S) {
  return *static_cast<EigenDenseLuContent*>(S->content);
}

/// \brief A SUNLinearSolver for n x n dense SUNMatrix systems, factoring with Eigen.
/// \param[in] n The system size.
/// \param[in] ctx The SUNDIALS context.
/// \return The solver (free it with SUNLinSolFree), or null if SUNDIALS could not allocate.
SOFTRNE_SIM_INLINE SUNLinearSolver make_eigen_dense_solver(sunindextype n, SUNContext ctx)
#if SOFTRNE_SIM_BODIES
{
  SUNLinearSolver S = SUNLinSolNewEmpty(ctx);
  if (!S) return nullptr;
  S->content = new EigenDenseLuContent(static_cast<Eigen::Index>(n));
  S->ops->gettype = [](SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; };
  S->ops->getid = [](SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; };
  S->ops->initialize = [](SUNLinearSolver s) {
    eigen_lu_content(s).last_flag = 0;
    return static_cast<int>(SUNLS_SUCCESS);
  };
  S->ops->setup = [](SUNLinearSolver s, SUNMatrix A) {
    auto& c = eigen_lu_content(s);
    const Eigen::Index n = static_cast<Eigen::Index>(SUNDenseMatrix_Rows(A));
    // Column-major with leading dimension n (SUNDIALS' dense format), as Eigen's default.
    c.lu.compute(Eigen::Map<const Eigen::MatrixXd>(SUNDenseMatrix_Data(A), n, n));
    const auto d = c.lu.matrixLU().diagonal();
    c.last_flag = 0;
    for (Eigen::Index i = 0; i < n; ++i)
      if (!(d(i) != 0.0 && std::isfinite(d(i)))) {
        c.last_flag = static_cast<sunindextype>(i + 1);  // as SUNLinSol_Dense reports it
        return static_cast<int>(SUNLS_LUFACT_FAIL);
      }
    // A^-1 column by column (see the file comment); the scratch vector holds e_j.
    for (Eigen::Index j = 0; j < n; ++j) {
      c.scratch.setZero();
      c.scratch(j) = 1.0;
      lu_solve(c, c.scratch.data(), c.inverse.col(j).data());
    }
    if (!c.inverse.allFinite()) {  // overflow of a nearly singular factor
      c.last_flag = static_cast<sunindextype>(n);
      return static_cast<int>(SUNLS_LUFACT_FAIL);
    }
    return static_cast<int>(SUNLS_SUCCESS);
  };
  S->ops->solve = [](SUNLinearSolver s, SUNMatrix, N_Vector x, N_Vector b, sunrealtype) {
    auto& c = eigen_lu_content(s);
    const Eigen::Index n = c.inverse.rows();
    // y = A^-1 b in the scratch vector (x and b may be the same vector), then x = y.
    c.scratch.noalias() = c.inverse * Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(b), n);
    Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(x), n) = c.scratch;
    return static_cast<int>(SUNLS_SUCCESS);
  };
  S->ops->lastflag = [](SUNLinearSolver s) { return eigen_lu_content(s).last_flag; };
  S->ops->space = [](SUNLinearSolver s, long* real_words, long* int_words) {
    const long n = static_cast<long>(eigen_lu_content(s).lu.rows());
    *real_words = 2 * n * n + n;
    *int_words = 2 * n;
    return static_cast<int>(SUNLS_SUCCESS);
  };
  S->ops->free = [](SUNLinearSolver s) {
    if (!s) return static_cast<int>(SUNLS_SUCCESS);
    delete static_cast<EigenDenseLuContent*>(s->content);
    s->content = nullptr;
    SUNLinSolFreeEmpty(s);
    return static_cast<int>(SUNLS_SUCCESS);
  };
  return S;
}
#else
    ;
#endif

}  // namespace softrne::sim::detail
