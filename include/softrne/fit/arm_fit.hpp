#pragma once
/// \file
/// \brief System identification of an arm: stiffness, damping (and optionally pressure gains
/// and effect parameters) fitted to measured angles by simulation error (paper section IV-B).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/fit/least_squares.hpp"
#include "softrne/fit/parameters.hpp"
#include "softrne/io/csv.hpp"
// The error statistics (signals/error_stats.hpp) through the header that also keeps their old
// names (softrne::ErrorStats, ...): user code that included only the fit headers names them so.
#include "softrne/model/error_stats.hpp"
#include "softrne/sim/arm_simulation.hpp"

namespace softrne::fit {

/// \brief What to fit.
struct ArmFitOptions {
  bool stiffness = true;       ///< per-axis K_spring of every joint
  bool damping = true;         ///< per-axis K_d of every joint
  bool pressure_gain = false;  ///< one factor on K_prs per CC joint
  bool effects = true;         ///< the parameters of the model's effects

  /// Bounds of K and D: [x0 / range, x0 * range] around the starting guess (log scale).
  double stiffness_range = 30.0;
  /// Samples that enter the objective (weight 1) or not (0); empty = all. Used for
  /// cross-validation: the simulation still runs through every sample.
  std::vector<bool> sample_mask;
  sim::ArmSimulationOptions simulation = default_simulation();  ///< integrator settings
  FitOptions optimiser = default_optimiser();  ///< optimiser settings

  /// The fits' integrator tolerances. atol 1e-5 rad on the angles is 300 times below the
  /// angle sensors' noise (3e-3 rad) and about 1 % of what a finite-difference step of the
  /// optimiser (fd_step 1e-3 of a parameter's normalised range, ~0.7 % of K) moves the
  /// simulated angles, so neither the objective nor its Jacobian sees the integrator. 1e-6
  /// made every simulation 1.6 to 1.9 times as long (3-joint arm, distributed inertia: 12.0k
  /// instead of 7.4k steps) for no change: the closed loop on random arm 1001 took 85.6 s
  /// instead of 53.9 s with the same decisions and held-out gains to 0.1 %. Effects with a
  /// sharp feature tighten it for the models that hold them (simulate_dataset).
  /// \return rtol 1e-6, atol 1e-5, at most 60 s per simulation.
  static sim::ArmSimulationOptions default_simulation() {
    sim::ArmSimulationOptions s;
    s.cvode.rtol = 1e-6;
    s.cvode.atol = 1e-5;
    s.cvode.max_wall_seconds = 60;
    return s;
  }
  /// \brief The fits' optimiser: a short global search, two local starts, finite-difference
  /// steps above the integrator's noise.
  /// \return The settings.
  static FitOptions default_optimiser() {
    FitOptions o;
    o.global_evals = 12;
    o.multistart_starts = 2;
    o.local_evals = 300;
    o.threads = 2;
    o.xtol_rel = 1e-4;
    o.ftol_rel = 1e-7;
    o.fd_step = 1e-3;  // CVODE's tolerance is noise in finite differences
    o.identifiability.fd_step = 1e-3;
    return o;
  }
};

/// \brief Outcome of fit_arm.
struct ArmFitResult {
  ArmDescription fitted;    ///< the model with the fitted values
  FitResult fit;            ///< the optimiser's result (normalised and physical values)
  ParameterSet parameters;  ///< what was fitted, with bounds
  signals::ErrorStats stats;  ///< on the fitting data (all samples)

