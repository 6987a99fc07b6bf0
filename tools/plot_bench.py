#!/usr/bin/env python3
"""Plots and tabulates softrne-bench results (Google Benchmark JSON).

    build/bin/softrne-bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \\
        --benchmark_out=bench.json --benchmark_out_format=json
    python3 tools/plot_bench.py bench.json -o docs/performance-scaling.png --markdown

Uses the median aggregate of each benchmark when present (else the single run), CPU time
(--time real for wall-clock). Writes a log-log PNG of time per call against the number of
CC segments n (runtime chain, each CC joint followed by a rigid link) with the revolute
chains (softrne and Pinocchio) as markers at their number of joints, and a second panel with
the time per CC segment. --markdown prints the tables used in docs/performance.md.
Needs numpy and matplotlib (Debian: python3-numpy python3-matplotlib).
"""
import argparse
import json
import re
import sys
from collections import defaultdict

UNIT_NS = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
ALGOS = ["rnea", "gravity", "bias", "mass_matrix", "forward_dynamics", "aba"]
# Pinocchio's counterpart: forward_dynamics (dense) and aba (O(n)) both against its aba.
PIN_NAME = {"rnea": "rnea", "gravity": "gravity", "bias": "bias", "mass_matrix": "crba",
            "forward_dynamics": "aba", "aba": "aba"}


def load(path, which):
    """name -> time in ns (median aggregate if present, else the last plain run)."""
    with open(path) as f:
        doc = json.load(f)
    plain, median = {}, {}
    for b in doc["benchmarks"]:
        if b.get("error_occurred"):
            continue
        t = b[f"{which}_time"] * UNIT_NS[b.get("time_unit", "ns")]
        name = b.get("run_name", b["name"])
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "median":
                median[name] = t
        else:
            plain[name] = t
    plain.update(median)
    return doc.get("context", {}), plain


def fmt(ns):
    if ns >= 1e6:
        return f"{ns / 1e6:.3g} ms"
    if ns >= 1e3:
        return f"{ns / 1e3:.3g} us"
    return f"{ns:.3g} ns"


def markdown(t):
    out = []
    # scaling table
    sizes = sorted({int(m.group(2)) for k in t for m in [re.match(r"cc/dynamic/(\w+)/(\d+)$", k)] if m})
    if sizes:
        out.append("| n (CC + link) | " + " | ".join(ALGOS) + " | rnea per segment |")
        out.append("|---:|" + "---:|" * (len(ALGOS) + 1))
        for n in sizes:
            cells = [fmt(t[f"cc/dynamic/{a}/{n}"]) if f"cc/dynamic/{a}/{n}" in t else "-"
                     for a in ALGOS]
            per = fmt(t[f"cc/dynamic/rnea/{n}"] / n) if f"cc/dynamic/rnea/{n}" in t else "-"
            out.append(f"| {n} | " + " | ".join(cells) + f" | {per} |")
        out.append("")
    # arm table
    if any(k.startswith("arm/") for k in t):
        out.append("| paper's arm | " + " | ".join(ALGOS) + " |")
        out.append("|---|" + "---:|" * len(ALGOS))
        for impl in ("static", "dynamic"):
            cells = [fmt(t[f"arm/{impl}/{a}"]) if f"arm/{impl}/{a}" in t else "-" for a in ALGOS]
            out.append(f"| {impl} | " + " | ".join(cells) + " |")
        out.append("")
    # revolute vs Pinocchio
    for m in ("rev6", "rev30"):
        if not any(k.startswith(m + "/") for k in t):
            continue
        out.append(f"| {m} | " + " | ".join(f"{a} (Pinocchio: {PIN_NAME[a]})" for a in ALGOS) + " |")
        out.append("|---|" + "---:|" * len(ALGOS))
        for impl in ("static", "dynamic", "pinocchio", "pinocchio_unaligned"):
            names = [f"{m}/{impl}/{PIN_NAME[a] if impl.startswith('pinocchio') else a}" for a in ALGOS]
            if not any(n in t for n in names):
                continue
            out.append(f"| {impl} | " + " | ".join(fmt(t[n]) if n in t else "-" for n in names) + " |")
        for impl in ("static", "dynamic"):
            for ref in ("pinocchio", "pinocchio_unaligned"):
                r = []
                for a in ALGOS:
                    x, y = f"{m}/{impl}/{a}", f"{m}/{ref}/{PIN_NAME[a]}"
                    r.append(f"{t[x] / t[y]:.2f}" if x in t and y in t else "-")
                if any(c != "-" for c in r):
                    out.append(f"| ratio {impl} / {ref} | " + " | ".join(r) + " |")
        out.append("")
    # calc
    if "calc/cc" in t:
        out.append("| calc | time | / revolute |")
        out.append("|---|---:|---:|")
        for s in ("cc", "revolute", "rigid_link"):
            if f"calc/{s}" in t:
                out.append(f"| {s} | {fmt(t[f'calc/{s}'])} | {t[f'calc/{s}'] / t['calc/revolute']:.2f} |")
        out.append("")
    return "\n".join(out)


