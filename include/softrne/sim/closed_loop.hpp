#pragma once
/// \file
/// \brief Control in the loop: simulate an arm (eq. 23 with its effects, CVODE as in
/// simulate_arm) under a controller sampled at a fixed period, its chamber pressures held
/// between samples (zero-order hold), optionally delayed by whole periods and clamped to the
/// chambers' range.
///
/// The integrator stops and restarts exactly at every sample (a breakpoint of integrate(),
/// whose set_segment hook hands the state there to the controller), so no step straddles a
/// change of the pressures. The applied pressures that a run returns reproduce it open loop:
/// simulate_arm on the same grid with zero-order-hold interpolation integrates the same
/// piecewise-constant input.

#include <cmath>
#include <cstddef>
#include <exception>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/arm/arm_dynamics.hpp"
#include "softrne/sim/arm_jacobian.hpp"
#include "softrne/sim/arm_simulation.hpp"
#include "softrne/sim/cvode.hpp"

namespace softrne::sim {

/// \brief What the controller sees at sample k.
struct ControllerInput {
  int k = 0;                   ///< sample index, t = k * control_period
  double t = 0;                ///< time, s
  Eigen::VectorXd angles;      ///< measured angles, gain .* q + offset (the measurement model), rad
  Eigen::VectorXd velocities;  ///< their rates, gain .* qdot, rad/s
  /// The simulator's whole state [q, qdot, effect states], for designs that assume full-state
  /// knowledge (an arm's sensors give the angles only).
  Eigen::VectorXd state;
};

/// \brief A controller: the chamber pressures (num_inputs, Pa) for what it sees at a sample.
/// It may throw; the run then fails with its message.
using Controller = std::function<Eigen::VectorXd(const ControllerInput&)>;

/// \brief Settings of simulate_closed_loop.
struct ClosedLoopOptions {
  /// Integrator and Jacobian settings and the velocities' tolerance factor, as for
  /// simulate_arm (its interpolation, pressure_smoothing and progress are not used: the
  /// pressures are held between samples).
  ArmSimulationOptions simulation;
  /// Whole control periods between a sample and the moment its pressures act (computation
  /// and communication delay); >= 0.
  int delay_periods = 0;
  /// Lowest chamber pressure, Pa. Default 0: gauge pressure of a vented chamber (the robot
  /// files give no limits; a chamber cannot be pulled below atmosphere without a vacuum
  /// source).
  double p_min = 0.0;
  /// Highest chamber pressure, Pa. Default: none (infinity); set the valves' range, e.g.
  /// 150e3 for the bundled arm's data.
  double p_max = std::numeric_limits<double>::infinity();
  /// Pressures that act before the first (delayed) command and that the arm rested under
  /// before t = 0 (they set the initial effect states, e.g. actuator_lag's); clamped like the
  /// commands. Empty: 0 (vented), num_inputs values otherwise.
  Eigen::VectorXd initial_pressures;
};

/// \brief A closed-loop run on the sample grid t_k = k * control_period, k = 0..N.
struct ClosedLoopSimulation {
  Eigen::VectorXd t;          ///< the N + 1 sample times, s
  Eigen::MatrixXd states;     ///< (N + 1) x num_states, the state at each sample
  Eigen::MatrixXd angles;     ///< (N + 1) x nq, the measured angles the controller saw
  Eigen::MatrixXd commands;   ///< (N + 1) x num_inputs, the controller's clamped outputs, Pa
  /// (N + 1) x num_inputs: the pressures held over [t_k, t_k+1): the commands delayed by
  /// delay_periods (initial_pressures before), Pa. Row N acts after the run.
  Eigen::MatrixXd pressures;
  SimulationResult result;  ///< success, the one-line message and solver statistics

  /// \return True if the run reached the last sample.
  bool ok() const { return result.ok; }
};

namespace detail {

/// A controller's bad output or exception: reported as the run's failure message.
struct ControllerError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The arm under a sampled controller as a System for integrate(): the controller runs in
/// set_segment at the samples, the held pressures drive ArmJacobian's f (and its Jacobian).
class ClosedLoopSystem {
 public:
  ClosedLoopSystem(const ArmDescription& desc, const Controller& controller, double h, int N,
                   const ClosedLoopOptions& opt, const Eigen::VectorXd& p_initial)
      : desc_(desc),
        f_(desc),
        controller_(controller),
        opt_(opt),
        h_(h),
        N_(N),
        delay_(desc.input_delay()),
        p_initial_(p_initial),
        states(N + 1, desc.num_states()),
        commands(N + 1, desc.num_inputs),
        pressures(N + 1, desc.num_inputs),
        p_held_(p_initial) {
    f_.set_method(opt.simulation.jacobian_method);
    desc.measurement(gain_, offset_);
  }

