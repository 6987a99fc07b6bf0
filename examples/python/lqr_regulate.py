#!/usr/bin/env python3
"""Regulate the bundled arm (examples/data/arm-a-1) to a bent pose with an LQR designed on
the zero-order-hold discretisation of its linearisation, in closed loop with the nonlinear
simulator, against holding the pose's pressures open loop. numpy only.

Steps:
 1. the pose: the equilibrium x_eq under chamber pressures p_eq (Robot.static_equilibrium);
 2. A, B at (x_eq, p_eq) and Ad, Bd for the control period h (discretise_zoh; cd = 0 at an
    equilibrium);
 3. the gain K of the infinite-horizon discrete LQR: the discrete algebraic Riccati equation
    solved by iterating its recursion (weights by Bryson's rule);
 4. softrne.simulate_closed_loop from rest at a displaced pose, p = p_eq - K (x - x_eq)
    clamped to the valves' range [0, 150 kPa], and the same start under p_eq alone.

Prints the regulation error max |q - q_eq| over time for both and exits 1 unless the LQR
settles (error < 1e-4 rad after 1 s) and does so at least 3 times faster than open loop.

    pip install .  (or PYTHONPATH=<build>/python)
    python3 examples/python/lqr_regulate.py [--robot robot.json] [--period 0.01]
"""

from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

import softrne

ARM = pathlib.Path(__file__).resolve().parents[1] / "data" / "arm-a-1"
P_MAX = 150e3  # Pa, the bundled data's valve range


def dlqr(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray, tol: float = 1e-12) -> tuple[np.ndarray, int]:
    """The gain K of u = -K x minimising sum x'Qx + u'Ru for x+ = A x + B u: iterates
    P <- Q + A'P(A - B K), K = (R + B'PB)^-1 B'PA from P = Q until P stops changing."""
    P = Q.copy()
    for it in range(1, 100_000):
        K = np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A)
        P_next = Q + A.T @ P @ (A - B @ K)
        P_next = 0.5 * (P_next + P_next.T)
        if np.abs(P_next - P).max() <= tol * np.abs(P_next).max():
            return np.linalg.solve(R + B.T @ P_next @ B, B.T @ P_next @ A), it
        P = P_next
    raise RuntimeError("the Riccati iteration did not converge")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robot", default=str(ARM / "robot.json"))
    ap.add_argument("--period", type=float, default=0.01, help="control period h, s (default 0.01)")
    ap.add_argument("--t-end", type=float, default=8.0, help="length of the runs, s (default 8)")
    args = ap.parse_args()

    robot = softrne.Robot.from_json(args.robot)
    nq, n, m, h = robot.nq, robot.num_states, robot.num_pressures, args.period

    # 1. The pose: one chamber of each joint at 40 to 70 kPa, the others at 20 kPa.
    p_eq = np.full(m, 20e3)
    p_eq[0::4] = np.linspace(70e3, 40e3, len(p_eq[0::4]))
    x_eq = robot.static_equilibrium(p_eq)
    q_eq = x_eq[:nq]

    # 2. The discretised linearisation; the design works in kPa (better-scaled B).
    d = robot.linearise(x_eq, p_eq).discretise_zoh(h)
    Ad, Bd = d.Ad, d.Bd * 1e3

    # 3. LQR weights by Bryson's rule: the largest acceptable angle, rate and pressure change.
    qa, qv, rp = 5e-3, 0.2, 20.0  # rad, rad/s, kPa
    weights = np.r_[np.full(nq, qa ** -2), np.full(nq, qv ** -2), np.full(n - 2 * nq, 1e-12)]
    K, iterations = dlqr(Ad, Bd, np.diag(weights), np.eye(m) / rp**2)
    rho = np.abs(np.linalg.eigvals(Ad - Bd @ K)).max()
    rho_open = np.abs(np.linalg.eigvals(Ad)).max()
    K_pa = K * 1e3  # Pa per unit of state

    # 4. Closed loop from rest at a displaced pose, against p_eq held open loop.
    q0 = q_eq + np.resize([0.15, -0.1, 0.1], nq)
    lqr = lambda s: p_eq - K_pa @ (s.state - x_eq)  # noqa: E731
    hold = lambda s: p_eq  # noqa: E731
    runs = {name: softrne.simulate_closed_loop(robot, c, args.t_end, h, q0, p_min=0.0, p_max=P_MAX,
                                               initial_pressures=p_eq)
            for name, c in (("LQR", lqr), ("open loop", hold))}

    print(f"{robot.name}: {n} states, {m} pressures, control period {h * 1e3:g} ms")
    print(f"pose: q_eq = {np.array2string(q_eq, precision=3)} rad under p_eq = "
          f"{np.array2string(p_eq / 1e3, precision=0)} kPa (|f| = {np.abs(robot.state_derivative(x_eq, p_eq)).max():.1e})")
    print(f"Riccati: {iterations} iterations; spectral radius of Ad {rho_open:.4f}, of Ad - Bd K {rho:.4f}")
    print("regulation error max |q - q_eq| (rad):")
    print("   t (s)        LQR    open loop")
    error = {name: np.abs(run.angles - q_eq).max(axis=1) for name, run in runs.items()}
    t = runs["LQR"].t
    for ti in (0.0, 0.1, 0.2, 0.3, 0.5, 1.0, 2.0, 4.0, args.t_end):
        k = int(np.argmin(np.abs(t - ti)))
        print(f"  {t[k]:6.2f}  {error['LQR'][k]:9.2e}  {error['open loop'][k]:9.2e}")
    settle = {}
    for name, e in error.items():
        above = np.nonzero(e >= 1e-3)[0]
        settle[name] = t[above[-1] + 1] if len(above) and above[-1] + 1 < len(t) else (0.0 if not len(above) else np.inf)
    clamped = np.mean((runs["LQR"].commands <= 0.0) | (runs["LQR"].commands >= P_MAX))
    print(f"settled to 1 mrad after: LQR {settle['LQR']:.2f} s, open loop {settle['open loop']:.2f} s; "
          f"{100 * clamped:.1f} % of the LQR's commands at a limit")

    after_1s = error["LQR"][t >= 1.0].max()
    ok = all(r.ok for r in runs.values()) and after_1s < 1e-4 and 3 * settle["LQR"] <= settle["open loop"]
    print(f"check (LQR error < 1e-4 rad after 1 s: {after_1s:.1e}; settles 3x faster than open loop): "
          f"{'passed' if ok else 'FAILED'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
