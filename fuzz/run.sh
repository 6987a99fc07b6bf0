#!/usr/bin/env bash
# Build the libFuzzer targets of the softrne::io parsers and run each for SECONDS.
#
#   fuzz/run.sh SECONDS [TARGET...]      (default targets: fuzz_robot_json fuzz_csv)
#
# Environment: FUZZ_BUILD_DIR (default build-fuzz, relative to the repository root),
#   CXX (default clang++), JOBS (default 2), FUZZ_WORKERS (parallel jobs per target,
#   default 1), FUZZ_MAX_LEN (default 16384 bytes), FUZZ_PARALLEL (1: all targets at the
#   same time, one core each; default 1 when JOBS >= 2).
# Each target starts from its seed corpus fuzz/corpus/<name>/ plus a working corpus in
# <build>/corpus/<name>/ (new inputs go there, never into the source tree), with
# -max_total_time=SECONDS -rss_limit_mb=2048 -timeout=10. Crashes, timeouts and
# out-of-memory inputs are copied to fuzz/regressions/<target>-<kind>-<sha1> (replayed by
# tests/fuzz_regressions). Exit status: 0 if no target found anything, 1 otherwise.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=$PWD

if [[ $# -lt 1 || ! $1 =~ ^[0-9]+$ ]]; then
  echo "usage: fuzz/run.sh SECONDS [TARGET...]" >&2
  exit 2
fi
seconds=$1
shift
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then targets=(fuzz_robot_json fuzz_csv); fi

build_dir=${FUZZ_BUILD_DIR:-build-fuzz}
[[ $build_dir = /* ]] || build_dir=$root/$build_dir
cxx=${CXX:-clang++}
jobs=${JOBS:-2}
workers=${FUZZ_WORKERS:-1}
max_len=${FUZZ_MAX_LEN:-16384}

if ! command -v "$cxx" >/dev/null; then
  echo "fuzz/run.sh: $cxx not found (Debian: apt-get install clang libclang-rt-dev)" >&2
  exit 2
fi
gen=()
if [[ ! -f $build_dir/CMakeCache.txt ]] && command -v ninja >/dev/null; then gen=(-G Ninja); fi
cmake -S "$root/fuzz" -B "$build_dir" "${gen[@]}" -DCMAKE_CXX_COMPILER="$cxx" >/dev/null
cmake --build "$build_dir" -j "$jobs" --target "${targets[@]}"

mkdir -p "$root/fuzz/regressions"
# One target per core: with FUZZ_PARALLEL (default: JOBS >= 2) the targets run at the same
# time, each its full SECONDS on its own core, so the wall time is SECONDS instead of
# SECONDS x targets; their reports are printed in order when all have finished.
parallel=${FUZZ_PARALLEL:-$((jobs >= 2 ? 1 : 0))}

fuzz_one() {  # target; prints the report, returns 1 on a finding or error
  local t=$1 name exe work artifacts log dict par start rc elapsed execs cov found f base kind sha dest
  name=${t#fuzz_}
  exe=$build_dir/$t
  work=$build_dir/corpus/$name
  artifacts=$build_dir/artifacts/$name
  mkdir -p "$work" "$artifacts"
  rm -f "$artifacts"/crash-* "$artifacts"/timeout-* "$artifacts"/oom-* "$artifacts"/leak-*
  log=$build_dir/$t.log
  dict=()
  [[ -f $root/fuzz/$name.dict ]] && dict=(-dict="$root/fuzz/$name.dict")
  echo "== $t: ${seconds} s, log $log"
  start=$SECONDS
  rc=0
  # -jobs/-workers run independent fuzzing processes (fuzz-<n>.log in the current directory).
  par=()
  if [[ $workers -gt 1 ]]; then par=(-jobs="$workers" -workers="$workers"); fi
  (cd "$build_dir" && "$exe" "$work" "$root/fuzz/corpus/$name" "${dict[@]}" "${par[@]}" \
      -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -max_len="$max_len" \
      -artifact_prefix="$artifacts/" -print_final_stats=1) >"$log" 2>&1 || rc=$?
  elapsed=$((SECONDS - start))
  execs=$(grep -ho 'stat::number_of_executed_units: *[0-9]*' "$log" | awk '{s += $2} END {print s + 0}')
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
  echo "   ran ${elapsed} s, ${execs} executions, ${cov:-cov: ?}, exit ${rc}"
  found=0
  for f in "$artifacts"/crash-* "$artifacts"/timeout-* "$artifacts"/oom-* "$artifacts"/leak-*; do
    [[ -f $f ]] || continue
    base=$(basename "$f")
    kind=${base%%-*}
    sha=$(sha1sum "$f" | cut -c1-40)
    dest=$root/fuzz/regressions/$t-$kind-$sha
    cp "$f" "$dest"
    echo "   FOUND $kind: $dest"
    found=1
  done
  if [[ $rc -ne 0 || $found -ne 0 ]]; then
    echo "   finding or error: see $log" >&2
    grep -m20 -E 'ERROR|SUMMARY|runtime error|terminate|what\(\)' "$log" >&2 || true
    return 1
  fi
  return 0
}

status=0
if [[ $parallel -eq 1 && ${#targets[@]} -gt 1 ]]; then
  echo "== ${#targets[@]} targets in parallel (FUZZ_PARALLEL=1)"
  pids=()
  for t in "${targets[@]}"; do
    fuzz_one "$t" >"$build_dir/$t.report" 2>&1 &
    pids+=($!)
  done
  for i in "${!targets[@]}"; do
    wait "${pids[i]}" || status=1
    cat "$build_dir/${targets[i]}.report"
  done
else
  for t in "${targets[@]}"; do
    fuzz_one "$t" || status=1
  done
fi
exit $status
