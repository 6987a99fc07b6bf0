#!/usr/bin/env bash
# Smoke test of softrne-make-case (tools/common/random_arm.hpp): for a fixed seed it writes
# robot.json, truth.json, case.json, train.csv and test.csv; robot.json and truth.json read
# back through softrne-sim with test.csv (simulating both must succeed); a bad command line
# is one line on stderr with exit status 2.
#
#   test_softrne_make_case.sh <path to softrne-make-case> <path to softrne-sim>
set -u
if [[ $# -ne 2 ]]; then
  echo "usage: $0 <softrne-make-case> <softrne-sim>" >&2
  exit 2
fi
make_case=$1
sim=$2
source "$(dirname "$0")/common.sh"
make_scratch softrne-make-case

for spec in "none:--none" "stiffening:--effects stiffening:joint"; do
  name=${spec%%:*}
  # shellcheck disable=SC2086
  if ! "$make_case" --seed 3 ${spec#*:} --test-seconds 4 --train-seconds 4 --out "$tmp/$name" \
      >"$tmp/$name.out" 2>"$tmp/$name.err"; then
    fail "$name: softrne-make-case failed: $(cat "$tmp/$name.err")"
    continue
  fi
  for f in robot.json truth.json case.json train.csv test.csv; do
    [[ -s $tmp/$name/$f ]] || fail "$name: $f missing or empty"
  done
  for r in robot.json truth.json; do
    if "$sim" --robot "$tmp/$name/$r" --pressures "$tmp/$name/test.csv" --quiet >"$tmp/sim.out" 2>"$tmp/sim.err"; then
      echo "ok   $name: softrne-sim reads $r with test.csv"
    else
      fail "$name: softrne-sim --robot $r --pressures test.csv: $(cat "$tmp/sim.err")"
    fi
  done
  grep -q '"format": "softrne-case/1"' "$tmp/$name/case.json" || fail "$name: case.json has no format"
done
# The declared robot simulated against the data it does not fully describe: an error table.
grep -q "median" "$tmp/sim.out" || fail "no error table from softrne-sim"
# With an effect the truth differs from the declared robot.
grep -q '"effects"' "$tmp/stiffening/truth.json" || fail "stiffening: truth.json has no effects"
grep -q '"effects"' "$tmp/stiffening/robot.json" && fail "stiffening: robot.json has effects"
# Same seed, same arm: the declared robots of the control and the effect case are identical.
cmp -s "$tmp/none/robot.json" "$tmp/stiffening/robot.json" || fail "seed 3: the arm depends on the effects"

# Bad command lines: exit 2, one line.
for bad in "--seed 1 --out $tmp/x" "--seed 1 --effects nosuch --out $tmp/x" \
           "--seed 1 --effects payload:joint --out $tmp/x" "--seed 1 --none --effects payload --out $tmp/x"; do
  # shellcheck disable=SC2086
  "$make_case" $bad >/dev/null 2>"$tmp/err.txt"
  rc=$?
  lines=$(wc -l <"$tmp/err.txt")
  if [[ $rc -ne 2 || $lines -ne 1 ]]; then
    fail "'$bad': exit $rc, $lines lines on stderr: $(cat "$tmp/err.txt")"
  else
    echo "ok   '$bad': $(cat "$tmp/err.txt")"
  fi
done
"$make_case" --list-effects >"$tmp/list.txt" || fail "--list-effects failed"
grep -q "^stiffening	shared	yes" "$tmp/list.txt" || fail "--list-effects: stiffening shared does not build"

finish
