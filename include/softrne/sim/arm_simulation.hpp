#pragma once
/// \file
/// \brief Simulating an arm from recorded pressures with CVODE (BDF), Jacobian by AutoDiff.
///
/// Tolerances. The state is x = [q, qdot, effect states]. CVODE's absolute tolerance
/// `cvode.atol` applies to the angles q (rad) and the effect states; the velocities get
/// `cvode.atol * velocity_atol_factor` (rad/s). The defaults (rtol 1e-6, atol 1e-4 rad,
/// velocities 1e-2 rad/s) keep the simulated angles within about 5e-4 rad of the converged
/// solution on the bundled arm (examples/data/arm-a-1/test.csv, 14 s), six times below the
/// angle sensors' noise (3e-3 rad) and far below the model error (0.1 rad), while not
/// resolving the 1e-5 rad, 3e-3 rad/s wiggles that the 300 Pa sensor noise of recorded
/// pressures drives at 50-100 Hz: at atol 1e-8 those cost 14 times the steps (34k instead of
/// 2.5k). Tighten them for verification (tools/softrne-sim --help).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "softrne/config.hpp"
#include "softrne/algorithms/rnea.hpp"
#include "softrne/arm/arm_dynamics.hpp"
#include "softrne/signals/input_signal.hpp"
#include "softrne/signals/jumps.hpp"
#include "softrne/signals/pchip.hpp"
#include "softrne/signals/smoothing.hpp"
#include "softrne/sim/cvode.hpp"

namespace softrne::sim {

// The signals the simulator reads its pressures through, under the names they had when they
// lived in sim/ (before signals/): user code that included only this header names them so.
using signals::InputSignal;
using signals::Interpolation;
using signals::PchipSignal;
using signals::pressure_jumps;
using signals::Side;
using signals::SignalCursor;
using signals::smooth_pressures;

/// \brief Settings of simulate_arm.
struct ArmSimulationOptions {
  /// Integrator settings. Defaults here: rtol 1e-6, atol 1e-4 (rad, for the angles; see the
  /// file comment), CvodeOptions' defaults otherwise.
  CvodeOptions cvode = default_cvode();
  /// How recorded pressures are read between samples (see PressureInterpolation).
  enum class PressureInterpolation { pchip, linear, zero_order_hold };
  PressureInterpolation interpolation = PressureInterpolation::pchip;  ///< PCHIP by default

  /// Jacobian of the state equation by forward-mode AutoDiff through the templated RNE
  /// (exact); false: CVODE's internal finite differences.
  bool autodiff_jacobian = true;
  /// How the AutoDiff Jacobian is formed (both exact; see ArmSystem::JacobianMethod).
  enum class JacobianMethod { inverse_dynamics, forward_dynamics };
  JacobianMethod jacobian_method = JacobianMethod::inverse_dynamics;  ///< the cheaper one

  /// Absolute tolerance of the velocities = cvode.atol * velocity_atol_factor (1/s): a
  /// velocity error dv moves the angles by about dv / omega for a mode of frequency omega.
  /// 1 gives every state the same atol.
  double velocity_atol_factor = 100.0;
  /// OPTIONAL input pre-smoothing, off (0) by default: the standard deviation (s) of a
  /// Gaussian kernel applied to the recorded pressures before they are interpolated
  /// (smooth_pressures). It changes the model's input (and so the result): it removes sensor
  /// noise that the integrator would otherwise resolve, at the price of rounding off pressure
  /// steps and delaying nothing (zero phase). With it on, no restarts are made at steps.
  double pressure_smoothing = 0.0;
  /// Called now and then (every 64 right-hand-side evaluations) with the integrator's time;
  /// for progress indicators. Empty: never.
  std::function<void(double t)> progress;

  /// \return CvodeOptions with rtol 1e-6 and atol 1e-4 (the defaults of `cvode`).
  static CvodeOptions default_cvode() {
    CvodeOptions c;
    c.rtol = 1e-6;
    c.atol = 1e-4;
    return c;
  }
};

/// \brief Result: measured-space angles (the measurement model applied to the simulated q:
/// gain .* q + offset) on the input grid.
struct ArmSimulation {
  Eigen::MatrixXd angles;  ///< N x nq (rows computed before a failure, if any)
  Eigen::MatrixXd states;  ///< N x num_states
  SimulationResult result;  ///< success, message and solver statistics

