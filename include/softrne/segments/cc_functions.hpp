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
///
/// Below the switch only \f$g_6\f$ and \f$g_7\f$ are summed; everything else follows from
/// three exact identities of the series, none of which divides by y:
/// - \f$g_k = 1/k! - y\,g_{k+2}\f$ (downward, stable for y < 1: the subtracted term is at most
///   \f$1/((k+1)(k+2))\f$ of the result),
/// - \f$g_k' = (k\,g_{k+2} - g_{k+1})/2\f$ and \f$g_k'' = (k\,g_{k+2}' - g_{k+1}')/2\f$,
/// - \f$d_k(x) = 4g_{k+2}(4x) - g_{k+2}(x)\f$, \f$d_k'(x) = 16g_{k+2}'(4x) - g_{k+2}'(x)\f$
///   (from the first identity; no cancellation: the two terms have ratio 4 and 16 at x = 0).
/// When both x and 4x are below the switch, no trigonometric function is evaluated at all.

#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace softrne {
namespace detail {

/// Switch point in \f$y = \phi^2\f$ between series and closed form for \f$g_k\f$.
constexpr double kCCSeriesSwitch = 1.0;
/// Switch point in \f$x\f$ for \f$d_k(x)\f$ (it needs \f$g_k\f$ at 4x).
constexpr double kCCDiffSwitch = 0.25;

constexpr long double factorial(int n) {
  return n <= 1 ? 1.0L : n * factorial(n - 1);
}

/// Capacity of the coefficient tables (double needs 8 terms, long double 9).
constexpr int kCCMaxSeriesTerms = 16;

/// Number of terms of the series of \f$g_6\f$ (and \f$g_7\f$) on \f$0 \le y < 1\f$ for the
/// precision of Real: the first dropped term, relative to \f$g_6 \ge g_6(1) > 6!^{-1}/1.1\f$,
/// is below eps/16 (double: 8 terms, long double: 9).
template <class Real>
constexpr int cc_series_terms() {
  const long double eps = static_cast<long double>(std::numeric_limits<Real>::epsilon());
  int n = 1;
  while (n < kCCMaxSeriesTerms && 1.1L * factorial(6) / factorial(2 * n + 6) >= eps / 16) ++n;
  return n;
}

/// Coefficients of the series of \f$g_K^{(D)}\f$ (the D-th derivative in y) in powers of y:
/// \f$(-1)^{m+D}(m+1)\cdots(m+D)/(2(m+D)+K)!\f$ (D = 0: \f$(-1)^m/(2m+K)!\f$).
template <int K, int D = 0>
struct CCSeries {
  static constexpr std::array<long double, kCCMaxSeriesTerms> make() {
    std::array<long double, kCCMaxSeriesTerms> c{};
    for (int m = 0; m < kCCMaxSeriesTerms; ++m) {
      long double rising = 1;  // (m+1)...(m+D)
      for (int i = 1; i <= D; ++i) rising *= m + i;
      c[static_cast<std::size_t>(m)] =
          ((m + D) % 2 == 0 ? 1.0L : -1.0L) * rising / factorial(2 * (m + D) + K);
    }
    return c;
  }
  static constexpr std::array<long double, kCCMaxSeriesTerms> coeffs = make();
};

/// Two series of CCSeries' form at y < 1, by Horner in one loop, with cc_series_terms terms.
template <class SeriesA, class SeriesB, class Scalar>
void cc_series_pair(const Scalar& y, Scalar& a, Scalar& b) {
  using Real = typename Eigen::NumTraits<Scalar>::Real;
  constexpr int N = cc_series_terms<Real>();
  const auto& ca = SeriesA::coeffs;
  const auto& cb = SeriesB::coeffs;
  a = Scalar(Real(ca[N - 1]));
  b = Scalar(Real(cb[N - 1]));
  for (int j = N - 2; j >= 0; --j) {
    a = a * y + Scalar(Real(ca[static_cast<std::size_t>(j)]));
    b = b * y + Scalar(Real(cb[static_cast<std::size_t>(j)]));
  }
}

/// \f$g_6(y)\f$ and \f$g_7(y)\f$ by their series, y < 1.
template <class Scalar>
void cc_series_g67(const Scalar& y, Scalar& g6, Scalar& g7) {
  cc_series_pair<CCSeries<6>, CCSeries<7>>(y, g6, g7);
}

/// \f$g_4''(y)\f$ and \f$g_5''(y)\f$ by their series, y < 1. Their terms fall faster than
/// those of g_6 (cc_series_terms): the first dropped one, relative to the sum, is below 1e-17
/// for double.
template <class Scalar>
void cc_series_g45_second(const Scalar& y, Scalar& g4, Scalar& g5) {
  cc_series_pair<CCSeries<4, 2>, CCSeries<5, 2>>(y, g4, g5);
}

/// \brief \f$g_0..g_3\f$ and their first two derivatives at one argument.
template <class Scalar>
struct CCFunctions {
  Scalar g[4];    ///< g[k] = g_k, k = 0..3 (g[0] = cos(phi))
  Scalar dg[4];   ///< first derivative with respect to y = phi^2
  Scalar ddg[4];  ///< second derivative with respect to y

