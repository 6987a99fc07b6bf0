#pragma once
/// \file
/// \brief Simulating an arm from recorded pressures with CVODE (BDF), Jacobian by AutoDiff.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "softrne/model/arm_model.hpp"
#include "softrne/sim/cvode.hpp"
#include "softrne/sim/input_signal.hpp"
#include "softrne/sim/pchip_signal.hpp"

namespace softrne::sim {

/// \brief Settings of simulate_arm.
struct ArmSimulationOptions {
  CvodeOptions cvode{};
  /// How recorded pressures are read between samples (see PressureInterpolation).
  enum class PressureInterpolation { pchip, linear, zero_order_hold };
  PressureInterpolation interpolation = PressureInterpolation::pchip;
  /// Jacobian of the state equation by forward-mode AutoDiff through the templated RNE
  /// (exact); false: CVODE's internal finite differences.
  bool autodiff_jacobian = true;
};

/// \brief Result: measured-space angles (simulated q plus any angle offset) on the input grid.
struct ArmSimulation {
  Eigen::MatrixXd angles;  ///< N x nq (rows computed before a failure, if any)
  Eigen::MatrixXd states;  ///< N x num_states
  SimulationResult result;
  bool ok() const { return result.ok; }
};

/// \brief Times where the recorded pressures jump (a pressure step): the integrator restarts
/// there. A jump is a sample-to-sample change larger than both 10x the channel's median change
/// (noise) and 5% of its range; relative, so it does not depend on units or the robot.
inline std::vector<double> pressure_jumps(const Eigen::VectorXd& t, const Eigen::MatrixXd& p) {
  std::vector<double> out;
  const Eigen::Index n = t.size();
  if (n < 3 || p.cols() == 0) return out;
  const Eigen::MatrixXd d = (p.bottomRows(n - 1) - p.topRows(n - 1)).cwiseAbs();
  Eigen::VectorXd thr(p.cols());
  for (Eigen::Index c = 0; c < p.cols(); ++c) {
    std::vector<double> col(d.col(c).data(), d.col(c).data() + d.rows());
    std::nth_element(col.begin(), col.begin() + static_cast<long>(col.size() / 2), col.end());
    const double med = col[col.size() / 2];
    const double range = p.col(c).maxCoeff() - p.col(c).minCoeff();
    thr(c) = std::max(10 * med, 0.05 * range);
    if (!(thr(c) > 0)) thr(c) = std::numeric_limits<double>::infinity();
  }
  for (Eigen::Index i = 0; i + 1 < n; ++i)
    for (Eigen::Index c = 0; c < p.cols(); ++c)
      if (d(i, c) > thr(c)) {
        out.push_back(t(i));  // the ramp of a step starts at sample i
        break;
      }
  return out;
}

/// \brief The arm as an ODE system for CVODE: x' = f(t, x) with the pressures of an
/// InputSignal, and its exact Jacobian by AutoDiff (blocks of kBlock directions at a time).
class ArmSystem {
 public:
  static constexpr int kBlock = 4;
  using AD = Eigen::AutoDiffScalar<Eigen::Matrix<double, kBlock, 1>>;

  /// \param smooth true: PCHIP (C1); false: `input`'s own linear or zero-order hold.
  ArmSystem(const ArmDescription& desc, const Eigen::VectorXd& t, const Eigen::MatrixXd& pressures,
            ArmSimulationOptions::PressureInterpolation mode)
      : desc_(desc),
        f_(desc),
        f_ad_(desc),
        mode_(mode),
        input_(t, pressures,
               mode == ArmSimulationOptions::PressureInterpolation::zero_order_hold
                   ? Interpolation::zero_order_hold
                   : Interpolation::linear),
        pchip_(t, pressures) {
    p_.resize(desc.num_inputs);
    x_ad_.resize(desc.num_states());
    xd_ad_.resize(desc.num_states());
  }

  int size() const { return desc_.num_states(); }

  /// Recorded pressures at time t.
  const Eigen::VectorXd& pressures(double t) {
    if (mode_ == ArmSimulationOptions::PressureInterpolation::pchip)
      pchip_.value(t, p_);
    else
      input_.value(t, p_, cursor_);
    return p_;
  }

  bool rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Ref<Eigen::VectorXd> xdot) {
    pressures(t);
    f_.rhs(x, p_, xdot);
    return xdot.allFinite();
  }

  bool jacobian(double t, const Eigen::Ref<const Eigen::VectorXd>& x,
                const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::MatrixXd> J) {
    pressures(t);
    const int n = size();
    for (int start = 0; start < n; start += kBlock) {
      for (int i = 0; i < n; ++i) {
        x_ad_(i).value() = x(i);
        x_ad_(i).derivatives().setZero();
        if (i >= start && i < start + kBlock) x_ad_(i).derivatives()(i - start) = 1.0;
      }
      f_ad_.rhs(x_ad_, p_, xd_ad_);
      for (int i = 0; i < n; ++i)
        for (int k = 0; k < kBlock && start + k < n; ++k) J(i, start + k) = xd_ad_(i).derivatives()(k);
    }
    return J.allFinite();
  }

 private:
  const ArmDescription& desc_;
  ArmDynamics<double> f_;
  ArmDynamics<AD> f_ad_;
  ArmSimulationOptions::PressureInterpolation mode_;
  InputSignal input_;
  PchipSignal pchip_;
  SignalCursor cursor_;
  Eigen::VectorXd p_;
  Eigen::Matrix<AD, Eigen::Dynamic, 1> x_ad_, xd_ad_;
};

/// \brief Simulates the arm on the time grid t with the recorded pressures (N x num_inputs),
/// from rest at the measured configuration q0 (size nq; zero if empty).
inline ArmSimulation simulate_arm(const ArmDescription& desc, const Eigen::VectorXd& t,
                                  const Eigen::MatrixXd& pressures, const Eigen::VectorXd& q0,
                                  const ArmSimulationOptions& opt = {}) {
  ArmSimulation out;
  ArmSystem sys(desc, t, pressures, opt.interpolation);
  const Eigen::VectorXd x0 = initial_state(desc, q0, pressures.row(0).transpose());
  CvodeOptions copt = opt.cvode;
  copt.use_analytic_jacobian = opt.autodiff_jacobian;
  using PI = ArmSimulationOptions::PressureInterpolation;
  const std::vector<double> bp =
      opt.interpolation == PI::zero_order_hold
          ? InputSignal(t, pressures, Interpolation::zero_order_hold).breakpoints()
          : pressure_jumps(t, pressures);
  out.result = integrate(sys, x0, t, bp, copt);
  out.states = out.result.x;
  const Eigen::Index rows = out.states.rows();
  out.angles = out.states.leftCols(desc.nq);
  if (rows > 0) out.angles.rowwise() += desc.measurement_offset().transpose();
  return out;
}

}  // namespace softrne::sim
