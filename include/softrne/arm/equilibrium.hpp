#pragma once
/// \file
/// \brief The arm's static equilibrium at given pressures: where a recording that starts at
/// rest begins when no angle was measured (markers only), and where random test arms rest.

#include <algorithm>
#include <stdexcept>
#include <string>

#include <Eigen/Core>
#include <Eigen/LU>

#include "softrne/config.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/arm/arm_dynamics.hpp"

namespace softrne {

/// \brief Configuration q at which the arm rests under pressures p: qddot(q, qdot = 0) = 0 with
/// the effect states at their at-rest values at q (rest_state()). Damped Newton on the
/// accelerations of eq. 23, Jacobian by central differences (step 1e-6 rad), at most 0.3 rad
/// per step and halved until the residual drops.
/// \param[in] d The arm.
/// \param[in] p The recorded pressures (num_inputs), Pa.
/// \param[in] q Starting guess (nq), or empty for the straight arm.
/// \return The coordinates (not the measured angles), rad.
/// \throws std::runtime_error if the accelerations are not below 1e-7 rad/s^2 after 200 steps.
SOFTRNE_SIM_INLINE Eigen::VectorXd static_equilibrium(const ArmDescription& d,
                                                      const Eigen::VectorXd& p,
                                                      Eigen::VectorXd q = Eigen::VectorXd())
#if SOFTRNE_SIM_BODIES
{
  using Vec = Eigen::VectorXd;
  ArmDynamics<double> f(d);
  const int n = d.nq;
  Vec x(d.num_states()), xd(x.size());
  auto acc = [&](const Vec& qq) {
    // At rest at qq: the effects' internal states at their at-rest values at qq, not at the
    // starting guess (a Maxwell branch at rest is relaxed where the arm is, effects/viscoelastic.hpp).
    x = rest_state(d, qq, p);
    f.rhs(x, p, xd);
    return Vec(xd.segment(n, n));
  };
  if (q.size() != n) q = Vec::Zero(n);
  Vec r = acc(q);
  for (int it = 0; it < 200 && r.lpNorm<Eigen::Infinity>() > 1e-10; ++it) {
    Eigen::MatrixXd J(n, n);
    for (int k = 0; k < n; ++k) {
      Vec a = q, b = q;
      a(k) += 1e-6;
      b(k) -= 1e-6;
      J.col(k) = (acc(a) - acc(b)) / 2e-6;
    }
    const Vec dq = J.partialPivLu().solve(-r);
    double step = std::min(1.0, 0.3 / std::max(1e-300, dq.lpNorm<Eigen::Infinity>()));
    Vec qn = q + step * dq, rn = acc(qn);
    for (int ls = 0; ls < 30 && !(rn.norm() < r.norm()); ++ls) {
      step *= 0.5;
      qn = q + step * dq;
      rn = acc(qn);
    }
    q = qn;
    r = rn;
  }
  if (!(r.lpNorm<Eigen::Infinity>() <= 1e-7))
    throw std::runtime_error("no static equilibrium found (residual " +
                             std::to_string(r.lpNorm<Eigen::Infinity>()) + " rad/s^2)");
  return q;
}
#else
;
#endif

}  // namespace softrne
