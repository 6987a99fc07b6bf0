#pragma once
/// \file
/// \brief Simulating an arm from recorded pressures with CVODE (BDF), Jacobian by AutoDiff.
///
/// Tolerances. The state is x = [q, qdot, effect states]. CVODE's absolute tolerance
/// `cvode.atol` applies to the angles q (rad) and the effect states; the velocities get
/// `cvode.atol * velocity_atol_factor` (rad/s). The defaults (rtol 1e-6, atol 1e-5 rad,
/// velocities 1e-2 rad/s) keep the simulated angles within 0.25 mrad of the converged solution
/// (rtol 1e-10) on the bundled arm (examples/data/arm-a-1/test.csv, 14 s: 0.12 mrad) and on the
/// test runs of eight random arms (softrne-make-case --seed 1001..1008 --none, simulated with
/// their truth: at most 0.23 mrad), ten times below the angle sensors' noise (3e-3 rad). The
/// velocities' tolerance is the looser one on purpose: the 300 Pa sensor noise of recorded
/// pressures drives 1e-5 rad, 3e-3 rad/s wiggles at 50-100 Hz, and resolving them in the rates
/// sets the step size (bundled run at atol 2e-5: 4748 steps with 2e-3 rad/s on the rates,
/// 2725 with 1e-2 rad/s; docs/performance.md has the grid). Tighten both for verification
/// (tools/softrne-sim --help).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/arm/arm_dynamics.hpp"
#include "softrne/signals/input_signal.hpp"
#include "softrne/signals/jumps.hpp"
#include "softrne/signals/pchip.hpp"
#include "softrne/signals/smoothing.hpp"
#include "softrne/sim/arm_jacobian.hpp"
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
  /// Integrator settings. Defaults here: rtol 1e-6, atol 1e-5 (rad, for the angles; see the
  /// file comment), CvodeOptions' defaults otherwise.
  CvodeOptions cvode = default_cvode();
  /// How recorded pressures are read between samples (see PressureInterpolation).
  using PressureInterpolation = signals::Interpolation;  ///< pchip, linear, zero_order_hold
  PressureInterpolation interpolation = PressureInterpolation::pchip;  ///< PCHIP by default

  /// Jacobian of the state equation by forward-mode AutoDiff through the templated RNE
  /// (exact); false: CVODE's internal finite differences.
  bool autodiff_jacobian = true;
  /// How the AutoDiff Jacobian is formed (both exact; see sim::JacobianMethod).
  using JacobianMethod = sim::JacobianMethod;
  JacobianMethod jacobian_method = JacobianMethod::inverse_dynamics;  ///< the cheaper one

  /// Absolute tolerance of the velocities = cvode.atol * velocity_atol_factor (1/s): a
  /// velocity error dv moves the angles by about dv / omega for a mode of frequency omega.
  /// 1 gives every state the same atol.
  double velocity_atol_factor = 1000.0;
  /// OPTIONAL input pre-smoothing, off (0) by default: the standard deviation (s) of a
  /// Gaussian kernel applied to the recorded pressures before they are interpolated
  /// (smooth_pressures). It changes the model's input (and so the result): it removes sensor
  /// noise that the integrator would otherwise resolve, at the price of rounding off pressure
  /// steps and delaying nothing (zero phase). With it on, no restarts are made at steps.
  double pressure_smoothing = 0.0;
  /// Called now and then (every 64 right-hand-side evaluations) with the integrator's time;
  /// for progress indicators. Empty: never.
  std::function<void(double t)> progress;

  /// \return CvodeOptions with rtol 1e-6 and atol 1e-5 (the defaults of `cvode`).
  static CvodeOptions default_cvode() {
    CvodeOptions c;
    c.rtol = 1e-6;
    c.atol = 1e-5;
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
/// pressures, and its exact Jacobian by AutoDiff (ArmJacobian).
class ArmSystem {
 public:
  /// \brief How jacobian() differentiates the acceleration rows; both are exact (AutoDiff).
  /// See sim::JacobianMethod.
  using JacobianMethod = sim::JacobianMethod;

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
  void set_jacobian_method(JacobianMethod m) { f_.set_method(m); }
  /// \return How jacobian() differentiates.
  JacobianMethod jacobian_method() const { return f_.method(); }

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
  bool rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Ref<Eigen::VectorXd> xdot) {
    if (progress_ && (++rhs_calls_ & 63u) == 0) (*progress_)(t);
    return f_.rhs(x, pressures(t), xdot);
  }

  /// \brief The exact Jacobian df/dx by AutoDiff (JacobianMethod).
  /// \param[in] t Time, s.
  /// \param[in] x The state.
  /// \param[out] J df/dx, size() x size().
  /// \return False if J is not finite.
  bool jacobian(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
                const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::MatrixXd> J) {
    return f_.state_jacobian(x, pressures(t), J);
  }

 private:
  const ArmDescription& desc_;
  ArmJacobian f_;
  InputSignal input_;
  SignalCursor cursor_;
  Eigen::VectorXd p_;
  double delay_ = 0;
  double segment_end_ = std::numeric_limits<double>::infinity();
  const std::function<void(double)>* progress_ = nullptr;
  unsigned rhs_calls_ = 0;
};

