#!/usr/bin/env bash
# One command on a new machine: install the dependencies, configure, build, run the tests.
#
#   ./tools/run-tests.sh [extra cmake -D options]
#
# Environment: BUILD_DIR (default build), BUILD_TYPE (default Release), JOBS (default nproc),
#              SOFTRNE_SKIP_DEPS=1 to skip tools/install-deps.sh (not a Debian machine).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build_dir=${BUILD_DIR:-build}
build_type=${BUILD_TYPE:-Release}
jobs=${JOBS:-$(nproc 2>/dev/null || echo 2)}

if [[ "${SOFTRNE_SKIP_DEPS:-0}" != 1 ]]; then
  ./tools/install-deps.sh
fi

gen=()
if [[ ! -f "$build_dir/CMakeCache.txt" ]] && command -v ninja >/dev/null 2>&1; then
  gen=(-G Ninja)
fi
echo "[run-tests] configure $build_dir ($build_type)"
cmake -S . -B "$build_dir" "${gen[@]}" -DCMAKE_BUILD_TYPE="$build_type" \
  -DSOFTRNE_REQUIRE_ALL=ON -DSOFTRNE_BUILD_TESTS=ON -DSOFTRNE_BUILD_EXAMPLES=ON \
  -DSOFTRNE_BUILD_TOOLS=ON -DSOFTRNE_BUILD_BENCH=ON "$@"
echo "[run-tests] build ($jobs jobs)"
cmake --build "$build_dir" -j "$jobs"
echo "[run-tests] ctest"
ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" --timeout "${TEST_TIMEOUT:-900}"
