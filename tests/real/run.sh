#!/usr/bin/env bash
# Real-data smoke test (docs/real-data.md): import the SRL soft-trunk logs, check the angle
# convention check's verdict, fit K and D on the training log and check the held-out error.
# Skips (exit 77) when the data is absent: it is not redistributable and never in the repo.
#   tests/real/run.sh BIN_DIR [WORK_DIR]
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
bin=${1:?usage: run.sh BIN_DIR [WORK_DIR]}
work=${2:-$(mktemp -d)}
data=${SRL_DATA:-$repo/../shared/data/real/srl-3d-soft-trunk}
py=${PYTHON:-python3}
if [[ ! -d "$data/longitudinal_q" ]]; then
  echo "SKIP: $data/longitudinal_q not found (real data absent)"; exit 77
fi
if ! "$py" -c 'import numpy, scipy' 2>/dev/null; then
  echo "SKIP: $py lacks numpy/scipy"; exit 77
fi
mkdir -p "$work"
"$py" "$repo/tools/import_srl_trunk.py" --data "$data" --out "$work" --guess-logs MPC_logger_ts1 > "$work/import.log"
"$bin/softrne-fit" --robot "$work/robot.json" --data "$work/MPC_logger_ts1.csv" \
  --test "$work/MPC_logger_ts2.csv" --fit-to angles --out "$work/fitted.json" --quiet > "$work/fit.log" 2>&1
"$py" - "$work" <<'PY'
import json, re, sys
w = sys.argv[1]
s = json.load(open(w + "/import-summary.json"))
assert s["kinematics_self_check"]["ok"], s["kinematics_self_check"]
rows = s["convention_check"]["candidates"]
proper = min(r["rms_mm_fitted_rotation"] for r in rows if r["det"] == 1)
improper = min(r["rms_mm_fitted_rotation"] for r in rows if r["det"] == -1)
assert proper < 20 and improper > 1.5 * proper, (proper, improper)
assert s["convention_check"]["S"] == [[0.0, 1.0], [-1.0, 0.0]], s["convention_check"]["S"]
# test-set total median error after the fit (README numbers: ~0.067 rad)
txt = open(w + "/fit.log").read().split("test, after")[1]
med = float(re.search(r"total\s+[\d.]+\s+([\d.]+)", txt).group(1))
assert med < 0.10, med
print("real-data smoke test: convention proper %.1f mm vs improper %.1f mm; test median %.3f rad" % (proper, improper, med))
PY