  /// Below the switch only: \f$g_4, g_5\f$ and their first derivatives (for \f$d_k\f$).
  Scalar g45[2], dg45[2];

  /// Below the switch (y < kCCSeriesSwitch): everything from the series of g_6, g_7.
  /// \param second_derivatives false skips ddg (unused at the argument 4x).
  void compute_series(const Scalar& y, bool second_derivatives = true) {
    const Real inv[8] = {Real(1),
                         Real(1),
                         Real(1) / Real(2),
                         Real(1) / Real(6),
                         Real(1) / Real(24),
                         Real(1) / Real(120),
                         Real(1) / Real(720),
                         Real(1) / Real(5040)};
    Scalar gg[8];
    cc_series_g67(y, gg[6], gg[7]);
    for (int k = 5; k >= 0; --k) gg[k] = Scalar(inv[k]) - y * gg[k + 2];
    Scalar d[6];  // d[k] = g_k'
    for (int k = 0; k <= 5; ++k) d[k] = (Scalar(Real(k)) * gg[k + 2] - gg[k + 1]) / Scalar(2);
    for (int k = 0; k < 4; ++k) {
      g[k] = gg[k];
      dg[k] = d[k];
    }
    g45[0] = gg[4];
    g45[1] = gg[5];
    dg45[0] = d[4];
    dg45[1] = d[5];
    if (second_derivatives)
      for (int k = 0; k < 4; ++k) ddg[k] = (Scalar(Real(k)) * d[k + 2] - d[k + 1]) / Scalar(2);
  }

  /// At or above the switch: closed forms and the recurrences g_k' = (g_{k-1} - k g_k) / (2y),
  /// g_k'' = (g_{k-1}' - (k+2) g_k') / (2y), g_0' = -g_1/2.
  /// \param phi \f$\sqrt y\f$ (y the argument), \param inv_y 1/y, \param inv_phi 1/phi (the caller
  /// forms them with one division), \param sin_phi, cos_phi the sine and cosine of phi. \param
  /// second_derivatives false (the argument 4x) skips ddg and dg[0], dg[1].
  void compute_closed(const Scalar& phi, const Scalar& inv_y, const Scalar& inv_phi,
                      const Scalar& sin_phi, const Scalar& cos_phi,
                      bool second_derivatives = true) {
    g[0] = cos_phi;
    g[1] = sin_phi * inv_phi;
    g[2] = (Scalar(1) - cos_phi) * inv_y;
    g[3] = (phi - sin_phi) * inv_y * inv_phi;
    const Scalar half_inv_y = Scalar(0.5) * inv_y;
    for (int k = second_derivatives ? 1 : 2; k <= 3; ++k)
      dg[k] = (g[k - 1] - Scalar(k) * g[k]) * half_inv_y;
    if (second_derivatives) {
      dg[0] = -g[1] / Scalar(2);
      ddg[0] = -dg[1] / Scalar(2);
      for (int k = 1; k <= 3; ++k) ddg[k] = (dg[k - 1] - Scalar(k + 2) * dg[k]) * half_inv_y;
    }
  }

  /// \brief At any argument y: the series below the switch, the closed form at or above it
  /// (one square root, sine and cosine), everything with second derivatives.
  void compute(const Scalar& y) {
    if (y < Scalar(kCCSeriesSwitch)) {
      compute_series(y);
      return;
    }
    using std::cos;
    using std::sin;
    using std::sqrt;
    const Scalar phi = sqrt(y);
    const Scalar inv_y = Scalar(1) / y;
    compute_closed(phi, inv_y, phi * inv_y, sin(phi), cos(phi));
  }

 private:
  using Real = typename Eigen::NumTraits<Scalar>::Real;
};

/// \brief Everything the CC joint needs at \f$x = u^2 + v^2\f$: \f$g_k(x)\f$ with two
/// derivatives, \f$g_2, g_3\f$ at \f$4x\f$ with one, and \f$d_2, d_3\f$ with one.
template <class Scalar>
struct CCArcFunctions {
  CCFunctions<Scalar> at_x;   ///< arguments x
  CCFunctions<Scalar> at_4x;  ///< arguments 4x (only g and dg of index 2, 3 are set)
  Scalar d2, d3;              ///< d_k(x) = (g_k(x) - g_k(4x)) / x
  Scalar dd2, dd3;            ///< derivatives of d_k with respect to x

