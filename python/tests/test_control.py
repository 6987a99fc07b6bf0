"""Linearisation and control in the loop (Robot.state_derivative, Robot.linearise,
discretise_zoh, simulate_closed_loop) against references that share nothing with the code
under test: central finite differences of state_derivative, the dynamics functions (rnea),
a matrix exponential written here (Taylor series with scaling and squaring, numpy only),
closed forms, and the open-loop simulator (simulate)."""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest

import softrne

from conftest import ARM

# Integrator tolerances at which two runs that step differently agree to ~1e-10
# (tests/sim/test_closed_loop.cpp uses the same).
TIGHT = dict(rtol=1e-11, atol=1e-11, atol_velocity=1e-11)


def expm(M: np.ndarray) -> np.ndarray:
    """exp(M): Taylor series of M / 2^s (norm <= 1/2, to the last bit) squared s times."""
    norm = np.abs(M).sum(axis=1).max()
    s = max(0, math.ceil(math.log2(norm / 0.5))) if norm > 0 else 0
    X = M / 2.0**s
    E = np.eye(len(M))
    term = np.eye(len(M))
    for k in range(1, 40):
        term = term @ X / k
        E = E + term
        if np.abs(term).max() <= 1e-17 * np.abs(E).max():
            break
    for _ in range(s):
        E = E @ E
    return E


def zoh_reference(A, B, f, h):
    """Van Loan: exp([[A, B, f], [0, 0, 0]] h) = [[Ad, Bd, cd], [0, I, 0], [0, 0, 1]]."""
    n, m = B.shape
    M = np.zeros((n + m + 1, n + m + 1))
    M[:n, :n], M[:n, n:n + m], M[:n, -1] = A * h, B * h, f * h
    E = expm(M)
    np.testing.assert_allclose(E[n:, n:], np.eye(m + 1), atol=1e-14)
    return E[:n, :n], E[:n, n:n + m], E[:n, -1]


def lag_robot() -> softrne.Robot:
    """The bundled arm with a first-order lag of joint2's chamber pressures (4 more states)."""
    d = softrne.Robot.from_json(ARM / "robot.json").to_dict()
    d["effects"] = [{"name": "actuator_lag", "joints": ["joint2"], "params": {"T": 0.04}}]
    return softrne.Robot.from_dict(d)


def bending_pressures(robot: softrne.Robot) -> np.ndarray:
    """Pressures that bend each joint: one chamber of four high (12 pressures, 3 CC joints)."""
    p = np.full(robot.num_pressures, 15e3)
    p[0::4] = [60e3, 45e3, 30e3]
    p[1::4] += [0.0, 20e3, 10e3]
    return p


def viscoelastic_robot() -> softrne.Robot:
    """The bundled arm with a Maxwell branch on every joint (6 more states, at rest where q is)."""
    d = softrne.Robot.from_json(ARM / "robot.json").to_dict()
    d["effects"] = [{"name": "viscoelastic", "params": {"k": 3.0, "tau": 0.3}}]
    return softrne.Robot.from_dict(d)


@pytest.mark.parametrize("make", [lambda: softrne.Robot.from_json(ARM / "robot.json"), lag_robot, viscoelastic_robot],
                         ids=["declared", "actuator_lag", "viscoelastic"])
def test_static_equilibrium_is_where_the_simulation_comes_to_rest(make):
    """Robot.static_equilibrium (Newton on the accelerations) against its definition, f(x, p) = 0,
    and against an independent path: the simulator run from the straight arm under the same
    constant pressures until it has settled (60 s; the slowest mode decays in about 2 s)."""
    robot = make()
    p = bending_pressures(robot)
    x = robot.static_equilibrium(p)
    assert x.shape == (robot.num_states,)
    np.testing.assert_array_equal(x[robot.nq:2 * robot.nq], np.zeros(robot.nq))
    assert np.abs(robot.state_derivative(x, p)).max() < 1e-9
    assert np.abs(x[:robot.nq]).max() > 0.05  # it bends
    settled = softrne.simulate(robot, [0.0, 60.0], [p, p], None, **TIGHT)[-1]
    np.testing.assert_allclose(settled, x[:robot.nq], rtol=0, atol=1e-7)
    # From a guess near the answer, the same answer; a guess of the wrong size is refused.
    np.testing.assert_allclose(robot.static_equilibrium(p, x[:robot.nq] + 0.01), x, rtol=0, atol=1e-10)
    with pytest.raises(ValueError, match="static_equilibrium.*q_guess"):
        robot.static_equilibrium(p, np.zeros(robot.nq + 1))


