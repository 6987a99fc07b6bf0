"""The dynamics functions: equal to the C++ library's numbers, consistent with each other and
with finite differences, batched == a loop of single calls."""

from __future__ import annotations

import json

import numpy as np
import pytest

import softrne

from conftest import ARM, run, tool


def random_states(rng, n, nq):
    q = rng.uniform(-0.6, 0.6, (n, nq))
    qd = rng.uniform(-2.0, 2.0, (n, nq))
    qdd = rng.uniform(-5.0, 5.0, (n, nq))
    tau = rng.uniform(-3.0, 3.0, (n, nq))
    return q, qd, qdd, tau


def test_names_and_sizes(robot):
    assert robot.nq == 6
    assert robot.coordinate_names == ["u1", "v1", "u2", "v2", "u3", "v3"]
    assert robot.pressure_names == [f"p{j}_{k}" for j in (1, 2, 3) for k in range(4)]
    assert robot.num_pressures == 12
    assert robot.segment_names == ["joint1", "link1", "joint2", "link2", "joint3", "link3"]
    np.testing.assert_array_equal(robot.gravity_vector, [0.0, 0.0, 9.81])


def test_equal_to_cpp(robot, rng, tmp_path):
    """rnea, M, G, C qd + G and forward dynamics equal those of the C++ library, evaluated by
    tests/pinocchio's softrne_pinocchio_eval on the same robot file and states."""
    helper = tool("SOFTRNE_EVAL")
    q, qd, qdd, tau = random_states(rng, 8, robot.nq)
    states = tmp_path / "states.txt"
    with open(states, "w") as f:
        for k in range(len(q)):
            f.write(" ".join(repr(float(x)) for x in np.concatenate([q[k], qd[k], qdd[k], tau[k]])) + "\n")
    p = run([helper, str(ARM / "robot.json"), str(states)])
    assert p.returncode == 0, p.stderr
    rows = [json.loads(line) for line in p.stdout.splitlines()]
    assert len(rows) == len(q)
    for k, c in enumerate(rows):
        tol = dict(rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(robot.rnea(q[k], qd[k], qdd[k]), c["rnea"], **tol)
        np.testing.assert_allclose(robot.mass_matrix(q[k]), c["mass_matrix"], **tol)
        np.testing.assert_allclose(robot.gravity(q[k]), c["gravity"], **tol)
        np.testing.assert_allclose(robot.bias(q[k], qd[k], with_gravity=True), c["bias"], **tol)
        np.testing.assert_allclose(robot.forward_dynamics(q[k], qd[k], tau[k]), c["forward_dynamics"], **tol)


def test_drnea_dqdd_is_mass_matrix(robot, rng):
    q, qd, qdd, _ = random_states(rng, 3, robot.nq)
    h = 1e-3  # rnea is linear in qdd: central differences are exact up to rounding
    for k in range(3):
        J = np.empty((robot.nq, robot.nq))
        for j in range(robot.nq):
            e = np.zeros(robot.nq)
            e[j] = h
            J[:, j] = (robot.rnea(q[k], qd[k], qdd[k] + e) - robot.rnea(q[k], qd[k], qdd[k] - e)) / (2 * h)
        M = robot.mass_matrix(q[k])
        np.testing.assert_allclose(J, M, rtol=0, atol=1e-10 * np.abs(M).max())
        np.testing.assert_allclose(M, M.T, rtol=0, atol=1e-15 * np.abs(M).max())
        assert np.linalg.eigvalsh(M).min() > 0


def test_gravity_and_bias_split_rnea(robot, rng):
    q, qd, qdd, _ = random_states(rng, 3, robot.nq)
    z = np.zeros(robot.nq)
    for k in range(3):
        G = robot.gravity(q[k])
        np.testing.assert_allclose(G, robot.rnea(q[k], z, z), rtol=1e-14, atol=1e-14)
        C = robot.bias(q[k], qd[k])
        np.testing.assert_allclose(C + G, robot.rnea(q[k], qd[k], z), rtol=1e-13, atol=1e-13)
        np.testing.assert_allclose(robot.bias(q[k], qd[k], with_gravity=True), C + G, rtol=1e-13, atol=1e-13)
        tau = robot.rnea(q[k], qd[k], qdd[k])
        np.testing.assert_allclose(tau, robot.mass_matrix(q[k]) @ qdd[k] + C + G, rtol=1e-12, atol=1e-12)


def test_power_balance_against_finite_differences(robot, rng):
    """Lagrangian consistency: qd . C(q, qd) qd = 1/2 qd^T dM/dt qd, with dM/dt = dM/dq qd by
    central differences of mass_matrix along qd (the default InertiaRate::Consistent)."""
    q, qd, _, _ = random_states(rng, 3, robot.nq)
    h = 1e-5
    for k in range(3):
        Mdot = (robot.mass_matrix(q[k] + h * qd[k]) - robot.mass_matrix(q[k] - h * qd[k])) / (2 * h)
        lhs = qd[k] @ robot.bias(q[k], qd[k])
        rhs = 0.5 * qd[k] @ Mdot @ qd[k]
        assert lhs == pytest.approx(rhs, rel=1e-7, abs=1e-9)


def test_gravity_is_gradient_of_potential_along_frames(robot, rng):
    """qd . G(q) = dV/dt for the potential energy; the rigid links' part of V is m g . com from
    frames(), so a robot of rigid links between revolute joints checks G against it."""
    d = {
        "format": "softrne-robot/1",
        "gravity": [0.0, -9.81, 0.0],
        "segments": [
            {"type": "revolute_joint", "name": "r1", "axis": [0, 0, 1], "stiffness": 0, "damping": 0},
            {"type": "rigid_link", "name": "l1", "mass": 2.0, "length": 0.0, "com": [0.3, 0, 0],
             "inertia": [0.01, 0.02, 0.03, 0, 0, 0]},
            {"type": "revolute_joint", "name": "r2", "axis": [0, 0, 1], "stiffness": 0, "damping": 0},
            {"type": "rigid_link", "name": "l2", "mass": 1.0, "length": 0.0, "com": [0.2, 0, 0],
             "inertia": [0.01, 0.02, 0.03, 0, 0, 0]},
        ],
    }
    r = softrne.Robot.from_dict(d)
    # Links of length 0 do not move their distal frame: the com of link i is frame i's
    # placement applied to its com.
    g = r.gravity_vector

    def V(q):
        F = r.frames(q)
        return -(2.0 * g @ (F[1, :3, :3] @ [0.3, 0, 0] + F[1, :3, 3]) +
                 1.0 * g @ (F[3, :3, :3] @ [0.2, 0, 0] + F[3, :3, 3]))

    for q in rng.uniform(-2, 2, (3, r.nq)):
        h = 1e-6
        grad = np.array([(V(q + h * e) - V(q - h * e)) / (2 * h) for e in np.eye(r.nq)])
        np.testing.assert_allclose(r.gravity(q), grad, rtol=1e-8, atol=1e-9)


def test_forward_dynamics_inverts_rnea(robot, rng):
    q, qd, qdd, tau = random_states(rng, 4, robot.nq)
    for k in range(4):
        a = robot.forward_dynamics(q[k], qd[k], tau[k])
        np.testing.assert_allclose(robot.rnea(q[k], qd[k], a), tau[k], rtol=1e-11, atol=1e-11)
        np.testing.assert_allclose(robot.aba(q[k], qd[k], tau[k]), a, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(robot.forward_dynamics(q[k], qd[k], robot.rnea(q[k], qd[k], qdd[k])),
                                   qdd[k], rtol=1e-10, atol=1e-10)


def test_frames(robot, rng):
    F = robot.frames(np.zeros(robot.nq))
    assert F.shape == (6, 4, 4)
    heights = np.cumsum([0.2, 0.15, 0.2, 0.15, 0.2, 0.05])
    for i in range(6):
        np.testing.assert_allclose(F[i, :3, :3], np.eye(3), atol=1e-15)
        np.testing.assert_allclose(F[i, :3, 3], [0, 0, heights[i]], atol=1e-15)
        np.testing.assert_array_equal(F[i, 3], [0, 0, 0, 1])
    for q in rng.uniform(-0.8, 0.8, (3, robot.nq)):
        F = robot.frames(q)
        for T in F:
            np.testing.assert_allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-14)
            assert np.linalg.det(T[:3, :3]) == pytest.approx(1.0, abs=1e-14)
        # A bent CC joint rotates the frames after it: u1 alone tilts everything past joint 1.
    q = np.zeros(robot.nq)
    q[0] = 0.3
    F = robot.frames(q)
    assert not np.allclose(F[0, :3, :3], np.eye(3))
    np.testing.assert_allclose(F[1, :3, :3], F[0, :3, :3], atol=1e-15)  # a straight link


@pytest.mark.parametrize("threads", [1, 3])
def test_batched_equals_loop(robot, rng, threads):
    n = 1000
    q, qd, qdd, tau = random_states(rng, n, robot.nq)
    cases = {
        "rnea": ((q, qd, qdd), {}),
        "mass_matrix": ((q,), {}),
        "gravity": ((q,), {}),
        "bias": ((q, qd), {}),
        "forward_dynamics": ((q, qd, tau), {}),
        "aba": ((q, qd, tau), {}),
        "frames": ((q,), {}),
    }
    for name, (args, kw) in cases.items():
        f = getattr(robot, name)
        batch = f(*args, threads=threads, **kw)
        single = np.stack([f(*(a[k] for a in args), **kw) for k in range(n)])
        assert batch.shape == single.shape, name
        np.testing.assert_array_equal(batch, single, err_msg=name)
    assert robot.rnea(q[:0], qd[:0], qdd[:0]).shape == (0, robot.nq)


def test_inputs_converted(robot):
    z = [0.0] * robot.nq
    a = robot.rnea(z, z, z)
    np.testing.assert_array_equal(a, robot.rnea(np.zeros(6), np.zeros(6), np.zeros(6)))
    q32 = np.linspace(-0.5, 0.5, 6, dtype=np.float32)
    np.testing.assert_array_equal(robot.gravity(q32), robot.gravity(q32.astype(np.float64)))
    strided = np.linspace(-0.5, 0.5, 12)[::2]
    np.testing.assert_array_equal(robot.gravity(strided), robot.gravity(strided.copy()))
    Q = np.asfortranarray(np.linspace(-0.5, 0.5, 30).reshape(5, 6))
    np.testing.assert_array_equal(robot.gravity(Q), robot.gravity(np.ascontiguousarray(Q)))


@pytest.mark.parametrize(
    "call, name, shape",
    [
        (lambda r, z: r.rnea(np.zeros(5), z, z), "q", "(5,)"),
        (lambda r, z: r.rnea(z, np.zeros(7), z), "qd", "(7,)"),
        (lambda r, z: r.rnea(z, z, np.zeros((2, 6))), "qdd", "(2, 6)"),
        (lambda r, z: r.mass_matrix(np.zeros((3, 4))), "q", "(3, 4)"),
        (lambda r, z: r.gravity(np.zeros((1, 2, 6))), "q", "(1, 2, 6)"),
        (lambda r, z: r.bias(np.zeros((4, 6)), np.zeros((3, 6))), "qd", "(3, 6)"),
        (lambda r, z: r.aba(z, z, np.zeros(2)), "tau", "(2,)"),
        (lambda r, z: r.forward_dynamics(z, z, np.zeros(())), "tau", "()"),
        (lambda r, z: r.frames(np.zeros(0)), "q", "(0,)"),
    ],
)
def test_bad_shapes_raise_value_error(robot, call, name, shape):
    with pytest.raises(ValueError) as e:
        call(robot, np.zeros(robot.nq))
    msg = str(e.value)
    assert not isinstance(e.value, softrne.InputError)
    assert f" {name} has shape {shape}" in msg, msg
    assert "6" in msg and msg.startswith("softrne."), msg


def test_bad_values_raise_value_error(robot):
    z = np.zeros(robot.nq)
    with pytest.raises(TypeError):
        robot.gravity(None)
    with pytest.raises(ValueError, match="qd is not an array of numbers"):
        robot.rnea(z, "abc", z)
    with pytest.raises(ValueError, match="q is not an array of numbers"):
        robot.rnea([[0.0] * 6, [0.0] * 5], z, z)


def test_derivatives_against_central_differences(robot, rng):
    """rnea_derivatives and aba_derivatives (exact, AutoDiff in C++) against central
    differences of rnea and aba through the same Python API (step 1e-6: truncation ~1e-12,
    roundoff ~1e-10 of the forces' size); the third block is M and M^-1; batched == singles."""
    q, qd, qdd, tau = random_states(rng, 4, robot.nq)
    h = 1e-6
    eye = np.eye(robot.nq)

    def central(f, x):
        return np.stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in eye], axis=1)

    for k in range(len(q)):
        D = robot.rnea_derivatives(q[k], qd[k], qdd[k])
        assert D.shape == (3, robot.nq, robot.nq)
        np.testing.assert_allclose(D[0], central(lambda x: robot.rnea(x, qd[k], qdd[k]), q[k]), rtol=0, atol=1e-7)
        np.testing.assert_allclose(D[1], central(lambda x: robot.rnea(q[k], x, qdd[k]), qd[k]), rtol=0, atol=1e-7)
        np.testing.assert_allclose(D[2], robot.mass_matrix(q[k]), rtol=0, atol=1e-12)
        A = robot.aba_derivatives(q[k], qd[k], tau[k])
        scale = max(1.0, np.abs(robot.aba(q[k], qd[k], tau[k])).max())
        np.testing.assert_allclose(A[0], central(lambda x: robot.aba(x, qd[k], tau[k]), q[k]), rtol=0, atol=1e-6 * scale)
        np.testing.assert_allclose(A[1], central(lambda x: robot.aba(q[k], x, tau[k]), qd[k]), rtol=0, atol=1e-6 * scale)
        np.testing.assert_allclose(A[2] @ robot.mass_matrix(q[k]), eye, rtol=0, atol=1e-9)
    batched = robot.rnea_derivatives(q, qd, qdd)
    assert batched.shape == (len(q), 3, robot.nq, robot.nq)
    np.testing.assert_array_equal(batched[2], robot.rnea_derivatives(q[2], qd[2], qdd[2]))
    np.testing.assert_array_equal(robot.aba_derivatives(q, qd, tau)[1], robot.aba_derivatives(q[1], qd[1], tau[1]))
