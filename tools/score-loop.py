#!/usr/bin/env python3
"""Score the closed loop (softrne-loop) on random arms it was never tuned to.

Makes N cases with softrne-make-case (about 1/4 effect-free controls, 1/2 single effects,
1/4 pairs; deterministic from --seed), runs

    softrne-loop --robot robot.json --train train.csv --test test.csv --out report.json --quiet

on each, and scores it:

- right effects: the report names exactly the injected effects, each with the injected scope
  (shared / joint / coordinate / chamber) and, unless shared, on the injected joint(s);
- test error: final test median <= half the baseline test median, or at the noise floor
  (<= 1.25 x 0.00202 rad, the median of |N(0, 0.003)|);
- controls: nothing added;
- no harm: the final test median is not above the baseline's (by more than 2 %).

Prints a markdown table and a summary, and writes them to WORK/score.md and WORK/score.json
(or --out). Reads the report defensively: format /2 items have "name", "scope", "joints";
format /1 items have "name", "joints", "params" (the scope is then read from the parameter
names: "beta" shared, "beta.joint2" joint, "beta.u1" coordinate, "gain.p1_2" chamber).

Stdlib only. Example:

    tools/score-loop.py --bin build/bin --cases 40 --seed 1000 --work /tmp/score --jobs 1
"""

import argparse
import concurrent.futures
import json
import os
import random
import re
import statistics
import subprocess
import sys
import time

NOISE = 0.003
FLOOR = 0.6744897501960817 * NOISE  # median of |N(0, NOISE)| = 0.00202 rad
FLOOR_FACTOR = 1.25
HARM_TOL = 0.02


def die(msg, code=2):
    print(f"score-loop: {msg}", file=sys.stderr)
    sys.exit(code)


