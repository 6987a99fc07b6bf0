#!/usr/bin/env bash
# Packaging test: install softrne to a temporary prefix, then build and run the consumer
# project in this folder twice -- with find_package(softrne CONFIG) against the install,
# and with add_subdirectory(<softrne source>).
# Usage: tests/packaging/run.sh     (env: KEEP_WORK=1 keeps the temp dir, JOBS=n)
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
here="$root/tests/packaging"
work=$(mktemp -d "${TMPDIR:-/tmp}/softrne-packaging.XXXXXX")
if [[ "${KEEP_WORK:-0}" == 1 ]]; then
  echo "[packaging] work dir kept: $work"
else
  trap 'rm -rf "$work"' EXIT
fi
jobs=${JOBS:-$(nproc 2>/dev/null || echo 2)}
gen=()
if command -v ninja >/dev/null 2>&1; then gen=(-G Ninja); fi
step() { echo "[packaging] $*"; }

step "1/3 configure + install softrne to $work/prefix"
# SOFTRNE_BUILD_COMPILED=OFF: src/ (the compiled entry points of our own tests and tools) is
# not installed, so building it here only cost CI minutes (src/fit.cpp alone compiles ~4 min).
cmake -S "$root" -B "$work/softrne-build" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_INSTALL_PREFIX="$work/prefix" -DSOFTRNE_INSTALL=ON \
  -DSOFTRNE_BUILD_TESTS=OFF -DSOFTRNE_BUILD_EXAMPLES=OFF -DSOFTRNE_BUILD_BENCH=OFF \
  -DSOFTRNE_BUILD_TOOLS=OFF -DSOFTRNE_BUILD_COMPILED=OFF >"$work/softrne-configure.log" \
  || { cat "$work/softrne-configure.log"; exit 1; }
cmake --build "$work/softrne-build" -j "$jobs"
cmake --install "$work/softrne-build" >"$work/install.log"
cfg=$(find "$work/prefix" -name softrneConfig.cmake | head -n1)
[[ -n "$cfg" ]] || { echo "[packaging] FAIL: no softrneConfig.cmake installed"; exit 1; }
[[ -f "$work/prefix/include/softrne/config.hpp" ]] \
  || { echo "[packaging] FAIL: headers not installed"; exit 1; }
components=()
[[ -f "$(dirname "$cfg")/softrneSimTargets.cmake" ]] && components+=(sim)
[[ -f "$(dirname "$cfg")/softrneFitTargets.cmake" ]] && components+=(fit)
step "installed $(find "$work/prefix/include" -name '*.hpp' | wc -l) headers," \
  "config $(realpath --relative-to="$work/prefix" "$cfg"), components: core ${components[*]:-}"

build_and_run() {  # name, cmake args...
  local name=$1
  shift
  cmake -S "$here" -B "$work/$name" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release "$@" \
    >"$work/$name-configure.log" || { cat "$work/$name-configure.log"; return 1; }
  grep -E '^-- softrne' "$work/$name-configure.log" || true
  cmake --build "$work/$name" -j "$jobs"
  ctest --test-dir "$work/$name" --output-on-failure
}

comp_list=$(IFS=';'; echo "${components[*]:-}")
step "2/3 consumer with find_package(softrne CONFIG REQUIRED COMPONENTS ${comp_list:-<none>})"
build_and_run consumer-installed -DSOFTRNE_CONSUMER_MODE=find_package \
  -DCMAKE_PREFIX_PATH="$work/prefix" -DSOFTRNE_CONSUMER_COMPONENTS="$comp_list"

step "3/3 consumer with add_subdirectory($root)"
build_and_run consumer-subdir -DSOFTRNE_CONSUMER_MODE=subdirectory -DSOFTRNE_SOURCE_DIR="$root"

step "PASSED"