  int size() const { return desc_.num_states(); }
  const ArmDescription& description() const { return desc_; }
  double input_delay() const { return delay_; }
  /// The samples taken so far.
  int samples() const { return next_k_; }

  // At the start of each segment: the samples due there, then the pressures that act over
  // the segment (constant: every change is a breakpoint).
  template <class X>
  void set_segment(std::size_t, double t_begin, double t_end, const X& x) {
    const double fuzz = 1e-9 * h_;
    while (next_k_ <= N_ && next_k_ * h_ <= t_begin + fuzz) sample(x);
    // Read the commands at the segment's midpoint minus the transport delay of the
    // input_delay effect (before t = 0: the first applied pressures, as simulate_arm does).
    const double tr = 0.5 * (t_begin + t_end) - delay_;
    const int j = std::min(std::max(static_cast<int>(std::floor(tr / h_)), 0), next_k_ - 1);
    p_held_ = pressures.row(j).transpose();
  }

  // The controller at sample next_k_, state x.
  template <class X>
  void sample(const X& x) {
    const int k = next_k_;
    in_.k = k;
    in_.t = k * h_;
    in_.state = x;
    in_.angles = gain_.cwiseProduct(x.head(desc_.nq)) + offset_;
    in_.velocities = gain_.cwiseProduct(x.segment(desc_.nq, desc_.nq));
    states.row(k) = x.transpose();
    const std::string at = "controller at t = " + format_time(in_.t) + " s (sample " +
                           std::to_string(k) + ")";
    Eigen::VectorXd p;
    try {
      p = controller_(in_);
    } catch (const std::exception& e) {
      throw ControllerError(at + " threw: " + e.what());
    }
    if (p.size() != desc_.num_inputs)
      throw ControllerError(at + " returned " + std::to_string(p.size()) +
                            " pressures; the arm has " + std::to_string(desc_.num_inputs) +
                            " inputs");
    for (Eigen::Index i = 0; i < p.size(); ++i)
      if (!std::isfinite(p(i)))
        throw ControllerError(at + " returned a non-finite pressure (" +
                              desc_.pressure_names[static_cast<std::size_t>(i)] + " = " +
                              format_time(p(i)) + ")");
    commands.row(k) = p.cwiseMax(opt_.p_min).cwiseMin(opt_.p_max).transpose();
    const int d = opt_.delay_periods;
    pressures.row(k) = k >= d ? Eigen::RowVectorXd(commands.row(k - d)) : p_initial_.transpose();
    ++next_k_;
  }

  bool rhs(double, const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Ref<Eigen::VectorXd> xdot) {
    return f_.rhs(x, p_held_, xdot);
  }
  bool jacobian(double, const Eigen::Ref<const Eigen::VectorXd>& x,
                const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::MatrixXd> J) {
    return f_.state_jacobian(x, p_held_, J);
  }

 private:
  const ArmDescription& desc_;
  ArmJacobian f_;
  const Controller& controller_;
  const ClosedLoopOptions& opt_;
  double h_;
  int N_;
  double delay_;
  Eigen::VectorXd p_initial_, gain_, offset_;

 public:
  Eigen::MatrixXd states, commands, pressures;  ///< rows 0..samples()-1 filled