# ---- the state and its equation --------------------------------------------------------

def test_num_states_and_initial_state(robot):
    assert robot.num_states == 2 * robot.nq == 12
    np.testing.assert_array_equal(robot.initial_state(), np.zeros(12))
    q0 = np.linspace(-0.2, 0.3, 6)
    np.testing.assert_array_equal(robot.initial_state(q0), np.r_[q0, np.zeros(6)])
    lagged = lag_robot()
    assert lagged.num_states == 12 + 4
    p0 = np.arange(12) * 1e3
    x0 = lagged.initial_state(q0, p0)
    np.testing.assert_array_equal(x0[:12], np.r_[q0, np.zeros(6)])
    # The lag states rest at the pressures of the lagged joint's chambers.
    np.testing.assert_array_equal(x0[12:], p0[4:8])
    np.testing.assert_array_equal(lagged.initial_state(q0)[12:], np.zeros(4))


def test_state_derivative_is_the_arm_equation(robot, rng):
    """f = [qd, qdd] where, at zero pressure, M qdd + C qd + G = -K q - D qd (robot.json's
    diagonal stiffness and damping): checked with rnea, which shares no code path with f's
    forward dynamics."""
    spec = robot.to_dict()
    K = np.concatenate([s["stiffness"] for s in spec["segments"] if s["type"] == "cc_joint"])
    D = np.concatenate([s["damping"] for s in spec["segments"] if s["type"] == "cc_joint"])
    for _ in range(5):
        q, qd = rng.uniform(-0.4, 0.4, 6), rng.uniform(-1, 1, 6)
        f = robot.state_derivative(np.r_[q, qd], np.zeros(12))
        np.testing.assert_array_equal(f[:6], qd)
        tau = robot.rnea(q, qd, f[6:])
        np.testing.assert_allclose(tau, -K * q - D * qd, rtol=0, atol=1e-12 * np.abs(K * q).max())
    # Hanging straight down at zero pressure: at rest.
    assert np.abs(robot.state_derivative(robot.initial_state(), np.zeros(12))).max() == 0.0
    # Pressures enter linearly: f(x, p) - f(x, 0) is linear in p.
    x = np.r_[rng.uniform(-0.4, 0.4, 6), rng.uniform(-1, 1, 6)]
    p1, p2 = rng.uniform(0, 1e5, 12), rng.uniform(0, 1e5, 12)
    f0 = robot.state_derivative(x, np.zeros(12))
    lhs = robot.state_derivative(x, p1 + p2) - f0
    rhs = (robot.state_derivative(x, p1) - f0) + (robot.state_derivative(x, p2) - f0)
    np.testing.assert_allclose(lhs, rhs, rtol=0, atol=1e-12 * np.abs(lhs).max())


def fd_jacobians(robot, x, p):
    """Central differences of state_derivative in x and p."""
    n, m = len(x), len(p)
    A, B = np.empty((n, n)), np.empty((n, m))
    for j in range(n):
        e = np.zeros(n)
        e[j] = 1e-5 * max(1.0, abs(x[j]))
        A[:, j] = (robot.state_derivative(x + e, p) - robot.state_derivative(x - e, p)) / (2 * e[j])
    for j in range(m):
        e = np.zeros(m)
        e[j] = 100.0  # Pa (f is linear in p: only rounding)
        B[:, j] = (robot.state_derivative(x, p + e) - robot.state_derivative(x, p - e)) / (2 * e[j])
    return A, B