  /// \return True if the integration reached the end of the grid.
  bool ok() const { return result.ok; }
};

/// \brief The arm as an ODE system for CVODE: x' = f(t, x) with the interpolated recorded
/// pressures, and its exact Jacobian by AutoDiff (blocks of kBlock directions at a time).
class ArmSystem {
 public:
  /// Derivative directions per AutoDiff pass. 2 (one SSE register) measured fastest for the
  /// 12-state bundled arm: 0.43M instructions per Jacobian against 0.67M with 4, 0.73M with 12.
  static constexpr int kBlock = 2;
  using AD = Eigen::AutoDiffScalar<Eigen::Matrix<double, kBlock, 1>>;  ///< kBlock directions
  using ADVector = Eigen::Matrix<AD, Eigen::Dynamic, 1>;  ///< a state of AD scalars

  /// \brief How jacobian() differentiates the acceleration rows; both are exact (AutoDiff).
  /// - inverse_dynamics: \f$\partial\ddot q/\partial x = M^{-1}(\partial\tau/\partial x -
  ///   \partial\,\mathrm{ID}(q,\dot q,\ddot q^*)/\partial x)\f$ at the current acceleration
  ///   \f$\ddot q^*\f$, with ID the chain's RNE (M qddot + C qdot + G) and tau every other
  ///   force (pressures, springs, dampers, effects). AutoDiff runs through one kinematics pass
  ///   and one RNE pass per block; M's Cholesky factor comes from a double evaluation. 1.3 to
  ///   2 times cheaper than differentiating forward dynamics (the default).
  /// - forward_dynamics: AutoDiff through the whole right-hand side (kinematics, nq + 1 RNE
  ///   passes, Cholesky).
  using JacobianMethod = ArmSimulationOptions::JacobianMethod;

  /// \brief The system of `desc` driven by the recorded pressures.
  /// \param desc the arm; it must outlive the system
  /// \param t the N sample times
  /// \param pressures the recorded samples, N x num_inputs
  /// \param mode PCHIP (C1, no overshoot), linear, or zero-order hold between samples
  ArmSystem(const ArmDescription& desc, const Eigen::VectorXd& t, const Eigen::MatrixXd& pressures,
            ArmSimulationOptions::PressureInterpolation mode);

  /// \return The number of states (2 nq + the effects' states).
  int size() const { return desc_.num_states(); }
  /// \return The arm it simulates.
  const ArmDescription& description() const { return desc_; }

  /// \brief Progress callback (see ArmSimulationOptions::progress); must outlive the system.
  /// \param[in] f The callback, or nullptr (or an empty function) for none.
  void set_progress(const std::function<void(double)>* f) { progress_ = f && *f ? f : nullptr; }
  /// \brief Chooses how jacobian() differentiates.
  /// \param[in] m The method.
  void set_jacobian_method(JacobianMethod m) { method_ = m; }
  /// \return How jacobian() differentiates.
  JacobianMethod jacobian_method() const { return method_; }

  /// \brief Called by integrate() before each segment between breakpoints: a zero-order-hold
  /// input gives at the segment's end the value held before the jump there (see cvode.hpp).
  /// \param[in] t_end The segment's end time, s.
  void set_segment(std::size_t, double, double t_end) { segment_end_ = t_end; }

  /// Recorded pressures that act at time t: read at t - input_delay (input_delay effect),
  /// clamped to the first sample before it (the signals clamp outside their range).
  /// \param[in] t Time, s.
  /// \return The num_inputs pressures, Pa (valid until the next call).
  const Eigen::VectorXd& pressures(double t) {
    const double tr = t - delay_;
    if (mode_ == ArmSimulationOptions::PressureInterpolation::pchip)
      pchip_.value(tr, p_);
    else
      input_.value(tr, p_, cursor_, t >= segment_end_ ? Side::left : Side::right);
    return p_;
  }