#if SOFTRNE_SIM_BODIES
SOFTRNE_SIM_INLINE ArmSystem::ArmSystem(const ArmDescription& desc, const Eigen::VectorXd& t,
                                        const Eigen::MatrixXd& pressures,
                                        ArmSimulationOptions::PressureInterpolation mode)
    : desc_(desc),
      f_(desc),
      input_(t, pressures, mode),
      delay_(desc.input_delay()) {
  p_.resize(desc.num_inputs);
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
  // The state form, if the system has it (integrate() prefers it): the unscaled state.
  template <class Y, class Sys = System,
            std::enable_if_t<has_set_segment_state<Sys>::value, int> = 0>
  void set_segment(std::size_t k, double t_begin, double t_end, const Y& y) {
    x_ = s_.cwiseProduct(y);
    sys_.set_segment(k, t_begin, t_end, ConstVectorMap(x_.data(), x_.size()));
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

/// \brief integrate() of an arm's system (ArmSystem or another with the arm's state layout)
/// with the velocities' absolute tolerance scaled by `velocity_atol_factor` (see
/// ArmSimulationOptions); the result's states are unscaled.
template <class System>
SimulationResult integrate_arm(System& sys, const Eigen::VectorXd& x0, const Eigen::VectorXd& t,
                               const std::vector<double>& breakpoints, const CvodeOptions& copt,
                               double velocity_atol_factor) {
  const ArmDescription& desc = sys.description();
  const double vf = velocity_atol_factor;
  if (!(vf > 0 && vf != 1.0 && std::isfinite(vf))) return integrate(sys, x0, t, breakpoints, copt);
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(desc.num_states());
  scale.segment(desc.nq, desc.nq).setConstant(vf);
  ScaledSystem<System> scaled(sys, scale);
  SimulationResult r = integrate(scaled, x0.cwiseQuotient(scale), t, breakpoints, copt);
  r.x = r.x * scale.asDiagonal();
  return r;
}

/// \brief What the sensors report for each row of simulated states: y = gain .* q + offset
/// (sensor_gain, angle_offset).
inline Eigen::MatrixXd measured_angles(const ArmDescription& desc, const Eigen::MatrixXd& states) {
  Eigen::VectorXd gain, offset;
  desc.measurement(gain, offset);
  Eigen::MatrixXd y = states.leftCols(desc.nq) * gain.asDiagonal();
  if (y.rows() > 0) y.rowwise() += offset.transpose();
  return y;
}

}  // namespace detail

/// \brief Simulates the arm on the time grid t with the recorded pressures (N x num_inputs),
/// from the measured configuration q0 (size nq; zero if empty) at the measured angle rates
/// qdot0 (size nq; at rest if empty: the overload without it).
///
/// The state equation is eq. 23 with the effects (ArmDynamics), integrated by CVODE's BDF
/// method with the exact AutoDiff Jacobian; the integration restarts at pressure steps
/// (pressure_jumps()).
/// \param[in] desc The arm (chain, springs, dampers, pressure maps, effects): build_arm().
/// \param[in] t The N output (and input sample) times, s.
/// \param[in] pressures N x num_inputs recorded pressures, Pa.
/// \param[in] q0 The measured angles at t(0) (size nq), or empty for zero.
/// \param[in] qdot0 The measured angle rates at t(0) (size nq, rad/s), or empty for rest.
/// \param[in] opt Integrator, interpolation and Jacobian settings.
/// \return The measured-space angles and states on the grid; result.ok false with a one-line
///   result.message if the integration failed (no exception for a computation that fails).
SOFTRNE_SIM_INLINE ArmSimulation simulate_arm(const ArmDescription& desc, const Eigen::VectorXd& t,
                                              const Eigen::MatrixXd& pressures, const Eigen::VectorXd& q0,
                                              const Eigen::VectorXd& qdot0, const ArmSimulationOptions& opt)
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
  const Eigen::VectorXd x0 = initial_state(desc, q0, p.row(0).transpose(), qdot0);
  CvodeOptions copt = opt.cvode;
  copt.use_analytic_jacobian = opt.autodiff_jacobian;
  std::vector<double> bp;
  if (opt.interpolation == PI::zero_order_hold)
    bp = InputSignal(t, p, Interpolation::zero_order_hold).breakpoints();
  else if (!smoothing)
    bp = pressure_jumps(t, p);
  // A delayed input jumps later (integrate drops breakpoints past the end).
  for (double& b : bp) b += sys.input_delay();

  out.result = detail::integrate_arm(sys, x0, t, bp, copt, opt.velocity_atol_factor);
  out.states = out.result.x;
  out.angles = detail::measured_angles(desc, out.states);
  return out;
}
#else
;
#endif

/// \brief simulate_arm() from rest at the measured configuration q0 (size nq; zero if empty).
/// \param[in] desc The arm.
/// \param[in] t The N output (and input sample) times, s.
/// \param[in] pressures N x num_inputs recorded pressures, Pa.
/// \param[in] q0 The measured angles at t(0) (size nq), or empty for zero.
/// \param[in] opt Integrator, interpolation and Jacobian settings.
/// \return As the overload with initial rates.
inline ArmSimulation simulate_arm(const ArmDescription& desc, const Eigen::VectorXd& t,
                                  const Eigen::MatrixXd& pressures, const Eigen::VectorXd& q0,
                                  const ArmSimulationOptions& opt = {}) {
  return simulate_arm(desc, t, pressures, q0, Eigen::VectorXd(), opt);
}

}  // namespace softrne::sim
