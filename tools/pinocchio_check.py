#!/usr/bin/env python3
"""Cross-check softrne against Pinocchio (an independent implementation) on chains of
revolute joints and rigid links.

For random chains (revolute joints each followed by one link; and mixed layouts: several
links in a row, joints without a link between, links before the first joint; random or
x/y/z-aligned axes, off-axis centres of mass, full inertia tensors, random gravity) the
script writes a softrne-robot/1 file and random states, runs the softrne helper
(tests/pinocchio/softrne_pinocchio_eval, built with the tests when nlohmann_json is found),
builds the same chain with Pinocchio's Python bindings and compares RNEA, CRBA (M),
gravity, bias (nonLinearEffects) and forward dynamics (ABA). Exit status 1 when any
relative difference exceeds --tol (default 1e-10).

    pip install pin numpy
    python3 tools/pinocchio_check.py --helper build/tests/softrne_pinocchio_eval
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

try:
    import pinocchio as pin
except ImportError:  # pragma: no cover
    sys.exit("pinocchio_check.py: needs Pinocchio's Python bindings (pip install pin)")

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def random_unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def random_inertia(rng, scale):
    """Q diag(a, b, c) Q^T with principal moments satisfying the triangle inequality."""
    a, b = rng.uniform(0.3, 1.0, size=2)
    c = rng.uniform(abs(a - b) + 0.05, a + b - 0.05)
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q @ np.diag(np.sign(np.diag(r)))
    inertia = scale * q @ np.diag([a, b, c]) @ q.T
    return 0.5 * (inertia + inertia.T)


def random_chain(rng, layout, aligned):
    """Segments as dicts (softrne-robot/1 fields) for a layout of 'R' and 'L'."""
    segs, j = [], 0
    for i, s in enumerate(layout):
        if s == "R":
            axis = np.eye(3)[j % 3] if aligned else random_unit(rng)
            j += 1
            segs.append({"type": "revolute_joint", "name": f"r{i}", "axis": axis.tolist(),
                         "stiffness": 0.0, "damping": 0.0})
        else:
            mass = 0.5 + 1.5 * abs(rng.uniform(-1, 1))
            length = 0.0 if rng.uniform() < 0.15 else 0.3 * rng.uniform()
            com = [0.05 * rng.uniform(-1, 1), 0.05 * rng.uniform(-1, 1),
                   0.15 * rng.uniform(-1, 1)]
            inertia = random_inertia(rng, 0.02 * mass)
            segs.append({"type": "rigid_link", "name": f"l{i}", "mass": mass, "length": length,
                         "com": com,
                         "inertia": [inertia[0, 0], inertia[1, 1], inertia[2, 2],
                                     inertia[0, 1], inertia[0, 2], inertia[1, 2]]})
    return segs


def to_pinocchio(segs, gravity):
    """Joint i sits where the links since joint i-1 carried the frame; a link's body is
    attached to the last joint (or the universe) at that placement."""
    model = pin.Model()
    parent, placement = 0, pin.SE3.Identity()
    for s in segs:
        if s["type"] == "revolute_joint":
            axis = np.array(s["axis"])
            if np.array_equal(axis, [1.0, 0.0, 0.0]):
                joint = pin.JointModelRX()
            elif np.array_equal(axis, [0.0, 1.0, 0.0]):
                joint = pin.JointModelRY()
            elif np.array_equal(axis, [0.0, 0.0, 1.0]):
                joint = pin.JointModelRZ()
            else:
                joint = pin.JointModelRevoluteUnaligned(axis)
            parent = model.addJoint(parent, joint, placement, s["name"])
            placement = pin.SE3.Identity()
        else:
            ixx, iyy, izz, ixy, ixz, iyz = s["inertia"]
            inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
            model.appendBodyToJoint(parent, pin.Inertia(s["mass"], np.array(s["com"]), inertia),
                                    placement)
            placement = placement * pin.SE3(np.eye(3), np.array([0.0, 0.0, s["length"]]))
    model.gravity.linear = np.array(gravity)
    return model


def rel(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, np.max(np.abs(b))))


def find_helper():
    for pattern in ("build*/tests/softrne_pinocchio_eval", "build*/tests/*/softrne_pinocchio_eval"):
        found = sorted(glob.glob(os.path.join(REPO, pattern)), key=os.path.getmtime)
        if found:
            return found[-1]
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--helper", help="path of softrne_pinocchio_eval (default: newest build*/tests/)")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--chains", type=int, default=8, help="random chains per layout family")
    ap.add_argument("--states", type=int, default=10, help="random states per chain")
    ap.add_argument("--tol", type=float, default=1e-10)
    args = ap.parse_args()
    helper = args.helper or find_helper()
    if not helper or not os.path.exists(helper):
        sys.exit("pinocchio_check.py: softrne_pinocchio_eval not found (build the tests; "
                 "--helper PATH)")

    rng = np.random.default_rng(args.seed)
    families = {
        # revolute joints, each followed by one rigid link (a classic arm)
        "revolute+link": lambda: "RL" * int(rng.integers(1, 13)),
        # mixed: several links in a row, two joints without a link between, links before the
        # first joint (never more than two joints in a row: M would be singular)
        "revolute+rigid mixed": lambda: "".join(
            rng.choice(["L", "LL", "RL", "RLL", "RRL"]) for _ in range(int(rng.integers(2, 12))))
        + "RL",
    }
    names = ["rnea", "mass_matrix", "gravity", "bias", "forward_dynamics"]
    worst = {f: {n: 0.0 for n in names} for f in families}
    count = {f: 0 for f in families}
    with tempfile.TemporaryDirectory() as tmp:
        for fam, make_layout in families.items():
            for c in range(args.chains):
                layout = make_layout()
                aligned = c % 2 == 1
                segs = random_chain(rng, layout, aligned)
                gravity = (9.81 * random_unit(rng)).tolist()
                robot = {"format": "softrne-robot/1", "name": f"{fam} {c}", "gravity": gravity,
                         "segments": segs}
                robot_path = os.path.join(tmp, "robot.json")
                with open(robot_path, "w") as f:
                    json.dump(robot, f)
                model = to_pinocchio(segs, gravity)
                data = model.createData()
                nq = model.nq
                states = [np.concatenate([rng.uniform(-3, 3, nq), rng.uniform(-2, 2, nq),
                                          rng.uniform(-5, 5, nq), rng.uniform(-10, 10, nq)])
                          for _ in range(args.states)]
                states_path = os.path.join(tmp, "states.txt")
                with open(states_path, "w") as f:
                    for s in states:
                        f.write(" ".join(repr(float(v)) for v in s) + "\n")
                out = subprocess.run([helper, robot_path, states_path], capture_output=True,
                                     text=True)
                if out.returncode != 0:
                    sys.exit(f"pinocchio_check.py: helper failed on layout {layout}: {out.stderr}")
                lines = [json.loads(l) for l in out.stdout.splitlines() if l.strip()]
                assert len(lines) == len(states)
                for s, res in zip(states, lines):
                    assert res["nq"] == nq, (res["nq"], nq, layout)
                    q, v, a, tau = s[:nq], s[nq:2 * nq], s[2 * nq:3 * nq], s[3 * nq:]
                    M = pin.crba(model, data, q).copy()
                    M = np.triu(M) + np.triu(M, 1).T
                    ref = {"rnea": pin.rnea(model, data, q, v, a).copy(),
                           "mass_matrix": M,
                           "gravity": pin.computeGeneralizedGravity(model, data, q).copy(),
                           "bias": pin.nonLinearEffects(model, data, q, v).copy(),
                           "forward_dynamics": pin.aba(model, data, q, v, tau).copy()}
                    for n in names:
                        worst[fam][n] = max(worst[fam][n], rel(res[n], ref[n]))
                    count[fam] += 1
    ok = True
    print(f"softrne vs Pinocchio {pin.__version__} (helper {helper}); "
          f"max |softrne - Pinocchio| / max(1, |Pinocchio|):")
    for fam in families:
        cells = "  ".join(f"{n} {worst[fam][n]:.1e}" for n in names)
        print(f"  {fam:22s} {count[fam]:4d} states: {cells}")
        ok &= all(worst[fam][n] <= args.tol for n in names)
    print("OK" if ok else f"FAILED: above tolerance {args.tol:g}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
