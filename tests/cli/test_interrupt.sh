#!/usr/bin/env bash
# Ctrl-C during a long computation (formats.md section 6): softrne-fit and softrne-loop stop
# cleanly, exit 130 with one line on stderr saying so, and write nothing (no output file, no
# temporary file). The wait is bounded only to catch a hang (no timing assertion).
#
#   test_interrupt.sh <softrne-fit> <softrne-loop> <examples/data/arm-a-1>
set -u
if [[ $# -ne 3 ]]; then
  echo "usage: $0 <softrne-fit> <softrne-loop> <examples/data/arm-a-1>" >&2
  exit 2
fi
fit=$1 loop=$2 data=$3
source "$(dirname "$0")/common.sh"
make_scratch softrne-interrupt

# interrupt <name> <output file> <command...>: SIGINT after 1 s, then wait up to 60 s.
interrupt() {
  local name=$1 out=$2
  shift 2
  "$@" >"$tmp/$name.stdout" 2>"$tmp/$name.stderr" </dev/null &
  local pid=$!
  sleep 1
  if ! kill -0 "$pid" 2>/dev/null; then
    wait "$pid"
    fail "$name: finished (status $?) before the interrupt; nothing tested"
    return
  fi
  kill -INT "$pid"
  local waited=0
  while kill -0 "$pid" 2>/dev/null && ((waited < 600)); do
    sleep 0.1
    waited=$((waited + 1))
  done
  if kill -0 "$pid" 2>/dev/null; then
    kill -KILL "$pid"
    fail "$name: still running 60 s after Ctrl-C"
    return
  fi
  wait "$pid"
  local rc=$?
  if [[ $rc -ne 130 ]]; then
    fail "$name: exit status $rc, expected 130; stderr: $(tail -2 "$tmp/$name.stderr")"
  elif ! tail -1 "$tmp/$name.stderr" | grep -q "interrupted (Ctrl-C)"; then
    fail "$name: last stderr line does not say interrupted: $(tail -1 "$tmp/$name.stderr")"
  elif [[ -e $out ]] || ls "$out".part-* >/dev/null 2>&1; then
    fail "$name: wrote $out after Ctrl-C"
  else
    echo "ok   $name: stopped $((waited / 10)).$((waited % 10)) s after Ctrl-C, exit 130, nothing written"
  fi
}

# One thread and the pressure gains: about 5 s on an idle fast machine, where the default fit
# (2 threads, stiffness and damping only) finished in under 2 s, before the interrupt.
interrupt softrne-fit "$tmp/fitted.json" "$fit" --robot "$data/robot.json" --data "$data/train.csv" \
  --out "$tmp/fitted.json" --quiet --threads 1 --pressure-gain
interrupt softrne-loop "$tmp/report.json" "$loop" --robot "$data/robot.json" --train "$data/train.csv" \
  --test "$data/test.csv" --out "$tmp/report.json"

finish