  /// \return The transport delay the system applies to the recorded pressures, s.
  double input_delay() const { return delay_; }

  /// \brief x' = f(t, x) (eq. 23 with the effects).
  /// \param[in] t Time, s.
  /// \param[in] x The state (q, qdot, effect states).
  /// \param[out] xdot Its time derivative.
  /// \return False if xdot is not finite.
  bool rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Ref<Eigen::VectorXd> xdot);

  /// \brief The exact Jacobian df/dx by AutoDiff (JacobianMethod).
  /// \param[in] t Time, s.
  /// \param[in] x The state.
  /// \param[out] J df/dx, size() x size().
  /// \return False if J is not finite.
  bool jacobian(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
                const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::MatrixXd> J);

 private:
  // Seeds x_ad_ with the value x and unit derivatives for states [start, start + kBlock).
  void seed(const Eigen::Ref<const Eigen::VectorXd>& x, int start);
  bool jacobian_forward(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Ref<Eigen::MatrixXd> J);
  bool jacobian_inverse(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Ref<Eigen::MatrixXd> J);

  const ArmDescription& desc_;
  ArmDynamics<double> f_;
  ArmDynamics<AD> f_ad_;
  ArmSimulationOptions::PressureInterpolation mode_;
  InputSignal input_;
  PchipSignal pchip_;
  SignalCursor cursor_;
  Eigen::VectorXd p_;
  ADVector x_ad_, xd_ad_, q_ad_, v_ad_, a_ad_, p_ad_;
  Eigen::VectorXd xdot_;
  Eigen::Matrix<double, Eigen::Dynamic, kBlock> dr_;
  JacobianMethod method_ = JacobianMethod::inverse_dynamics;
  double delay_ = 0;
  double segment_end_ = std::numeric_limits<double>::infinity();
  const std::function<void(double)>* progress_ = nullptr;
  unsigned rhs_calls_ = 0;
};

#if SOFTRNE_SIM_BODIES
// ArmSystem's members that run the dynamics (double and AutoDiff): compiled once in src/sim.cpp
// for the targets that link softrne::sim_compiled, inline otherwise (config.hpp). Defined in
// the class, they were instantiated in every translation unit that included this header.
SOFTRNE_SIM_INLINE ArmSystem::ArmSystem(const ArmDescription& desc, const Eigen::VectorXd& t,
                                        const Eigen::MatrixXd& pressures,
                                        ArmSimulationOptions::PressureInterpolation mode)
    : desc_(desc),
      f_(desc),
      f_ad_(desc),
      mode_(mode),
      input_(t, pressures,
             mode == ArmSimulationOptions::PressureInterpolation::zero_order_hold
                 ? Interpolation::zero_order_hold
                 : Interpolation::linear),
      pchip_(t, pressures),
      delay_(desc.input_delay()) {
  const int nq = desc.nq, ns = desc.num_states();
  p_.resize(desc.num_inputs);
  x_ad_.resize(ns);
  xd_ad_.resize(ns);
  q_ad_.resize(nq);
  v_ad_.resize(nq);
  a_ad_.resize(nq);
  p_ad_.resize(desc.num_inputs);
  xdot_.resize(ns);
  dr_.resize(nq, kBlock);
}

SOFTRNE_SIM_INLINE bool ArmSystem::rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
                                        Eigen::Ref<Eigen::VectorXd> xdot) {
  if (progress_ && (++rhs_calls_ & 63u) == 0) (*progress_)(t);
  pressures(t);
  f_.rhs(x, p_, xdot);
  return xdot.allFinite();
}

SOFTRNE_SIM_INLINE bool ArmSystem::jacobian(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
                                             const Eigen::Ref<const Eigen::VectorXd>&,
                                             Eigen::Ref<Eigen::MatrixXd> J) {
  pressures(t);
  if (method_ == JacobianMethod::forward_dynamics) return jacobian_forward(x, J);
  return jacobian_inverse(x, J);
}

SOFTRNE_SIM_INLINE void ArmSystem::seed(const Eigen::Ref<const Eigen::VectorXd>& x, int start) {
  const int n = size();
  for (int i = 0; i < n; ++i) {
    x_ad_(i).value() = x(i);
    x_ad_(i).derivatives().setZero();
    if (i >= start && i < start + kBlock) x_ad_(i).derivatives()(i - start) = 1.0;
  }
}

