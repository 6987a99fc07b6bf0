// 04_lqr_tracking: the bundled arm tracks a smooth reference with feed-forward pressures from
// the inverse dynamics plus a time-varying LQR on the discretised linearisation around the
// reference, in closed loop (simulate_closed_loop), against feed-forward alone.
//
//   04_lqr_tracking [robot.json [ignored.csv [out.csv]]]
//
// The plant is not the controller's model: it is robot.json with the effect that the closed
// loop found in the bundled arm's data (shared stiffening, beta = 2.04 /rad^2;
// docs/closing-the-loop.md), which the controller does not know. Writes t, the reference
// u1_ref..v3_ref, the LQR-tracked u1..v3 and the feed-forward-only u1_ff..v3_ff (default
// <build>/examples/arm-a-1-lqr-tracking.csv); plot with
//   python3 tools/plot_tracking.py build/examples/arm-a-1-lqr-tracking.csv --out tracking.png
// Exits 1 unless the LQR tracks within the bounds below (ctest example_04_lqr_tracking).
//
// Steps:
//  1. reference q_ref(t) = a (1 - cos(w t)) per coordinate: starts at rest at q = 0;
//  2. feed-forward: the torques eq. 23 needs along it, K_prs p = M qdd + C qd + G + K q + D qd
//     (rnea and the model's own passive forces), allocated to the chambers as in
//     02_feedforward_controller (antagonistic_pressures, with a 20 kPa bias so that feedback
//     can push both ways);
//  3. linearise f at (x_ref(t_k), p_ff(t_k)) and discretise for the control period (ZOH);
//  4. LQR with integral action on the angle errors: gains by the backward Riccati recursion
//     along the reference, started from the discrete algebraic Riccati equation at its end
//     (solved by iterating the same recursion);
//  5. closed loop on the plant: p = p_ff(t_k) - K_k [x_measured - x_ref(t_k), z_k], clamped
//     to [0, 150 kPa] (the bundled data's range).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "softrne/algorithms/pressure_allocation.hpp"
#include "softrne/algorithms/rnea.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/arm/arm_dynamics.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/sim/closed_loop.hpp"
#include "softrne/sim/linearisation.hpp"

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// Tracking bounds checked at the end. Measured on the bundled arm (README, "Examples"): LQR
// median 4.0e-4 rad, max 6.4e-3 rad; feed-forward alone 9.1e-3 and 0.14 rad. The median bound
// is half the angle sensors' noise (3e-3 rad, examples/data/arm-a-1/README.md): tracking
// below what the arm could measure. The max bound is a seventh of feed-forward's max, three
// times the measured value (room for another compiler's or CVODE's rounding, none for a
// controller that loses the integral action: 0.03 rad then). Feed-forward alone must be 5x
// worse in the median (measured 23x).
constexpr double kMaxMedianError = 1.5e-3;       // rad
constexpr double kMaxMaxError = 0.02;            // rad
constexpr double kMinGainOverFeedForward = 5.0;  // FF median error / LQR median error

struct Reference {
  VectorXd a, w;
  void at(double t, VectorXd& q, VectorXd& qd, VectorXd& qdd) const {
    q = a.array() * (1 - (w * t).array().cos());
    qd = a.array() * w.array() * (w * t).array().sin();
    qdd = a.array() * w.array().square() * (w * t).array().cos();
  }
};

// Step 2: pressures whose torques, with the model's springs, dampers and effects, drive the
// model along (q, qd, qdd).
VectorXd feed_forward(softrne::ArmDynamics<double>& f, const VectorXd& q, const VectorXd& qd,
                      const VectorXd& qdd, double bias) {
  const softrne::ArmDescription& d = f.description();
  const VectorXd xs = VectorXd::Zero(d.num_effect_states);
  const VectorXd id = softrne::rnea(f.chain(), f.data(), q, qd, qdd);  // M qdd + C qd + G
  // Every other force at zero pressure: -K q - D qd (and the model's effects).
  const VectorXd passive = f.joint_forces(q, qd, VectorXd::Zero(d.num_inputs), xs);
  const VectorXd tau = id - passive;
  VectorXd p(d.num_inputs);
  for (const auto& j : d.joints)
    softrne::antagonistic_pressures(j.pressure_to_torque, tau.segment(j.q_offset, 2), bias,
                                    p.segment(j.input_offset, j.num_inputs));
  return p;
}

