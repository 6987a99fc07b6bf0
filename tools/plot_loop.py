#!/usr/bin/env python3
"""Plots of a closed-loop run (softrne-loop --plots DIR): measured vs simulated angles before
and after the loop on train and test (like the paper's Figs. 5-6), and the baseline
equation-error residual against the regressor of the first effect the loop added."""
import argparse
import glob
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read(path):
    with open(path) as f:
        lines = [ln for ln in f if not ln.startswith("#") and ln.strip()]
    header = [h.strip() for h in lines[0].split(",")]
    data = np.array([[float(x) for x in ln.split(",")] for ln in lines[1:]])
    return header, data


def angles_figure(measured, baseline, final, title, out):
    hm, m = read(measured)
    hb, b = read(baseline)
    hf, f = read(final)
    names = hb[1:]
    joints = len(names) // 2
    fig, axes = plt.subplots(joints, 1, figsize=(10, 2.6 * joints), sharex=True, squeeze=False)
    for j in range(joints):
        ax = axes[j][0]
        for k, color in ((2 * j, "tab:red"), (2 * j + 1, "tab:blue")):
            name = names[k]
            ax.plot(m[:, 0], m[:, hm.index(name)], ":", color=color, lw=1.2, label=f"{name} measured")
            ax.plot(b[:, 0], b[:, k + 1], "-", color=color, lw=0.8, alpha=0.45, label=f"{name} baseline")
            ax.plot(f[:, 0], f[:, k + 1], "-", color=color, lw=1.4, label=f"{name} final")
        ax.set_ylabel("rad")
        ax.legend(fontsize=7, ncol=3, loc="upper right")
    axes[-1][0].set_xlabel("t (s)")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def residual_figure(directory, out):
    regs = glob.glob(os.path.join(directory, "regressor_*.csv"))
    if not regs:
        return
    name = os.path.basename(regs[0])[len("regressor_"):-4]
    hr, r = read(os.path.join(directory, "residual_baseline.csv"))
    _, x = read(regs[0])
    _, rf = read(os.path.join(directory, "residual_final.csv"))
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for k in range(1, r.shape[1]):
        axes[0].scatter(x[:, k], r[:, k], s=2, alpha=0.4, label=hr[k])
    axes[0].set_xlabel(f"regressor of {name} (N m per unit parameter)")
    axes[0].set_ylabel("baseline equation-error residual (N m)")
    axes[0].legend(fontsize=7, markerscale=4)
    axes[0].set_title("residual vs the chosen effect's regressor")
    for k in range(1, r.shape[1]):
        axes[1].plot(r[:, 0], r[:, k], lw=0.6, alpha=0.5)
    axes[1].plot(rf[:, 0], np.linalg.norm(rf[:, 1:], axis=1), "k-", lw=1.0, label="|final residual|")
    axes[1].set_xlabel("t (s)")
    axes[1].set_title("baseline residual per coordinate, and final norm")
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--dir", required=True)
    ap.add_argument("--train", required=True)
    ap.add_argument("--test", required=True)
    a = ap.parse_args()
    d = a.dir
    angles_figure(a.train, f"{d}/train_baseline.csv", f"{d}/train_final.csv",
                  "training data: measured (dotted), baseline (thin), after the loop (thick)", f"{d}/train.png")
    angles_figure(a.test, f"{d}/test_baseline.csv", f"{d}/test_final.csv",
                  "test data: measured (dotted), baseline (thin), after the loop (thick)", f"{d}/test.png")
    residual_figure(d, f"{d}/residual.png")


if __name__ == "__main__":
    main()
