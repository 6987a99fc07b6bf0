#pragma once
/// \file
/// \brief The closed loop's candidates and their screen: every effect the library knows, in
/// every scope it allows (shared by all joints it applies to, on one joint, per coordinate or
/// per chamber of one joint), each judged by a linearised HELD-OUT simulation error.
///
/// The screen works on simulated trajectories, not on an equation error: for a fold's base
/// model B (fitted on that fold's training blocks only) and a candidate at its neutral value
/// theta0 (where it changes nothing), the sensitivity S = d y_sim / d theta is formed by a
/// forward difference of two simulations of the whole record. One Gauss-Newton step on the
/// fold's training rows, together with nuisance sensitivities of every stiffness and damping
/// (so that a candidate only scores for what a changed K or D could not do),
///   [a; dtheta] = argmin || e_T - [S_KD  S]_T [a; dtheta] ||,   e = y_measured - y_sim(B),
/// predicts the held-out residual e_H - [S_KD S]_H [a; dtheta]. Its relative drop against the
/// K, D-only step is the candidate's predicted gain in that fold. The screen orders and seeds
/// (dtheta starts the fold's refit); it decides nothing: the refits' measured held-out errors
/// do (loop.hpp).
///
/// Kinds of an effect that do nothing at the neutral value of the others (a Maxwell branch's
/// relaxation time when its stiffness is zero, say) have no sensitivity there; they are
/// detected numerically (the simulation does not move) and screened at three values spread
/// over their bounds instead (log-spaced for log-scale kinds).

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/QR>

#include "softrne/config.hpp"
#include "softrne/fit/arm_fit.hpp"
#include "softrne/fit/parallel_for.hpp"

