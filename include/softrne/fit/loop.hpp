#pragma once
/// \file
/// \brief The closed loop: fit the declared model, look at the residual, find the effect the
/// model lacks, add it, refit, and measure the error before and after.
///
/// Method (docs/closing-the-loop.md):
///  1. Baseline: fit stiffness and damping by simulation error on the training data.
///  2. Residual: the equation error \f$r = M\ddot q + C\dot q + G - \tau(q,\dot q,p)\f$ on the
///     measured trajectory (Savitzky-Golay smoothed q, qdot, qddot), where tau holds the
///     declared springs, dampers, pressure torques and the effects added so far.
///  3. Ranking: each candidate effect's generalised force is (to first order) linear in its
///     parameter, \f$\tau_e \approx \theta\,\varphi_e(q,\dot q,p,\dot p)\f$. Regressing r on
///     \f$\varphi_e\f$ together with nuisance regressors for re-estimated K and D gives the
///     fraction of the residual each candidate explains beyond a stiffness/damping change.
///  4. Confirmation: the best candidates (those that explain at least `min_explained` of the
///     residual) are refitted in full (simulation error) and scored by
///     two-fold cross-validation on the TRAINING data (interleaved time blocks: each fold is
///     fitted on the other blocks, the simulation runs through all samples, the error is
///     measured on the held-out blocks). An effect is added only if it lowers the held-out
///     error by at least `min_gain` in every fold: a parameter that only fits noise cannot do
///     that, so declared-model data gets no effect. Test data is never used to select.
///  5. Repeat until no candidate earns its place.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/QR>

#include "softrne/fit/arm_fit.hpp"
#include "softrne/fit/savitzky_golay.hpp"

