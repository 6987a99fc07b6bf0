#!/usr/bin/env bash
# The command line of every tool (docs/formats.md section 6; parsed by CLI11 through
# tools/common/cli.hpp): --help, and bad command lines that exit 2 with one line on stderr,
# "<tool>: ... (see --help)", naming the option or argument at fault. Nothing here gets as far
# as reading a file, so nothing is simulated.
#
#   test_command_line.sh <softrne-sim> <softrne-fit> <softrne-loop> <softrne-make-case> <examples/data/arm-a-1>
set -u
if [[ $# -ne 5 ]]; then
  echo "usage: $0 <softrne-sim> <softrne-fit> <softrne-loop> <softrne-make-case> <examples/data/arm-a-1>" >&2
  exit 2
fi
sim=$1 fit=$2 loop=$3 make_case=$4 data=$5
source "$(dirname "$0")/common.sh"
make_scratch softrne-command-line
robot=$data/robot.json train=$data/train.csv test=$data/test.csv

# usage <tool> <name> <text the one line must contain> <args...>: exit 2, one line.
usage() {
  local tool=$1
  shift
  expect_failure 2 "$tool" "$(basename "$tool"): $1" "${@:2}"
  [[ $(cat "$tmp/stderr.txt") == *"(see --help)" ]] ||
    fail "$(basename "$tool"): $1: the message does not end with '(see --help)'"
}

# ---- --help: on stdout, exit 0, wherever it stands and whatever else is wrong --------------
for tool in "$sim" "$fit" "$loop" "$make_case"; do
  name=$(basename "$tool")
  for args in "--help" "-h" "--seed 1.5 --frobnicate --help" "--help --out"; do
    # shellcheck disable=SC2086
    if "$tool" $args >"$tmp/help.txt" 2>"$tmp/help_err.txt" </dev/null &&
      grep -q "^usage: $name --" "$tmp/help.txt" && grep -q "^exit status: 0 success" "$tmp/help.txt" &&
      [[ ! -s $tmp/help_err.txt ]]; then
      echo "ok   $name $args: help"
    else
      fail "$name $args: exit status, help text or stderr wrong: $(head -3 "$tmp/help.txt") $(cat "$tmp/help_err.txt")"
    fi
  done
done

# ---- the same rules in every tool -----------------------------------------------------------
# A good command line of each tool, ending in --out and its value (nothing is run with it).
sim_ok=(--robot "$robot" --pressures "$test" --out "$tmp/sim.csv")
fit_ok=(--robot "$robot" --data "$train" --out "$tmp/fitted.json")
loop_ok=(--robot "$robot" --train "$train" --test "$test" --out "$tmp/report.json")
make_case_ok=(--seed 3 --none --out "$tmp/case")
for tool in sim fit loop make_case; do
  declare -n ok=${tool}_ok
  exe=${!tool}
  n=${#ok[@]}
  usage "$exe" "unknown option" "unexpected argument: '--frobnicate'" "${ok[@]}" --frobnicate
  usage "$exe" "unknown option with a value" "unexpected arguments: '--frobnicate' '3'" "${ok[@]}" --frobnicate 3
  usage "$exe" "positional argument" "unexpected argument: 'extra.csv'" "${ok[@]}" extra.csv
  usage "$exe" "single-dash option" "unexpected argument: '-q'" "${ok[@]}" -q
  usage "$exe" "missing value" "--out" "${ok[@]:0:n-2}" --out
  usage "$exe" "empty value" "--out: empty value" "${ok[@]:0:n-1}" ""
  usage "$exe" "option given twice" "--out" "${ok[@]}" --out "$tmp/again"
  usage "$exe" "flag with a value" "--quiet = junk" "${ok[@]}" --quiet=junk
  # The misspelt option is named, not only the required one it leaves missing.
  usage "$exe" "misspelt required option" "unexpected arguments: '${ok[0]}x'" "${ok[0]}x" "${ok[@]:1}"
  unset -n ok
done

# ---- a robot file that reads but does not build: the same status and message in every tool --
# (exit 3, an input file's problem, README "Exit codes"; the file named once)
# (the file's last "]" closes "segments"; an "effects" entry with no parameters follows it)
sed '$d' "$robot" | sed '$d' >"$tmp/unbuildable.json"
echo '  ], "effects": [{"name": "stiffening", "joints": ["joint1"], "params": {}}]}' >>"$tmp/unbuildable.json"
bad_robot=$tmp/unbuildable.json
for tool in sim fit loop; do
  declare -n ok=${tool}_ok
  exe=${!tool}
  expect_failure 3 "$exe" "$tool: robot file that does not build" \
    "$(basename "$exe"): $bad_robot: effects[0] 'stiffening': field 'params': no parameters" \
    --robot "$bad_robot" "${ok[@]:2}"
  [[ $(grep -o "$bad_robot" "$tmp/stderr.txt" | wc -l) -eq 1 ]] ||
    fail "$tool: the robot file is not named exactly once: $(cat "$tmp/stderr.txt")"
  unset -n ok
done

# ---- integer options take decimal integers only ---------------------------------------------
for bad in 1.5 1e3 0x10 abc "" " 7"; do
  usage "$fit" "--seed '$bad'" "--seed" "${fit_ok[@]}" --seed "$bad"
done
usage "$fit" "--seed 1.5 says why" "--seed: not an integer: '1.5'" "${fit_ok[@]}" --seed 1.5
usage "$fit" "--seed -1" "--seed: Value -1 not in range" "${fit_ok[@]}" --seed -1
usage "$fit" "--seed 2^32" "--seed: Value 4294967296 not in range" "${fit_ok[@]}" --seed 4294967296
usage "$fit" "--threads 0" "--threads: Value 0 not in range 1 to 64" "${fit_ok[@]}" --threads 0
usage "$loop" "--threads 1.5" "--threads: not an integer" "${loop_ok[@]}" --threads 1.5
usage "$loop" "--max-effects 17" "--max-effects: Value 17 not in range 0 to 16" "${loop_ok[@]}" --max-effects 17
usage "$sim" "--max-steps 2.5" "--max-steps: not an integer" "${sim_ok[@]}" --max-steps 2.5
usage "$make_case" "--seed 1.5" "--seed: not an integer" "${make_case_ok[@]}" --seed 1.5
# Leading zeros are decimal: --max-effects 010 is 10, not 8 (octal); out of range there.
usage "$loop" "--max-effects 0017 is decimal" "--max-effects: Value 17 not in range" "${loop_ok[@]}" --max-effects 0017

# ---- numbers: finite, in range --------------------------------------------------------------
usage "$sim" "--rtol nan" "--rtol: not a finite number: 'nan'" "${sim_ok[@]}" --rtol nan
usage "$sim" "--atol inf" "--atol: not a finite number: 'inf'" "${sim_ok[@]}" --atol inf
usage "$sim" "--rtol 0" "--rtol: must be > 0 and <= 1 (got 0)" "${sim_ok[@]}" --rtol 0
usage "$sim" "--smooth -1" "--smooth: must be >= 0 (got -1)" "${sim_ok[@]}" --smooth -1
usage "$make_case" "--train-seconds 1" "--train-seconds: must be >= 3 and <= 600 (got 1)" "${make_case_ok[@]}" \
  --train-seconds 1
usage "$sim" "--jacobian bad" "--jacobian: bad not in {ad,ad-forward,fd}" "${sim_ok[@]}" --jacobian bad

# ---- softrne-make-case: exactly one of --effects and --none; --list-effects wins ---------------
usage "$make_case" "neither --effects nor --none" "[--effects,--none]" --seed 3 --out "$tmp/case"
usage "$make_case" "both --effects and --none" "[--effects,--none]" --seed 3 --none --effects payload \
  --out "$tmp/case"
usage "$make_case" "--seed missing" "--seed is required" --none --out "$tmp/case"
usage "$make_case" "--effects empty item" "--effects: empty item" --seed 3 --effects "payload,,stiffening" \
  --out "$tmp/case"
if "$make_case" --seed 1.5 --list-effects >"$tmp/list.txt" 2>"$tmp/list_err.txt" </dev/null &&
  grep -q "^stiffening	shared" "$tmp/list.txt" && [[ ! -s $tmp/list_err.txt ]]; then
  echo "ok   softrne-make-case --list-effects with a bad --seed: the list, exit 0"
else
  fail "softrne-make-case --seed 1.5 --list-effects: $(cat "$tmp/list_err.txt")"
fi

# ---- no tool writes over its input ---------------------------------------------------------
usage "$fit" "--out is --data" "refusing to overwrite an input" --robot "$robot" --data "$train" --out "$train"
usage "$loop" "--out is --test" "refusing to overwrite an input" --robot "$robot" --train "$train" --test "$test" \
  --out "$test"
usage "$fit" "--out is the second --data" "refusing to overwrite an input" --robot "$robot" --data "$train" \
  --data "$test" --out "$test"

# ---- several recordings: one file per --data/--train/--test, each once ------------------------
usage "$fit" "--data a b" "unexpected argument: '" --robot "$robot" --data "$train" "$test" \
  --out "$tmp/fitted.json"
usage "$fit" "a file given twice" "--data: $train is given twice" --robot "$robot" --data "$train" \
  --data "$train" --out "$tmp/fitted.json"
usage "$loop" "a --test file given twice" "--test: $test is given twice" "${loop_ok[@]:0:4}" --test "$test" \
  --test "$test" --out "$tmp/report.json"
usage "$loop" "--initial-motion moving" "--initial-motion: moving not in {rest,estimated}" "${loop_ok[@]}" \
  --initial-motion moving
[[ -e $tmp/fitted.json || -e $tmp/report.json || -e $tmp/case ]] && fail "a refused command line wrote a file"

finish
