#pragma once
/// \file
/// \brief Finite-difference Jacobian of the residual: forward or central differences, each
///        step kept inside the parameter box, the other side tried when an evaluation fails,
///        the columns evaluated in parallel. Its central difference is also the one of the
///        identifiability analysis.

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/fit/residual_evaluation.hpp"

namespace softrne::fit::detail {

/// The coordinates a difference steps in: normalised \f$u \in [0,1]^p\f$ or physical.
enum class Coordinates { normalised, physical };

/// Central difference of the residual along coordinate k at `x` (where it is `r`): evaluates
/// it at x[k] + h if that is <= `upper` and at x[k] - h if that is >= `lower`, and writes the
/// central difference into `column`, or the one-sided difference of the side that succeeded.
/// `v` is a copy of `x` whose entry k this moves. Returns false, `column` untouched, when no
/// side succeeded. The one formula of both the LM Jacobian (steps inside [0,1]) and the
/// identifiability Jacobian (steps w.r.t. physical parameters).
inline bool central_difference_column(Evaluator& ev, Coordinates coordinates,
                                      const Eigen::VectorXd& x, const Eigen::VectorXd& r, int k,
                                      double h, double lower, double upper, Eigen::VectorXd& v,
                                      Eigen::Ref<Eigen::VectorXd> column) {
  auto eval_at = [&](double xk, Eigen::VectorXd& out) {
    v[k] = xk;
    return coordinates == Coordinates::physical ? ev.physical(v, out) : ev.normalised(v, out);
  };
  Eigen::VectorXd r_plus, r_minus;
  const double up = x[k] + h, down = x[k] - h;
  const bool a = up <= upper && eval_at(up, r_plus);
  const bool b = down >= lower && eval_at(down, r_minus);
  if (a && b)
    column = (r_plus - r_minus) / (up - down);
  else if (a)
    column = (r_plus - r) / (up - x[k]);
  else if (b)
    column = (r - r_minus) / (x[k] - down);
  return a || b;
}

/// Forward (or central) differences of r(u) in normalised coordinates,
/// stepping inside [0,1] and falling back to the other side when an
/// evaluation fails. Columns that cannot be formed are zero, `column_ok` false.
SOFTRNE_FIT_INLINE void jacobian_normalised(Runner& runner, const Eigen::VectorXd& u, const Eigen::VectorXd& r,
                                            double h, bool central, Eigen::MatrixXd& J,
                                            std::vector<char>& column_ok)
#if SOFTRNE_FIT_BODIES
{
  const int p = static_cast<int>(u.size());
  J.resize(r.size(), p);
  column_ok.assign(static_cast<std::size_t>(p), 0);
  runner.run(p, [&](int k, Evaluator& ev) {
    Eigen::VectorXd v = u, r_plus;
    auto eval_at = [&](double uk, Eigen::VectorXd& out) {
      v[k] = uk;
      return ev.normalised(v, out);
    };
    const double up = u[k] + h, down = u[k] - h;
    const bool up_inside = up <= 1.0, down_inside = down >= 0.0;
    bool ok = false;
    if (central && up_inside && down_inside) {
      ok = central_difference_column(ev, Coordinates::normalised, u, r, k, h, 0.0, 1.0, v,
                                     J.col(k));
    } else {
      // One-sided. The backward step is (r(u - h) - r) / (-h) here: the value of the helper's
      // (r - r(u - h)) / h but -0 where that gives +0, so this form stays (bit-identical LM).
      const double first = up_inside ? 1.0 : -1.0;
      for (const double dir : {first, -first}) {
        if (!(dir > 0 ? up_inside : down_inside)) continue;
        const double uk = dir > 0 ? up : down;
        if (eval_at(uk, r_plus)) {
          J.col(k) = (r_plus - r) / (uk - u[k]);
          ok = true;
          break;
        }
      }
    }
    if (!ok) J.col(k).setZero();
    column_ok[k] = ok ? 1 : 0;
  });
}
#else
;
#endif

}  // namespace softrne::fit::detail