SOFTRNE_SIM_INLINE bool ArmSystem::jacobian_forward(const Eigen::Ref<const Eigen::VectorXd>& x,
                                                     Eigen::Ref<Eigen::MatrixXd> J) {
  const int n = size();
  for (int start = 0; start < n; start += kBlock) {
    seed(x, start);
    f_ad_.rhs(x_ad_, p_, xd_ad_);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < kBlock && start + k < n; ++k)
        J(i, start + k) = xd_ad_(i).derivatives()(k);
  }
  return J.allFinite();
}

SOFTRNE_SIM_INLINE bool ArmSystem::jacobian_inverse(const Eigen::Ref<const Eigen::VectorXd>& x,
                                                     Eigen::Ref<Eigen::MatrixXd> J) {
  const ArmDescription& d = desc_;
  const int nq = d.nq, n = size(), nz = d.num_effect_states;
  // Double evaluation: the acceleration qddot* and M's Cholesky factor at x.
  f_.rhs(x, p_, xdot_);
  if (!xdot_.allFinite()) return false;
  const Eigen::MatrixXd& L = f_.data().mass_factor;  // Cholesky factor in the lower triangle
  const auto& qdd = f_.data().qddot;
  for (int i = 0; i < nq; ++i) {
    a_ad_(i).value() = qdd(i);
    a_ad_(i).derivatives().setZero();
  }
  // d qdot / d qdot = I; d qdot / d (q, z) = 0 (J arrives zeroed from CVODE; not from tests).
  J.topRows(nq).setZero();
  J.block(0, nq, nq, nq).setIdentity();
  for (int start = 0; start < n; start += kBlock) {
    const int cols = std::min(kBlock, n - start);
    seed(x, start);
    q_ad_ = x_ad_.head(nq);
    v_ad_ = x_ad_.segment(nq, nq);
    const auto xs = x_ad_.segment(2 * nq, nz);
    f_ad_.effective_pressures(xs, p_, p_ad_);
    const auto& tau = f_ad_.joint_forces(q_ad_, v_ad_, p_ad_, xs);
    const auto& id = rnea(f_ad_.chain(), f_ad_.data(), q_ad_, v_ad_, a_ad_);
    for (int i = 0; i < nq; ++i)
      for (int k = 0; k < kBlock; ++k)
        dr_(i, k) = tau(i).derivatives()(k) - id(i).derivatives()(k);
    L.triangularView<Eigen::Lower>().solveInPlace(dr_);
    L.transpose().triangularView<Eigen::Upper>().solveInPlace(dr_);
    J.block(nq, start, nq, cols) = dr_.leftCols(cols);
    // Effect states: differentiate their own derivative (it may depend on q and qdot).
    f_ad_.effect_state_derivative(xs, q_ad_, v_ad_, p_, xd_ad_.segment(2 * nq, nz));
    for (int i = 2 * nq; i < n; ++i)
      for (int k = 0; k < cols; ++k) J(i, start + k) = xd_ad_(i).derivatives()(k);
  }
  return J.allFinite();
}
#endif  // SOFTRNE_SIM_BODIES

namespace detail {

/// \brief A System in scaled variables y = x ./ s (s > 0): a scalar absolute tolerance on y
/// is a tolerance atol * s_i on x_i (CvodeOptions has one atol for all states).
template <class System>
class ScaledSystem {
 public:
  ScaledSystem(System& sys, Eigen::VectorXd scale)
      : sys_(sys), s_(std::move(scale)), x_(s_.size()), f_(s_.size()), J_(s_.size(), s_.size()) {}

  int size() const { return static_cast<int>(s_.size()); }
  void set_segment(std::size_t k, double t_begin, double t_end) {
    sys_.set_segment(k, t_begin, t_end);
  }

  bool rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) {
    x_ = s_.cwiseProduct(y);
    const bool ok = sys_.rhs(t, x_, f_);
    ydot = f_.cwiseQuotient(s_);
    return ok;
  }

