"""The type stubs that nanobind's stubgen writes next to the module (built with it, and
installed in the wheel) cover the API with numpy types."""

from __future__ import annotations

import pathlib

import pytest

import softrne


def test_stubs_next_to_the_module():
    stub = pathlib.Path(softrne._softrne.__file__).with_name("_softrne.pyi")
    if not stub.exists():
        pytest.skip(f"no {stub} (the stub target was not built)")
    text = stub.read_text()
    for name in ("class Robot", "def rnea(self, q: numpy.typing.ArrayLike", "def mass_matrix", "def gravity",
                 "def bias", "def forward_dynamics", "def aba", "def frames", "def from_json", "def from_dict",
                 "def to_dict(self) -> dict", "class Dataset", "def read_dataset", "def write_dataset",
                 "def simulate(robot: Robot", "**solver_options", "-> numpy.typing.NDArray[numpy.float64]",
                 "def num_states(self) -> int", "def initial_state", "def state_derivative",
                 "def linearise(self, x: numpy.typing.ArrayLike, p: numpy.typing.ArrayLike) -> Linearisation",
                 "class Linearisation", "class DiscreteLinearisation", "def discretise_zoh(self, h: float)",
                 "def discretise_zoh(A: numpy.typing.ArrayLike", "class ControllerInput", "class ClosedLoopSimulation",
                 "def simulate_closed_loop(robot: Robot, controller: Callable[[ControllerInput], "
                 "numpy.typing.ArrayLike]"):
        assert name in text, name
    assert (stub.parent / "py.typed").exists()
