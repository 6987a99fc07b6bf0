#!/usr/bin/env python3
"""Plots of a closed-loop run (softrne-loop --plots DIR): measured vs simulated angles before
and after the loop on train and test (like the paper's Figs. 5-6), and the training
simulation residual per coordinate before and after."""
import argparse
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
    base = os.path.join(directory, "residual_baseline.csv")
    final = os.path.join(directory, "residual_final.csv")
    if not (os.path.exists(base) and os.path.exists(final)):
        return
    hr, r = read(base)
    _, rf = read(final)
    n = r.shape[1] - 1
    fig, axes = plt.subplots(n, 1, figsize=(10, 1.6 * n + 1), sharex=True, squeeze=False)
    for k in range(n):
        ax = axes[k][0]
        ax.plot(r[:, 0], r[:, k + 1], "-", color="tab:gray", lw=0.7, label="baseline")
        ax.plot(rf[:, 0], rf[:, k + 1], "-", color="tab:green", lw=0.9, label="after the loop")
        ax.set_ylabel(f"{hr[k + 1]} (rad)")
        ax.legend(fontsize=7, loc="upper right", ncol=2)
    axes[-1][0].set_xlabel("t (s)")
    fig.suptitle("training simulation residual (measured - simulated), before and after the loop")
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