def plot(t, context, path, which):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5))
    series = defaultdict(list)
    for k, v in t.items():
        m = re.match(r"cc/dynamic/(\w+)/(\d+)$", k)
        if m:
            series[m.group(1)].append((int(m.group(2)), v))
    markers = dict(zip(ALGOS, "os^dv*"))
    for a in ALGOS:
        if a not in series:
            continue
        pts = sorted(series[a])
        n = np.array([p[0] for p in pts], float)
        y = np.array([p[1] for p in pts]) * 1e-3
        ax.loglog(n, y, marker=markers[a], label=f"softrne {a} (CC chain)")
        if a == "rnea":
            ax2.semilogx(n, y * 1e3 / n, marker="o", label="rnea")
        if a in ("gravity", "bias", "aba"):
            ax2.semilogx(n, y * 1e3 / n, marker=markers[a], label=a)
    for impl, style in (("dynamic", "k"), ("pinocchio", "r")):
        for a, mk in (("rnea", "o"), ("mass_matrix", "d"), ("forward_dynamics", "v"), ("aba", "*")):
            if impl == "pinocchio" and a == "aba":
                continue  # Pinocchio's aba is already drawn against forward_dynamics
            pts = []
            for m in (6, 30):
                name = f"rev{m}/{impl}/{PIN_NAME[a] if impl == 'pinocchio' else a}"
                if name in t:
                    pts.append((m, t[name] * 1e-3))
            if pts:
                label = (f"{'softrne' if impl == 'dynamic' else 'Pinocchio'} "
                         f"{PIN_NAME[a] if impl == 'pinocchio' else a} (revolute chain)")
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], style + mk, mfc="none",
                          ms=9, ls=":", label=label)
    nn = np.array([1, 1000.0])
    if "rnea" in series:
        n0, y0 = sorted(series["rnea"])[2] if len(series["rnea"]) > 2 else sorted(series["rnea"])[0]
        ax.loglog(nn, y0 * 1e-3 * nn / n0, color="0.7", lw=0.8, label="slope 1 (O(n))")
    if "mass_matrix" in series:
        n0, y0 = sorted(series["mass_matrix"])[-1]
        ax.loglog(nn, y0 * 1e-3 * (nn / n0) ** 2, color="0.7", lw=0.8, ls="--",
                  label="slope 2 (O(n nq))")
    ax.set_xlabel("n: CC segments (each with a rigid link) / revolute joints")
    ax.set_ylabel(f"{which} time per call [us]")
    ax.set_title("time per call (medians)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax2.set_xlabel("n: CC segments (each with a rigid link)")
    ax2.set_ylabel("time per CC segment [ns]")
    ax2.set_ylim(bottom=0)
    ax2.set_title("O(n) algorithms: time per segment")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=8)
    host = context.get("host_name", "")
    cpus = context.get("num_cpus", "")
    mhz = context.get("mhz_per_cpu", "")
    fig.suptitle(f"softrne-bench ({host}, {cpus} CPUs at {mhz} MHz, {context.get('date', '')})",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("json", help="softrne-bench --benchmark_out=... --benchmark_out_format=json")
    ap.add_argument("-o", "--output", help="PNG to write")
    ap.add_argument("--markdown", action="store_true", help="print the tables in Markdown")
    ap.add_argument("--time", choices=["cpu", "real"], default="cpu")
    args = ap.parse_args()
    context, t = load(args.json, args.time)
    if not t:
        sys.exit("plot_bench.py: no benchmarks in " + args.json)
    if args.markdown:
        print(markdown(t))
    if args.output:
        plot(t, context, args.output, args.time)
    return 0


if __name__ == "__main__":
    sys.exit(main())