  bool jacobian(double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                const Eigen::Ref<const Eigen::VectorXd>& fy, Eigen::Ref<Eigen::MatrixXd> Jy) {
    x_ = s_.cwiseProduct(y);
    f_ = s_.cwiseProduct(fy);
    J_.setZero();
    const bool ok = sys_.jacobian(t, x_, f_, J_);
    // dy_i'/dy_j = J_ij s_j / s_i
    Jy = s_.cwiseInverse().asDiagonal() * J_ * s_.asDiagonal();
    return ok;
  }

 private:
  System& sys_;
  Eigen::VectorXd s_, x_, f_;
  Eigen::MatrixXd J_;
};

}  // namespace detail

/// \brief Simulates the arm on the time grid t with the recorded pressures (N x num_inputs),
/// from rest at the measured configuration q0 (size nq; zero if empty).
///
/// The state equation is eq. 23 with the effects (ArmDynamics), integrated by CVODE's BDF
/// method with the exact AutoDiff Jacobian; the integration restarts at pressure steps
/// (pressure_jumps()).
/// \param[in] desc The arm (chain, springs, dampers, pressure maps, effects): build_arm().
/// \param[in] t The N output (and input sample) times, s.
/// \param[in] pressures N x num_inputs recorded pressures, Pa.
/// \param[in] q0 The measured angles at t(0) (size nq), or empty for zero.
/// \param[in] opt Integrator, interpolation and Jacobian settings.
/// \return The measured-space angles and states on the grid; result.ok false with a one-line
///   result.message if the integration failed (no exception for a computation that fails).
SOFTRNE_SIM_INLINE ArmSimulation simulate_arm(const ArmDescription& desc, const Eigen::VectorXd& t,
                                              const Eigen::MatrixXd& pressures, const Eigen::VectorXd& q0,
                                              const ArmSimulationOptions& opt = {})
#if SOFTRNE_SIM_BODIES
{
  using PI = ArmSimulationOptions::PressureInterpolation;
  ArmSimulation out;
  const bool smoothing = opt.pressure_smoothing > 0;
  const Eigen::MatrixXd smoothed =
      smoothing ? smooth_pressures(t, pressures, opt.pressure_smoothing) : Eigen::MatrixXd();
  const Eigen::MatrixXd& p = smoothing ? smoothed : pressures;

  ArmSystem sys(desc, t, p, opt.interpolation);
  sys.set_progress(&opt.progress);
  sys.set_jacobian_method(opt.jacobian_method);
  const Eigen::VectorXd x0 = initial_state(desc, q0, p.row(0).transpose());
  CvodeOptions copt = opt.cvode;
  copt.use_analytic_jacobian = opt.autodiff_jacobian;
  std::vector<double> bp;
  if (opt.interpolation == PI::zero_order_hold)
    bp = InputSignal(t, p, Interpolation::zero_order_hold).breakpoints();
  else if (!smoothing)
    bp = pressure_jumps(t, p);
  // A delayed input jumps later (integrate drops breakpoints past the end).
  for (double& b : bp) b += sys.input_delay();

  const double vf = opt.velocity_atol_factor;
  if (vf > 0 && vf != 1.0 && std::isfinite(vf)) {
    Eigen::VectorXd scale = Eigen::VectorXd::Ones(desc.num_states());
    scale.segment(desc.nq, desc.nq).setConstant(vf);
    detail::ScaledSystem<ArmSystem> scaled(sys, scale);
    out.result = integrate(scaled, x0.cwiseQuotient(scale), t, bp, copt);
    out.result.x = out.result.x * scale.asDiagonal();
  } else {
    out.result = integrate(sys, x0, t, bp, copt);
  }
  out.states = out.result.x;
  const Eigen::Index rows = out.states.rows();
  // What the sensors report: y = gain .* q + offset (sensor_gain, angle_offset).
  Eigen::VectorXd gain, offset;
  desc.measurement(gain, offset);
  out.angles = out.states.leftCols(desc.nq) * gain.asDiagonal();
  if (rows > 0) out.angles.rowwise() += offset.transpose();
  return out;
}
#else
;
#endif

}  // namespace softrne::sim
