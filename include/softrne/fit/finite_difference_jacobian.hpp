#pragma once
/// \file
/// \brief Finite-difference Jacobian of the residual: forward or central differences, each
///        step kept inside the parameter box, the other side tried when an evaluation fails,
///        the columns evaluated in parallel.

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/fit/residual_evaluation.hpp"

namespace softrne::fit::detail {

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
    Eigen::VectorXd v = u, r_plus, r_minus;
    auto eval_at = [&](double uk, Eigen::VectorXd& out) {
      v[k] = uk;
      return ev.normalised(v, out);
    };
    const double up = u[k] + h, down = u[k] - h;
    const bool up_inside = up <= 1.0, down_inside = down >= 0.0;
    bool ok = false;
    if (central && up_inside && down_inside) {
      const bool a = eval_at(up, r_plus), b = eval_at(down, r_minus);
      if (a && b) {
        J.col(k) = (r_plus - r_minus) / (up - down);
        ok = true;
      } else if (a) {
        J.col(k) = (r_plus - r) / (up - u[k]);
        ok = true;
      } else if (b) {
        J.col(k) = (r - r_minus) / (u[k] - down);
        ok = true;
      }
    } else {
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
