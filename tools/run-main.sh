#!/usr/bin/env bash
# One command on a new machine: install the dependencies, build (Release), run the main job.
#
#   ./tools/run-main.sh
#
# The main job is the closed loop on the example arm (formats.md section 5):
#   build/bin/softrne-loop --robot examples/data/arm-a-1/robot.json \
#     --train examples/data/arm-a-1/train.csv --test examples/data/arm-a-1/test.csv \
#     --out build/loop-report.json
# Until softrne-loop exists it falls back to softrne-sim on the test set, then to the
# examples in build/bin.
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
if [[ -x "$bin/softrne-loop" ]]; then
  run "$bin/softrne-loop" --robot "$data/robot.json" --train "$data/train.csv" \
    --test "$data/test.csv" --out "$build_dir/loop-report.json"
  echo "[run-main] report: $build_dir/loop-report.json"
elif [[ -x "$bin/softrne-sim" ]]; then
  run "$bin/softrne-sim" --robot "$data/robot.json" --pressures "$data/test.csv" \
    --out "$build_dir/sim-test.csv"
  echo "[run-main] simulation: $build_dir/sim-test.csv"
else
  # Examples: executables in bin/ named example*, softrne-example* or NN_* / NN-*.
  mapfile -t examples < <(find "$bin" -maxdepth 1 -type f -perm -u+x \
    \( -name 'example*' -o -name 'softrne-example*' -o -name '[0-9][0-9][_-]*' \) 2>/dev/null | sort)
  if [[ ${#examples[@]} -eq 0 ]]; then
    echo "[run-main] nothing to run yet: no softrne-loop, softrne-sim or examples in $bin"
    exit 0
  fi
  for ex in "${examples[@]}"; do run "$ex"; done
fi
