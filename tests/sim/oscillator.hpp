#pragma once
// Closed form of the damped harmonic oscillator
//   x'' + 2 zeta w x' + w^2 x = F,  F constant,  0 <= zeta < 1,
// advanced by tau from (x0, v0); and a piecewise-constant-force reference.

#include <cmath>
#include <vector>

#include <Eigen/Core>

namespace softrne_test {

struct Oscillator {
  double w = 2.0 * 3.14159265358979323846 * 1.5;
  double zeta = 0.1;

  /// State (x, v) after time tau under constant force F.
  Eigen::Vector2d advance(const Eigen::Vector2d& s0, double F, double tau) const {
    const double wd = w * std::sqrt(1.0 - zeta * zeta);
    const double sigma = zeta * w;
    const double e0 = s0[0] - F / (w * w);  // offset from the static equilibrium
    const double v0 = s0[1];
    const double decay = std::exp(-sigma * tau);
    const double c = std::cos(wd * tau), s = std::sin(wd * tau);
    const double e = decay * (e0 * c + (v0 + sigma * e0) / wd * s);
    const double v = decay * (v0 * c - (sigma * v0 + w * w * e0) / wd * s);
    return {e + F / (w * w), v};
  }
};

/// Force F_k on [b_{k-1}, b_k) (b_{-1} = -inf); forces.size() == breaks.size() + 1.
struct StepForce {
  std::vector<double> breaks;
  std::vector<double> forces;

  double at(double t) const {  // right-continuous
    std::size_t k = 0;
    while (k < breaks.size() && t >= breaks[k]) ++k;
    return forces[k];
  }

  /// Exact state at t from s0 at t0 by chaining closed-form segments.
  Eigen::Vector2d exact(const Oscillator& osc, Eigen::Vector2d s, double t0, double t) const {
    double tc = t0;
    for (std::size_t k = 0; k < breaks.size(); ++k) {
      if (breaks[k] <= tc) continue;
      if (breaks[k] >= t) break;
      s = osc.advance(s, at(tc), breaks[k] - tc);
      tc = breaks[k];
    }
    return osc.advance(s, at(tc), t - tc);
  }
};

}  // namespace softrne_test
