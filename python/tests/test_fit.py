"""fit() and loop(): the same reports as softrne-fit --report and softrne-loop --out."""

from __future__ import annotations

import json

import numpy as np
import pytest

import softrne

from conftest import ARM, run, tool


def without_timing(report):
    r = json.loads(json.dumps(report))
    r.pop("wall_seconds")
    return r


@pytest.fixture(scope="module")
def short_files(robot, train_data, test_data, tmp_path_factory):
    """The first 3 s of each data set, written by write_dataset (the tools read the same)."""
    d = tmp_path_factory.mktemp("short")
    paths = {}
    for name, data in {"train": train_data, "test": test_data}.items():
        n = 300
        paths[name] = d / f"{name}.csv"
        softrne.write_dataset(paths[name], robot, data.t[:n], data.pressures[:n], data.angles[:n])
    return paths


def test_fit_same_report_as_softrne_fit(robot, short_files, tmp_path):
    train, test = str(short_files["train"]), str(short_files["test"])
    report_path = tmp_path / "report.json"
    p = run([tool("SOFTRNE_FIT"), "--robot", str(ARM / "robot.json"), "--data", train, "--test", test,
             "--out", str(tmp_path / "fitted.json"), "--report", str(report_path), "--quiet"])
    assert p.returncode == 0, p.stderr
    expected = json.loads(report_path.read_text())
    report = softrne.fit(robot, train, test)
    assert report["format"] == "softrne-fit-report/1"
    assert without_timing(report) == without_timing(expected)
    # The fitted robot is a robot, and the one softrne-fit wrote.
    fitted = softrne.Robot.from_dict(report["fitted_robot"])
    assert fitted.to_dict() == softrne.Robot.from_json(tmp_path / "fitted.json").to_dict()
    names = [p["name"] for p in report["parameters"]]
    assert names[:2] == ["stiffness.u1", "damping.u1"] and len(names) == 12
    assert report["train"]["after"]["median"] < report["train"]["before"]["median"]


def test_fit_takes_datasets(robot, short_files):
    data = softrne.read_dataset(short_files["train"], robot, require_angles=True)
    a = softrne.fit(robot, data, seed=1)
    b = softrne.fit(robot, str(short_files["train"]))
    assert without_timing(a) == without_timing(b)
    assert "test" not in a


def test_fit_takes_several_recordings_as_softrne_fit_does(robot, train_data, tmp_path):
    """A list of recordings with initial_motion='estimated': the same report as softrne-fit with
    the option repeated (the 'recordings' key included), one entry per file."""
    paths = []
    for k, (a, b) in enumerate(((0, 150), (150, 300))):
        paths.append(tmp_path / f"part{k}.csv")
        t = train_data.t[a:b] - train_data.t[a]
        softrne.write_dataset(paths[-1], robot, t, train_data.pressures[a:b], train_data.angles[a:b])
    report_path = tmp_path / "report.json"
    p = run([tool("SOFTRNE_FIT"), "--robot", str(ARM / "robot.json"), "--data", str(paths[0]), "--data",
             str(paths[1]), "--initial-motion", "estimated", "--out", str(tmp_path / "fitted.json"),
             "--report", str(report_path), "--quiet"])
    assert p.returncode == 0, p.stderr
    expected = json.loads(report_path.read_text())
    report = softrne.fit(robot, [str(x) for x in paths], initial_motion="estimated")
    assert without_timing(report) == without_timing(expected)
    rec = report["recordings"]["train"]
    assert [r["rows"] for r in rec] == [150, 150] and rec[1]["first_row"] == 150
    assert all(len(r["initial_rates"]) == robot.nq for r in rec)
    with pytest.raises(ValueError, match="initial_motion"):
        softrne.fit(robot, [str(x) for x in paths], initial_motion="moving")


def test_fit_needs_angles(robot, test_data):
    no_angles = softrne.Dataset(robot, test_data.t[:50], test_data.pressures[:50], None, source="mine")
    with pytest.raises(softrne.SimulationError, match="^mine: the data set has no measured angles"):
        softrne.fit(robot, no_angles)
    with pytest.raises(softrne.InputError, match="missing.csv"):
        softrne.fit(robot, "missing.csv")


def test_loop_same_report_as_softrne_loop(robot, short_files, tmp_path):
    train, test = str(short_files["train"]), str(short_files["test"])
    out = tmp_path / "loop.json"
    p = run([tool("SOFTRNE_LOOP"), "--robot", str(ARM / "robot.json"), "--train", train, "--test", test,
             "--out", str(out), "--max-effects", "0", "--quiet"])
    assert p.returncode == 0, p.stderr
    expected = json.loads(out.read_text())
    lines = []
    report = softrne.loop(robot, train, test, max_effects=0, log=lines.append)
    assert report["format"] == "softrne-loop-report/2"
    assert without_timing(report) == without_timing(expected)
    assert lines and all(isinstance(s, str) for s in lines)


def test_ctrl_c_stops_a_fit():
    """SIGINT during fit() (no GIL, C++ running) stops it with KeyboardInterrupt instead of
    letting it run to its end, and Python's own handler is back afterwards."""
    import os
    import signal
    import subprocess
    import sys
    import time

    code = f"""
import signal, sys, time, softrne
r = softrne.Robot.from_json({str(ARM / 'robot.json')!r})
print('started', flush=True)
t0 = time.time()
try:
    softrne.fit(r, {str(ARM / 'train.csv')!r})
    print('finished', flush=True)
except KeyboardInterrupt:
    print('interrupted', round(time.time() - t0, 2), signal.getsignal(signal.SIGINT) is signal.default_int_handler, flush=True)
"""
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, env=os.environ)
    assert p.stdout.readline().strip() == "started"
    time.sleep(0.5)  # the fit takes seconds
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=60)
    assert p.returncode == 0
    words = out.split()
    assert words[0] == "interrupted", out  # not "finished": the fit stopped
    assert words[2] == "True", out  # Python's SIGINT handler is back
