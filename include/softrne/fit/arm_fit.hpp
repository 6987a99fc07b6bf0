#pragma once
/// \file
/// \brief System identification of an arm: stiffness, damping (and optionally pressure gains
/// and effect parameters) fitted to measured angles by simulation error (paper section IV-B).

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/QR>

#include "softrne/config.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/arm/equilibrium.hpp"
#include "softrne/arm/markers.hpp"
#include "softrne/fit/least_squares.hpp"
#include "softrne/fit/parameters.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/recordings.hpp"
// The error statistics (signals/error_stats.hpp) through the header that also keeps their old
// names (softrne::ErrorStats, ...): user code that included only the fit headers names them so.
#include "softrne/model/error_stats.hpp"
#include "softrne/sim/arm_simulation.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne::fit {

/// \brief What to fit.
struct ArmFitOptions {
  bool stiffness = true;       ///< per-axis K_spring of every joint
  bool damping = true;         ///< per-axis K_d of every joint
  bool pressure_gain = false;  ///< one factor on K_prs per CC joint
  bool effects = true;         ///< the parameters of the model's effects

  /// Bounds of K and D: [x0 / range, x0 * range] around the starting guess (log scale).
  double stiffness_range = 30.0;
  /// Weight of a marker's position error against an angle's error, rad per m, where the data
  /// have both; 0: 1 / the arm's reach (arm_reach()), so that a tip error of reach x dtheta
  /// weighs as much as an angle error dtheta. Irrelevant to a fit from markers alone.
  double marker_weight = 0;
  /// One capture frame per recording (logs recorded with different motion-capture
  /// calibrations) instead of one for all.
  bool capture_frame_per_recording = false;
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
  /// The velocities keep 1e-3 rad/s (velocity factor 100, tighter than the simulator's
  /// default 1e-2): the loop's decisions and scores were measured with it.
  /// \return rtol 1e-6, atol 1e-5 (1e-3 rad/s on the velocities), at most 60 s per simulation.
  static sim::ArmSimulationOptions default_simulation() {
    sim::ArmSimulationOptions s;
    s.cvode.rtol = 1e-6;
    s.cvode.atol = 1e-5;
    s.velocity_atol_factor = 100;
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

  /// Data with markers: the motion-capture frames fitted with the physical parameters (solved
  /// in closed form for each simulation: fit_capture_frame()), one shared or one per recording
  /// (ArmFitOptions::capture_frame_per_recording), their standard errors (6 each:
  /// rotation about the capture axes, rad, then translation, m; from the Jacobian of the whole
  /// residual in the physical parameters and the frame at the optimum), the simulated markers
  /// in the capture frame (N x 3M) and their errors: per marker the distance between
  /// simulated and measured positions, in mm.
  std::vector<CaptureFrame> capture_frames;  ///< one (shared) or one per recording
  std::vector<Eigen::VectorXd> capture_frame_std_errors;  ///< 6 per frame
  Eigen::MatrixXd markers;          ///< simulated markers in the capture frames (N x 3M), m
  signals::ErrorStats marker_stats;  ///< per marker, simulated vs measured distance, mm
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

SOFTRNE_FIT_INLINE std::vector<ParamSlot> make_slots(const ArmDescription& d,
                                                     const ArmFitOptions& o, ParameterSet& ps)
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
/// row (at rest, or at the recording's initial rates: io::estimate_initial_rates(); data with
/// markers and no angles: at rest in the static equilibrium of its first pressures), at
/// `opt`'s tolerances or tighter where the model's effects need it (effect_max_atol: a
/// smoothed Coulomb friction needs atol 1e-6), so that every fit, screen and held-out error
/// sees such an effect resolved whatever the caller's default. The recordings' simulations
/// are stacked as their rows are; the first that fails ends it (its message names the file).
/// \param[in] d The arm.
/// \param[in] data The data set (times, recorded pressures, measured angles).
/// \param[in] opt The integrator settings.
/// \return The simulation (result.ok false with a message if it failed).
SOFTRNE_FIT_INLINE sim::ArmSimulation simulate_dataset(const ArmDescription& d,
                                                       const io::Dataset& data,
                                                       const sim::ArmSimulationOptions& opt)
#if SOFTRNE_FIT_BODIES
{
  sim::ArmSimulationOptions o = opt;
  for (const AnyEffect& e : d.effects) o.cvode.atol = std::min(o.cvode.atol, effect_max_atol(e));
  // Without measured angles (markers only) a recording starts at rest where its first
  // pressures hold the arm (static_equilibrium); if there is none, straight.
  auto first_angles = [&](Eigen::Index row) -> Eigen::VectorXd {
    if (data.has_angles) return data.angles.row(row).transpose();
    if (!data.has_markers) return Eigen::VectorXd::Zero(d.nq);
    try {
      return d.measured(static_equilibrium(d, data.pressures.row(row).transpose()));
    } catch (const std::runtime_error&) {
      return Eigen::VectorXd::Zero(d.nq);
    }
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
    out.result.stats += s.result.stats;
    out.result.stats.restarts += 1;  // each recording starts afresh
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
SOFTRNE_FIT_INLINE void check_fit_data(const ArmDescription& d, const io::Dataset& data)
#if SOFTRNE_FIT_BODIES
{
  const bool markers = data.has_markers && !d.spec.markers.empty() &&
                       data.markers.cols() == 3 * static_cast<Eigen::Index>(d.spec.markers.size());
  if (!markers && (!data.has_angles || data.angles.cols() != d.nq))
    throw std::invalid_argument(data.source + ": the data set has no measured angles for every coordinate" +
                                std::string(d.spec.markers.empty() ? "" : " and no marker positions"));
  if (data.t.size() < 20)
    throw std::invalid_argument(data.source + ": too short to fit (" + std::to_string(data.t.size()) +
                                " samples; at least 20 are needed)");
  const Eigen::VectorXd prange = data.pressures.colwise().maxCoeff() - data.pressures.colwise().minCoeff();
  const Eigen::MatrixXd& y = data.has_angles ? data.angles : data.markers;
  const Eigen::VectorXd qrange = y.colwise().maxCoeff() - y.colwise().minCoeff();
  if (data.pressures.cols() > 0 && prange.maxCoeff() <= 0 && qrange.maxCoeff() < 1e-3)
    throw std::invalid_argument(data.source +
                                ": the pressures are constant and the arm does not move: stiffness and "
                                "damping are not identifiable from it");
}
#else
;
#endif

namespace detail {

/// Index of the capture frame of every row: 0 everywhere for one shared frame, the recording's
/// index with one frame per recording.
inline std::vector<int> frame_of_rows(const io::Dataset& data, bool per_recording) {
  std::vector<int> g(static_cast<std::size_t>(data.t.size()), 0);
  if (!per_recording) return g;
  const std::vector<io::Dataset::Recording> recs = io::recordings_of(data);
  for (std::size_t k = 0; k < recs.size(); ++k)
    for (Eigen::Index i = recs[k].first_row; i < recs[k].first_row + recs[k].rows; ++i)
      g[static_cast<std::size_t>(i)] = static_cast<int>(k);
  return g;
}

/// The capture frames that best map `base` (N x 3M, base frame) onto data.markers on the rows of
/// `use` (all if empty), one per group of frame_of_rows().
SOFTRNE_FIT_INLINE std::vector<CaptureFrame> fit_capture_frames(const Eigen::MatrixXd& base,
                                                                const io::Dataset& data,
                                                                const std::vector<int>& group,
                                                                const std::vector<bool>& use)
#if SOFTRNE_FIT_BODIES
{
  const int G = group.empty() ? 0 : *std::max_element(group.begin(), group.end()) + 1;
  std::vector<CaptureFrame> frames(static_cast<std::size_t>(G));
  for (int g = 0; g < G; ++g) {
    std::vector<bool> mine(group.size());
    for (std::size_t i = 0; i < group.size(); ++i) mine[i] = group[i] == g && (use.empty() || use[i]);
    frames[static_cast<std::size_t>(g)] = fit_capture_frame(base, data.markers, mine);
  }
  return frames;
}
#else
;
#endif

/// Base-frame positions mapped into each row's capture frame.
SOFTRNE_FIT_INLINE Eigen::MatrixXd in_capture_frames(const Eigen::MatrixXd& base,
                                                     const std::vector<CaptureFrame>& frames,
                                                     const std::vector<int>& group)
#if SOFTRNE_FIT_BODIES
{
  Eigen::MatrixXd y(base.rows(), base.cols());
  for (Eigen::Index i = 0; i < base.rows(); ++i)
    y.row(i) = frames[static_cast<std::size_t>(group[static_cast<std::size_t>(i)])].apply(base.row(i));
  return y;
}
#else
;
#endif

/// The fit's residual of one simulation `s` of arm `d`: for each row of `rows`, the nq angle
/// errors (data with angles), then the 3M marker errors in the row's capture frame times
/// `marker_weight` (data with markers, marker_weight > 0); all times `scale`. The frames are
/// `fixed` if given, else solved for this simulation on the rows of `mask` (fit_capture_frames)
/// and returned in `frames`.
SOFTRNE_FIT_INLINE void fit_residual(const ArmDescription& d, const sim::ArmSimulation& s,
                                     const io::Dataset& data, const std::vector<Eigen::Index>& rows,
                                     const std::vector<bool>& mask, double scale,
                                     double marker_weight, const std::vector<int>& group,
                                     const std::vector<CaptureFrame>* fixed,
                                     std::vector<CaptureFrame>* frames, Eigen::VectorXd& r)
#if SOFTRNE_FIT_BODIES
{
  const Eigen::Index na = data.has_angles ? d.nq : 0;
  const Eigen::Index nm = marker_weight > 0 && data.has_markers ? data.markers.cols() : 0;
  r.resize(static_cast<Eigen::Index>(rows.size()) * (na + nm));
  Eigen::MatrixXd y;
  if (nm > 0) {
    const Eigen::MatrixXd base = marker_positions(d, s.states);
    const std::vector<CaptureFrame> f = fixed ? *fixed : fit_capture_frames(base, data, group, mask);
    if (frames) *frames = f;
    y = in_capture_frames(base, f, group);
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Eigen::Index row = rows[i], at = static_cast<Eigen::Index>(i) * (na + nm);
    if (na > 0) r.segment(at, na) = scale * (s.angles.row(row) - data.angles.row(row)).transpose();
    if (nm > 0) r.segment(at + na, nm) = scale * marker_weight * (y.row(row) - data.markers.row(row)).transpose();
  }
}
#else
;
#endif

/// Per marker, the distance between simulated (capture frame) and measured positions, mm.
SOFTRNE_FIT_INLINE signals::ErrorStats marker_error_stats(const ArmDescription& d,
                                                          const Eigen::MatrixXd& simulated,
                                                          const Eigen::MatrixXd& measured)
#if SOFTRNE_FIT_BODIES
{
  const auto M = static_cast<Eigen::Index>(d.spec.markers.size());
  Eigen::MatrixXd dist(simulated.rows(), M);
  std::vector<std::string> names;
  for (Eigen::Index k = 0; k < M; ++k) {
    names.push_back(d.spec.markers[static_cast<std::size_t>(k)].name);
    for (Eigen::Index i = 0; i < simulated.rows(); ++i)
      dist(i, k) = 1e3 * (simulated.row(i).segment<3>(3 * k) - measured.row(i).segment<3>(3 * k)).norm();
  }
  return signals::error_stats(dist, Eigen::MatrixXd::Zero(dist.rows(), M), names);
}
#else
;
#endif

/// Standard errors of the fitted capture frames (per frame: 3 rotation angles about the capture
/// axes, rad, then 3 translations, m) from the Jacobian of the whole residual at the optimum in
/// the physical parameters (central differences, the frames held: 2 simulations each) and in
/// the frames (closed form: a rotation dtheta moves R x by dtheta x (R x), a translation by
/// itself): covariance s^2 (J^T J)^+ with s^2 = |r|^2 / (m - n). The fit's own standard errors
/// of the physical parameters come from the residual with the frames solved (projected), which
/// is the same marginal covariance.
SOFTRNE_FIT_INLINE std::vector<Eigen::VectorXd> capture_frame_std_errors(
    const ArmFitResult& out, const std::vector<ParamSlot>& slots, const ArmDescription& start,
    const io::Dataset& data, const std::vector<Eigen::Index>& rows, const ArmFitOptions& opt,
    double scale, double marker_weight, const std::vector<int>& group, const Eigen::VectorXd& r0,
    std::atomic<int>& sims)
#if SOFTRNE_FIT_BODIES
{
  const int np = out.fit.params.size() == out.parameters.size() ? out.parameters.size() : 0;
  const auto G = static_cast<Eigen::Index>(out.capture_frames.size());
  const Eigen::Index m = r0.size();
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(m, np + 6 * G);
  ArmDescription d = start;
  for (int i = 0; i < np; ++i) {
    const Parameter& par = out.parameters[i];
    const double x = out.fit.params(i);
    const double h = 1e-3 * std::max(std::abs(x), 1e-3 * (par.upper - par.lower));
    Eigen::VectorXd r[2];
    bool ok = true;
    for (int side = 0; side < 2; ++side) {
      Eigen::VectorXd xs = out.fit.params;
      xs(i) = x + (side == 0 ? h : -h);
      apply(slots, xs, start, d);
      const sim::ArmSimulation s = simulate_dataset(d, data, opt.simulation);
      ++sims;
      ok = ok && s.ok() && s.angles.rows() == data.t.size();
      if (ok)
        fit_residual(d, s, data, rows, opt.sample_mask, scale, marker_weight, group, &out.capture_frames, nullptr,
                     r[side]);
    }
    if (ok && r[0].size() == m && r[1].size() == m) J.col(i) = (r[0] - r[1]) / (2 * h);
  }
  // The frames' columns: the marker rows of each used sample, in its own frame's six columns.
  const Eigen::Index na = data.has_angles ? start.nq : 0, nm = data.markers.cols();
  const Eigen::MatrixXd& y = out.markers;  // R x + t of the fitted model, capture frames
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const int g = group[static_cast<std::size_t>(rows[i])];
    const Eigen::Index col = np + 6 * g;
    for (Eigen::Index k = 0; k < nm; k += 3) {
      const Eigen::Index at = static_cast<Eigen::Index>(i) * (na + nm) + na + k;
      const Eigen::Vector3d Rx =
          y.row(rows[i]).segment<3>(k).transpose() - out.capture_frames[static_cast<std::size_t>(g)].t;
      J.block<3, 3>(at, col) = -scale * marker_weight * skew(Rx);
      J.block<3, 3>(at, col + 3) = scale * marker_weight * Eigen::Matrix3d::Identity();
    }
  }
  const double dof = static_cast<double>(std::max<Eigen::Index>(1, m - (np + 6 * G)));
  const double s2 = r0.squaredNorm() / dof;
  const Eigen::MatrixXd cov = s2 * (J.transpose() * J).completeOrthogonalDecomposition().pseudoInverse();
  std::vector<Eigen::VectorXd> out_se;
  for (Eigen::Index g = 0; g < G; ++g)
    out_se.push_back(cov.diagonal().segment(np + 6 * g, 6).cwiseMax(0.0).cwiseSqrt());
  return out_se;
}
#else
;
#endif

}  // namespace detail

/// \brief The marker errors (per marker the distance between simulated and measured positions,
/// mm) of model `d` simulated on `data` (with markers; `s` = simulate_dataset(d, data, ...)),
/// in capture frames `frames` (one shared, or one per recording as `per_recording` says) or,
/// if null, in the frames fitted in closed form to this simulation (returned in `fitted` if
/// given). A held-out data set is measured in the frame fitted on the training data when the
/// frame is shared, in its own recordings' frames (fitted to them: 6 numbers each, the physics
/// untouched) when each recording has its own.
/// \param[in] d The arm (with markers).
/// \param[in] data The data set (with marker columns).
/// \param[in] s The arm simulated on the data set.
/// \param[in] per_recording One frame per recording instead of one shared.
/// \param[in] frames The frames to measure in (one shared), or null to fit them.
/// \param[out] fitted The frames used, if not null.
/// \return The statistics; empty if the simulation failed or the data have no markers.
SOFTRNE_FIT_INLINE signals::ErrorStats marker_errors(const ArmDescription& d,
                                                     const io::Dataset& data,
                                                     const sim::ArmSimulation& s,
                                                     bool per_recording,
                                                     const std::vector<CaptureFrame>* frames,
                                                     std::vector<CaptureFrame>* fitted = nullptr)
#if SOFTRNE_FIT_BODIES
{
  if (!data.has_markers || d.spec.markers.empty()) return {};
  if (!s.ok() || s.states.rows() != data.t.size()) return {};
  const Eigen::MatrixXd base = marker_positions(d, s.states);
  const std::vector<int> group = detail::frame_of_rows(data, per_recording);
  const std::vector<CaptureFrame> f =
      frames && !per_recording ? *frames : detail::fit_capture_frames(base, data, group, {});
  if (fitted) *fitted = f;
  return detail::marker_error_stats(d, detail::in_capture_frames(base, f, group), data.markers);
}
#else
;
#endif

/// \brief Fits the free parameters of `start` to the measured angles of `data`, minimising the
/// simulation error (the model is simulated from the first sample with the recorded pressures,
/// not one step ahead). Deterministic for a given optimiser seed.
///
/// Data with motion-capture markers (the robot's `markers`, the data's `<name>_x, _y, _z`):
/// their positions enter the objective in the capture frame, which is solved in closed form
/// for every simulation (variable projection: fit_capture_frame()) and reported with its
/// standard errors; with angles too, a marker's error in m weighs marker_weight rad per m.
///
/// The parameters are eq. 23's K_spring and K_d (and optionally a gain on eq. 24's K_prs)
/// and the effects' parameters, as the paper identifies K_spring and K_d (section IV-B).
/// \param[in] start The model and starting values.
/// \param[in] data The data set (with angles, markers or both).
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
  const Eigen::Index N = data.t.size();
  // Markers enter the objective where the robot declares them and the data carry them.
  const bool use_markers = data.has_markers && !start.spec.markers.empty();
  const double marker_weight = !use_markers ? 0.0
                               : !data.has_angles ? 1.0
                               : opt.marker_weight > 0 ? opt.marker_weight
                                                       : 1.0 / std::max(arm_reach(start), 1e-3);
  const std::vector<int> group = detail::frame_of_rows(data, opt.capture_frame_per_recording);
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < N; ++i)
    if (opt.sample_mask.empty() || opt.sample_mask[static_cast<std::size_t>(i)]) rows.push_back(i);
  const Eigen::Index per_row = (data.has_angles ? start.nq : 0) + (use_markers ? data.markers.cols() : 0);
  const int m = static_cast<int>(static_cast<Eigen::Index>(rows.size()) * per_row);
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
      detail::fit_residual(d, s, data, rows, opt.sample_mask, scale, marker_weight, group, nullptr, nullptr, r);
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
    if (data.has_angles) out.stats = signals::error_stats(s.angles, data.angles, out.fitted.coordinate_names);
    if (use_markers) {
      Eigen::VectorXd r0;
      detail::fit_residual(out.fitted, s, data, rows, opt.sample_mask, scale, marker_weight, group, nullptr,
                           &out.capture_frames, r0);
      out.markers = detail::in_capture_frames(marker_positions(out.fitted, s.states), out.capture_frames, group);
      out.marker_stats = detail::marker_error_stats(out.fitted, out.markers, data.markers);
      out.capture_frame_std_errors = detail::capture_frame_std_errors(out, slots, start, data, rows, opt, scale,
                                                                      marker_weight, group, r0, sims);
    }
  }
  out.simulations = sims;
  out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}
#else
;
#endif

}  // namespace softrne::fit