@pytest.mark.parametrize("which", ["arm", "arm with actuator lag"])
def test_linearise_equals_finite_differences(robot, rng, which):
    r = robot if which == "arm" else lag_robot()
    x = r.initial_state(rng.uniform(-0.4, 0.4, 6), rng.uniform(0, 8e4, 12))
    x[6:12] = rng.uniform(-1, 1, 6)
    x[12:] += rng.uniform(-5e3, 5e3, r.num_states - 12)
    p = rng.uniform(0, 8e4, 12)
    lin = r.linearise(x, p)
    assert isinstance(lin, softrne.Linearisation)
    np.testing.assert_array_equal(lin.x, x)
    np.testing.assert_array_equal(lin.p, p)
    np.testing.assert_array_equal(lin.f, r.state_derivative(x, p))
    assert lin.A.shape == (r.num_states, r.num_states) and lin.B.shape == (r.num_states, 12)
    A_fd, B_fd = fd_jacobians(r, x, p)
    # Column by column, relative to the column's size (the lag states are in Pa, the rest
    # in rad): differences of 1e-5 leave <= 1e-9 of truncation and rounding.
    for J, J_fd in ((lin.A, A_fd), (lin.B, B_fd)):
        scale = np.maximum(np.abs(J).max(axis=0), 1e-300)
        err = (np.abs(J - J_fd).max(axis=0) / scale).max()
        assert err < 1e-8, err
    # The position rows: d qdot / d qd = I, nothing else.
    np.testing.assert_array_equal(lin.A[:6, :], np.eye(r.num_states)[6:12, :])
    np.testing.assert_array_equal(lin.B[:6, :], 0.0)


# ---- zero-order hold -------------------------------------------------------------------

def test_discretise_zoh_closed_forms():
    # Scalar: Ad = e^(ah), Bd = (e^(ah) - 1)/a b, cd = (e^(ah) - 1)/a f.
    a, b, f, h = -3.0, 2.0, 0.5, 0.1
    d = softrne.discretise_zoh([[a]], [[b]], h, [f])
    g = math.expm1(a * h) / a
    np.testing.assert_allclose(d.Ad, [[math.exp(a * h)]], rtol=1e-15)
    np.testing.assert_allclose(d.Bd, [[g * b]], rtol=1e-14)
    np.testing.assert_allclose(d.cd, [g * f], rtol=1e-14)
    # Double integrator: Ad = [[1, h], [0, 1]], Bd = [h^2/2, h].
    Ad, Bd, cd = softrne.discretise_zoh(np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]), h)
    np.testing.assert_allclose(Ad, [[1, h], [0, 1]], rtol=0, atol=1e-16)
    np.testing.assert_allclose(Bd, [[h * h / 2], [h]], rtol=1e-15)
    np.testing.assert_array_equal(cd, [0.0, 0.0])


@pytest.mark.parametrize("h", [1e-3, 0.01, 0.05])
def test_discretise_zoh_equals_matrix_exponential(robot, rng, h):
    x = np.r_[rng.uniform(-0.4, 0.4, 6), rng.uniform(-1, 1, 6)]
    lin = robot.linearise(x, rng.uniform(0, 8e4, 12))
    d = lin.discretise_zoh(h)
    assert d.h == h
    Ad, Bd, cd = zoh_reference(lin.A, lin.B, lin.f, h)
    for got, ref in ((d.Ad, Ad), (d.Bd, Bd), (d.cd, cd)):
        assert np.abs(got - ref).max() <= 1e-9 * np.abs(ref).max(), np.abs(got - ref).max() / np.abs(ref).max()
    # The free function on the same matrices: the same numbers.
    free = softrne.discretise_zoh(lin.A, lin.B, h, lin.f)
    for name in ("Ad", "Bd", "cd"):
        np.testing.assert_array_equal(getattr(free, name), getattr(d, name))
    np.testing.assert_array_equal(softrne.discretise_zoh(lin.A, lin.B, h).cd, np.zeros(12))


