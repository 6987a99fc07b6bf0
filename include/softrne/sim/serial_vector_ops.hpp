#pragma once
/// \file
/// \brief The vector operations CVODE spends its own time in, compiled with softrne, in place
/// of those of SUNDIALS' serial N_Vector: the vector stays a serial N_Vector (same data layout,
/// N_VGetArrayPointer, clones), only the function pointers of the hot operations change.
///
/// Why: in a whole softrne-sim run of the paper's arm (12 states) the serial vector's
/// N_VLinearSum, N_VWrmsNorm, N_VScale, N_VScaleAddMulti, N_VLinearCombination and N_VConst
/// took 30 % of all instructions (callgrind, Debian's SUNDIALS 6.4 build: about 420
/// instructions for one N_VLinearSum of 12 entries); the loops below do the same arithmetic in
/// a fraction of that (docs/performance.md gives the numbers). N_VAbs, N_VInv and N_VAddConst
/// (the error weights, once per step) followed on 2026-12-07: about 160 instructions each for
/// 12 entries, 2.2 % of the run. CVODE clones its work vectors from the state vector with
/// N_VClone, which copies the operations table, so setting them on the state vector before
/// CVodeInit reaches every vector CVODE makes.
///
/// Each operation computes what SUNDIALS documents for it (sundials_nvector.h); results
/// differ from SUNDIALS' only in rounding (the order of the additions of a norm).

#include <cmath>

#include <nvector/nvector_serial.h>
#include <sundials/sundials_nvector.h>

namespace softrne::sim::detail {

namespace serial_ops {

inline sunindextype length(N_Vector v) {
  return NV_LENGTH_S(v);
}
inline sunrealtype* data(N_Vector v) {
  return NV_DATA_S(v);
}

/// z = a x + b y (x, y and z may be the same vector).
inline void linear_sum(sunrealtype a, N_Vector x, sunrealtype b, N_Vector y, N_Vector z) {
  const sunindextype n = length(z);
  const sunrealtype* xd = data(x);
  const sunrealtype* yd = data(y);
  sunrealtype* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = a * xd[i] + b * yd[i];
}

/// z = c (every entry).
inline void constant(sunrealtype c, N_Vector z) {
  const sunindextype n = length(z);
  sunrealtype* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c;
}

/// z = c x.
inline void scale(sunrealtype c, N_Vector x, N_Vector z) {
  const sunindextype n = length(z);
  const sunrealtype* xd = data(x);
  sunrealtype* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c * xd[i];
}

/// z = |x| (x and z may be the same vector).
inline void abs(N_Vector x, N_Vector z) {
  const sunindextype n = length(z);
  const sunrealtype* xd = data(x);
  sunrealtype* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = std::fabs(xd[i]);
}

/// z = 1 / x entry by entry, no check for zero (as N_VInv_Serial).
inline void inv(N_Vector x, N_Vector z) {
  const sunindextype n = length(z);
  const sunrealtype* xd = data(x);
  sunrealtype* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = sunrealtype(1) / xd[i];
}

/// z = x + b (every entry).
inline void add_const(N_Vector x, sunrealtype b, N_Vector z) {
  const sunindextype n = length(z);
  const sunrealtype* xd = data(x);
  sunrealtype* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] + b;
}

/// sum (x_i w_i)^2.
inline sunrealtype weighted_square_sum(N_Vector x, N_Vector w) {
  const sunindextype n = length(x);
  const sunrealtype* xd = data(x);
  const sunrealtype* wd = data(w);
  sunrealtype s = 0;
  for (sunindextype i = 0; i < n; ++i) {
    const sunrealtype p = xd[i] * wd[i];
    s += p * p;
  }
  return s;
}

/// sqrt(sum (x_i w_i)^2 / n), the norm of CVODE's error tests.
inline sunrealtype wrms_norm(N_Vector x, N_Vector w) {
  return std::sqrt(weighted_square_sum(x, w) / static_cast<sunrealtype>(length(x)));
}

/// z = sum_k c_k X_k (z may be X_0).
inline int linear_combination(int nvec, sunrealtype* c, N_Vector* X, N_Vector z) {
  if (nvec < 1) return -1;
  const sunindextype n = length(z);
  sunrealtype* zd = data(z);
  const sunrealtype* x0 = data(X[0]);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c[0] * x0[i];
  for (int k = 1; k < nvec; ++k) {
    const sunrealtype* xk = data(X[k]);
    const sunrealtype ck = c[k];
    for (sunindextype i = 0; i < n; ++i) zd[i] += ck * xk[i];
  }
  return 0;
}

/// Z_k = a_k x + Y_k for every k (Z_k may be Y_k).
inline int scale_add_multi(int nvec, sunrealtype* a, N_Vector x, N_Vector* Y, N_Vector* Z) {
  if (nvec < 1) return -1;
  const sunindextype n = length(x);
  const sunrealtype* xd = data(x);
  for (int k = 0; k < nvec; ++k) {
    const sunrealtype* yk = data(Y[k]);
    sunrealtype* zk = data(Z[k]);
    const sunrealtype ak = a[k];
    for (sunindextype i = 0; i < n; ++i) zk[i] = ak * xd[i] + yk[i];
  }
  return 0;
}

}  // namespace serial_ops

/// \brief Points the hot operations of serial vector v (and of every later clone of it) at
/// the loops above.
/// \param[in,out] v A serial N_Vector (N_VNew_Serial).
inline void use_softrne_vector_ops(N_Vector v) {
  v->ops->nvlinearsum = &serial_ops::linear_sum;
  v->ops->nvconst = &serial_ops::constant;
  v->ops->nvscale = &serial_ops::scale;
  v->ops->nvwrmsnorm = &serial_ops::wrms_norm;
  v->ops->nvwsqrsumlocal = &serial_ops::weighted_square_sum;
  v->ops->nvlinearcombination = &serial_ops::linear_combination;
  v->ops->nvscaleaddmulti = &serial_ops::scale_add_multi;
  v->ops->nvabs = &serial_ops::abs;
  v->ops->nvinv = &serial_ops::inv;
  v->ops->nvaddconst = &serial_ops::add_const;
}

}  // namespace softrne::sim::detail
