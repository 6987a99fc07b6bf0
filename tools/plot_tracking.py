#!/usr/bin/env python3
"""Plot reference against tracked joint angles (examples/04_lqr_tracking.cpp's CSV).

One panel per coordinate: the reference dashed, feed-forward + LQR solid, feed-forward alone
dotted (if present); the panel title carries the median/max absolute errors.

    python3 tools/plot_tracking.py build/examples/arm-a-1-lqr-tracking.csv --out tracking.png

The CSV has t, <c>_ref, <c> and optionally <c>_ff per coordinate c (u1, v1, ...). Needs numpy
and matplotlib (tools/install-deps.sh --python).
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_simulation import fail, read_csv  # noqa: E402  the same CSV reader


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", help="04_lqr_tracking output")
    ap.add_argument("--out", required=True, help="image file (png, pdf, svg)")
    args = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    header, data = read_csv(args.csv)
    coords = [h for h in header if h != "t" and f"{h}_ref" in header]
    if not coords:
        fail(f"{args.csv}: no column pair '<c>' and '<c>_ref'")
    col = {h: i for i, h in enumerate(header)}
    t = data[:, col["t"]]
    fig, axes = plt.subplots(len(coords), 1, sharex=True, figsize=(9, 1.8 * len(coords)))
    for ax, c in zip(np.atleast_1d(axes), coords):
        ref, y = data[:, col[f"{c}_ref"]], data[:, col[c]]
        ax.plot(t, ref, "k--", lw=1.2, label="reference")
        ax.plot(t, y, "C0", lw=1.0, label="feed-forward + LQR")
        if f"{c}_ff" in col:
            ax.plot(t, data[:, col[f"{c}_ff"]], "C3:", lw=1.0, label="feed-forward alone")
        e = np.abs(y - ref)
        ax.set_title(f"{c}: LQR error median {np.median(e):.1e} rad, max {e.max():.1e} rad", fontsize=9)
        ax.set_ylabel("rad")
    np.atleast_1d(axes)[0].legend(loc="upper right", fontsize=8)
    np.atleast_1d(axes)[-1].set_xlabel("t (s)")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
