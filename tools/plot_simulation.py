#!/usr/bin/env python3
"""Plot simulated against measured joint angles, like the paper's Figs. 5-6.

One panel per joint: u (rotation about x) in red, v (about y) in blue; the measurement
dotted, the simulation solid. Panel titles carry the mean/median/max absolute errors.

    python3 tools/plot_simulation.py --measured examples/data/arm-a-1/test.csv \\
        --simulated sim.csv --out sim.png [--title TEXT] [--pressures]

--measured: a data CSV (docs/formats.md section 2: t, p{j}_{k}, u{j}, v{j}, ...; '#'
comment lines allowed). --simulated: a softrne-sim output (section 3: t,u1,v1,...). Either may
be omitted to plot only the other. --pressures adds a top panel with joint 1's pressures
(like Fig. 4). Needs numpy and matplotlib (tools/install-deps.sh --python).
"""

import argparse
import re
import sys


def fail(msg):
    print(f"plot_simulation.py: {msg}", file=sys.stderr)
    sys.exit(2)


def read_csv(path):
    """Header names and an (N, C) float array; '#' lines skipped."""
    import numpy as np

    try:
        with open(path, encoding="utf-8-sig") as f:
            lines = [ln.strip() for ln in f if ln.strip() and not ln.lstrip().startswith("#")]
    except OSError as e:
        fail(f"{path}: cannot read: {e.strerror}")
    if not lines:
        fail(f"{path}: no header line")
    header = [h.strip().strip('"') for h in lines[0].split(",")]
    if "t" not in header:
        fail(f"{path}: no column 't'")
    rows = []
    for i, ln in enumerate(lines[1:], start=2):
        cells = ln.split(",")
        if len(cells) != len(header):
            fail(f"{path}: data row {i - 1}: {len(cells)} cells, the header has {len(header)}")
        try:
            rows.append([float(c) for c in cells])
        except ValueError:
            fail(f"{path}: data row {i - 1}: not a number")
    if not rows:
        fail(f"{path}: no data rows")
    return header, np.asarray(rows)


def joints_of(header):
    """Sorted cc-joint indices j with both u{j} and v{j} columns."""
    us = {int(m.group(1)) for h in header if (m := re.fullmatch(r"u(\d+)", h))}
    vs = {int(m.group(1)) for h in header if (m := re.fullmatch(r"v(\d+)", h))}
    return sorted(us & vs)


def stats(err):
    import numpy as np

    a = np.abs(err)
    return a.mean(), np.median(a), a.max()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--measured", help="measured data CSV (t, pressures, u1, v1, ...)")
    ap.add_argument("--simulated", help="simulated CSV (t, u1, v1, ...)")
    ap.add_argument("--out", required=True, help="PNG file to write")
    ap.add_argument("--title", default=None, help="figure title")
    ap.add_argument("--pressures", action="store_true",
                    help="add a panel with joint 1's chamber pressures (from --measured)")
    ap.add_argument("--dpi", type=int, default=130)
    args = ap.parse_args()
    if not args.measured and not args.simulated:
        fail("give --measured, --simulated or both")

    import numpy as np
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    meas = read_csv(args.measured) if args.measured else None
    sim = read_csv(args.simulated) if args.simulated else None
    joints = sorted(set(joints_of(meas[0]) if meas else []) | set(joints_of(sim[0]) if sim else []))
    if not joints:
        fail("no u{j}, v{j} angle columns in the input(s)")

    def col(table, name):
        header, data = table
        return data[:, header.index(name)] if name in header else None

    p_names = [h for h in meas[0] if re.fullmatch(r"p1_\d+", h)] if (meas and args.pressures) else []
    n_panels = len(joints) + (1 if p_names else 0)
    fig, axes = plt.subplots(n_panels, 1, figsize=(10, 2.4 * n_panels + 0.6), sharex=True,
                             squeeze=False)
    axes = axes[:, 0]
    k = 0
    if p_names:
        ax = axes[0]
        t = col(meas, "t")
        for name in p_names:
            ax.plot(t, col(meas, name) / 1e3, lw=0.8, label=name)
        ax.set_ylabel("pressure (kPa)")
        ax.set_title("joint 1 chamber pressures (measured)", fontsize=10)
        ax.legend(loc="upper right", fontsize=8, ncol=len(p_names))
        ax.grid(alpha=0.3)
        k = 1

    for j in joints:
        ax = axes[k]
        k += 1
        parts = []
        for name, color in ((f"u{j}", "tab:red"), (f"v{j}", "tab:blue")):
            ym = col(meas, name) if meas else None
            ys = col(sim, name) if sim else None
            what = "u (about x)" if name[0] == "u" else "v (about y)"
            if ym is not None:
                ax.plot(col(meas, "t"), ym, ":", color=color, lw=1.4, label=f"{what} measured")
            if ys is not None:
                ax.plot(col(sim, "t"), ys, "-", color=color, lw=1.2, label=f"{what} simulated")
            if ym is not None and ys is not None:
                ts, tm = col(sim, "t"), col(meas, "t")
                # The simulation is on the input's grid; interpolate in case it is not.
                same = len(ts) == len(tm) and np.allclose(ts, tm, rtol=0, atol=1e-9)
                err = ys - ym if same else np.interp(tm, ts, ys) - ym
                mean, med, mx = stats(err)
                parts.append(f"{name}: mean {mean:.3f}, median {med:.3f}, max {mx:.3f} rad")
        ax.set_ylabel(f"joint {j} (rad)")
        ax.set_title("; ".join(parts) if parts else f"joint {j}", fontsize=9)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("t (s)")
    # One legend for all joint panels (same styles everywhere), above them.
    handles, labels = axes[k - 1].get_legend_handles_labels()
    top = 1.0
    if args.title:
        fig.suptitle(args.title)
        top = 0.97
    fig.legend(handles, labels, loc="upper center", ncol=4, fontsize=9, frameon=False,
               bbox_to_anchor=(0.5, top - (0.02 if args.title else 0.0)))
    fig.tight_layout(rect=(0, 0, 1, top - (0.05 if args.title else 0.03)))
    try:
        fig.savefig(args.out, dpi=args.dpi)
    except OSError as e:
        fail(f"{args.out}: cannot write: {e.strerror}")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
