#!/usr/bin/env bash
# One command on a new machine: install the dependencies, build (Release), run the main job.
#
#   ./tools/run-main.sh
#
# The main job is the closed loop on the example arm (formats.md section 5):
#   build/bin/softrne-loop --robot examples/data/arm-a-1/robot.json \
#     --train examples/data/arm-a-1/train.csv --test examples/data/arm-a-1/test.csv \
#     --out build/loop-report.json
# It first runs the example simulation (softrne-sim on the test set, error table), then the
# closed loop with plots when numpy and matplotlib are present (install-deps.sh --python).
# Environment: BUILD_DIR (default build), JOBS (default nproc), SOFTRNE_SKIP_DEPS=1.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build_dir=${BUILD_DIR:-build}
jobs=${JOBS:-$(nproc 2>/dev/null || echo 2)}
data=examples/data/arm-a-1

if [[ "${SOFTRNE_SKIP_DEPS:-0}" != 1 ]]; then
  ./tools/install-deps.sh
fi

gen=()
if [[ ! -f "$build_dir/CMakeCache.txt" ]] && command -v ninja >/dev/null 2>&1; then
  gen=(-G Ninja)
fi
echo "[run-main] configure + build $build_dir (Release)"
cmake -S . -B "$build_dir" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release -DSOFTRNE_REQUIRE_ALL=ON \
  -DSOFTRNE_BUILD_TOOLS=ON -DSOFTRNE_BUILD_EXAMPLES=ON -DSOFTRNE_BUILD_TESTS=OFF \
  -DSOFTRNE_BUILD_BENCH=OFF
cmake --build "$build_dir" -j "$jobs"

bin="$build_dir/bin"
run() { echo "[run-main] \$ $*"; "$@"; }
# 1. The example simulation: the nominal robot on the test pressures, error table vs measured.
if [[ -x "$bin/softrne-sim" ]]; then
  run "$bin/softrne-sim" --robot "$data/robot.json" --pressures "$data/test.csv" \
    --out "$build_dir/sim-test.csv"
  echo "[run-main] simulation: $build_dir/sim-test.csv"
fi
# 2. The closed loop: baseline fit, residual, effect discovery, refit, report (+ plots).
if [[ -x "$bin/softrne-loop" ]]; then
  plots=()
  for py in python3 /usr/bin/python3; do  # the first interpreter with numpy and matplotlib
    if "$py" -c 'import numpy, matplotlib' 2>/dev/null; then
      export SOFTRNE_PYTHON=$py
      plots=(--plots "$build_dir/loop-plots")
      break
    fi
  done
  run "$bin/softrne-loop" --robot "$data/robot.json" --train "$data/train.csv" \
    --test "$data/test.csv" --out "$build_dir/loop-report.json" "${plots[@]}"
  echo "[run-main] report: $build_dir/loop-report.json"
  if [[ ${#plots[@]} -gt 0 ]]; then echo "[run-main] plots: $build_dir/loop-plots/*.png"; fi
fi
if [[ ! -x "$bin/softrne-sim" && ! -x "$bin/softrne-loop" ]]; then
  echo "[run-main] no tools were built in $bin" >&2
  exit 1
fi
