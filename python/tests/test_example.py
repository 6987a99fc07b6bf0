"""The Python examples run: simulate_arm.py writes its PNG (where matplotlib is installed),
lqr_regulate.py passes its own check."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from conftest import REPO


def test_simulate_arm_example(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "arm.png"
    p = subprocess.run([sys.executable, str(REPO / "examples/python/simulate_arm.py"), "--out", str(out)],
                       capture_output=True, text=True, timeout=300, env=dict(os.environ, MPLBACKEND="Agg"))
    assert p.returncode == 0, p.stderr
    assert "wrote" in p.stdout and out.stat().st_size > 10_000
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_lqr_regulate_example():
    """examples/python/lqr_regulate.py (numpy only) designs its LQR and passes its own check."""
    p = subprocess.run([sys.executable, str(REPO / "examples/python/lqr_regulate.py")], capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "regulation error" in p.stdout and "passed" in p.stdout