def test_discrete_step_at_an_equilibrium_equals_the_simulator(robot):
    """At an equilibrium (cd = 0) the sensitivities of the simulated step to the initial angles
    and the held pressures are Ad and Bd exactly: central differences of the simulator in a
    perturbation (dq, dp) equal Ad dx + Bd dp up to O(eps^2)."""
    p_eq = bending_pressures(robot)
    x_eq = robot.static_equilibrium(p_eq)
    assert np.abs(x_eq[:6]).max() > 0.05  # it bends
    h = 0.02
    d = robot.linearise(x_eq, p_eq).discretise_zoh(h)
    assert np.abs(d.cd).max() < 1e-12
    rng = np.random.default_rng(3)
    dq, dp = rng.uniform(-1, 1, 6), rng.uniform(-1, 1, 12) * 1e5  # effects on the step of like size
    eps = 1e-4

    def step(sign):
        q0 = x_eq[:6] + sign * eps * dq
        p = p_eq + sign * eps * dp
        cl = softrne.simulate_closed_loop(robot, lambda s: p, h, h, q0, initial_pressures=p, p_max=1e6, **TIGHT)
        angles = softrne.simulate(robot, [0.0, h], [p, p], q0, **TIGHT)
        np.testing.assert_allclose(angles[1], cl.angles[1], rtol=0, atol=1e-10)
        return cl.states[1]

    sensitivity = (step(+1) - step(-1)) / (2 * eps)
    expected = d.Ad @ np.r_[dq, np.zeros(6)] + d.Bd @ dp
    err = np.abs(sensitivity - expected)
    for rows in (slice(0, 6), slice(6, 12)):  # angles, rates
        assert err[rows].max() <= 5e-7 * np.abs(expected[rows]).max(), err[rows].max() / np.abs(expected[rows]).max()


def test_discrete_step_off_equilibrium_is_third_order(robot):
    """Off an equilibrium the drift cd carries the step's first two orders in h: the step
    x0 + cd misses the simulated one by O(h^3): halving h divides the miss by 8 once the
    arm's fastest mode (|eigenvalue| ~300 /s) is resolved (by 5.9 and 6.9 from 2 ms)."""
    p = bending_pressures(robot)
    q0 = np.full(6, 0.05)
    x0 = robot.initial_state(q0, p)
    misses = []
    for h in (5e-4, 2.5e-4, 1.25e-4):
        cd = robot.linearise(x0, p).discretise_zoh(h).cd
        cl = softrne.simulate_closed_loop(robot, lambda s: p, h, h, q0, initial_pressures=p, p_max=1e6, **TIGHT)
        misses.append(np.abs(cl.states[1] - (x0 + cd)).max())
        assert misses[-1] < 1e-6 * np.abs(cd).max()
    for coarse, fine in zip(misses, misses[1:]):
        assert 7.2 < coarse / fine < 8.5, misses


def test_linearisation_errors(robot):
    with pytest.raises(ValueError, match=r"softrne.state_derivative: x has shape \(11,\); the robot has 12 states: "
                                         r"expected \(12,\)"):
        robot.state_derivative(np.zeros(11), np.zeros(12))
    with pytest.raises(ValueError, match=r"softrne.state_derivative: p has shape \(12, 1\); the robot has 12 "
                                         r"pressures: expected \(12,\)"):
        robot.state_derivative(np.zeros(12), np.zeros((12, 1)))
    with pytest.raises(ValueError, match=r"softrne.linearise: p has shape \(3,\); the robot has 12 pressures"):
        robot.linearise(np.zeros(12), np.zeros(3))
    with pytest.raises(ValueError, match=r"softrne.initial_state: q0 has shape \(5,\); the robot has 6 coordinates"):
        robot.initial_state(np.zeros(5))
    with pytest.raises(ValueError, match=r"softrne.initial_state: p0 has shape \(6,\); the robot has 12 pressures"):
        robot.initial_state(None, np.zeros(6))
    with pytest.raises(ValueError, match="softrne.linearise: f.* not finite"):
        robot.linearise(np.full(12, np.nan), np.zeros(12))
    lin = robot.linearise(np.zeros(12), np.zeros(12))
    with pytest.raises(ValueError, match=r"h must be positive and finite \(got 0\)"):
        lin.discretise_zoh(0.0)
    with pytest.raises(ValueError, match=r"softrne.discretise_zoh: A has shape \(2, 3\); expected a square"):
        softrne.discretise_zoh(np.zeros((2, 3)), np.zeros((2, 1)), 0.1)
    with pytest.raises(ValueError, match=r"softrne.discretise_zoh: B has shape \(3, 1\); A has 2 rows: "
                                         r"expected \(2, m\)"):
        softrne.discretise_zoh(np.zeros((2, 2)), np.zeros((3, 1)), 0.1)
    with pytest.raises(ValueError, match=r"softrne.discretise_zoh: f has shape \(3,\); expected \(2,\)"):
        softrne.discretise_zoh(np.zeros((2, 2)), np.zeros((2, 1)), 0.1, np.zeros(3))
    with pytest.raises(ValueError, match="softrne.discretise_zoh: A is not finite"):
        softrne.discretise_zoh(np.full((2, 2), np.inf), np.zeros((2, 1)), 0.1)
    with pytest.raises(ValueError, match=r"h must be positive and finite \(got nan\)"):
        softrne.discretise_zoh(np.zeros((2, 2)), np.zeros((2, 1)), math.nan)


