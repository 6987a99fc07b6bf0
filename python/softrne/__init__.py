"""softrne: dynamics of soft/rigid robot arms from Python.

The compiled core of the softrne C++ library (module ``softrne._softrne``, built with
nanobind): constant-curvature pneumatic joints, rigid links and revolute joints in any order,
inverse and forward dynamics by the recursive Newton-Euler algorithm, simulation of recorded
chamber pressures with CVODE, linearisation and simulation under a controller in the loop,
and the fits and closed loop of the command-line tools.

    >>> import softrne
    >>> robot = softrne.Robot.from_json("examples/data/arm-a-1/robot.json")
    >>> tau = robot.rnea(q, qd, qdd)            # (nq,) or batched (N, nq)
    >>> angles = softrne.simulate(robot, t, pressures, q0)
    >>> lin = robot.linearise(x, p)             # A, B, f; lin.discretise_zoh(h) -> Ad, Bd, cd
    >>> run = softrne.simulate_closed_loop(robot, controller, t_end, control_period)

See docs/python.md.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Optional, Sequence, Union

from ._softrne import (
    ClosedLoopSimulation,
    ControllerInput,
    Dataset,
    DiscreteLinearisation,
    InputError,
    Linearisation,
    Robot,
    SimulationError,
    discretise_zoh,
    read_dataset,
    simulate,
    simulate_closed_loop,
    write_dataset,
)
from . import _softrne

__all__ = [
    "ClosedLoopSimulation",
    "ControllerInput",
    "Dataset",
    "DiscreteLinearisation",
    "InputError",
    "Linearisation",
    "Robot",
    "SimulationError",
    "discretise_zoh",
    "fit",
    "loop",
    "read_dataset",
    "simulate",
    "simulate_closed_loop",
    "write_dataset",
]

__version__ = "0.1.0"

PathOrDataset = Union[str, "os.PathLike[str]", Dataset]
#: One recording, or several (a list or tuple): each is simulated from its own first sample.
Recordings = Union[PathOrDataset, Sequence[PathOrDataset]]


def _robot_from_dict(d: dict) -> Robot:
    """What pickle calls to rebuild a Robot (Robot.__reduce__)."""
    return Robot.from_dict(d)


def _dataset(robot: Robot, data: Recordings, initial_motion: str = "rest") -> Dataset:
    """One data set of one or several recordings (docs/formats.md section 2): several are
    stacked, each simulated from its own first sample; initial_motion 'estimated' starts each
    at the angle rates of its first samples."""
    parts = list(data) if isinstance(data, (list, tuple)) else [data]
    if not parts:
        raise ValueError("softrne: no recordings given")
    sets = [p if isinstance(p, Dataset) else read_dataset(p, robot, require_angles=True) for p in parts]
    if len(sets) == 1 and initial_motion == "rest":
        return sets[0]
    return _softrne._stack_recordings(sets, initial_motion)


def fit(
    robot: Robot,
    data: Recordings,
    test: Optional[Recordings] = None,
    *,
    pressure_gain: bool = False,
    seed: int = 1,
    threads: int = 2,
    initial_motion: str = "rest",
    fit_to: str = "all",
    frame_per_recording: bool = False,
) -> dict[str, Any]:
    """Fits stiffness and damping of every joint (and the effects' parameters) to measured
    angles (and motion-capture markers, where the robot declares them) by simulation error,
    as ``softrne-fit`` does with the same options.

    ``data`` and ``test`` are Datasets with measured angles or paths of data set CSVs, or
    lists of them (several recordings, each simulated from its own first sample);
    ``initial_motion`` 'rest' or 'estimated' (recordings that start in motion), ``fit_to``
    'all', 'angles' or 'markers', ``frame_per_recording`` as ``softrne-fit``'s options.
    Returns the fit report (``softrne-fit --report``, format ``softrne-fit-report/1``) as a
    dict: the parameters with standard errors, error statistics before and after on the
    training (and test) data, and ``fitted_robot`` (``Robot.from_dict`` reads it).
    Raises SimulationError if a model fails to simulate; Ctrl-C stops it (KeyboardInterrupt).
    """
    train = _dataset(robot, data, initial_motion)
    held_out = None if test is None else _dataset(robot, test, initial_motion)
    return _softrne._fit(robot, train, held_out, pressure_gain, seed, threads, fit_to, frame_per_recording)


def loop(
    robot: Robot,
    train: Recordings,
    test: Recordings,
    *,
    threads: int = 2,
    max_effects: int = 4,
    log: Optional[Callable[[str], None]] = None,
    initial_motion: str = "rest",
) -> dict[str, Any]:
    """The closed loop of ``softrne-loop``: baseline fit, residual analysis, effect discovery
    in cross-validation folds of the training data, refit. ``test`` only measures.

    ``train`` and ``test`` may be lists of recordings (the folds then hold out whole
    recordings); ``initial_motion`` as in fit(). Returns the loop report (format
    ``softrne-loop-report/2``, docs/formats.md section 5) as a dict, the same JSON that
    ``softrne-loop --out`` writes. ``log`` receives the progress lines that ``softrne-loop``
    prints.
    """
    return _softrne._loop(robot, _dataset(robot, train, initial_motion), _dataset(robot, test, initial_motion),
                          threads, max_effects, log)
