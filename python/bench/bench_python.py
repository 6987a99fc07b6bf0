#!/usr/bin/env python3
"""Costs of the Python package (docs/python.md, "Costs"): medians of repeated timings.

- one Python call of Robot.rnea (one state, numpy arrays in and out) against the C++ call
  (softrne::rnea in a C++ loop: softrne_py_bench_cpp, python/bench/rnea_loop.cpp);
- batched rnea on N states (one call, shape (N, nq)) on 1 thread and on all cores, per state;
- where Pinocchio's Python bindings import (pip install pin): one Python call of pin.rnea
  against one of softrne's Robot.rnea on the same chain of 6 revolute joints and links
  (built by tools/pinocchio_check.py's helpers; the results are checked equal).

    cmake --build BUILD --target softrne_py_bench_cpp
    PYTHONPATH=BUILD/python python3 python/bench/bench_python.py --cpp BUILD/python/softrne_py_bench_cpp

(the same interpreter the module was built for; numbers are medians over --rounds rounds)

A benchmark, not a test: no thresholds.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import time

import numpy as np

import softrne

ROOT = pathlib.Path(__file__).resolve().parents[2]


def per_call(f, number):
    t0 = time.perf_counter()
    f(number)
    return (time.perf_counter() - t0) / number


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robot", default=str(ROOT / "examples/data/arm-a-1/robot.json"))
    ap.add_argument("--cpp", help="softrne_py_bench_cpp (the C++ loop); omitted: no C++ baseline")
    ap.add_argument("--states", type=int, default=100_000)
    ap.add_argument("--rounds", type=int, default=9,
                    help="every measurement once per round, interleaved (a loaded machine drifts); medians")
    args = ap.parse_args()

    robot = softrne.Robot.from_json(args.robot)
    nq = robot.nq
    rng = np.random.default_rng(17)
    q, qd, qdd = rng.uniform(-0.6, 0.6, (3, nq))
    N = args.states
    Q = rng.uniform(-0.6, 0.6, (N, nq))
    Qd = rng.uniform(-1.8, 1.8, (N, nq))
    Qdd = rng.uniform(-4.8, 4.8, (N, nq))
    pin_case = pinocchio_case()

    def single(n):
        f = robot.rnea
        for _ in range(n):
            f(q, qd, qdd)

    def empty_call(n):  # a Python loop calling a trivial C function, for reference
        f = len
        for _ in range(n):
            f(q)

    samples = {}

    def add(key, seconds):
        samples.setdefault(key, []).append(1e9 * seconds)

    for _ in range(args.rounds):
        if args.cpp:
            p = subprocess.run([args.cpp, args.robot, str(N // 4), "3"], capture_output=True, text=True, check=True)
            samples.setdefault("cpp_rnea_loop_ns_per_state", []).append(json.loads(p.stdout)["median_ns_per_state"])
        add("python_rnea_call_ns", per_call(single, 20_000))
        add("python_loop_len_call_ns", per_call(empty_call, 20_000))
        add("batched_rnea_ns_per_state_threads_1", per_call(lambda n: robot.rnea(Q, Qd, Qdd, threads=1), 1) / N)
        add("batched_rnea_ns_per_state_threads_all", per_call(lambda n: robot.rnea(Q, Qd, Qdd, threads=0), 1) / N)
        if pin_case:
            for key, f in pin_case["calls"].items():
                add(key, per_call(f, 20_000))

    out = {"robot": args.robot, "nq": nq, "cores": os.cpu_count(), "rounds": args.rounds, "states": N}
    out.update({k: statistics.median(v) for k, v in samples.items()})
    if args.cpp:
        c = out["cpp_rnea_loop_ns_per_state"]
        out["python_call_overhead_ns"] = out["python_rnea_call_ns"] - c
        out["batched_1_thread_over_cpp_loop"] = out["batched_rnea_ns_per_state_threads_1"] / c
    out["pinocchio"] = pin_case["version"] if pin_case else "not installed (pip install pin)"
    print(json.dumps(out, indent=2))


def pinocchio_case():
    """Pinocchio's and softrne's Python rnea on one chain of 6 revolute joints and links."""
    try:
        import pinocchio as pin
    except ImportError:
        return None
    import sys

    sys.path.insert(0, str(ROOT / "tools"))
    import pinocchio_check as pc

    rng = np.random.default_rng(6)
    segs = pc.random_chain(rng, "RL" * 6, aligned=True)
    gravity = [0.0, 0.0, -9.81]
    robot = softrne.Robot.from_dict({"format": "softrne-robot/1", "gravity": gravity, "segments": segs})
    model = pc.to_pinocchio(segs, gravity)
    data = model.createData()
    q, v, a = rng.uniform(-1, 1, (3, robot.nq))
    np.testing.assert_allclose(pin.rnea(model, data, q, v, a), robot.rnea(q, v, a), rtol=1e-10, atol=1e-10)

    def pin_calls(n):
        f = pin.rnea
        for _ in range(n):
            f(model, data, q, v, a)

    def softrne_calls(n):
        f = robot.rnea
        for _ in range(n):
            f(q, v, a)

    return {"version": pin.__version__,
            "calls": {"rev6_pin_rnea_call_ns": pin_calls, "rev6_softrne_rnea_call_ns": softrne_calls}}


if __name__ == "__main__":
    main()
