#!/usr/bin/env bash
# Real hardware data, end to end: the ETH SRL two-segment soft trunk (docs/real-data.md).
#
#   ./tools/run-real-data.sh
#
# 1. builds softrne-sim/fit/loop into $BUILD_DIR (default build-real) if they are missing,
# 2. imports the logs (tools/import_srl_trunk.py): robot.json, one CSV per log, the angle
#    convention check, into $BUILD_DIR/srl (outside git: the data has no license),
# 3. fits stiffness and damping on the training log (softrne-fit, with uncertainties),
# 4. runs the closed loop (softrne-loop) on training + test log, with plots,
# 5. measures the baseline and the final model on the other test logs (softrne-sim) and
#    writes $BUILD_DIR/srl/results.md,
# 6. fits several logs that start in motion from their angles alone and from the tip marker
#    alone, compares both on held-out logs, and runs the loop on the several logs (results.md).
# The data is read from ../shared/data/real/srl-3d-soft-trunk (relative to the repository) or
# $SRL_DATA; when it is absent the script says so and exits 0 without doing anything.
# Environment: BUILD_DIR, JOBS (default 2), SRL_DATA, PYTHON (default: the first python3 with numpy and scipy),
# SRL_TRAIN (default MPC_logger_ts1), SRL_TEST (default MPC_logger_ts2),
# SRL_MORE_TESTS (default "MPC_logger_ts3 MPC_logger_tube1 MPC_logger_tube2 MPC_logger_tube3"),
# SRL_MULTI_TRAIN, SRL_MULTI_TEST (item 6: default ts1 tube1 tube2 / ts2 ts3 tube3).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

data=${SRL_DATA:-../shared/data/real/srl-3d-soft-trunk}
build_dir=${BUILD_DIR:-build-real}
jobs=${JOBS:-2}
# The importer needs numpy and scipy: take $PYTHON, else the first of python3, /usr/bin/python3
# that has both (as run-main.sh searches for numpy and matplotlib).
py=${PYTHON:-}
if [[ -z "$py" ]]; then
  for candidate in python3 /usr/bin/python3; do
    if "$candidate" -c 'import numpy, scipy' 2>/dev/null; then py=$candidate; break; fi
  done
  if [[ -z "$py" ]]; then
    echo "[run-real-data] error: no python3 with numpy and scipy (tools/install-deps.sh --python, or set PYTHON)" >&2
    exit 2
  fi
elif ! "$py" -c 'import numpy, scipy' 2>/dev/null; then
  echo "[run-real-data] error: PYTHON=$py lacks numpy or scipy" >&2
  exit 2
fi
train=${SRL_TRAIN:-MPC_logger_ts1}
test=${SRL_TEST:-MPC_logger_ts2}
more_tests=${SRL_MORE_TESTS:-MPC_logger_ts3 MPC_logger_tube1 MPC_logger_tube2 MPC_logger_tube3}
# Item 6: logs of one arm build (the same commit of the SRL code), several for training.
multi_train=${SRL_MULTI_TRAIN:-MPC_logger_ts1 MPC_logger_tube1 MPC_logger_tube2}
multi_test=${SRL_MULTI_TEST:-MPC_logger_ts2 MPC_logger_ts3 MPC_logger_tube3}
out="$build_dir/srl"

if [[ ! -d "$data/longitudinal_q" ]]; then
  echo "[run-real-data] $data/longitudinal_q not found: the real data is not on this machine; skipped"
  exit 0
fi
bin="$build_dir/bin"
if [[ ! -x "$bin/softrne-loop" || ! -x "$bin/softrne-sim" || ! -x "$bin/softrne-fit" ]]; then
  gen=()
  if [[ ! -f "$build_dir/CMakeCache.txt" ]] && command -v ninja >/dev/null 2>&1; then gen=(-G Ninja); fi
  echo "[run-real-data] configure + build $build_dir (Release)"
  cmake -S . -B "$build_dir" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release -DSOFTRNE_REQUIRE_ALL=ON \
    -DSOFTRNE_BUILD_TOOLS=ON -DSOFTRNE_BUILD_TESTS=OFF -DSOFTRNE_BUILD_BENCH=OFF
  cmake --build "$build_dir" -j "$jobs"
