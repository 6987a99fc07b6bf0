"""Fixtures of the softrne pytest suite (python/tests; run by ctest as python.pytest).

The C++ programs the tests compare with come from the environment that ctest sets
(python/CMakeLists.txt): SOFTRNE_SIM, SOFTRNE_FIT, SOFTRNE_LOOP (the tools) and SOFTRNE_EVAL
(tests/pinocchio's softrne_pinocchio_eval). Without them those comparisons skip, unless
SOFTRNE_PYTEST_REQUIRE_TOOLS=1 (a build that has the tools), where they fail.
"""

from __future__ import annotations

import os
import pathlib
import subprocess

import numpy as np
import pytest

import softrne

REPO = pathlib.Path(__file__).resolve().parents[2]
DATA = pathlib.Path(os.environ.get("SOFTRNE_DATA_DIR", REPO / "examples" / "data"))
ARM = DATA / "arm-a-1"


def tool(env_name: str) -> str:
    """Path of a C++ program named by an environment variable; skip (or fail) without it."""
    path = os.environ.get(env_name, "")
    if path and os.access(path, os.X_OK):
        return path
    msg = f"{env_name} does not name an executable ({path!r})"
    if os.environ.get("SOFTRNE_PYTEST_REQUIRE_TOOLS") == "1":
        pytest.fail(msg)
    pytest.skip(msg)


def run(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300, **kw)


def tool_error(cmd: list[str]) -> str:
    """The one-line error a tool prints, without its 'tool: ' prefix."""
    p = run(cmd)
    assert p.returncode == 3, (p.returncode, p.stderr)  # 3: bad input file
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1, p.stderr
    name = os.path.basename(cmd[0])
    assert lines[0].startswith(name + ": ")
    return lines[0][len(name) + 2 :]


@pytest.fixture(scope="session")
def robot() -> softrne.Robot:
    return softrne.Robot.from_json(ARM / "robot.json")


@pytest.fixture(scope="session")
def test_data(robot) -> softrne.Dataset:
    return softrne.read_dataset(ARM / "test.csv", robot, require_angles=True)


@pytest.fixture(scope="session")
def train_data(robot) -> softrne.Dataset:
    return softrne.read_dataset(ARM / "train.csv", robot, require_angles=True)


@pytest.fixture()
def rng() -> np.random.Generator:
    return np.random.default_rng(17)