# ---- control in the loop ---------------------------------------------------------------

def time_pressures(t: float) -> np.ndarray:
    """A controller output that depends on time only (delays then compare sample by sample)."""
    return 40e3 + 30e3 * np.sin(2.0 * t + 0.7 * np.arange(12))


def test_constant_controller_equals_simulate(robot):
    p = time_pressures(0.3)
    q0 = np.full(6, 0.05)
    cl = softrne.simulate_closed_loop(robot, lambda s: p, 1.0, 0.02, q0, initial_pressures=p, **TIGHT)
    assert cl.ok and cl.message == "" and len(cl) == 51
    np.testing.assert_allclose(cl.t, np.arange(51) * 0.02, rtol=0, atol=1e-15)
    assert cl.stats["restarts"] == 49 and cl.stats["steps"] > 0  # one restart per sample inside the run
    np.testing.assert_array_equal(cl.pressures, np.tile(p, (51, 1)))
    np.testing.assert_array_equal(cl.commands, np.tile(p, (51, 1)))
    open_loop = softrne.simulate(robot, cl.t, cl.pressures, q0, **TIGHT)
    assert np.abs(cl.angles - open_loop).max() < 1e-9
    np.testing.assert_array_equal(cl.angles, cl.states[:, :6])  # no measurement effects
    assert np.ptp(cl.angles, axis=0).max() > 0.05  # it moved


def test_feedback_run_replayed_open_loop(robot):
    """A state feedback: the pressures it applied, replayed open loop with zero-order hold,
    give the same angles; the controller saw the run's own samples."""
    seen = []

    def controller(s: softrne.ControllerInput):
        seen.append((s.k, s.t, s.angles, s.velocities, s.state))
        return time_pressures(s.t) - 2e4 * np.repeat(s.angles, 2) - 1e3 * np.repeat(s.velocities, 2)

    cl = softrne.simulate_closed_loop(robot, controller, 0.6, 0.01, initial_pressures=time_pressures(0.0), **TIGHT)
    assert cl.ok and len(cl) == 61
    assert [k for k, *_ in seen] == list(range(61))
    for k, t, angles, velocities, state in seen:
        assert t == pytest.approx(k * 0.01, abs=1e-15)
        np.testing.assert_array_equal(state, cl.states[k])
        np.testing.assert_array_equal(angles, cl.angles[k])
        np.testing.assert_array_equal(velocities, cl.states[k, 6:])
    np.testing.assert_array_equal(cl.commands, cl.pressures)  # no delay
    open_loop = softrne.simulate(robot, cl.t, cl.pressures, interpolation="zoh", **TIGHT)
    assert np.abs(cl.angles - open_loop).max() < 1e-9
    assert np.ptp(cl.angles, axis=0).max() > 0.02


