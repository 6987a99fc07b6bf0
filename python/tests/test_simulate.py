"""simulate(): the same simulation as softrne-sim, to 1e-12."""

from __future__ import annotations

import numpy as np
import pytest

import softrne

from conftest import ARM, run, tool


def sim_tool(tmp_path, *options):
    out = tmp_path / "sim.csv"
    p = run([tool("SOFTRNE_SIM"), "--robot", str(ARM / "robot.json"), "--pressures", str(ARM / "test.csv"),
             "--out", str(out), "--quiet", *options])
    assert p.returncode == 0, p.stderr
    table = np.loadtxt(out, delimiter=",", comments="#", skiprows=1)
    return table[:, 0], table[:, 1:]


def test_same_as_softrne_sim(robot, test_data, tmp_path):
    t, expected = sim_tool(tmp_path)
    np.testing.assert_array_equal(t, test_data.t)
    angles = softrne.simulate(robot, test_data.t, test_data.pressures, q0=test_data.angles[0])
    assert angles.shape == (len(test_data), robot.nq)
    assert np.abs(angles - expected).max() <= 1e-12
    # It is a simulation that moves: the arm swings by more than 0.1 rad.
    assert np.ptp(angles, axis=0).max() > 0.1


def test_same_as_softrne_sim_with_options(robot, test_data, tmp_path):
    _, expected = sim_tool(tmp_path, "--rtol", "1e-7", "--interpolation", "linear", "--jacobian", "ad-forward")
    angles = softrne.simulate(robot, test_data.t, test_data.pressures, test_data.angles[0], rtol=1e-7,
                              interpolation="linear", jacobian="ad-forward")
    assert np.abs(angles - expected).max() <= 1e-12
    default = softrne.simulate(robot, test_data.t, test_data.pressures, test_data.angles[0])
    assert np.abs(default - angles).max() > 1e-9  # the options changed something


def test_q0_default_is_rest_at_zero(robot, test_data):
    n = 50
    a = softrne.simulate(robot, test_data.t[:n], test_data.pressures[:n])
    b = softrne.simulate(robot, test_data.t[:n], test_data.pressures[:n], np.zeros(robot.nq))
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a[0], np.zeros(robot.nq))


def test_bad_arguments(robot, test_data):
    t, p = test_data.t[:20], test_data.pressures[:20]
    with pytest.raises(ValueError, match=r"pressures has shape \(20, 11\); expected \(20, 12\)"):
        softrne.simulate(robot, t, p[:, :11])
    with pytest.raises(ValueError, match=r"q0 has shape \(5,\); expected \(6,\)"):
        softrne.simulate(robot, t, p, np.zeros(5))
    with pytest.raises(TypeError, match="unknown solver option 'rtoll'"):
        softrne.simulate(robot, t, p, rtoll=1e-3)
    with pytest.raises(ValueError, match="rtol must be a positive number"):
        softrne.simulate(robot, t, p, rtol=-1.0)
    with pytest.raises(ValueError, match="interpolation must be"):
        softrne.simulate(robot, t, p, interpolation="cubic")


def test_failure_raises_simulation_error(robot, test_data):
    with pytest.raises(softrne.SimulationError, match="too many steps"):
        softrne.simulate(robot, test_data.t, test_data.pressures, test_data.angles[0], max_steps=5)
