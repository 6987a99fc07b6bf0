#!/usr/bin/env python3
"""Simulate the bundled arm (examples/data/arm-a-1) from its recorded chamber pressures and plot
the simulated against the measured bending angles (like the paper's Figs. 5-6), and the arm's
shape at a few instants in 3-D (frames along the arm from Robot.frames).

    pip install .  (or PYTHONPATH=<build>/python)  and  pip install matplotlib
    python3 examples/python/simulate_arm.py [--data test.csv] [--out arm-a-1.png]
"""

from __future__ import annotations

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt
import numpy as np

import softrne

ARM = pathlib.Path(__file__).resolve().parents[1] / "data" / "arm-a-1"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robot", default=str(ARM / "robot.json"))
    ap.add_argument("--data", default=str(ARM / "test.csv"))
    ap.add_argument("--out", default="arm-a-1.png")
    args = ap.parse_args()

    robot = softrne.Robot.from_json(args.robot)
    data = softrne.read_dataset(args.data, robot, require_angles=True)
    # From rest at the first measured configuration, as softrne-sim does.
    sim = softrne.simulate(robot, data.t, data.pressures, q0=data.angles[0])
    err = np.abs(sim - data.angles)
    print(f"{len(data)} samples, {data.t[-1] - data.t[0]:.1f} s; median |error| {np.median(err):.4f} rad, "
          f"max {err.max():.4f} rad")

    fig = plt.figure(figsize=(13, 7))
    names = robot.coordinate_names
    for i, name in enumerate(names):
        ax = fig.add_subplot(len(names) // 2, 3, 3 * (i // 2) + i % 2 + 1)
        ax.plot(data.t, data.angles[:, i], color="0.5", lw=1, label="measured")
        ax.plot(data.t, sim[:, i], color="C0", lw=1, label="simulated")
        ax.set_ylabel(f"{name} (rad)")
        if i >= len(names) - 2:
            ax.set_xlabel("t (s)")
        if i == 0:
            ax.legend(loc="upper right", fontsize=8)

    # The arm's shape: the distal frame origins of every segment, from the base (origin).
    ax3 = fig.add_subplot(1, 3, 3, projection="3d")
    instants = np.linspace(0, len(data) - 1, 5).astype(int)
    for k, idx in enumerate(instants):
        F = robot.frames(sim[idx])
        pts = np.vstack([np.zeros(3), F[:, :3, 3]])
        ax3.plot(pts[:, 0], pts[:, 1], pts[:, 2], "-o", ms=3, color=plt.cm.viridis(k / (len(instants) - 1)),
                 label=f"t = {data.t[idx]:.1f} s")
    ax3.set_xlabel("x (m)")
    ax3.set_ylabel("y (m)")
    ax3.set_zlabel("z (m, down)")
    ax3.invert_zaxis()  # the arm hangs: base z points down
    ax3.legend(fontsize=8)
    fig.suptitle(f"{robot.name}: simulated vs measured ({pathlib.Path(args.data).name})")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