fi
run() { echo "[run-real-data] \$ $*"; "$@"; }

# 2. Import (the convention check prints its table; --guess-logs = the training log only).
run "$py" tools/import_srl_trunk.py --data "$data" --out "$out" --guess-logs "$train" | tee "$out.import.log"
mv "$out.import.log" "$out/import.log"

# 3. Baseline fit of K and D with parameter uncertainties.
# (--fit-to angles: the tip marker columns are item 6's.)
run "$bin/softrne-fit" --robot "$out/robot.json" --data "$out/$train.csv" --test "$out/$test.csv" \
  --fit-to angles --out "$out/fitted.json" --quiet 2>&1 | tee "$out/fit.log"

# 4. The closed loop (plots when matplotlib is there: softrne-loop calls tools/plot_loop.py).
plots=()
if "$py" -c 'import numpy, matplotlib' 2>/dev/null; then
  export SOFTRNE_PYTHON=$py
  plots=(--plots "$out/plots")
fi
run "$bin/softrne-loop" --robot "$out/robot.json" --train "$out/$train.csv" --test "$out/$test.csv" \
  --out "$out/loop-report.json" "${plots[@]}" 2>&1 | tee "$out/loop.log"
"$py" -c 'import json,sys; json.dump(json.load(open(sys.argv[1]))["fitted_robot"], open(sys.argv[2], "w"), indent=2)' \
  "$out/loop-report.json" "$out/final.json"

# 5. Both models on every test log; a summary table.
for log in "$test" $more_tests; do
  for model in fitted final; do
    "$bin/softrne-sim" --robot "$out/$model.json" --pressures "$out/$log.csv" --quiet \
      --out "$out/sim-$model-$log.csv" > "$out/sim-$model-$log.txt" 2>&1
  done
done
"$py" - "$out" "$train" "$test" $more_tests <<'EOF'
import json, os, re, sys
out, train, logs = sys.argv[1], sys.argv[2], sys.argv[3:]
rep = json.load(open(os.path.join(out, "loop-report.json")))
if rep.get("format") != "softrne-loop-report/2":
    sys.exit("run-real-data: %s: unknown report format %r (expected softrne-loop-report/2)"
             % (os.path.join(out, "loop-report.json"), rep.get("format")))
def table(path):
    rows = {}
    for line in open(path):
        m = re.match(r"\s+(u\d|v\d|total)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)", line)
        if m:
            rows[m.group(1)] = tuple(float(x) for x in m.groups()[1:])
    return rows
lines = ["# softrne on the SRL soft trunk (generated by tools/run-real-data.sh; not for git)", "",
         "effects added by the loop: " + (", ".join("%s (%s %s)" % (e["name"], e.get("scope", ""), " ".join(e.get("joints", [])))
                                            for e in rep["effects"]) or "none"), "",
         "still unexplained (train): " + rep.get("unexplained", {}).get("train", {}).get("statement", ""), "",
         "| log | role | baseline mean | baseline median | baseline max | final mean | final median | final max |",
         "| --- | --- | --- | --- | --- | --- | --- | --- |"]
for key, role in (("train", "train"),):
    b, f = rep["baseline"][key], rep["final"][key]
    lines.append("| %s | %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f |" % (
        train, role, b["mean"], b["median"], b["max"], f["mean"], f["median"], f["max"]))
for i, log in enumerate(logs):
    b = table(os.path.join(out, "sim-fitted-%s.txt" % log)).get("total")
    f = table(os.path.join(out, "sim-final-%s.txt" % log)).get("total")
    if b and f:
        lines.append("| %s | %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f |" % (
            (log, "test (loop)" if i == 0 else "test") + b + f))
lines += ["", "per angle (mean / median / max, rad), baseline -> final:", ""]
for log in logs:
    b = table(os.path.join(out, "sim-fitted-%s.txt" % log))
    f = table(os.path.join(out, "sim-final-%s.txt" % log))
    lines.append("- %s: " % log + "; ".join(
        "%s %.3f/%.3f/%.3f -> %.3f/%.3f/%.3f" % ((k,) + b[k] + f[k]) for k in ("u1", "v1", "u2", "v2") if k in b and k in f))