 private:
  Eigen::VectorXd p_held_;
  ControllerInput in_;
  int next_k_ = 0;
};

}  // namespace detail

/// \brief Simulates the arm under `controller`, sampled every `control_period` from t = 0
/// to the first sample at or after t_end, starting at rest at the measured angles q0 under
/// the initial pressures (ClosedLoopOptions::initial_pressures).
///
/// At each sample t_k = k h the controller sees the measured angles and velocities (and the
/// state); its pressures are clamped to [p_min, p_max] and act, delay_periods samples later,
/// over a whole period (zero-order hold). The integrator (CVODE BDF with the exact AutoDiff
/// Jacobian, as simulate_arm) restarts at every sample.
/// \param[in] desc The arm (build_arm()); its input_delay effect, if any, delays the
///   pressures further (as for recorded ones).
/// \param[in] controller Returns num_inputs finite pressures, Pa.
/// \param[in] q0 The measured angles at t = 0 (size nq), or empty for zero.
/// \param[in] t_end The end time, s (> 0); the run covers N = ceil(t_end / h) periods.
/// \param[in] control_period The sample time h, s (> 0).
/// \param[in] opt Delay, pressure range, initial pressures and integrator settings.
/// \return The samples; result.ok false with a one-line result.message (naming the argument,
///   or the sample and what the controller returned: the wrong number of pressures, a
///   non-finite one, an exception) and the samples before the failure. Never throws for a bad
///   controller or argument.
SOFTRNE_SIM_INLINE ClosedLoopSimulation simulate_closed_loop(const ArmDescription& desc,
                                                             const Controller& controller,
                                                             const Eigen::VectorXd& q0, double t_end,
                                                             double control_period,
                                                             const ClosedLoopOptions& opt = {})
#if SOFTRNE_SIM_BODIES
{
  ClosedLoopSimulation out;
  auto fail = [&](const std::string& message) {
    out.result.ok = false;
    out.result.message = message;
    return out;
  };
  const int m = desc.num_inputs;
  const double h = control_period;
  if (!controller) return fail("invalid arguments: no controller");
  if (!(h > 0) || !std::isfinite(h))
    return fail("invalid arguments: control_period must be positive and finite");
  if (!(t_end > 0) || !std::isfinite(t_end))
    return fail("invalid arguments: t_end must be positive and finite");
  const double periods = std::ceil(t_end / h - 1e-9);
  if (periods > 1e8) return fail("invalid arguments: more than 1e8 control periods");
  const int N = std::max(1, static_cast<int>(periods));
  if (opt.delay_periods < 0) return fail("invalid arguments: delay_periods must be >= 0");
  if (std::isnan(opt.p_min) || std::isnan(opt.p_max) || !(opt.p_min <= opt.p_max))
    return fail("invalid arguments: the pressure range [p_min, p_max] must satisfy p_min <= p_max");
  if (q0.size() != 0 && q0.size() != desc.nq)
    return fail("invalid arguments: q0 has " + std::to_string(q0.size()) + " angles; the arm has " +
                std::to_string(desc.nq) + " coordinates");
  if (opt.initial_pressures.size() != 0 && opt.initial_pressures.size() != m)
    return fail("invalid arguments: initial_pressures has " +
                std::to_string(opt.initial_pressures.size()) + " values; the arm has " +
                std::to_string(m) + " inputs");
  if (!opt.initial_pressures.allFinite())
    return fail("invalid arguments: initial_pressures are not finite");
  const Eigen::VectorXd p_initial =
      (opt.initial_pressures.size() ? opt.initial_pressures : Eigen::VectorXd::Zero(m))
          .cwiseMax(opt.p_min)
          .cwiseMin(opt.p_max);

  detail::ClosedLoopSystem sys(desc, controller, h, N, opt, p_initial);
  out.t = Eigen::VectorXd::LinSpaced(N + 1, 0.0, N * h);
  std::vector<double> bp;
  for (int k = 1; k < N; ++k) bp.push_back(k * h);
  if (sys.input_delay() > 0)
    for (int k = 0; k < N; ++k) bp.push_back(k * h + sys.input_delay());
  const Eigen::VectorXd x0 = initial_state(desc, q0, p_initial);
  CvodeOptions copt = opt.simulation.cvode;
  copt.use_analytic_jacobian = opt.simulation.autodiff_jacobian;
  try {
    out.result = detail::integrate_arm(sys, x0, out.t, bp, copt, opt.simulation.velocity_atol_factor);
    // The last sample: its commands would act after the run.
    if (out.result.ok) sys.sample(Eigen::VectorXd(out.result.x.bottomRows(1).transpose()));
  } catch (const detail::ControllerError& e) {
    out.result.ok = false;
    out.result.message = e.what();
    out.result.t_reached = (sys.samples()) * h;
  }
  // The samples taken (all N + 1 on success).
  const int rows = sys.samples();
  out.t.conservativeResize(rows);
  out.states = sys.states.topRows(rows);
  out.commands = sys.commands.topRows(rows);
  out.pressures = sys.pressures.topRows(rows);
  out.angles = detail::measured_angles(desc, out.states);
  return out;
}
#else
;
#endif

}  // namespace softrne::sim
