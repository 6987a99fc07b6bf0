"""softrne: dynamics of soft/rigid robot arms from Python.

The compiled core of the softrne C++ library (module ``softrne._softrne``, built with
nanobind): constant-curvature pneumatic joints, rigid links and revolute joints in any order,
inverse and forward dynamics by the recursive Newton-Euler algorithm, simulation of recorded
chamber pressures with CVODE, and the fits and closed loop of the command-line tools.

    >>> import softrne
    >>> robot = softrne.Robot.from_json("examples/data/arm-a-1/robot.json")
    >>> tau = robot.rnea(q, qd, qdd)            # (nq,) or batched (N, nq)
    >>> angles = softrne.simulate(robot, t, pressures, q0)

See docs/python.md.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Optional, Union

from ._softrne import (
    Dataset,
    InputError,
    Robot,
    SimulationError,
    read_dataset,
    simulate,
    write_dataset,
)
from . import _softrne

__all__ = [
    "Dataset",
    "InputError",
    "Robot",
    "SimulationError",
    "fit",
    "loop",
    "read_dataset",
    "simulate",
    "write_dataset",
]

__version__ = "0.1.0"

PathOrDataset = Union[str, "os.PathLike[str]", Dataset]


def _robot_from_dict(d: dict) -> Robot:
    """What pickle calls to rebuild a Robot (Robot.__reduce__)."""
    return Robot.from_dict(d)


def _dataset(robot: Robot, data: PathOrDataset) -> Dataset:
    if isinstance(data, Dataset):
        return data
    return read_dataset(data, robot, require_angles=True)


def fit(
    robot: Robot,
    data: PathOrDataset,
    test: Optional[PathOrDataset] = None,
    *,
    pressure_gain: bool = False,
    seed: int = 1,
    threads: int = 2,
) -> dict[str, Any]:
    """Fits stiffness and damping of every joint (and the effects' parameters) to measured
    angles by simulation error, as ``softrne-fit`` does with the same options.

    ``data`` and ``test`` are Datasets with measured angles or paths of data set CSVs.
    Returns the fit report (``softrne-fit --report``, format ``softrne-fit-report/1``) as a
    dict: the parameters with standard errors, error statistics before and after on the
    training (and test) data, and ``fitted_robot`` (``Robot.from_dict`` reads it).
    Raises SimulationError if a model fails to simulate; Ctrl-C stops it (KeyboardInterrupt).
    """
    train = _dataset(robot, data)
    held_out = None if test is None else _dataset(robot, test)
    return _softrne._fit(robot, train, held_out, pressure_gain, seed, threads)


def loop(
    robot: Robot,
    train: PathOrDataset,
    test: PathOrDataset,
    *,
    threads: int = 2,
    max_effects: int = 4,
    log: Optional[Callable[[str], None]] = None,
) -> dict[str, Any]:
    """The closed loop of ``softrne-loop``: baseline fit, residual analysis, effect discovery
    in cross-validation folds of the training data, refit. ``test`` only measures.

    Returns the loop report (format ``softrne-loop-report/2``, docs/formats.md section 5) as
    a dict, the same JSON that ``softrne-loop --out`` writes. ``log`` receives the progress
    lines that ``softrne-loop`` prints.
    """
    return _softrne._loop(robot, _dataset(robot, train), _dataset(robot, test), threads, max_effects, log)
