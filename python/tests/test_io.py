"""Robot files, dicts and data sets: round trips, and the tools' one-line errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

import softrne

from conftest import ARM, tool, tool_error


def test_round_trip_dict(robot, rng, tmp_path):
    d = robot.to_dict()
    assert d["format"] == "softrne-robot/1"
    assert [s["name"] for s in d["segments"]] == robot.segment_names
    r2 = softrne.Robot.from_dict(d)
    assert r2.to_dict() == d
    # The file's dict reads back as the same robot.
    with open(ARM / "robot.json") as f:
        from_file = softrne.Robot.from_dict(json.load(f))
    assert from_file.to_dict() == d
    q, qd, qdd = rng.uniform(-0.5, 0.5, (3, robot.nq))
    np.testing.assert_array_equal(r2.rnea(q, qd, qdd), robot.rnea(q, qd, qdd))
    # numpy values inside a dict are accepted.
    d2 = json.loads(json.dumps(d))
    d2["gravity"] = np.array([0.0, 0.0, 9.81])
    d2["segments"][0]["mass"] = np.float64(0.8)
    assert softrne.Robot.from_dict(d2).to_dict() == d
    # to_json writes a file that reads back bit for bit.
    robot.to_json(tmp_path / "r.json")
    assert softrne.Robot.from_json(str(tmp_path / "r.json")).to_dict() == d


def test_changed_dict_changes_dynamics(robot):
    d = robot.to_dict()
    d["segments"][1]["mass"] = 3.0
    heavier = softrne.Robot.from_dict(d)
    q = np.full(robot.nq, 0.2)
    assert np.all(np.abs(heavier.gravity(q)[:2]) > np.abs(robot.gravity(q)[:2]))


def bad_robot_files(tmp_path):
    text = (ARM / "robot.json").read_text()
    cases = {
        "negative_mass.json": text.replace('"mass": 0.8', '"mass": -0.8', 1),
        "unknown_type.json": text.replace('"rigid_link"', '"rigid_rod"', 1),
        "truncated.json": text[:300],
        "unknown_field.json": text.replace('"height"', '"heigth"', 1),
    }
    for name, body in cases.items():
        (tmp_path / name).write_text(body)
    return [tmp_path / n for n in cases]


def test_bad_robot_file_same_message_as_tools(tmp_path):
    sim = tool("SOFTRNE_SIM")
    for path in bad_robot_files(tmp_path):
        with pytest.raises(softrne.InputError) as e:
            softrne.Robot.from_json(path)
        assert isinstance(e.value, ValueError)
        expected = tool_error([sim, "--robot", str(path), "--pressures", str(ARM / "test.csv")])
        assert str(e.value) == expected
        assert "\n" not in str(e.value)
        assert e.value.source == str(path)
        assert str(e.value).startswith(f"{path}: {e.value.where}: " if e.value.where else f"{path}: ")


def test_bad_robot_file_messages_name_the_field(tmp_path):
    neg, unknown_type, truncated, unknown_field = bad_robot_files(tmp_path)
    with pytest.raises(softrne.InputError, match=r"segments\[0\] 'joint1': field 'mass': must be > 0"):
        softrne.Robot.from_json(neg)
    with pytest.raises(softrne.InputError, match="rigid_rod"):
        softrne.Robot.from_json(unknown_type)
    with pytest.raises(softrne.InputError, match="heigth"):
        softrne.Robot.from_json(unknown_field)
    with pytest.raises(softrne.InputError) as e:
        softrne.Robot.from_json(tmp_path / "missing.json")
    assert e.value.category == "FileNotFound"


def test_bad_dict(robot):
    d = robot.to_dict()
    d["segments"][2]["mass"] = -1.0
    with pytest.raises(softrne.InputError, match=r"^<dict>: segments\[2\] 'joint2': field 'mass': must be > 0 \(got -1\)$") as e:
        softrne.Robot.from_dict(d)
    assert e.value.source == "<dict>"
    d = robot.to_dict()
    d["format"] = "softrne-robot/9"
    with pytest.raises(softrne.InputError, match="unknown format"):
        softrne.Robot.from_dict(d, source="mine")
    with pytest.raises(softrne.InputError, match="^<dict>: "):
        softrne.Robot.from_dict({"format": "softrne-robot/1", "gravity": [0, 0, float("nan")], "segments": []})
    with pytest.raises(softrne.InputError, match="cannot be written as JSON"):
        softrne.Robot.from_dict({"format": object()})


def test_read_dataset(robot, test_data):
    d = test_data
    assert len(d) == d.t.shape[0] > 1000
    assert d.pressures.shape == (len(d), robot.num_pressures)
    assert d.angles.shape == (len(d), robot.nq)
    assert d.has_angles and d.source == str(ARM / "test.csv")
    assert d.pressure_names == robot.pressure_names and d.angle_names == robot.coordinate_names
    assert np.all(np.diff(d.t) > 0)
    # The first data row of the file, parsed by numpy.
    lines = [ln for ln in (ARM / "test.csv").read_text().splitlines() if ln and not ln.startswith("#")]
    header = lines[0].split(",")
    first = dict(zip(header, map(float, lines[1].split(","))))
    assert d.t[0] == first["t"]
    assert d.pressures[0, 5] == first[robot.pressure_names[5]]
    assert d.angles[0, 3] == first["v2"]


def test_write_dataset_round_trip(robot, test_data, tmp_path):
    path = tmp_path / "out.csv"
    softrne.write_dataset(path, robot, test_data.t, test_data.pressures, test_data.angles)
    back = softrne.read_dataset(path, robot, require_angles=True)
    np.testing.assert_array_equal(back.t, test_data.t)
    np.testing.assert_array_equal(back.pressures, test_data.pressures)
    np.testing.assert_array_equal(back.angles, test_data.angles)
    softrne.write_dataset(path, robot, test_data.t, test_data.pressures)
    assert softrne.read_dataset(path, robot).angles is None
    with pytest.raises(softrne.InputError, match="missing column 'u1'"):
        softrne.read_dataset(path, robot, require_angles=True)
    with pytest.raises(ValueError, match=r"pressures has shape \(3, 12\); expected \(\d+, 12\)"):
        softrne.write_dataset(path, robot, test_data.t, test_data.pressures[:3])


def test_dataset_from_arrays(robot, test_data):
    d = softrne.Dataset(robot, test_data.t, test_data.pressures, test_data.angles, source="mine")
    np.testing.assert_array_equal(d.angles, test_data.angles)
    assert d.source == "mine"
    with pytest.raises(ValueError, match=r"angles has shape \(\d+, 5\); expected"):
        softrne.Dataset(robot, test_data.t, test_data.pressures, test_data.angles[:, :5])
    with pytest.raises(ValueError, match="not strictly increasing at index 1"):
        softrne.Dataset(robot, [0.0, 0.0, 1.0], np.zeros((3, 12)))


def test_bad_csv_same_message_as_tools(robot, tmp_path):
    sim = tool("SOFTRNE_SIM")
    lines = (ARM / "test.csv").read_text().splitlines()
    header_at = next(i for i, ln in enumerate(lines) if ln.startswith("t,"))
    bad_number = lines[: header_at + 5]
    cells = bad_number[header_at + 3].split(",")
    cells[2] = "1.2.3"
    bad_number[header_at + 3] = ",".join(cells)
    non_increasing = lines[: header_at + 5]
    non_increasing[header_at + 3] = non_increasing[header_at + 1]
    for name, body in {"bad_number.csv": bad_number, "time.csv": non_increasing}.items():
        path = tmp_path / name
        path.write_text("\n".join(body) + "\n")
        with pytest.raises(softrne.InputError) as e:
            softrne.read_dataset(path, robot)
        expected = tool_error([sim, "--robot", str(ARM / "robot.json"), "--pressures", str(path)])
        assert str(e.value) == expected
        assert "line" in e.value.where


def test_robot_pickles(robot, rng):
    import pickle

    r2 = pickle.loads(pickle.dumps(robot))
    assert r2.to_dict() == robot.to_dict()
    q, qd, qdd = rng.uniform(-0.5, 0.5, (3, robot.nq))
    np.testing.assert_array_equal(r2.rnea(q, qd, qdd), robot.rnea(q, qd, qdd))
