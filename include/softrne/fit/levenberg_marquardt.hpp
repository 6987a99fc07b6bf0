#pragma once
/// \file
/// \brief Projected Levenberg-Marquardt in the normalised box \f$[0,1]^p\f$ on
///        finite-difference Jacobians: the fitter's local stage, and the short refinements
///        of multistart.

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/fit/finite_difference_jacobian.hpp"
#include "softrne/fit/residual_evaluation.hpp"

namespace softrne::fit::detail {

struct LmSettings {
  int max_evals = 400;
  double xtol_rel = 1e-6;
  double ftol_rel = 1e-10;
  bool central = false;
  double fd_step = 1e-6;
  const Deadline* deadline = nullptr;
  std::function<void(double cost)> on_accept;  // progress; main thread only
};

struct LmOutcome {
  Eigen::VectorXd u, r;
  double cost = kInf;
  bool valid = false;  // u is a point where the residual succeeded
  bool converged = false;
  int iterations = 0;
  std::string message;
};

/// \brief Projected Levenberg-Marquardt in normalised coordinates (box [0,1]^p).
///
/// Step: \f$(J_F^T J_F + \lambda D_F)\,\delta_F = -g_F\f$ over the free set F
/// (variables not held at a bound by the gradient), \f$D\f$ the running
/// maximum of diag(\f$J^TJ\f$) (Moré 1978), projected onto the box. Gain-ratio
/// acceptance and the \f$\lambda\f$ update of Nielsen (1999).
SOFTRNE_FIT_INLINE LmOutcome levenberg_marquardt(Runner& runner, const Eigen::VectorXd& u0,
                                                 const LmSettings& s)
#if SOFTRNE_FIT_BODIES
{
  LmOutcome out;
  const int p = static_cast<int>(u0.size());
  const int start = runner.evaluations();
  auto used = [&] { return runner.evaluations() - start; };
  const int jacobian_cost = s.central ? 2 * p : p;

  Eigen::VectorXd u = u0, r;
  out.u = u0;
  if (!runner.main().normalised(u, r)) {
    out.message = "the residual fails at the starting point";
    return out;
  }
  double cost = half_squared_norm(r);
  out.valid = true;

  Eigen::MatrixXd J, A;
  Eigen::VectorXd g, D = Eigen::VectorXd::Zero(p), u_new, r_new, step;
  std::vector<char> column_ok;
  double lambda = 1e-3, nu = 2.0;
  bool done = false;
  while (!done) {
    if (cost == 0.0) {
      out.converged = true;
      out.message = "zero residual";
      break;
    }
    if (used() + jacobian_cost + 1 > s.max_evals) {
      out.message = "evaluation budget exhausted";
      break;
    }
    if (s.deadline && s.deadline->passed()) {
      out.message = "wall-clock limit reached";
      break;
    }
    jacobian_normalised(runner, u, r, s.fd_step, s.central, J, column_ok);
    ++out.iterations;
    g.noalias() = J.transpose() * r;
    A.noalias() = J.transpose() * J;
    D = D.cwiseMax(A.diagonal());
    const double d_floor = 1e-12 * std::max(D.maxCoeff(), std::numeric_limits<double>::min());
    const Eigen::VectorXd D_used = D.cwiseMax(d_floor);

    // Free set: a variable on a bound whose gradient pushes it outwards is held.
    std::vector<int> free_set;
    for (int i = 0; i < p; ++i) {
      const bool held = (u[i] <= 0.0 && g[i] > 0.0) || (u[i] >= 1.0 && g[i] < 0.0);
      if (!held) free_set.push_back(i);
    }
    double free_gradient = 0.0;
    for (const int i : free_set) free_gradient = std::max(free_gradient, std::abs(g[i]));
    if (free_gradient == 0.0) {
      out.converged = true;
      out.message = "projected gradient is zero";
      break;
    }
    const int nf = static_cast<int>(free_set.size());
    Eigen::MatrixXd A_free(nf, nf);
    Eigen::VectorXd g_free(nf), d_free(nf);
    for (int a = 0; a < nf; ++a) {
      g_free[a] = g[free_set[a]];
      d_free[a] = D_used[free_set[a]];
      for (int b = 0; b < nf; ++b) A_free(a, b) = A(free_set[a], free_set[b]);
    }

    for (;;) {  // inner loop: find an acceptable step for this Jacobian
      if (used() >= s.max_evals) {
        out.message = "evaluation budget exhausted";
        done = true;
        break;
      }
      if (s.deadline && s.deadline->passed()) {
        out.message = "wall-clock limit reached";
        done = true;
        break;
      }
      Eigen::MatrixXd M = A_free;
      M.diagonal() += lambda * d_free;
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(M);
      const Eigen::VectorXd delta_free = ldlt.solve(-g_free);
      if (ldlt.info() != Eigen::Success || !delta_free.allFinite()) {
        lambda *= nu;
        nu *= 2.0;
        if (lambda > 1e20) {
          out.message = "linear solve failed";
          done = true;
          break;
        }
        continue;
      }
      u_new = u;
      for (int a = 0; a < nf; ++a) {
        const int i = free_set[a];
        u_new[i] = std::clamp(u[i] + delta_free[a], 0.0, 1.0);
      }
      step = u_new - u;
      const double step_norm = step.norm();
      const bool small_step = step_norm <= s.xtol_rel * (u.norm() + s.xtol_rel);
      if (step_norm == 0.0) {
        out.converged = true;
        out.message = "step vanished at the bounds";
        done = true;
        break;
      }
      const double predicted = -(g.dot(step) + 0.5 * step.dot(A * step));
      const bool ok = runner.main().normalised(u_new, r_new);
      const double cost_new = ok ? half_squared_norm(r_new) : kInf;
      const double actual = cost - cost_new;
      const double rho = (ok && predicted > 0.0) ? actual / predicted : -1.0;
      if (ok && actual > 0.0 && rho > 1e-4) {
        const bool small_f = actual <= s.ftol_rel * cost && predicted <= s.ftol_rel * cost;
        u = u_new;
        r = r_new;
        cost = cost_new;
        lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
        nu = 2.0;
        if (s.on_accept) s.on_accept(cost);
        if (small_step) {
          out.converged = true;
          out.message = "step below xtol_rel";
          done = true;
        } else if (small_f) {
          out.converged = true;
          out.message = "relative cost change below ftol_rel";
          done = true;
        }
        break;
      }
      if (small_step) {
        out.converged = true;
        out.message = "no decrease within xtol_rel of the point";
        done = true;
        break;
      }
      lambda *= nu;
      nu *= 2.0;
      if (lambda > 1e20) {
        out.message = "no decrease found (damping limit)";
        done = true;
        break;
      }
    }
  }
  out.u = u;
  out.r = r;
  out.cost = cost;
  return out;
}
#else
;
#endif

}  // namespace softrne::fit::detail