def test_delay_shifts_the_commands(robot):
    controller = lambda s: time_pressures(s.t)  # noqa: E731
    now = softrne.simulate_closed_loop(robot, controller, 0.5, 0.01)
    late = softrne.simulate_closed_loop(robot, controller, 0.5, 0.01, delay_periods=3,
                                        initial_pressures=np.full(12, 12e3))
    np.testing.assert_array_equal(late.commands, now.commands)
    np.testing.assert_array_equal(late.pressures[3:], now.pressures[:-3])
    np.testing.assert_array_equal(late.pressures[:3], np.full((3, 12), 12e3))
    assert np.abs(late.angles - now.angles).max() > 1e-3  # the arm moves later


def test_pressures_are_clamped(robot):
    def controller(s):
        p = np.linspace(-50e3, 200e3, 12)
        p[0] = s.k * 1e4  # crosses the upper limit during the run
        return p

    cl = softrne.simulate_closed_loop(robot, controller, 0.1, 0.01, p_min=5e3, p_max=60e3)
    assert cl.pressures.min() == 5e3 and cl.pressures.max() == 60e3
    assert cl.commands[3, 0] == 30e3  # inside: unchanged
    assert cl.commands[0, 0] == 5e3 and cl.commands[10, 0] == 60e3
    np.testing.assert_array_equal(cl.commands[:, 1:], np.tile(np.clip(np.linspace(-50e3, 200e3, 12)[1:], 5e3, 60e3),
                                                               (11, 1)))
    # initial_pressures are clamped too; by default p_min = 0 and there is no upper limit.
    late = softrne.simulate_closed_loop(robot, controller, 0.1, 0.01, delay_periods=1, p_min=5e3, p_max=60e3,
                                        initial_pressures=np.full(12, 1e6))
    np.testing.assert_array_equal(late.pressures[0], np.full(12, 60e3))
    wide = softrne.simulate_closed_loop(robot, controller, 0.1, 0.01)
    assert wide.commands.min() == 0.0 and wide.commands.max() == 200e3


class SensorOffline(Exception):
    pass


def test_controller_exception_propagates(robot):
    raised = SensorOffline("sensor 3 offline")

    def controller(s):
        if s.k == 2:
            raise raised
        return np.zeros(12)

    with pytest.raises(SensorOffline) as info:
        softrne.simulate_closed_loop(robot, controller, 0.2, 0.01)
    assert info.value is raised
    assert any(entry.name == "controller" for entry in info.traceback)  # raised where it was
    # Also from another thread, and a KeyError (a LookupError, not a RuntimeError) stays one.
    errors = []

    def run():
        try:
            softrne.simulate_closed_loop(robot, lambda s: {}["missing"], 0.2, 0.01)
        except BaseException as e:  # noqa: BLE001
            errors.append(e)

    t = threading.Thread(target=run)
    t.start()
    t.join()
    assert len(errors) == 1 and type(errors[0]) is KeyError


def test_bad_controller_outputs(robot):
    prefix = r"softrne.simulate_closed_loop: the controller at t = 0 s \(sample 0\) returned "
    with pytest.raises(ValueError, match=prefix + r"shape \(11,\); the robot has 12 pressures: expected \(12,\)"):
        softrne.simulate_closed_loop(robot, lambda s: np.zeros(11), 0.2, 0.01)
    with pytest.raises(ValueError, match=prefix + r"shape \(1, 12\); the robot has 12 pressures"):
        softrne.simulate_closed_loop(robot, lambda s: np.zeros((1, 12)), 0.2, 0.01)
    with pytest.raises(ValueError, match=prefix + r"shape \(\)"):
        softrne.simulate_closed_loop(robot, lambda s: 1e4, 0.2, 0.01)
    with pytest.raises(TypeError, match=prefix + "None; the robot has 12 pressures"):
        softrne.simulate_closed_loop(robot, lambda s: None, 0.2, 0.01)
    with pytest.raises(ValueError, match=prefix + "something that is not an array of numbers"):
        softrne.simulate_closed_loop(robot, lambda s: ["a"] * 12, 0.2, 0.01)

    def nan_at_5(s):
        p = np.full(12, 1e4)
        if s.k == 5:
            p[2] = np.nan
        return p

    with pytest.raises(ValueError, match=r"the controller at t = 0.05 s \(sample 5\) returned a non-finite "
                                         r"pressure \(p1_2 = nan\)"):
        softrne.simulate_closed_loop(robot, nan_at_5, 0.2, 0.01)
    # Lists and other dtypes are converted; the returned array may be reused by the caller.
    buf = np.zeros(12, dtype=np.float32)
    a = softrne.simulate_closed_loop(robot, lambda s: buf, 0.05, 0.01)
    b = softrne.simulate_closed_loop(robot, lambda s: [0.0] * 12, 0.05, 0.01)
    np.testing.assert_array_equal(a.states, b.states)