// Step 4: one step of the Riccati recursion, P <- Q + A'P(A - BK), and its gain K.
MatrixXd riccati_step(const MatrixXd& A, const MatrixXd& B, const MatrixXd& Q, const MatrixXd& R,
                      MatrixXd& P) {
  const MatrixXd K = (R + B.transpose() * P * B).ldlt().solve(B.transpose() * P * A);
  P = Q + A.transpose() * P * (A - B * K);
  P = 0.5 * (P + P.transpose());
  return K;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = std::string(SOFTRNE_EXAMPLE_DATA_DIR) + "/arm-a-1";
  const std::string robot_path = argc > 1 ? argv[1] : dir + "/robot.json";
  const std::string out_path =
      argc > 3 ? argv[3] : std::string(SOFTRNE_EXAMPLE_OUTPUT_DIR) + "/arm-a-1-lqr-tracking.csv";
  try {
    const softrne::ArmDescription model = softrne::build_arm(softrne::io::read_robot_json(robot_path));
    softrne::ArmDescription plant = model;
    softrne::AnyEffect stiffening =
        softrne::make_effect_at_neutral("stiffening", plant, softrne::Scope::Shared);
    softrne::effect_base(stiffening).params(0) = 2.04;
    softrne::add_effect(plant, stiffening);

    const int nq = model.nq, n = model.num_states(), m = model.num_inputs;
    const double h = 0.01, t_end = 10.0, bias = 20e3;
    const int N = static_cast<int>(std::lround(t_end / h));

    // 1. The reference: 0.1 to 0.25 rad at 0.15 to 0.4 Hz per coordinate.
    Reference ref;
    ref.a = VectorXd::LinSpaced(nq, 0.1, 0.25);
    ref.w = 2 * M_PI * VectorXd::LinSpaced(nq, 0.4, 0.15);

    // 2.-3. Feed-forward and the discretised linearisation at every sample.
    softrne::ArmDynamics<double> dyn(model);
    softrne::sim::ArmJacobian jac(model);
    std::vector<VectorXd> x_ref(N + 1), p_ff(N + 1);
    std::vector<softrne::sim::DiscreteLinearisation> lin(N + 1);
    VectorXd q, qd, qdd;
    for (int k = 0; k <= N; ++k) {
      ref.at(k * h, q, qd, qdd);
      x_ref[k].resize(n);
      x_ref[k] << q, qd;
      p_ff[k] = feed_forward(dyn, q, qd, qdd, bias);
      lin[k] = softrne::sim::discretise_zoh(softrne::sim::linearise(jac, x_ref[k], p_ff[k]), h);
    }

    // 4. LQR with integral action: the state [dx, z], z_k+1 = z_k + h (q_k - q_ref,k) (the
    // plant's unknown stiffening is a slowly varying force: without z it leaves an offset).
    // Weights by Bryson's rule: the largest acceptable angle, rate, integral and pressure.
    const double qa = 1e-3, qv = 0.3, qi = 2e-4, rp = 50e3;  // rad, rad/s, rad s, Pa
    const int na = n + nq;
    VectorXd weights(na);
    weights << VectorXd::Constant(nq, 1 / (qa * qa)), VectorXd::Constant(nq, 1 / (qv * qv)),
        VectorXd::Constant(nq, 1 / (qi * qi));
    const MatrixXd Q = weights.asDiagonal();
    const MatrixXd R = MatrixXd::Identity(m, m) / (rp * rp);
    auto augmented = [&](const softrne::sim::DiscreteLinearisation& dl, MatrixXd& A, MatrixXd& B) {
      A = MatrixXd::Identity(na, na);
      A.topLeftCorner(n, n) = dl.Ad;
      A.block(n, 0, nq, nq) = h * MatrixXd::Identity(nq, nq);
      B = MatrixXd::Zero(na, m);
      B.topRows(n) = dl.Bd;
    };
    MatrixXd A, B, P = Q;
    augmented(lin[N], A, B);
    int iterations = 0;
    for (double change = 1; change > 1e-10 && iterations < 100000; ++iterations) {
      const MatrixXd before = P;
      riccati_step(A, B, Q, R, P);
      change = (P - before).norm() / P.norm();
    }
    std::vector<MatrixXd> K(N + 1);
    K[N] = riccati_step(A, B, Q, R, P);
    for (int k = N - 1; k >= 0; --k) {
      augmented(lin[k], A, B);
      K[k] = riccati_step(A, B, Q, R, P);
    }
    std::printf("Riccati: terminal DARE in %d iterations, %d time-varying gains\n", iterations, N + 1);

    // 5. Closed loop on the plant, with LQR and with feed-forward alone.
    softrne::sim::ClosedLoopOptions opt;
    opt.p_min = 0;
    opt.p_max = 150e3;
    opt.initial_pressures = p_ff[0];
    VectorXd z = VectorXd::Zero(nq);  // the controller's integral of the angle error
    auto lqr = [&](const softrne::sim::ControllerInput& in) -> VectorXd {
      VectorXd e(na);
      e << in.angles - x_ref[in.k].head(nq), in.velocities - x_ref[in.k].tail(nq), z;
      z += h * e.head(nq);
      return p_ff[in.k] - K[in.k] * e;
    };
    auto ff = [&](const softrne::sim::ControllerInput& in) -> VectorXd { return p_ff[in.k]; };
    const softrne::sim::ClosedLoopSimulation run = simulate_closed_loop(plant, lqr, VectorXd(), t_end, h, opt);
    const softrne::sim::ClosedLoopSimulation open = simulate_closed_loop(plant, ff, VectorXd(), t_end, h, opt);
    if (!run.ok() || !open.ok()) {
      std::fprintf(stderr, "04_lqr_tracking: %s\n", (run.ok() ? open : run).result.message.c_str());
      return 1;
    }

    // Errors over every coordinate and sample.
    MatrixXd q_ref(N + 1, nq);
    for (int k = 0; k <= N; ++k) q_ref.row(k) = x_ref[k].head(nq).transpose();
    auto errors = [&](const MatrixXd& angles) {
      const MatrixXd e = (angles - q_ref).cwiseAbs();
      return std::vector<double>(e.data(), e.data() + e.size());
    };
    const std::vector<double> e_lqr = errors(run.angles), e_ff = errors(open.angles);
    const double med_lqr = median(e_lqr), max_lqr = *std::max_element(e_lqr.begin(), e_lqr.end());
    const double med_ff = median(e_ff), max_ff = *std::max_element(e_ff.begin(), e_ff.end());
    const double clamped = (run.commands.array() >= opt.p_max || run.commands.array() <= opt.p_min)
                               .cast<double>()
                               .mean();
    std::printf("tracking error over %d samples x %d angles (rad):\n", N + 1, nq);
    std::printf("  feed-forward alone:  median %.2e  max %.2e\n", med_ff, max_ff);
    std::printf("  feed-forward + LQR:  median %.2e  max %.2e  (%.1f %% of commands at a limit)\n",
                med_lqr, max_lqr, 100 * clamped);

    // CSV: t, the reference, LQR, feed-forward only.
    std::vector<std::string> names;
    for (const auto& c : model.coordinate_names) names.push_back(c + "_ref");
    for (const auto& c : model.coordinate_names) names.push_back(c);
    for (const auto& c : model.coordinate_names) names.push_back(c + "_ff");
    MatrixXd table(N + 1, 3 * nq);
    table << q_ref, run.angles, open.angles;
    softrne::io::write_trajectory_csv(out_path, run.t, table, names);
    std::printf("wrote %s\n", out_path.c_str());

    const bool pass = med_lqr < kMaxMedianError && max_lqr < kMaxMaxError &&
                      med_ff > kMinGainOverFeedForward * med_lqr;
    std::printf("check (median < %.1e, max < %.1e, %.0fx better than feed-forward): %s\n",
                kMaxMedianError, kMaxMaxError, kMinGainOverFeedForward, pass ? "passed" : "FAILED");
    return pass ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "04_lqr_tracking: %s\n", e.what());
    return 1;
  }
}