def effect_table(make_case):
    """[(name, scope, builds)] from softrne-make-case --list-effects."""
    try:
        out = subprocess.run([make_case, "--list-effects"], check=True, capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        die(f"{make_case} --list-effects failed: {e}", 1)
    rows = []
    for line in out.splitlines():
        if not line or line.startswith("#"):
            continue
        f = line.split("\t")
        rows.append((f[0], f[1], f[2] == "yes"))
    return rows


def plan_cases(n, seed, pool, controls_only=False):
    """Deterministic list of (case seed, [(effect, scope), ...])."""
    if controls_only:  # effect-free arms only: the false-positive rate of the selection rule
        return [(seed + i, []) for i in range(n)]
    rng = random.Random(seed)
    names = sorted({e for e, _ in pool})
    scopes = {e: sorted(s for x, s in pool if x == e) for e in names}
    n_ctrl = round(n / 4)
    n_pair = round(n / 4) if len(names) >= 2 else 0
    n_single = n - n_ctrl - n_pair
    kinds = ["control"] * n_ctrl + ["single"] * n_single + ["pair"] * n_pair
    rng.shuffle(kinds)
    cycle = []
    plan = []
    for i, kind in enumerate(kinds):
        effects = []
        if kind == "single":
            if not cycle:  # every effect once before any twice
                cycle = names[:]
                rng.shuffle(cycle)
            e = cycle.pop()
            effects = [(e, rng.choice(scopes[e]))]
        elif kind == "pair":
            a, b = rng.sample(names, 2)
            effects = [(a, rng.choice(scopes[a])), (b, rng.choice(scopes[b]))]
        plan.append((seed + i, effects))
    return plan


def scope_from_key(key, joints):
    if "." not in key:
        return "shared"
    suffix = key.split(".", 1)[1]
    if suffix in joints:
        return "joint"
    if re.fullmatch(r"p\d+_\d+", suffix):
        return "chamber"
    if re.fullmatch(r"[uv]\d+", suffix) or suffix.startswith("q"):
        return "coordinate"
    return "joint"


def read_found(report):
    """[(name, scope, joints, param keys)] from a /1 or /2 report."""
    found = []
    for item in report.get("effects") or []:
        if not isinstance(item, dict):
            continue
        name = item.get("name", "?")
        joints = item.get("joints") or []
        params = item.get("params") or {}
        keys = list(params.keys()) if isinstance(params, dict) else []
        scope = item.get("scope")
        if scope not in ("shared", "joint", "coordinate", "chamber"):
            scopes = {scope_from_key(k, joints) for k in keys} or {"shared"}
            scope = scopes.pop() if len(scopes) == 1 else "mixed"
            if name == "payload":
                scope = "shared"
        found.append((name, scope, list(joints), keys))
    return found


def read_equivalents(report):
    """Per reported effect, its indistinguishable alternatives as (name, scope, joints, [])."""
    out = []
    for item in report.get("effects") or []:
        alts = []
        for label in (item.get("equivalent") or []) if isinstance(item, dict) else []:
            m = re.match(r"^(\w+) \((shared|joint|coordinate|chamber)((?: [^ )]+)*)\)", label)
            if m:
                alts.append((m.group(1), m.group(2), m.group(3).split(), []))
        out.append(alts)
    return out


def median_of(report, which, part):
    try:
        return float(report[which][part]["median"])
    except (KeyError, TypeError, ValueError):
        return float("nan")


def effect_matches(inj, f, cc_joints):
    """Same name and scope; shared and joint count as the same scope where they cover the same
    joints (an arm with one CC joint, or a shared effect reported on all of them)."""
    name, scope, joints, keys = f
    if name != inj["name"]:
        return False
    if scope != inj["scope"]:
        if {scope, inj["scope"]} != {"shared", "joint"}:
            return False
        # Only CC joints count: the loop lists revolute joints under a shared effect too.
        cover = lambda s, js: set(cc_joints) if s == "shared" and not js else set(js) & set(cc_joints)
        return cover(scope, joints) == cover(inj["scope"], inj["joints"])
    if scope == "shared":
        return True
    if set(joints) != set(inj["joints"]):
        return False
    target = inj.get("target")
    if target and scope in ("coordinate", "chamber") and keys:
        return any(k.endswith("." + target) for k in keys)
    return True


def rescore_case(args, seed, effects):
    d = os.path.join(args.work, f"case{seed}")
    res = {"seed": seed, "requested": [f"{e}:{s}" for e, s in effects], "dir": d}
    try:
        with open(os.path.join(d, "case.json")) as f:
            case = json.load(f)
        with open(os.path.join(d, "report.json")) as f:
            report = json.load(f)
    except (OSError, ValueError) as e:
        res.update(verdict="loop-failed", error=f"no case or report to rescore: {e}")
        return res
    res["arm"] = case.get("arm", "?")
    res["injected"] = case.get("effects", [])
    res["cc_joints"] = [j.get("name") for j in case.get("joints", [])]
    try:
        with open(os.path.join(d, "loop.seconds")) as f:
            res["seconds"] = float(f.read())
    except (OSError, ValueError):
        pass
    score(res, report)
    return res


def run_case(args, seed, effects, tools):
    d = os.path.join(args.work, f"case{seed}")
    done = all(os.path.exists(os.path.join(d, f)) for f in ("report.json", "loop.seconds", "case.json"))
    if args.rescore or (args.resume and done):
        return rescore_case(args, seed, effects)
    os.makedirs(d, exist_ok=True)
    res = {"seed": seed, "requested": [f"{e}:{s}" for e, s in effects], "dir": d}
    cmd = [tools["make"], "--seed", str(seed), "--out", d, "--quiet"]
    cmd += ["--effects", ",".join(res["requested"])] if effects else ["--none"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        res.update(verdict="gen-failed", error=(p.stderr.strip().splitlines() or ["?"])[-1])
        return res
    with open(os.path.join(d, "case.json")) as f:
        case = json.load(f)
    res["arm"] = case.get("arm", "?")
    res["injected"] = case.get("effects", [])
    res["cc_joints"] = [j.get("name") for j in case.get("joints", [])]
    report_path = os.path.join(d, "report.json")
    cmd = [tools["loop"], "--robot", os.path.join(d, "robot.json"), "--train", os.path.join(d, "train.csv"),
           "--test", os.path.join(d, "test.csv"), "--out", report_path, "--quiet"] + args.loop_arg
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout or None)
        rc, err = p.returncode, p.stderr
        with open(os.path.join(d, "loop.log"), "w") as f:
            f.write(p.stdout + p.stderr)
    except subprocess.TimeoutExpired:
        rc, err = -1, "timeout"
    res["seconds"] = time.monotonic() - t0
    with open(os.path.join(d, "loop.seconds"), "w") as f:
        f.write(f"{res['seconds']:.3f}\n")
    if rc != 0:
        res.update(verdict="loop-failed", error=(err.strip().splitlines() or ["?"])[-1])
        return res
    try:
        with open(report_path) as f:
            report = json.load(f)
    except (OSError, ValueError) as e:
        res.update(verdict="loop-failed", error=f"report: {e}")
        return res
    score(res, report)
    return res


def score(res, report):
    inj = res["injected"]
    found = read_found(report)
    res["found"] = [f"{n}:{s}" + ("" if s == "shared" else "[" + ",".join(j) + "]") for n, s, j, _ in found]
    res["report_format"] = report.get("format", "?")
    inertia = report.get("inertia_model") or {}
    res["inertia"] = f"distributed (round {inertia.get('round')})" if inertia.get("chosen") == "distributed" else "as declared"
    res["removed"] = [e.get("label", e.get("name", "?")) for e in report.get("removed_effects", [])]
    res["equivalent"] = [l for e in report.get("effects", []) for l in e.get("equivalent", [])]
    b, fin = median_of(report, "baseline", "test"), median_of(report, "final", "test")
    res["test_before"], res["test_after"] = b, fin
    at_floor = fin <= FLOOR_FACTOR * FLOOR
    halved = fin <= 0.5 * b
    harm = fin > b * (1 + HARM_TOL)
    res["at_floor"], res["halved"], res["harm"] = at_floor, halved, harm
    if not inj:
        res["names_right"] = res["scopes_right"] = not found
        res["verdict"] = "ok" if not found and not harm else ("false positive" if found else "harm")
        return
    cc = res.get("cc_joints", [])

    def judge(found):
        names_right = sorted(e["name"] for e in inj) == sorted(f[0] for f in found)
        matched = sum(1 for e in inj if any(effect_matches(e, f, cc) for f in found))
        return names_right, names_right and matched == len(inj)

    names_right, scopes_right = judge(found)
    # The report may say that the data cannot tell a found effect from another one (a shared
    # mass scale s is a shared chamber gain 1/s once K and D are refitted): substituting such a
    # stated alternative for a found effect is scored separately ("right up to an equivalence").
    equivalent_right = False
    if not scopes_right:
        swapped = list(found)
        for i, alts in enumerate(read_equivalents(report)):
            if i < len(swapped) and not any(effect_matches(e, swapped[i], cc) for e in inj):
                for a in alts:
                    if any(effect_matches(e, a, cc) for e in inj):
                        swapped[i] = a
                        break
        equivalent_right = judge(swapped)[1]
    res["names_right"], res["scopes_right"] = names_right, scopes_right
    named = sum(1 for e in inj if any(f[0] == e["name"] for f in found))
    if scopes_right and (halved or at_floor) and not harm:
        v = "right"
    elif equivalent_right and (halved or at_floor) and not harm:
        v = "right up to an equivalence"
    elif scopes_right:
        v = "right, test not improved" if not harm else "right, harms test"
    elif names_right:
        v = "right name, wrong scope"
    elif not found:
        v = "missed"
    elif named:
        v = f"partial ({named}/{len(inj)} named, {len(found)} added)"
    else:
        v = "wrong"
    res["verdict"] = v


def fmt(x):
    return "nan" if x != x else f"{x:.4f}"


def injected_text(r):
    if "injected" not in r:
        return ", ".join(r["requested"]) or "none"
    out = []
    for e in r["injected"]:
        s = e["name"] + ":" + e["scope"]
        if e["scope"] != "shared":
            s += "[" + (e.get("target") or ",".join(e.get("joints", []))) + "]"
        out.append(s)
    return ", ".join(out) or "none"


def render(results, args, excluded):
    lines = ["| case | arm | injected | found | inertia | test median before -> after (rad) | time (s) | verdict |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in results:
        found = ", ".join(r.get("found", [])) or ("none" if "found" in r else "-")
        if r.get("equivalent"):
            found += " (indistinguishable: " + ", ".join(r["equivalent"]) + ")"
        if r.get("removed"):
            found += " (removed: " + ", ".join(r["removed"]) + ")"
        if "test_before" in r:
            tm = f"{fmt(r['test_before'])} -> {fmt(r['test_after'])}" + (" (floor)" if r.get("at_floor") else "")
        else:
            tm = "-"
        t = f"{r['seconds']:.0f}" if "seconds" in r else "-"
        verdict = r["verdict"] + (f": {r['error']}" if "error" in r else "")
        lines.append(f"| {r['seed']} | {r.get('arm', '-')} | {injected_text(r)} | {found} | {r.get('inertia', '-')} "
                     f"| {tm} | {t} | {verdict} |")
    scored = [r for r in results if r["verdict"] not in ("gen-failed", "loop-failed")]
    eff = [r for r in scored if r.get("injected")]
    ctrl = [r for r in scored if not r.get("injected")]
    pct = lambda k, n: f"{100.0 * k / n:.0f} % ({k}/{n})" if n else "n/a"
    times = [r["seconds"] for r in results if "seconds" in r]
    summary = {
        "cases": len(results),
        "scored": len(scored),
        "failed": len(results) - len(scored),
        "effect_cases_right": sum(r["verdict"] == "right" for r in eff),
        "effect_cases_right_up_to_equivalence": sum(r["verdict"] == "right up to an equivalence" for r in eff),
        "effect_cases_names_right": sum(bool(r.get("names_right")) for r in eff),
        "effect_cases_scopes_right": sum(bool(r.get("scopes_right")) for r in eff),
        "effect_cases": len(eff),
        "controls": len(ctrl),
        "control_false_positives": sum(bool(r.get("found")) for r in ctrl),
        "test_improved_or_floor": sum(bool(r.get("halved") or r.get("at_floor")) for r in eff),
        "harm": sum(bool(r.get("harm")) for r in scored),
        "median_seconds": statistics.median(times) if times else float("nan"),
        "max_seconds": max(times) if times else float("nan"),
        "distributed_inertia_adopted": sum(str(r.get("inertia", "")).startswith("distributed") for r in scored),
        "excluded_from_pool": excluded,
    }
    per = {}
    for r in eff:
        for e in r["injected"]:
            k = e["name"]
            per.setdefault(k, [0, 0])
            per[k][1] += 1
            per[k][0] += int(any(f.split(":")[0] == k for f in r.get("found", [])))
    summary["named_per_effect"] = {k: f"{a}/{b}" for k, (a, b) in sorted(per.items())}
    s = summary
    lines += ["", "## Summary", "",
              f"- cases: {s['cases']} ({s['scored']} scored, {s['failed']} failed to generate or run)",
              f"- effect cases right (names, scopes, test halved or at floor, no harm): {pct(s['effect_cases_right'], s['effect_cases'])}",
              f"- and right once an alternative the report calls indistinguishable is taken for the found effect: "
              f"{pct(s['effect_cases_right_up_to_equivalence'], s['effect_cases'])}",
              f"- effect names right: {pct(s['effect_cases_names_right'], s['effect_cases'])}; names and scopes: "
              f"{pct(s['effect_cases_scopes_right'], s['effect_cases'])}",
              f"- test median halved or at the noise floor (<= {FLOOR_FACTOR * FLOOR:.5f} rad): "
              f"{pct(s['test_improved_or_floor'], s['effect_cases'])}",
              f"- false positives on controls: {pct(s['control_false_positives'], s['controls'])}",
              f"- final test median above baseline by > {100 * HARM_TOL:.0f} %: {pct(s['harm'], s['scored'])}",
              f"- median time per case: {s['median_seconds']:.0f} s (max {s['max_seconds']:.0f} s)",
              f"- distributed inertia adopted: {s['distributed_inertia_adopted']} of {s['scored']}",
              "- named per effect: " + (", ".join(f"{k} {v}" for k, v in s["named_per_effect"].items()) or "-")]
    if excluded:
        lines.append("- not in the pool (this build of the library does not accept them): " + ", ".join(excluded))
    return "\n".join(lines) + "\n", summary


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--bin", default=os.path.join(here, "..", "build", "bin"),
                    help="folder with softrne-make-case and softrne-loop [default: build/bin]")
    ap.add_argument("--cases", type=int, default=40, help="number of cases [40]")
    ap.add_argument("--seed", type=int, default=1000, help="base seed; case i has seed SEED + i [1000]")
    ap.add_argument("--work", default="score-loop-work", help="folder for the cases [score-loop-work]")
    ap.add_argument("--jobs", type=int, default=1, help="cases run at once (the loop uses 2 threads) [1]")
    ap.add_argument("--only", action="append", default=[],
                    help="restrict the effect pool (repeat or comma separate); EFFECT or EFFECT:SCOPE")
    ap.add_argument("--all-effects", action="store_true",
                    help="keep effects/scopes this build does not accept in the pool (their cases fail to generate)")
    ap.add_argument("--out", help="markdown output [WORK/score.md]; JSON next to it")
    ap.add_argument("--timeout", type=float, default=0, help="seconds per loop run, 0 = none [0]")
    ap.add_argument("--controls-only", action="store_true",
                    help="effect-free cases only (calibrates the false-positive rate)")
    ap.add_argument("--rescore", action="store_true",
                    help="do not run anything: score the cases already in WORK again (e.g. after a scoring change)")
    ap.add_argument("--resume", action="store_true",
                    help="score cases whose report is already in WORK from it and run only the others "
                         "(delete a case folder to run it again)")
    ap.add_argument("--loop-arg", action="append", default=[], help="extra argument for softrne-loop (repeatable)")
    ap.add_argument("--pick", action="append", default=[],
                    help="run and score only the planned cases with these seeds (repeat or comma separate); "
                         "the plan is still that of --cases and --seed, so a case is the same as in the full run")
    args = ap.parse_args()
    if args.cases < 1:
        die("--cases must be >= 1")
    if args.jobs < 1:
        die("--jobs must be >= 1")
    tools = {k: os.path.join(args.bin, n) for k, n in (("make", "softrne-make-case"), ("loop", "softrne-loop"))}
    for t in tools.values():
        if not os.access(t, os.X_OK):
            die(f"{t}: not an executable (see --bin)")
    table = effect_table(tools["make"])
    only = [x for o in args.only for x in o.split(",") if x]
    known = {e for e, _, _ in table}
    for o in only:
        if o.split(":")[0] not in known:
            die(f"--only: unknown effect '{o}' (one of {', '.join(sorted(known))})")
    pool, excluded = [], []
    for e, s, ok in table:
        if only and not any(o == e or o == f"{e}:{s}" for o in only):
            continue
        if ok or args.all_effects:
            pool.append((e, s))
        else:
            excluded.append(f"{e}:{s}")
    if not pool:
        die("the effect pool is empty (see --only, --all-effects)")
    args.work = os.path.abspath(args.work)
    os.makedirs(args.work, exist_ok=True)
    plan = plan_cases(args.cases, args.seed, pool, args.controls_only)
    if args.pick:
        try:
            picked = {int(x) for p in args.pick for x in p.split(",") if x}
        except ValueError:
            die("--pick: seeds are integers")
        missing = sorted(picked - {s for s, _ in plan})
        if missing:
            die(f"--pick: seed {missing[0]} is not in the plan (seeds {args.seed}..{args.seed + args.cases - 1})")
        plan = [(s, e) for s, e in plan if s in picked]
    results = [None] * len(plan)
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as ex:
        futs = {ex.submit(run_case, args, s, e, tools): i for i, (s, e) in enumerate(plan)}
        for fut in concurrent.futures.as_completed(futs):
            i = futs[fut]
            results[i] = fut.result()
            r = results[i]
            print(f"score-loop: case {r['seed']} ({', '.join(r['requested']) or 'none'}): {r['verdict']}"
                  + (f" in {r['seconds']:.0f} s" if "seconds" in r else ""), file=sys.stderr, flush=True)
    md, summary = render(results, args, excluded)
    print(md, end="")
    out = args.out or os.path.join(args.work, "score.md")
    with open(out, "w") as f:
        f.write(md)
    with open(os.path.splitext(out)[0] + ".json", "w") as f:
        json.dump({"summary": summary, "cases": results, "floor": FLOOR, "floor_factor": FLOOR_FACTOR},
                  f, indent=2, default=str)
    print(f"score-loop: wrote {out} and {os.path.splitext(out)[0]}.json", file=sys.stderr)


if __name__ == "__main__":
    main()