namespace softrne::fit {

/// \brief One candidate: an effect with its scope and joints at its neutral value (secondary
/// kinds at one of their screening values).
struct Candidate {
  AnyEffect effect;  ///< the effect, its scope, joints and screening values
  std::vector<int> screened;  ///< indices into the effect's params moved by the screen
  std::string label;          ///< e.g. "stiffening (joint joint2)"
};

/// \brief The screen of one candidate in one fold.
struct FoldScreen {
  /// Relative drop of the held-out residual the linearised step predicts (file comment).
  double predicted_gain = -std::numeric_limits<double>::infinity();
  Eigen::VectorXd start;  ///< the effect's params after the Gauss-Newton step (clamped)
};

/// \brief "name (scope joints)" as the loop prints and reports a candidate.
/// \param[in] e The candidate's effect.
/// \param[in] d The arm (joint names).
/// \return The label.
inline std::string candidate_label(const AnyEffect& e, const ArmDescription& d) {
  const EffectBase& b = effect_base(e);
  std::string s = effect_name(e) + " (" + scope_name(b.scope);
  if (b.scope != Scope::Shared || b.joints.size() < d.joints.size())
    for (int j : b.joints) s += " " + d.joints[static_cast<std::size_t>(j)].name;
  return s + ")";
}

namespace detail {

/// Whether `current` already holds effect `name` on any of `joints`.
inline bool already_covered(const ArmDescription& current, const std::string& name,
                            const std::vector<int>& joints) {
  for (const AnyEffect& e : current.effects) {
    if (effect_name(e) != name) continue;
    for (int j : effect_base(e).joints)
      if (std::find(joints.begin(), joints.end(), j) != joints.end()) return true;
    if (effect_base(e).joints.empty()) return true;
  }
  return false;
}

/// The description with `e` appended (state offsets updated).
inline ArmDescription with_effect(const ArmDescription& d, const AnyEffect& e) {
  ArmDescription w = d;
  add_effect(w, e);
  return w;
}

/// Simulated angles (N x nq) of `d` on `data`; empty on failure.
SOFTRNE_FIT_INLINE Eigen::MatrixXd simulated_angles(const ArmDescription& d, const io::Dataset& data,
                                                    const sim::ArmSimulationOptions& opt)
#if SOFTRNE_FIT_BODIES
{
  const sim::ArmSimulation s = simulate_dataset(d, data, opt);
  if (!s.ok() || s.angles.rows() != data.t.size() || !s.angles.allFinite()) return {};
  return s.angles;
}
#else
;
#endif

/// Screening step of a parameter from its neutral value: toward the interior of its bounds,
/// 2 % of the range (linear kinds) or a factor (upper/lower)^0.1 (log-scale kinds).
inline double screening_step(const EffectBounds& b) {
  double h = b.log_scale ? b.neutral * (std::pow(b.upper / b.lower, 0.1) - 1.0)
                         : 0.02 * (b.upper - b.lower);
  if (b.neutral + h > b.upper) h = -h;
  return h;
}

}  // namespace detail

/// \brief Every effect in every allowed scope on `current`'s joints, at its neutral value,
/// leaving out what `current` already holds. On an arm with CC and revolute joints, the
/// shared scope is also tried over the joints of each kind (two or more of it). Secondary kinds are not yet resolved (see
/// expand_secondary_kinds).
/// \param[in] current The model so far.
/// \return The candidate effects.
SOFTRNE_FIT_INLINE std::vector<AnyEffect> enumerate_candidates(const ArmDescription& current)
#if SOFTRNE_FIT_BODIES
{
  std::vector<AnyEffect> out;
  for (const std::string& name : effect_names()) {
    AnyEffect probe;
    make_effect(name, probe);
    std::vector<int> applicable;
    for (std::size_t j = 0; j < current.joints.size(); ++j)
      if (effect_applies_to(probe, current.joints[j])) applicable.push_back(static_cast<int>(j));
    if (applicable.empty()) continue;
    const std::vector<Scope> scopes = effect_scopes(probe);
    auto allowed = [&](Scope s) { return std::find(scopes.begin(), scopes.end(), s) != scopes.end(); };
    auto add = [&](Scope s, const std::vector<int>& joints) {
      if (detail::already_covered(current, name, joints)) return;
      out.push_back(make_effect_at_neutral(name, current, s, joints));
    };
    if (allowed(Scope::Shared)) {
      add(Scope::Shared, applicable);
      // Shared by the joints of one kind as well, where an arm has both kinds: a soft
      // segment's friction, drag or sensor and a revolute joint's bearing or encoder are
      // different mechanisms, and one value over all of them puts the soft segments' value on
      // the revolute joint. Random arm 1007 (C-L-Rz-C, the same Coulomb friction on both
      // CC joints): the shared scope, refitted from joint2's, gave the passive revolute joint
      // a dead band of half a radian and lost (+16 % held-out in one fold), so the friction was
      // reported on joint2 alone.
      std::vector<int> cc, revolute;
      for (int j : applicable) (current.joints[static_cast<std::size_t>(j)].is_cc() ? cc : revolute).push_back(j);
      if (!cc.empty() && !revolute.empty()) {
        if (cc.size() > 1) add(Scope::Shared, cc);
        if (revolute.size() > 1) add(Scope::Shared, revolute);
      }
    }
    for (int j : applicable) {
      const ArmJoint& jt = current.joints[static_cast<std::size_t>(j)];
      // On an arm with one such joint, "that joint" is the shared candidate already.
      const bool single = applicable.size() == 1 && allowed(Scope::Shared);
      if (allowed(Scope::PerJoint) && !single) add(Scope::PerJoint, {j});
      // Per coordinate only where a joint has more than one (else it is the per-joint one).
      if (allowed(Scope::PerCoordinate) && (jt.nq > 1 || (!allowed(Scope::PerJoint) && !single)))
        add(Scope::PerCoordinate, {j});
      if (allowed(Scope::PerChamber) && jt.num_inputs > 1) add(Scope::PerChamber, {j});
    }
  }
  return out;
}
#else
;
#endif

/// \brief Resolves secondary kinds: a kind whose parameters do not move the simulation of
/// `base` + effect (all at neutral) is screened at three fixed values; the others are screened
/// by sensitivity. Returns one Candidate per variant. Costs one simulation per kind of a
/// multi-kind effect.
/// \param[in] effects The candidates of enumerate_candidates().
/// \param[in] base The model they would be added to.
/// \param[in] base_angles Its simulated angles on data.
/// \param[in] data The data set.
/// \param[in] sim_opt The integrator settings.
/// \param[in] threads The most threads to use.
/// \param[in,out] simulations If not null, incremented by the simulations run.
/// \return One Candidate per variant.
SOFTRNE_FIT_INLINE std::vector<Candidate> expand_secondary_kinds(const std::vector<AnyEffect>& effects,
                                                                 const ArmDescription& base,
                                                                 const Eigen::MatrixXd& base_angles,
                                                                 const io::Dataset& data,
                                                                 const sim::ArmSimulationOptions& sim_opt,
                                                                 int threads, int* simulations = nullptr)
#if SOFTRNE_FIT_BODIES
{
  const double mass = base.segment_mass();
  // Which (effect, kind) pairs need a probe simulation.
  struct Probe {
    std::size_t effect;
    int kind;
    bool moves = true;
  };
  std::vector<Probe> probes;
  for (std::size_t i = 0; i < effects.size(); ++i)
    if (effect_num_kinds(effects[i]) > 1)
      for (int k = 0; k < effect_num_kinds(effects[i]); ++k) probes.push_back({i, k});
  if (simulations) *simulations += static_cast<int>(probes.size());
  parallel_for(static_cast<int>(probes.size()), threads, [&](int p) {
    Probe& pr = probes[static_cast<std::size_t>(p)];
    AnyEffect e = effects[pr.effect];
    EffectBase& b = effect_base(e);
    const int nk = effect_num_kinds(e);
    for (Eigen::Index i = pr.kind; i < b.params.size(); i += nk) {
      const EffectBounds bd = effect_param_bounds(e, static_cast<int>(i), mass);
      b.params(i) += 5 * detail::screening_step(bd);
    }
    const Eigen::MatrixXd y = detail::simulated_angles(detail::with_effect(base, e), data, sim_opt);
    // "Does not move" up to the integrator's own noise: the effect's extra states change
    // CVODE's step sequence, and so the result by about its tolerance, even when inert.
    const double noise = 10 * std::max(sim_opt.cvode.atol, 1e-10);
    pr.moves = y.size() == 0 || y.rows() != base_angles.rows() ||
               (y - base_angles).cwiseAbs().maxCoeff() > noise;
  });
  std::vector<Candidate> out;
  for (std::size_t i = 0; i < effects.size(); ++i) {
    const AnyEffect& e0 = effects[i];
    const int nk = effect_num_kinds(e0);
    std::vector<int> secondary;
    for (const Probe& pr : probes)
      if (pr.effect == i && !pr.moves) secondary.push_back(pr.kind);
    if (static_cast<int>(secondary.size()) == nk) secondary.clear();  // nothing moves: screen all
    // Variants: every combination of three values per secondary kind.
    int variants = 1;
    for (std::size_t s = 0; s < secondary.size(); ++s) variants *= 3;
    for (int v = 0; v < variants; ++v) {
      Candidate c;
      c.effect = e0;
      EffectBase& b = effect_base(c.effect);
      int code = v;
      std::string fixed;
      for (int kind : secondary) {
        const int level = code % 3;
        code /= 3;
        const double frac = 0.25 * (level + 1);  // 1/4, 1/2, 3/4 of the way through the bounds
        for (Eigen::Index pi = kind; pi < b.params.size(); pi += nk) {
          const EffectBounds bd = effect_param_bounds(c.effect, static_cast<int>(pi), mass);
          b.params(pi) = bd.log_scale ? bd.lower * std::pow(bd.upper / bd.lower, frac)
                                      : bd.lower + frac * (bd.upper - bd.lower);
        }
        char buf[64];
        std::snprintf(buf, sizeof buf, "%s%s = %.3g", fixed.empty() ? "" : ", ",
                      effect_param_names(c.effect, base.joints, base.coordinate_names,
                                         base.pressure_names)[static_cast<std::size_t>(kind)]
                          .c_str(),
                      b.params(kind));
        fixed += buf;
      }
      for (Eigen::Index pi = 0; pi < b.params.size(); ++pi)
        if (std::find(secondary.begin(), secondary.end(), static_cast<int>(pi % nk)) == secondary.end())
          c.screened.push_back(static_cast<int>(pi));
      c.label = candidate_label(c.effect, base) + (fixed.empty() ? "" : " at " + fixed);
      out.push_back(std::move(c));
    }
  }
  return out;
}
#else
;
#endif

/// \brief Sensitivities of the simulated angles (flattened row-major, N*nq) to every
/// stiffness and damping of `base` (relative step 1e-3): the nuisance columns of the screen.
/// \param[in] base The model.
/// \param[in] y0 Its simulated angles on data (N x nq).
/// \param[in] data The data set.
/// \param[in] sim_opt The integrator settings.
/// \param[in] threads The most threads to use.
/// \param[in,out] simulations If not null, incremented by the simulations run.
/// \return N nq x (number of stiffnesses and dampings).
SOFTRNE_FIT_INLINE Eigen::MatrixXd nuisance_sensitivities(const ArmDescription& base, const Eigen::MatrixXd& y0,
                                                          const io::Dataset& data,
                                                          const sim::ArmSimulationOptions& sim_opt, int threads,
                                                          int* simulations = nullptr)
#if SOFTRNE_FIT_BODIES
{
  struct Col {
    int joint, k;
    bool damping;
  };
  std::vector<Col> cols;
  for (std::size_t j = 0; j < base.joints.size(); ++j)
    for (int k = 0; k < base.joints[j].nq; ++k) {
      cols.push_back({static_cast<int>(j), k, false});
      cols.push_back({static_cast<int>(j), k, true});
    }
  const Eigen::Index m = y0.size();
  if (simulations) *simulations += static_cast<int>(cols.size());
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(m, static_cast<Eigen::Index>(cols.size()));
  parallel_for(static_cast<int>(cols.size()), threads, [&](int c) {
    ArmDescription d = base;
    ArmJoint& jt = d.joints[static_cast<std::size_t>(cols[static_cast<std::size_t>(c)].joint)];
    const int k = cols[static_cast<std::size_t>(c)].k;
    double& v = cols[static_cast<std::size_t>(c)].damping ? jt.damping(k) : jt.stiffness(k);
    const double h = 1e-3 * std::max(std::abs(v), 1e-6);
    v += h;
    const Eigen::MatrixXd y = detail::simulated_angles(d, data, sim_opt);
    if (y.size() != m) return;  // a failed simulation leaves a zero column (not used)
    const Eigen::MatrixXd dy = (y - y0) / h;
    for (Eigen::Index i = 0; i < y0.rows(); ++i)
      S.col(c).segment(i * y0.cols(), y0.cols()) = dy.row(i).transpose();
  });
  return S;
}
#else
;
#endif

/// \brief Screens every candidate in one fold (see the file comment). `base` is the fold's
/// model, `y0` its simulated angles, `fit_rows` / `held_rows` the fold's sample masks.
/// \param[in] cands The candidates.
/// \param[in] base The fold's model.
/// \param[in] y0 Its simulated angles on data (N x nq).
/// \param[in] data The data set.
/// \param[in] fit_rows The samples the fold fits on.
/// \param[in] held_rows The samples it holds out.
/// \param[in] sim_opt The integrator settings.
/// \param[in] threads The most threads to use.
/// \param[in,out] simulations If not null, incremented by the simulations run.
/// \return One screen per candidate, in order.
SOFTRNE_FIT_INLINE std::vector<FoldScreen> screen_fold(const std::vector<Candidate>& cands,
                                                       const ArmDescription& base, const Eigen::MatrixXd& y0,
                                                       const io::Dataset& data, const std::vector<bool>& fit_rows,
                                                       const std::vector<bool>& held_rows,
                                                       const sim::ArmSimulationOptions& sim_opt, int threads,
                                                       int* simulations = nullptr)
#if SOFTRNE_FIT_BODIES
{
  const Eigen::Index N = y0.rows(), nq = y0.cols();
  const double mass = base.segment_mass();
  const Eigen::MatrixXd SKD = nuisance_sensitivities(base, y0, data, sim_opt, threads, simulations);
  // One task per (candidate, screened parameter).
  std::vector<std::pair<std::size_t, int>> tasks;
  for (std::size_t c = 0; c < cands.size(); ++c)
    for (int p : cands[c].screened) tasks.push_back({c, p});
  if (simulations) *simulations += static_cast<int>(tasks.size());
  std::vector<Eigen::VectorXd> sens(tasks.size());
  std::vector<double> steps(tasks.size(), 0.0);
  parallel_for(static_cast<int>(tasks.size()), threads, [&](int t) {
    const auto [c, p] = tasks[static_cast<std::size_t>(t)];
    AnyEffect e = cands[c].effect;
    const EffectBounds bd = effect_param_bounds(e, p, mass);
    const double h = detail::screening_step(bd);
    effect_base(e).params(p) += h;
    const Eigen::MatrixXd y = detail::simulated_angles(detail::with_effect(base, e), data, sim_opt);
    if (y.rows() != N) return;
    Eigen::VectorXd s(N * nq);
    for (Eigen::Index i = 0; i < N; ++i) s.segment(i * nq, nq) = ((y.row(i) - y0.row(i)) / h).transpose();
    sens[static_cast<std::size_t>(t)] = s;
    steps[static_cast<std::size_t>(t)] = h;
  });
  // Rows of the two masks, flattened.
  std::vector<Eigen::Index> T, H;
  for (Eigen::Index i = 0; i < N; ++i)
    for (Eigen::Index k = 0; k < nq; ++k) {
      if (fit_rows[static_cast<std::size_t>(i)]) T.push_back(i * nq + k);
      if (held_rows[static_cast<std::size_t>(i)]) H.push_back(i * nq + k);
    }
  Eigen::VectorXd e(N * nq);
  for (Eigen::Index i = 0; i < N; ++i)
    e.segment(i * nq, nq) = (data.angles.row(i) - y0.row(i)).transpose();
  auto rows_of = [](const Eigen::MatrixXd& X, const std::vector<Eigen::Index>& r) {
    Eigen::MatrixXd out(static_cast<Eigen::Index>(r.size()), X.cols());
    for (std::size_t i = 0; i < r.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = X.row(r[i]);
    return out;
  };
  auto rms = [](const Eigen::VectorXd& v) { return std::sqrt(v.squaredNorm() / std::max<Eigen::Index>(1, v.size())); };
  const Eigen::VectorXd eT = rows_of(e, T), eH = rows_of(e, H);
  const Eigen::MatrixXd KT = rows_of(SKD, T), KH = rows_of(SKD, H);
  // K, D-only step: the reference the candidate must beat.
  const Eigen::VectorXd a0 = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(KT).solve(eT);
  const double ref = rms(eH - KH * a0);
  std::vector<FoldScreen> out(cands.size());
  std::size_t t = 0;
  for (std::size_t c = 0; c < cands.size(); ++c) {
    const Candidate& cand = cands[c];
    const Eigen::Index np = static_cast<Eigen::Index>(cand.screened.size());
    Eigen::MatrixXd S(N * nq, np);
    bool ok = true;
    for (Eigen::Index j = 0; j < np; ++j, ++t) {
      if (sens[t].size() != N * nq || !sens[t].allFinite()) ok = false;
      else S.col(j) = sens[t];
    }
    if (!ok || np == 0 || !(ref > 0)) continue;
    const Eigen::MatrixXd ST = rows_of(S, T), SH = rows_of(S, H);
    Eigen::MatrixXd XT(static_cast<Eigen::Index>(T.size()), KT.cols() + np);
    XT << KT, ST;
    const Eigen::VectorXd coef = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(XT).solve(eT);
    // Clamp the step to the effect's bounds, then re-solve K, D for the clamped effect.
    FoldScreen fs;
    fs.start = effect_base(cand.effect).params;
    Eigen::VectorXd dth(np);
    for (Eigen::Index j = 0; j < np; ++j) {
      const int p = cand.screened[static_cast<std::size_t>(j)];
      const EffectBounds bd = effect_param_bounds(cand.effect, p, mass);
      const double v = std::clamp(fs.start(p) + coef(KT.cols() + j), bd.lower, bd.upper);
      dth(j) = v - fs.start(p);
      fs.start(p) = v;
    }
    const Eigen::VectorXd a = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(KT).solve(eT - ST * dth);
    fs.predicted_gain = 1.0 - rms(eH - KH * a - SH * dth) / ref;
    out[c] = fs;
  }
  return out;
}
#else
;
#endif

}  // namespace softrne::fit