def test_bad_arguments(robot):
    zero = lambda s: np.zeros(12)  # noqa: E731
    run = softrne.simulate_closed_loop
    prefix = "softrne.simulate_closed_loop: "
    with pytest.raises(TypeError, match=prefix + "controller is not callable"):
        run(robot, np.zeros(12), 0.2, 0.01)
    with pytest.raises(ValueError, match=prefix + r"control_period must be positive and finite \(got 0\)"):
        run(robot, zero, 0.2, 0.0)
    with pytest.raises(ValueError, match=prefix + r"t_end must be positive and finite \(got -1\)"):
        run(robot, zero, -1.0, 0.01)
    with pytest.raises(ValueError, match=prefix + r"delay_periods must be >= 0 \(got -1\)"):
        run(robot, zero, 0.2, 0.01, delay_periods=-1)
    with pytest.raises(ValueError, match=prefix + r"p_min \(100000\) must not exceed p_max \(0\)"):
        run(robot, zero, 0.2, 0.01, p_min=1e5, p_max=0.0)
    with pytest.raises(ValueError, match=prefix + r"q0 has shape \(2,\); the robot has 6 coordinates: expected \(6,\)"):
        run(robot, zero, 0.2, 0.01, np.zeros(2))
    with pytest.raises(ValueError, match=prefix + r"initial_pressures has shape \(3,\); the robot has 12 pressures"):
        run(robot, zero, 0.2, 0.01, initial_pressures=np.zeros(3))
    with pytest.raises(ValueError, match=prefix + "initial_pressures are not finite"):
        run(robot, zero, 0.2, 0.01, initial_pressures=np.full(12, np.nan))
    with pytest.raises(TypeError, match=prefix + "unknown solver option 'rtoll'"):
        run(robot, zero, 0.2, 0.01, rtoll=1e-3)
    with pytest.raises(TypeError, match=prefix + "solver option 'interpolation' does not apply"):
        run(robot, zero, 0.2, 0.01, interpolation="zoh")
    with pytest.raises(ValueError, match=prefix + "rtol must be a positive number"):
        run(robot, zero, 0.2, 0.01, rtol=0.0)
    with pytest.raises(TypeError):  # keyword-only
        run(robot, zero, 0.2, 0.01, None, 2)


def test_integration_failure(robot):
    p = time_pressures(0.0)
    with pytest.raises(softrne.SimulationError, match="softrne.simulate_closed_loop: .*too many steps"):
        softrne.simulate_closed_loop(robot, lambda s: p, 0.5, 0.01, max_steps=2)
    cl = softrne.simulate_closed_loop(robot, lambda s: p, 0.5, 0.01, max_steps=2, check=False)
    assert not cl.ok and "too many steps" in cl.message and "\n" not in cl.message
    assert 1 <= len(cl) < 51
    assert cl.states.shape == (len(cl), 12) and cl.pressures.shape == (len(cl), 12)
    assert "failed" in repr(cl)


def test_runs_in_threads(robot):
    """The integration runs without the GIL and the controller re-takes it: two runs in two
    threads give the results of one run alone."""
    controller = lambda s: time_pressures(s.t) - 1e4 * np.repeat(s.angles, 2)  # noqa: E731
    alone = softrne.simulate_closed_loop(robot, controller, 0.5, 0.01)
    results = [None, None]

    def run(i):
        results[i] = softrne.simulate_closed_loop(robot, controller, 0.5, 0.01)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        np.testing.assert_array_equal(r.states, alone.states)