namespace softrne::fit {

/// \brief Settings of the closed loop.
struct LoopOptions {
  ArmFitOptions fit{};
  int max_effects = 3;
  int candidates_to_confirm = 3;  ///< best-ranked candidates refitted per round
  double min_gain = 0.05;         ///< relative drop of the held-out error, in every fold
  /// Candidates that explain less of the equation-error residual than this are not refitted
  /// (a term that explains almost none of the residual cannot lower the error by min_gain).
  double min_explained = 0.02;
  int cv_blocks = 4;              ///< contiguous time blocks; folds take every other block
  SgOptions smoothing{};          ///< differentiator of the measured angles and pressures
  std::function<void(const std::string&)> log;  ///< progress lines (may be empty)
};

/// \brief One candidate's evidence.
struct CandidateScore {
  std::string name;
  double residual_explained = 0;  ///< fraction of the equation-error residual (after K, D)
  Eigen::VectorXd estimate;       ///< regression estimate of its parameter(s)
  bool confirmed = false;
  double cv_gain = 0;             ///< relative drop of the held-out simulation error
  std::vector<double> fold_gains;
};

/// \brief An effect the loop added.
struct AddedEffect {
  AnyEffect effect;
  std::string evidence;
  double selection_gain = 0;
};

/// \brief Outcome of run_loop.
struct LoopResult {
  ArmFitResult baseline;
  ErrorStats baseline_test, final_train, final_test;
  std::vector<std::vector<CandidateScore>> rounds;  ///< ranked candidates of each round
  std::vector<AddedEffect> added;
  ArmFitResult final_fit;
  Eigen::MatrixXd residual;   ///< equation error of the baseline on train (N x nq)
  Eigen::MatrixXd final_residual;
  double wall_seconds = 0;
};

namespace detail {

/// Measured trajectory, smoothed and differentiated.
struct Trajectory {
  Eigen::MatrixXd q, qd, qdd, p, pd;
};

inline Trajectory differentiate(const io::Dataset& d, const SgOptions& sg) {
  Trajectory tr;
  Eigen::MatrixXd pdd;
  savgol(d.t, d.angles, sg, tr.q, tr.qd, tr.qdd);
  savgol(d.t, d.pressures, sg, tr.p, tr.pd, pdd);
  return tr;
}

/// Equation error r = M qdd + C qd + G - tau(q, qd, p) for every sample (N x nq).
inline Eigen::MatrixXd equation_error(const ArmDescription& desc, const Trajectory& tr) {
  ArmDynamics<double> dyn(desc);
  auto chain = desc.make_chain<double>();
  auto data = chain.make_data();
  const Eigen::Index N = tr.q.rows();
  Eigen::MatrixXd r(N, desc.nq);
  const Eigen::VectorXd offset = desc.measurement_offset();
  for (Eigen::Index i = 0; i < N; ++i) {
    const Eigen::VectorXd q = tr.q.row(i).transpose() - offset, qd = tr.qd.row(i).transpose(),
                          qdd = tr.qdd.row(i).transpose(), p = tr.p.row(i).transpose();
    const Eigen::VectorXd tau = dyn.joint_forces(q, qd, p);
    r.row(i) = (rnea(chain, data, q, qd, qdd) - tau).transpose();
  }
  return r;
}

/// A candidate effect on every joint it applies to, shared parameter.
inline AnyEffect make_candidate(const std::string& name, const ArmDescription& d) {
  AnyEffect e;
  make_effect(name, e);
  EffectBase& b = effect_base(e);
  for (std::size_t j = 0; j < d.joints.size(); ++j) {
    if (std::holds_alternative<ChamberMisalignment>(e) && !d.joints[j].is_cc()) continue;
    if ((std::holds_alternative<ActuatorLag>(e) || std::holds_alternative<PressureStiffening>(e)) &&
        d.joints[j].num_inputs == 0)
      continue;
    b.joints.push_back(static_cast<int>(j));
  }
  b.shared = !std::holds_alternative<AngleOffset>(e);
  b.params = Eigen::VectorXd::Zero(effect_num_params(e, d.joints));
  return e;
}

/// Regressors of a candidate: d tau_effect / d theta at theta = 0 (N*nq x n_params), with
/// tau_effect the force the effect adds to the right-hand side; the declared model's equation
/// error is then r ~ Phi theta.
inline Eigen::MatrixXd candidate_regressors(const ArmDescription& base, const AnyEffect& cand,
                                            const Trajectory& tr) {
  const Eigen::Index N = tr.q.rows();
  const int nq = base.nq;
  const int np = effect_num_params(cand, base.joints);
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Zero(N * nq, np);
  const Eigen::VectorXd offset = base.measurement_offset();
  if (std::holds_alternative<ActuatorLag>(cand)) {
    // p_eff = p - T pdot + O(T^2): d tau/dT = -K_prs pdot.
    for (Eigen::Index i = 0; i < N; ++i)
      for (int jj : effect_base(cand).joints) {
        const ArmJoint& j = base.joints[static_cast<std::size_t>(jj)];
        for (int k = 0; k < j.nq; ++k)
          for (int c = 0; c < j.num_inputs; ++c)
            Phi(i * nq + j.q_offset + k, 0) -= j.pressure_to_torque(k, c) * tr.pd(i, j.input_offset + c);
      }
    return Phi;
  }
  if (std::holds_alternative<AngleOffset>(cand)) {
    // Measured = q + b, so the residual computed with measured angles shifts by
    // -(d r/dq) b; d r/dq by central differences of the equation error.
    auto chain = base.make_chain<double>();
    auto data = chain.make_data();
    ArmDynamics<double> dyn(base);
    const double h = 1e-6;
    int col = 0;
    for (int jj : effect_base(cand).joints) {
      const ArmJoint& j = base.joints[static_cast<std::size_t>(jj)];
      for (int k = 0; k < j.nq; ++k, ++col)
        for (Eigen::Index i = 0; i < N; ++i) {
          Eigen::VectorXd q = tr.q.row(i).transpose() - offset;
          const Eigen::VectorXd qd = tr.qd.row(i).transpose(), qdd = tr.qdd.row(i).transpose(),
                                p = tr.p.row(i).transpose();
          q(j.q_offset + k) += h;
          Eigen::VectorXd rp = rnea(chain, data, q, qd, qdd) - dyn.joint_forces(q, qd, p);
          q(j.q_offset + k) -= 2 * h;
          Eigen::VectorXd rm = rnea(chain, data, q, qd, qdd) - dyn.joint_forces(q, qd, p);
          // r(q_meas - b) = r(q_meas) - (dr/dq) b: the added force is +(dr/dq) b.
          Phi.block(i * nq, col, nq, 1) = (rp - rm) / (2 * h);
        }
    }
    return Phi;
  }
  // Every other effect: finite difference of the model's joint forces (or of the RNE for a
  // payload) in its parameter around zero; exact for effects linear in it.
  const double h = std::holds_alternative<ChamberMisalignment>(cand) ? 1e-6 : 1e-3;
  ArmDescription with = base, without = base;
  AnyEffect e = cand;
  effect_base(e).params.setConstant(h);
  with.effects.push_back(e);
  with.effect_state_offsets.push_back(with.num_effect_states);
  ArmDynamics<double> dyn_with(with), dyn_without(without);
  auto chain_with = with.make_chain<double>();
  auto data_with = chain_with.make_data();
  auto chain_without = without.make_chain<double>();
  auto data_without = chain_without.make_data();
  const bool payload = std::holds_alternative<Payload>(cand);
  for (Eigen::Index i = 0; i < N; ++i) {
    const Eigen::VectorXd q = tr.q.row(i).transpose() - offset, qd = tr.qd.row(i).transpose(),
                          qdd = tr.qdd.row(i).transpose(), p = tr.p.row(i).transpose();
    Eigen::VectorXd d = dyn_with.joint_forces(q, qd, p) - dyn_without.joint_forces(q, qd, p);
    if (payload) {
      const Eigen::VectorXd a = rnea(chain_with, data_with, q, qd, qdd);
      d -= a - rnea(chain_without, data_without, q, qd, qdd);  // inertia is on the left side
    }
    Phi.block(i * nq, 0, nq, 1) = d / h;
  }
  return Phi;
}

/// Nuisance regressors: re-estimated stiffness and damping (q_k and qdot_k on coordinate k).
inline Eigen::MatrixXd nuisance_regressors(const ArmDescription& d, const Trajectory& tr) {
  const Eigen::Index N = tr.q.rows();
  const int nq = d.nq;
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(N * nq, 2 * nq);
  for (Eigen::Index i = 0; i < N; ++i)
    for (int k = 0; k < nq; ++k) {
      X(i * nq + k, 2 * k) = tr.q(i, k);
      X(i * nq + k, 2 * k + 1) = tr.qd(i, k);
    }
  return X;
}

inline double rss_after(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, Eigen::VectorXd* coef = nullptr) {
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  const Eigen::VectorXd c = qr.solve(y);
  if (coef) *coef = c;
  return (y - X * c).squaredNorm();
}

/// RMS of the simulation error over the masked samples.
inline double masked_rms(const Eigen::MatrixXd& sim, const Eigen::MatrixXd& meas, const std::vector<bool>& mask) {
  double s = 0;
  long n = 0;
  for (Eigen::Index i = 0; i < std::min(sim.rows(), meas.rows()); ++i)
    if (mask[static_cast<std::size_t>(i)]) {
      s += (sim.row(i) - meas.row(i)).squaredNorm();
      n += sim.cols();
    }
  return n ? std::sqrt(s / static_cast<double>(n)) : 0.0;
}

}  // namespace detail

/// \brief Runs the closed loop on a training set; `test` only measures (may be empty).
inline LoopResult run_loop(const ArmDescription& declared, const io::Dataset& train,
                           const io::Dataset* test, const LoopOptions& opt = {}) {
  const auto t0 = std::chrono::steady_clock::now();
  auto log = [&](const std::string& s) {
    if (opt.log) opt.log(s);
  };
  LoopResult out;
  log("baseline fit of stiffness and damping");
  out.baseline = fit_arm(declared, train, opt.fit);
  auto test_stats = [&](const ArmDescription& d) {
    ErrorStats s;
    if (!test) return s;
    const auto sim = simulate_dataset(d, *test, opt.fit.simulation);
    if (sim.ok()) s = error_stats(sim.angles, test->angles, d.coordinate_names);
    return s;
  };
  out.baseline_test = test_stats(out.baseline.fitted);
  const detail::Trajectory tr = detail::differentiate(train, opt.smoothing);
  const Eigen::Index N = train.t.size();

  // Folds: interleaved contiguous time blocks.
  std::vector<std::vector<bool>> fit_masks(2), held_masks(2);
  for (int f = 0; f < 2; ++f) {
    fit_masks[f].resize(static_cast<std::size_t>(N));
    held_masks[f].resize(static_cast<std::size_t>(N));
    for (Eigen::Index i = 0; i < N; ++i) {
      const int block = static_cast<int>((i * opt.cv_blocks) / N);
      const bool held = block % 2 == f;
      held_masks[f][static_cast<std::size_t>(i)] = held;
      fit_masks[f][static_cast<std::size_t>(i)] = !held;
    }
  }
  // Refits start from the current fit (warm start): local stage only.
  ArmFitOptions refit = opt.fit;
  refit.optimiser.global_evals = 0;
  auto cv_errors = [&](const ArmDescription& d) {
    std::vector<double> e(2);
    for (int f = 0; f < 2; ++f) {
      ArmFitOptions o = refit;
      o.sample_mask = fit_masks[f];
      const ArmFitResult r = fit_arm(d, train, o);
      const auto sim = simulate_dataset(r.fitted, train, opt.fit.simulation);
      e[static_cast<std::size_t>(f)] = sim.ok() ? detail::masked_rms(sim.angles, train.angles, held_masks[f])
                                                : std::numeric_limits<double>::infinity();
    }
    return e;
  };

  ArmDescription current = out.baseline.fitted;
  ArmFitResult current_fit = out.baseline;
  std::vector<std::string> used;
  std::vector<double> base_cv;  // held-out errors of the current model (reused across rounds)
  for (int round = 0; round < opt.max_effects; ++round) {
    const Eigen::MatrixXd R = detail::equation_error(current, tr);
    if (round == 0) out.residual = R;
    Eigen::VectorXd y(R.size());
    for (Eigen::Index i = 0; i < N; ++i) y.segment(i * current.nq, current.nq) = R.row(i).transpose();
    const Eigen::MatrixXd X0 = detail::nuisance_regressors(current, tr);
    const double rss0 = detail::rss_after(X0, y);
    std::vector<CandidateScore> scores;
    for (const std::string& name : effect_names()) {
      if (std::find(used.begin(), used.end(), name) != used.end()) continue;
      const AnyEffect cand = detail::make_candidate(name, current);
      if (effect_base(cand).joints.empty()) continue;
      const Eigen::MatrixXd Phi = detail::candidate_regressors(current, cand, tr);
      if (!Phi.allFinite() || Phi.norm() == 0) continue;
      Eigen::MatrixXd X(X0.rows(), X0.cols() + Phi.cols());
      X << X0, Phi;
      Eigen::VectorXd coef;
      const double rss = detail::rss_after(X, y, &coef);
      CandidateScore s;
      s.name = name;
      s.residual_explained = rss0 > 0 ? (rss0 - rss) / rss0 : 0.0;
      // r = tau_effect = Phi theta: the coefficient estimates the parameter.
      s.estimate = coef.tail(Phi.cols());
      scores.push_back(s);
    }
    std::sort(scores.begin(), scores.end(),
              [](const CandidateScore& a, const CandidateScore& b) { return a.residual_explained > b.residual_explained; });
    log("round " + std::to_string(round + 1) + ": ranked " + std::to_string(scores.size()) + " candidates");
    int best = -1;
    double best_gain = 0;
    ArmDescription best_desc;
    std::vector<double> best_cv;
    for (int c = 0; c < std::min<int>(opt.candidates_to_confirm, static_cast<int>(scores.size())); ++c) {
      CandidateScore& s = scores[static_cast<std::size_t>(c)];
      if (s.residual_explained < opt.min_explained) break;  // sorted: the rest explain less
      if (base_cv.empty()) base_cv = cv_errors(current);
      ArmDescription with = current;
      AnyEffect e = detail::make_candidate(s.name, current);
      const EffectBounds b = effect_bounds(e, current.segment_mass());
      Eigen::VectorXd init = s.estimate;
      for (Eigen::Index k = 0; k < init.size(); ++k) {
        double v = std::isfinite(init(k)) ? init(k) : 0.0;
        v = std::clamp(v, b.lower, b.upper);
        if (b.log_scale) v = std::max(v, std::sqrt(b.lower * b.upper) * 0.1);
        init(k) = v;
      }
      effect_base(e).params = init;
      with.effects.push_back(e);
      with.effect_state_offsets.push_back(with.num_effect_states);
      with.num_effect_states += std::visit([&](const auto& x) { return x.num_states(with.joints); }, e);
      const std::vector<double> cv = cv_errors(with);
      s.confirmed = true;
      s.fold_gains = {(base_cv[0] - cv[0]) / base_cv[0], (base_cv[1] - cv[1]) / base_cv[1]};
      s.cv_gain = ((base_cv[0] + base_cv[1]) - (cv[0] + cv[1])) / (base_cv[0] + base_cv[1]);
      if (std::isfinite(s.cv_gain))
        log("  " + s.name + ": explains " + std::to_string(100 * s.residual_explained) + " % of the residual, held-out error " +
            std::to_string(100 * s.fold_gains[0]) + " % / " + std::to_string(100 * s.fold_gains[1]) + " % lower");
      else
        log("  " + s.name + ": explains " + std::to_string(100 * s.residual_explained) +
            " % of the residual; its refit failed to simulate in a fold: rejected");
      const bool significant = s.fold_gains[0] >= opt.min_gain && s.fold_gains[1] >= opt.min_gain;
      if (significant && s.cv_gain > best_gain) {
        best = c;
        best_gain = s.cv_gain;
        best_desc = with;
        best_cv = cv;
      }
    }
    out.rounds.push_back(scores);
    if (best < 0) break;
    const CandidateScore& w = scores[static_cast<std::size_t>(best)];
    log("adding " + w.name);
    ArmFitOptions full = refit;
    current_fit = fit_arm(best_desc, train, full);
    current = current_fit.fitted;
    base_cv = best_cv;
    used.push_back(w.name);
    char ev[256];
    std::snprintf(ev, sizeof ev,
                  "explains %.0f%% of the equation-error residual beyond K and D; held-out training error "
                  "%.0f%% and %.0f%% lower in the two folds",
                  100 * w.residual_explained, 100 * w.fold_gains[0], 100 * w.fold_gains[1]);
    out.added.push_back({current.effects.back(), ev, w.cv_gain});
  }
  out.final_fit = current_fit;
  out.final_train = current_fit.stats;
  out.final_test = test_stats(current);
  out.final_residual = detail::equation_error(current, tr);
  out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace softrne::fit
