#pragma once
/// \file
/// \brief Singularity-free scalar functions of a constant-curvature arc.
///
/// Every quantity of the CC joint (paper eqs. 1-9, 19-22) can be written with the even,
/// entire functions
/// \f[ g_k(y) = \sum_{n\ge 0} \frac{(-1)^n y^n}{(2n+k)!},\qquad y = \phi^2, \f]
/// i.e. \f$g_0 = \cos\phi\f$, \f$g_1 = \sin\phi/\phi\f$, \f$g_2 = (1-\cos\phi)/\phi^2\f$,
/// \f$g_3 = (\phi-\sin\phi)/\phi^3\f$, and the difference quotients
/// \f$d_k(x) = (g_k(x) - g_k(4x))/x\f$ that appear in the inertia of the arc (eq. 19).
/// They are functions of \f$\phi^2 = u^2+v^2\f$, so derivatives with respect to (u, v) follow
/// from the chain rule without any \f$1/\phi\f$ (the paper's eqs. 1-5 divide by \f$\phi\f$).
///
/// Evaluation: a Taylor series below a switch point, the closed form above it. The switch is
/// placed where the closed form has lost at most about two digits to cancellation and the
/// series converges to full precision with a fixed number of terms; both sides agree to about
/// 1e-15 relative (tested, including first derivatives across the switch).

#include <array>
#include <cmath>

#include <Eigen/Core>

namespace softrne {
namespace detail {

/// Number of series terms: for arguments below 1, the first dropped term is below
/// 1/(2N)! = 1/28! ~ 3e-30, enough for long double.
constexpr int kCCSeriesTerms = 14;

/// Switch point in \f$y = \phi^2\f$ between series and closed form for \f$g_k\f$.
constexpr double kCCSeriesSwitch = 1.0;
/// Switch point in \f$x\f$ for \f$d_k(x)\f$ (its series has terms in \f$(4x)^n\f$).
constexpr double kCCDiffSwitch = 0.25;

constexpr long double factorial(int n) { return n <= 1 ? 1.0L : n * factorial(n - 1); }

/// Series coefficients of the m-th derivative of \f$g_k\f$ (diff = false) or of
/// \f$d_k\f$ (diff = true), in increasing powers of the argument.
template <int K, int M, bool Diff>
struct CCSeries {
  static constexpr std::array<long double, kCCSeriesTerms> make() {
    std::array<long double, kCCSeriesTerms> c{};
    for (int j = 0; j < kCCSeriesTerms; ++j) {
      // g_k: power y^j of the m-th derivative comes from n = j + m.
      // d_k: d_k = sum_{n>=1} (-1)^n (1-4^n) x^{n-1}/(2n+k)!, so power j comes from n = j+m+1.
      const int n = Diff ? j + M + 1 : j + M;
      long double falling = 1.0L;  // (power+m)!/power!
      const int power = Diff ? n - 1 : n;
      for (int i = 0; i < M; ++i) falling *= static_cast<long double>(power - i);
      long double sign = (n % 2 == 0) ? 1.0L : -1.0L;
      long double pow4 = 1.0L;
      for (int i = 0; i < n; ++i) pow4 *= 4.0L;
      const long double weight = Diff ? (1.0L - pow4) : 1.0L;
      c[j] = sign * weight * falling / factorial(2 * n + K);
    }
    return c;
  }
  static constexpr std::array<long double, kCCSeriesTerms> coeffs = make();
};

template <int K, int M, bool Diff, class Scalar>
Scalar cc_series(const Scalar& y) {
  using Real = typename Eigen::NumTraits<Scalar>::Real;
  const auto& c = CCSeries<K, M, Diff>::coeffs;
  Scalar acc = Scalar(Real(c[kCCSeriesTerms - 1]));
  for (int j = kCCSeriesTerms - 2; j >= 0; --j) acc = acc * y + Scalar(Real(c[j]));
  return acc;
}

/// \brief \f$g_1, g_2, g_3\f$ and their first two derivatives at one argument.
template <class Scalar>
struct CCFunctions {
  Scalar g[4];    ///< g[k] = g_k, k = 0..3 (g[0] = cos(phi))
  Scalar dg[4];   ///< first derivative with respect to y = phi^2
  Scalar ddg[4];  ///< second derivative with respect to y

