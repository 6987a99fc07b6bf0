#!/usr/bin/env python3
"""Costs of the Python package (docs/python.md, "Costs"): medians of repeated timings.

- one Python call of Robot.rnea (one state, numpy arrays in and out) against the C++ call
  (softrne::rnea in a C++ loop: softrne_py_bench_cpp, python/bench/rnea_loop.cpp);
- batched rnea on N states (one call, shape (N, nq)) on 1 thread and on all cores, per state.

    cmake --build BUILD --target softrne_py_bench_cpp
    PYTHONPATH=BUILD/python python3 python/bench/bench_python.py --cpp BUILD/python/softrne_py_bench_cpp

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


def median_time(f, number, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f(number)
        times.append((time.perf_counter() - t0) / number)
    return statistics.median(times)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robot", default=str(ROOT / "examples/data/arm-a-1/robot.json"))
    ap.add_argument("--cpp", help="softrne_py_bench_cpp (the C++ loop); omitted: no C++ baseline")
    ap.add_argument("--states", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=15)
    args = ap.parse_args()

    robot = softrne.Robot.from_json(args.robot)
    nq = robot.nq
    rng = np.random.default_rng(17)
    q, qd, qdd = rng.uniform(-0.6, 0.6, (3, nq))
    out = {"robot": args.robot, "nq": nq, "cores": os.cpu_count()}

    def single(n):
        f = robot.rnea
        for _ in range(n):
            f(q, qd, qdd)

    def empty_call(n):  # the cost of a Python loop plus a trivial C call, for reference
        f = len
        for _ in range(n):
            f(q)

    out["python_rnea_call_ns"] = 1e9 * median_time(single, 20_000, args.repeat)
    out["python_loop_len_call_ns"] = 1e9 * median_time(empty_call, 20_000, args.repeat)

    N = args.states
    Q = rng.uniform(-0.6, 0.6, (N, nq))
    Qd = rng.uniform(-1.8, 1.8, (N, nq))
    Qdd = rng.uniform(-4.8, 4.8, (N, nq))
    for threads in (1, 0):
        t = median_time(lambda n: [robot.rnea(Q, Qd, Qdd, threads=threads) for _ in range(n)], 1, args.repeat)
        out[f"batched_rnea_ns_per_state_threads_{threads or 'all'}"] = 1e9 * t / N

    if args.cpp:
        p = subprocess.run([args.cpp, args.robot, str(N), str(args.repeat)], capture_output=True, text=True, check=True)
        cpp = json.loads(p.stdout)
        c = cpp["median_ns_per_state"]
        out["cpp_rnea_loop_ns_per_state"] = c
        out["python_call_overhead_ns"] = out["python_rnea_call_ns"] - c
        out["batched_1_thread_over_cpp_loop"] = out["batched_rnea_ns_per_state_threads_1"] / c
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