  /// The fitted model simulated through every sample of the data (N x nq), masked or not;
  /// empty if that simulation failed. Callers measure held-out errors on it.
  Eigen::MatrixXd angles;
  int simulations = 0;      ///< simulations run by the fit
  double wall_seconds = 0;  ///< wall-clock time of the fit
};

namespace detail {

/// Which numbers of the description the parameter vector addresses.
struct ParamSlot {
  enum Kind { kStiffness, kDamping, kGain, kEffect } kind;
  int joint;  // or effect index
  int k;      // axis or effect parameter index
};

SOFTRNE_FIT_INLINE std::vector<ParamSlot> make_slots(const ArmDescription& d, const ArmFitOptions& o,
                                                     ParameterSet& ps)
#if SOFTRNE_FIT_BODIES
{
  std::vector<ParamSlot> slots;
  const double range = o.stiffness_range;
  auto bounded = [&](double x0, double fallback) {
    const double c = x0 > 0 ? x0 : fallback;
    return std::pair<double, double>(c / range, c * range);
  };
  for (std::size_t j = 0; j < d.joints.size(); ++j) {
    const ArmJoint& jt = d.joints[j];
    for (int k = 0; k < jt.nq; ++k) {
      const std::string axis = d.coordinate_names[static_cast<std::size_t>(jt.q_offset + k)];
      if (o.stiffness) {
        auto [lo, hi] = bounded(jt.stiffness(k), 1.0);
        ps.add({"stiffness." + axis, std::max(jt.stiffness(k), lo), lo, hi, true});
        slots.push_back({ParamSlot::kStiffness, static_cast<int>(j), k});
      }
      if (o.damping) {
        auto [lo, hi] = bounded(jt.damping(k), 0.1);
        ps.add({"damping." + axis, std::max(jt.damping(k), lo), lo, hi, true});
        slots.push_back({ParamSlot::kDamping, static_cast<int>(j), k});
      }
    }
    if (o.pressure_gain && jt.is_cc()) {
      ps.add({"pressure_gain." + jt.name, 1.0, 0.3, 3.0, true});
      slots.push_back({ParamSlot::kGain, static_cast<int>(j), 0});
    }
  }
  if (o.effects) {
    // Bounds come from each effect's own description (never from the data set).
    const double arm_mass = d.segment_mass();
    for (std::size_t e = 0; e < d.effects.size(); ++e) {
      const auto names = effect_param_names(d.effects[e], d);
      const auto& params = effect_base(d.effects[e]).params;
      for (std::size_t k = 0; k < names.size(); ++k) {
        const EffectBounds b = effect_param_bounds(d.effects[e], static_cast<int>(k), arm_mass);
        ps.add({effect_name(d.effects[e]) + "." + names[k], params(static_cast<Eigen::Index>(k)),
                b.lower, b.upper, b.log_scale});
        slots.push_back({ParamSlot::kEffect, static_cast<int>(e), static_cast<int>(k)});
      }
    }
  }
  return slots;
}
#else
;
#endif

SOFTRNE_FIT_INLINE void apply(const std::vector<ParamSlot>& slots, const Eigen::VectorXd& x,
                              const ArmDescription& start, ArmDescription& d)
#if SOFTRNE_FIT_BODIES
{
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const ParamSlot& s = slots[i];
    const double v = x(static_cast<Eigen::Index>(i));
    auto& jt = d.joints[static_cast<std::size_t>(s.joint)];
    switch (s.kind) {
      case ParamSlot::kStiffness: jt.stiffness(s.k) = v; break;
      case ParamSlot::kDamping: jt.damping(s.k) = v; break;
      case ParamSlot::kGain:
        jt.pressure_to_torque = start.joints[static_cast<std::size_t>(s.joint)].pressure_to_torque * v;
        break;
      case ParamSlot::kEffect: effect_base(d.effects[static_cast<std::size_t>(s.joint)]).params(s.k) = v; break;
    }
  }
}
#else
;
#endif

}  // namespace detail

/// \brief Simulates the arm on a data set, each of its recordings from its own first measured
/// row (at rest, or at the recording's initial rates: io::estimate_initial_rates()), at
/// `opt`'s tolerances or tighter where the model's effects need it (effect_max_atol: a
/// smoothed Coulomb friction needs atol 1e-6), so that every fit, screen and held-out error
/// sees such an effect resolved whatever the caller's default. The recordings' simulations
/// are stacked as their rows are; the first that fails ends it (its message names the file).
/// \param[in] d The arm.
/// \param[in] data The data set (times, recorded pressures, measured angles).
/// \param[in] opt The integrator settings.
/// \return The simulation (result.ok false with a message if it failed).
SOFTRNE_FIT_INLINE sim::ArmSimulation simulate_dataset(const ArmDescription& d, const io::Dataset& data,
                                                       const sim::ArmSimulationOptions& opt)
#if SOFTRNE_FIT_BODIES
{
  sim::ArmSimulationOptions o = opt;
  for (const AnyEffect& e : d.effects) o.cvode.atol = std::min(o.cvode.atol, effect_max_atol(e));
  auto first_angles = [&](Eigen::Index row) {
    return data.has_angles ? Eigen::VectorXd(data.angles.row(row).transpose()) : Eigen::VectorXd::Zero(d.nq);
  };
  if (data.recordings.empty()) return sim::simulate_arm(d, data.t, data.pressures, first_angles(0), o);
  sim::ArmSimulation out;
  const Eigen::Index N = data.t.size();
  out.angles.resize(N, d.nq);
  out.states.resize(N, d.num_states());
  out.result.ok = true;
  for (const io::Dataset::Recording& r : data.recordings) {
    // Each recording on its own times (its time shift taken off): a pressure signal, its
    // breakpoints and any input delay start at the recording's own first sample.
    const Eigen::VectorXd t = data.t.segment(r.first_row, r.rows).array() - r.time_shift;
    sim::ArmSimulation s = sim::simulate_arm(d, t, data.pressures.middleRows(r.first_row, r.rows),
                                             first_angles(r.first_row), r.initial_rates, o);
    sim::SimulationStats& st = out.result.stats;
    const sim::SimulationStats& rs = s.result.stats;
    st.steps += rs.steps;
    st.rhs_evals += rs.rhs_evals;
    st.jac_evals += rs.jac_evals;
    st.rhs_evals_for_jacobian_fd += rs.rhs_evals_for_jacobian_fd;
    st.error_test_failures += rs.error_test_failures;
    st.nonlinear_convergence_failures += rs.nonlinear_convergence_failures;
    st.restarts += rs.restarts + 1;  // each recording starts afresh
    st.wall_seconds += rs.wall_seconds;
    const Eigen::Index done = s.states.rows();
    out.states.middleRows(r.first_row, done) = s.states;
    out.angles.middleRows(r.first_row, done) = s.angles;
    out.result.t_reached = r.first_row + done > 0 ? data.t(r.first_row + done - 1) : data.t(0);
    if (!s.ok()) {
      out.result.ok = false;
      out.result.message = r.source + ": " + s.result.message;
      const Eigen::Index rows = r.first_row + done;
      out.states.conservativeResize(rows, Eigen::NoChange);
      out.angles.conservativeResize(rows, Eigen::NoChange);
      break;
    }
  }
  out.result.x = out.states;
  return out;
}
#else
;
#endif