  /// \param y \f$\phi^2\f$; \param sin_phi, cos_phi of \f$\phi = \sqrt{y}\f$ (used above the
  /// switch point only, so callers may pass any value below it).
  void compute(const Scalar& y, const Scalar& phi, const Scalar& sin_phi, const Scalar& cos_phi) {
    using std::cos;
    using std::sin;
    if (y < Scalar(kCCSeriesSwitch)) {
      g[0] = cos_phi;
      g[1] = cc_series<1, 0, false>(y);
      g[2] = cc_series<2, 0, false>(y);
      g[3] = cc_series<3, 0, false>(y);
      dg[1] = cc_series<1, 1, false>(y);
      dg[2] = cc_series<2, 1, false>(y);
      dg[3] = cc_series<3, 1, false>(y);
      ddg[1] = cc_series<1, 2, false>(y);
      ddg[2] = cc_series<2, 2, false>(y);
      ddg[3] = cc_series<3, 2, false>(y);
      dg[0] = -g[1] / Scalar(2);
      ddg[0] = -dg[1] / Scalar(2);
      return;
    }
    // Closed forms and the recurrences g_k' = (g_{k-1} - k g_k) / (2y),
    // g_k'' = (g_{k-1}' - (k+2) g_k') / (2y), g_0' = -g_1/2.
    g[0] = cos_phi;
    g[1] = sin_phi / phi;
    g[2] = (Scalar(1) - cos_phi) / y;
    g[3] = (phi - sin_phi) / (y * phi);
    const Scalar two_y = Scalar(2) * y;
    dg[0] = -g[1] / Scalar(2);
    for (int k = 1; k <= 3; ++k) dg[k] = (g[k - 1] - Scalar(k) * g[k]) / two_y;
    ddg[0] = -dg[1] / Scalar(2);
    for (int k = 1; k <= 3; ++k) ddg[k] = (dg[k - 1] - Scalar(k + 2) * dg[k]) / two_y;
  }
};

/// \brief Everything the CC joint needs at \f$x = u^2 + v^2\f$: \f$g_k(x)\f$ with two
/// derivatives, \f$g_2, g_3\f$ at \f$4x\f$ with one, and \f$d_2, d_3\f$ with one.
template <class Scalar>
struct CCArcFunctions {
  CCFunctions<Scalar> at_x;   ///< arguments x
  CCFunctions<Scalar> at_4x;  ///< arguments 4x (only g and dg of index 2, 3 are used)
  Scalar d2, d3;              ///< d_k(x) = (g_k(x) - g_k(4x)) / x
  Scalar dd2, dd3;            ///< derivatives of d_k with respect to x
  Scalar sin_phi, cos_phi;

  void compute(const Scalar& x) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const bool zero = !(x > Scalar(0));
    const Scalar phi = zero ? Scalar(0) : Scalar(sqrt(x));
    sin_phi = sin(phi);
    cos_phi = cos(phi);
    at_x.compute(x, phi, sin_phi, cos_phi);
    // Double angle: sin(2 phi) = 2 S C, cos(2 phi) = 1 - 2 S^2.
    const Scalar x4 = Scalar(4) * x;
    at_4x.compute(x4, Scalar(2) * phi, Scalar(2) * sin_phi * cos_phi,
                  Scalar(1) - Scalar(2) * sin_phi * sin_phi);
    if (x < Scalar(kCCDiffSwitch)) {
      d2 = cc_series<2, 0, true>(x);
      d3 = cc_series<3, 0, true>(x);
      dd2 = cc_series<2, 1, true>(x);
      dd3 = cc_series<3, 1, true>(x);
    } else {
      d2 = (at_x.g[2] - at_4x.g[2]) / x;
      d3 = (at_x.g[3] - at_4x.g[3]) / x;
      dd2 = (at_x.dg[2] - Scalar(4) * at_4x.dg[2] - d2) / x;
      dd3 = (at_x.dg[3] - Scalar(4) * at_4x.dg[3] - d3) / x;
    }
  }
};

}  // namespace detail
}  // namespace softrne