open(os.path.join(out, "results.md"), "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
EOF
# 6. Several logs of one arm build that start in motion, and the tip marker (issue 19 item 4):
#    fitted from the angles alone and from the motion-capture tip alone (a frame per log: the
#    logs' capture frames differ), both measured on held-out logs in angle and tip error; then
#    the closed loop on the several training logs, held-out logs before and after.
fit_multi() {  # fit_multi <what the objective holds>
  "$bin/softrne-fit" --robot "$out/robot.json" "${multi_data[@]}" "${multi_tests[@]}" --initial-motion estimated \
    --frame-per-recording --fit-to "$1" --out "$out/multi-fit-$1.json" --report "$out/multi-fit-$1-report.json" \
    --quiet > "$out/multi-fit-$1.log" 2>&1
}
multi_data=() multi_tests=() multi_train_args=()
for log in $multi_train; do multi_data+=(--data "$out/$log.csv"); multi_train_args+=(--train "$out/$log.csv"); done
for log in $multi_test; do multi_tests+=(--test "$out/$log.csv"); done
run fit_multi angles
run fit_multi markers
run "$bin/softrne-loop" --robot "$out/robot.json" "${multi_train_args[@]}" "${multi_tests[@]}" \
  --initial-motion estimated --out "$out/multi-loop-report.json" > "$out/multi-loop.log" 2>&1
"$py" - "$out" <<'EOF'
import json, os, sys
out = sys.argv[1]
fa, fm = (json.load(open(os.path.join(out, "multi-fit-%s-report.json" % w))) for w in ("angles", "markers"))
loop = json.load(open(os.path.join(out, "multi-loop-report.json")))
def tip(rep, part):
    return rep["markers"][part]["after"]["median"]
rows = ["", "## Several logs, angles or the tip marker (issue 19 item 4)", "",
        "train: %s; held out: %s; each log from its estimated initial rates; one capture frame per log"
        % (", ".join(os.path.basename(r["source"]) for r in loop["recordings"]["train"]),
           ", ".join(os.path.basename(r["source"]) for r in loop["recordings"]["test"])), "",
        "| fitted to | test angle median (rad) | test tip median (mm) | train angle median (rad) | train tip median (mm) |",
        "| --- | --- | --- | --- | --- |"]
for name, rep in (("angles only", fa), ("tip marker only (never saw an angle)", fm)):
    rows.append("| %s | %.4f | %.1f | %.4f | %.1f |" % (name, rep["test"]["after"]["median"], tip(rep, "test"),
                                                      rep["train"]["after"]["median"], tip(rep, "train")))
rows += ["", "| parameter | fitted to angles | fitted to the tip |", "| --- | --- | --- |"]
pm = {p["name"]: p for p in fm["parameters"]}
def fmt(x):
    se = x.get("std_error")
    return "%.4g +- %s" % (x["value"], "%.2g" % se if se is not None else "?")
for p in fa["parameters"]:
    q = pm.get(p["name"])
    rows.append("| %s | %s | %s |" % (p["name"], fmt(p), fmt(q) if q else "-"))
def effect(e):
    params = ", ".join("%s %.3g +- %s" % (k, v, "%.2g" % e["std_errors"][k] if e["std_errors"].get(k) is not None else "?")
                       for k, v in e["params"].items())
    return "%s (%s %s: %s)" % (e["name"], e["scope"], " ".join(e["joints"]), params)
rows += ["", "closed loop on the training logs (folds hold out whole logs): added " +
         ("; ".join(effect(e) for e in loop["effects"]) or "nothing") +
         ". Test median %.4f -> %.4f rad; per held-out log:" % (loop["baseline"]["test"]["median"],
                                                              loop["final"]["test"]["median"])]
for r in loop["recordings"]["test_medians"]:
    rows.append("- %s: %.4f -> %.4f rad" % (os.path.basename(r["source"]), r["baseline_median"], r["final_median"]))
with open(os.path.join(out, "results.md"), "a") as f:
    f.write("\n".join(rows) + "\n")
print("\n".join(rows))
EOF
echo "[run-real-data] outputs in $out (robot.json, conventions.md, fit.log, loop-report.json, plots/, multi-*, results.md)"