/// \brief Checks that a data set can support a fit; throws std::invalid_argument naming the
/// data set and what is missing.
/// \param[in] d The arm.
/// \param[in] data The data set.
/// \throws std::invalid_argument if it has no angles, fewer than 20 samples or no motion.
inline void check_fit_data(const ArmDescription& d, const io::Dataset& data) {
  if (!data.has_angles || data.angles.cols() != d.nq)
    throw std::invalid_argument(data.source + ": the data set has no measured angles for every coordinate");
  if (data.t.size() < 20)
    throw std::invalid_argument(data.source + ": too short to fit (" + std::to_string(data.t.size()) +
                                " samples; at least 20 are needed)");
  const Eigen::VectorXd prange = data.pressures.colwise().maxCoeff() - data.pressures.colwise().minCoeff();
  const Eigen::VectorXd qrange = data.angles.colwise().maxCoeff() - data.angles.colwise().minCoeff();
  if (data.pressures.cols() > 0 && prange.maxCoeff() <= 0 && qrange.maxCoeff() < 1e-3)
    throw std::invalid_argument(data.source +
                                ": the pressures are constant and the arm does not move: stiffness and "
                                "damping are not identifiable from it");
}

/// \brief Fits the free parameters of `start` to the measured angles of `data`, minimising the
/// simulation error (the model is simulated from the first sample with the recorded pressures,
/// not one step ahead). Deterministic for a given optimiser seed.
///
/// The parameters are eq. 23's K_spring and K_d (and optionally a gain on eq. 24's K_prs)
/// and the effects' parameters, as the paper identifies K_spring and K_d (section IV-B).
/// \param[in] start The model and starting values.
/// \param[in] data The data set (with angles).
/// \param[in] opt What to fit and how.
/// \return The fitted model, the optimiser's result and the errors on data.
/// \throws std::invalid_argument if data cannot support a fit (check_fit_data()).
SOFTRNE_FIT_INLINE ArmFitResult fit_arm(const ArmDescription& start, const io::Dataset& data,
                                        const ArmFitOptions& opt = {})
#if SOFTRNE_FIT_BODIES
{
  check_fit_data(start, data);
  const auto t0 = std::chrono::steady_clock::now();
  ArmFitResult out;
  const std::vector<detail::ParamSlot> slots = detail::make_slots(start, opt, out.parameters);
  const int nq = start.nq;
  const Eigen::Index N = data.t.size();
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < N; ++i)
    if (opt.sample_mask.empty() || opt.sample_mask[static_cast<std::size_t>(i)]) rows.push_back(i);
  const int m = static_cast<int>(rows.size()) * nq;
  const double scale = 1.0 / std::sqrt(static_cast<double>(rows.size()));  // r^2 sums to MSE
  std::atomic<int> sims{0};
  auto make_residual = [&]() -> ResidualFn {
    return [&, d = start](const Eigen::VectorXd& x, Eigen::VectorXd& r) mutable {
      detail::apply(slots, x, start, d);
      // Payload and mass_scale change the chain, which simulate_dataset rebuilds; everything
      // else is read at evaluation time.
      const sim::ArmSimulation s = simulate_dataset(d, data, opt.simulation);
      ++sims;
      if (!s.ok() || s.angles.rows() != N) return false;
      r.resize(m);
      for (std::size_t i = 0; i < rows.size(); ++i)
        r.segment(static_cast<Eigen::Index>(i) * nq, nq) =
            scale * (s.angles.row(rows[i]) - data.angles.row(rows[i])).transpose();
      return true;
    };
  };
  if (out.parameters.size() == 0) {
    out.fitted = start;
  } else {
    out.fit = fit_least_squares(out.parameters, m, ResidualFactory(make_residual), opt.optimiser);
    out.fitted = start;
    if (out.fit.params.size() == out.parameters.size()) detail::apply(slots, out.fit.params, start, out.fitted);
  }
  const sim::ArmSimulation s = simulate_dataset(out.fitted, data, opt.simulation);
  ++sims;
  if (s.ok() && s.angles.rows() == N && s.angles.allFinite()) {
    out.angles = s.angles;
    out.stats = signals::error_stats(s.angles, data.angles, out.fitted.coordinate_names);
  }
  out.simulations = sims;
  out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}
#else
;
#endif

}  // namespace softrne::fit
