#pragma once
/// \file
/// \brief What fit_least_squares() is asked and what it answers: the choice of global and
///        local stage, the options (FitOptions, IdentifiabilityOptions) and the result
///        (FitResult).

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace softrne::fit {

/// \brief Global stage.
enum class GlobalMethod {
  /// Screen a seeded, shifted Halton set (plus the initial guess), then
  /// refine the best few distinct points with short LM runs. Parallel.
  multistart,
  /// NLopt NLOPT_GN_CRS2_LM (controlled random search), seeded by nlopt_srand. Serial.
  crs2_lm,
  /// NLopt NLOPT_GN_DIRECT_L (deterministic, ignores the seed). Serial.
  direct_l,
};

/// \brief Local stage.
enum class LocalMethod {
  /// Projected Levenberg-Marquardt on finite-difference Jacobians.
  levenberg_marquardt,
  /// NLopt NLOPT_LN_BOBYQA on the cost (half the budget), then LM.
  bobyqa_then_lm,
};

/// \brief Settings of the identifiability analysis at the optimum.
struct IdentifiabilityOptions {
  /// A parameter is identifiable when its relative std error is below this.
  double max_relative_std_error = 0.1;
  /// Singular values of the scaled Jacobian below `null_space_rtol * s_max`
  /// span the null space.
  double null_space_rtol = 1e-8;
  /// Pairs with \f$|\mathrm{corr}|\f$ above this are reported as correlated.
  double correlation_threshold = 0.95;
  /// Relative central-difference step on the physical parameters; 0 means
  /// \f$\epsilon^{1/3} \approx 6\cdot10^{-6}\f$. Raise it (1e-4..1e-3) when
  /// the residual carries integrator noise.
  double fd_step = 0.0;
};

/// \brief Options of fit_least_squares().
struct FitOptions {
  /// Seed of the global stage; a fixed seed gives a bit-identical result.
  unsigned seed = 1;
  /// Residual evaluations of the global stage; 0 skips it.
  int global_evals = 200;
  /// Residual evaluations of the local stage.
  int local_evals = 400;
  /// Stop when an accepted step is below `xtol_rel * (|u| + xtol_rel)` (normalised coordinates).
  double xtol_rel = 1e-6;
  /// Stop when an accepted step lowers the cost by less than `ftol_rel * cost`
  /// (and the model predicted no more).
  double ftol_rel = 1e-10;
  /// Worker threads for independent evaluations (multistart points and
  /// starts, Jacobian columns). Used only by the ResidualFactory overload.
  int threads = 1;
  /// Wall-clock limit for the whole fit in seconds; 0 means none.
  double max_wall_seconds = 0.0;
  /// Called from the calling thread with (evaluations so far, best cost).
  std::function<void(int evals, double best_cost)> progress;

  GlobalMethod global_method = GlobalMethod::multistart;  ///< the global stage

  /// Multistart: number of distinct starts refined after screening.
  int multistart_starts = 4;
  LocalMethod local_method = LocalMethod::levenberg_marquardt;  ///< the local stage

  /// Central instead of forward differences in the LM Jacobian.
  bool central_differences = false;
  /// Finite-difference step in normalised coordinates; 0 means 1e-6
  /// (forward) or 1e-5 (central).
  double fd_step = 0.0;
  /// Run the identifiability analysis (2p extra evaluations).
  bool compute_identifiability = true;
  IdentifiabilityOptions identifiability;  ///< settings of that analysis
};

/// \brief Outcome of fit_least_squares().
///
/// Never holds NaN. Infinite values mean "unbounded / unavailable": `cost`
/// when no valid point was found, `std_errors` of parameters in the
/// null space, `condition_number` of a rank-deficient Jacobian, and the
/// covariance when \f$m \le p\f$.
struct FitResult {
  Eigen::VectorXd params;    ///< physical values at the optimum
  Eigen::VectorXd residual;  ///< r(params); empty when no valid point was found
  double cost = std::numeric_limits<double>::infinity();  ///< \f$\tfrac12\sum r^2\f$
  double rms = std::numeric_limits<double>::infinity();   ///< \f$\sqrt{\sum r^2/m}\f$
  int evaluations = 0;                                    ///< residual calls, all stages
  int failed_evaluations = 0;                             ///< calls that failed
  bool converged = false;  ///< the local stage met xtol_rel or ftol_rel
  std::string message;     ///< what each stage did, and notes

  /// \f$s^2 (J^T J)^{+}\f$, \f$s^2 = 2c/(m-p)\f$, J w.r.t. physical parameters.
  Eigen::MatrixXd covariance;
  Eigen::VectorXd std_errors;           ///< sqrt(diag(covariance)); inf in the null space
  Eigen::VectorXd relative_std_errors;  ///< std_errors / max(|x|, 1e-3 (upper - lower))
  Eigen::MatrixXd correlation;          ///< from the pseudo-inverse covariance
  Eigen::VectorXd singular_values;      ///< of J scaled by parameter magnitude
  double condition_number = std::numeric_limits<double>::infinity();  ///< of the scaled J
  std::vector<bool> identifiable;  ///< per parameter: determined by the data
  std::string identifiability_report;  ///< human-readable lines
};

}  // namespace softrne::fit