  void compute(const Scalar& x) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const Scalar x4 = Scalar(4) * x;
    if (x < Scalar(kCCDiffSwitch)) {
      // x and 4x below the series switch: no trigonometry, d_k without a quotient.
      at_x.compute_series(x);
      at_4x.compute_series(x4, false);
      d2 = Scalar(4) * at_4x.g45[0] - at_x.g45[0];
      d3 = Scalar(4) * at_4x.g45[1] - at_x.g45[1];
      dd2 = Scalar(16) * at_4x.dg45[0] - at_x.dg45[0];
      dd3 = Scalar(16) * at_4x.dg45[1] - at_x.dg45[1];
      return;
    }
    const Scalar phi = sqrt(x);
    const Scalar sin_phi = sin(phi);
    const Scalar cos_phi = cos(phi);
    const Scalar inv_x = Scalar(1) / x;  // the only division
    const Scalar inv_phi = phi * inv_x;
    if (x < Scalar(kCCSeriesSwitch))
      at_x.compute_series(x);
    else
      at_x.compute_closed(phi, inv_x, inv_phi, sin_phi, cos_phi);
    // Double angle: sin(2 phi) = 2 S C, cos(2 phi) = 1 - 2 S^2.
    at_4x.compute_closed(Scalar(2) * phi, Scalar(0.25) * inv_x, Scalar(0.5) * inv_phi,
                         Scalar(2) * sin_phi * cos_phi, Scalar(1) - Scalar(2) * sin_phi * sin_phi,
                         false);
    d2 = (at_x.g[2] - at_4x.g[2]) * inv_x;
    d3 = (at_x.g[3] - at_4x.g[3]) * inv_x;
    dd2 = (at_x.dg[2] - Scalar(4) * at_4x.dg[2] - d2) * inv_x;
    dd3 = (at_x.dg[3] - Scalar(4) * at_4x.dg[3] - d3) * inv_x;
  }

  /// \brief The second derivatives with respect to x that the inertia's second derivatives
  /// need (after compute(x)): \f$d^2 g_k(4x)/dx^2 = 16 g_k''(4x)\f$ into ddG[k - 2] and
  /// \f$d_k''(x)\f$ into ddd[k - 2], k = 2, 3.
  ///
  /// Below kCCDiffSwitch, from the series: \f$g_k'' = (k g_{k+2}' - g_{k+1}')/2\f$ at 4x and
  /// \f$d_k'' = 64 g_{k+2}''(4x) - g_{k+2}''(x)\f$ (the second derivative of the identity of
  /// d_k; no cancellation). At or above it, 4x >= 1: the closed-form recurrence at 4x and
  /// \f$d_k'' = (g_k''(x) - 16 g_k''(4x) - 2 d_k')/x\f$, the second derivative of
  /// \f$x d_k = g_k(x) - g_k(4x)\f$ (about one digit lost to cancellation at the switch).
  void second_derivatives(const Scalar& x, Scalar (&ddG)[2], Scalar (&ddd)[2]) const {
    Scalar g_4x[2];  // g_2'', g_3'' at 4x (with respect to their argument)
    if (x < Scalar(kCCDiffSwitch)) {
      g_4x[0] = (Scalar(2) * at_4x.dg45[0] - at_4x.dg[3]) / Scalar(2);
      g_4x[1] = (Scalar(3) * at_4x.dg45[1] - at_4x.dg45[0]) / Scalar(2);
      Scalar g45_x[2], g45_4x[2];
      cc_series_g45_second(x, g45_x[0], g45_x[1]);
      cc_series_g45_second(Scalar(4) * x, g45_4x[0], g45_4x[1]);
      for (int k = 0; k < 2; ++k) ddd[k] = Scalar(64) * g45_4x[k] - g45_x[k];
    } else {
      const Scalar inv_x = Scalar(1) / x;
      const Scalar half_inv_y = Scalar(0.125) * inv_x;  // 1 / (2 (4x))
      const Scalar dg1 = (at_4x.g[0] - at_4x.g[1]) * half_inv_y;
      g_4x[0] = (dg1 - Scalar(4) * at_4x.dg[2]) * half_inv_y;
      g_4x[1] = (at_4x.dg[2] - Scalar(5) * at_4x.dg[3]) * half_inv_y;
      ddd[0] = (at_x.ddg[2] - Scalar(16) * g_4x[0] - Scalar(2) * dd2) * inv_x;
      ddd[1] = (at_x.ddg[3] - Scalar(16) * g_4x[1] - Scalar(2) * dd3) * inv_x;
    }
    for (int k = 0; k < 2; ++k) ddG[k] = Scalar(16) * g_4x[k];
  }
};

}  // namespace detail
}  // namespace softrne
