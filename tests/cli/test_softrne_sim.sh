#!/usr/bin/env bash
# Command-line contract of softrne-sim (docs/formats.md section 6): on bad input it
# exits non-zero (< 128: no crash, no signal) with exactly one line on stderr,
# "softrne-sim: <file>: ...", naming the file (or the option) at fault; on good input it exits
# 0 and writes t,u1,v1,... on the input's time grid.
#
#   test_softrne_sim.sh <path to softrne-sim> <examples/data/arm-a-1>
set -u
if [[ $# -ne 2 ]]; then
  echo "usage: $0 <softrne-sim> <examples/data/arm-a-1>" >&2
  exit 2
fi
abspath() { (cd "$(dirname "$1")" && echo "$(pwd)/$(basename "$1")"); }
tool=$(abspath "$1")
data=$(abspath "$2")
if [[ ! -x $tool || ! -f $data/robot.json || ! -f $data/test.csv ]]; then
  echo "FAIL: no executable $tool or no $data/robot.json, $data/test.csv" >&2
  exit 1
fi
robot=$data/robot.json
csv=$data/test.csv

source "$(dirname "$0")/common.sh"
make_scratch softrne-cli
cd "$tmp" || exit 1

# expect_error <name> <text the one line must contain> <args...>: common.sh's expect_failure
# for softrne-sim, any exit status in 1..127.
expect_error() { expect_failure any "$tool" "$@"; }

# ---- malformed inputs, generated from the bundled example -----------------------------
header_line=$(grep -n '^t,' "$csv" | head -1 | cut -d: -f1)
first_rows=$((header_line + 20))

head -c 300 "$robot" >truncated.json
sed 's/"rigid_link"/"rigid_rod"/' "$robot" >unknown_type.json
sed '0,/"mass": 0.8/s//"mass": -0.8/' "$robot" >negative_mass.json
head -n "$first_rows" "$csv" | awk -F, -v h="$header_line" '
  NR < h { print; next }
  { out = ""; for (i = 1; i <= NF; ++i) if (i != 9) out = out (out == "" ? "" : ",") $i; print out }' \
  >missing_column.csv
{ head -n "$first_rows" "$csv"; sed -n "$((header_line + 5))p" "$csv"; } >time_backwards.csv
head -n "$first_rows" "$csv" | awk -F, -v OFS=, -v h="$header_line" 'NR == h + 7 { $3 = "NaN" } { print }' \
  >nan_pressure.csv
# A fifth chamber on joint 1: the robot has four.
head -n "$first_rows" "$csv" | awk -F, -v h="$header_line" 'NR < h { print; next }
  NR == h { print $0 ",p1_4"; next } { print $0 ",1000.0" }' >extra_chamber.csv
# A robot with three chambers on joint 1 (custom pressure map) against four-chamber data.
three_chamber_robot() {
  awk '/"chamber_radius": 0.03,/ && !done { print; print "      \"pressure_to_torque\": [[1e-4, -0.5e-4, -0.5e-4], [0.0, 0.8e-4, -0.8e-4]],"; done = 1; next } { print }' "$robot"
}
three_chamber_robot >three_chambers.json
: >empty.csv
printf '# only a comment\n' >comment_only.csv
head -n "$((header_line + 1))" "$csv" >one_row.csv
# An effect naming a joint that does not exist.
awk '/"segments": \[/ && !done { print "  \"effects\": [{\"name\": \"stiffening\", \"joints\": [\"joint9\"], \"params\": {\"beta\": 0.1}}],"; done = 1 } { print }' "$robot" >bad_effect.json
mkdir -p a_directory.csv

expect_error "missing robot file" "no_such_robot.json" --robot no_such_robot.json --pressures "$csv"
expect_error "missing pressure file" "no_such.csv" --robot "$robot" --pressures no_such.csv
expect_error "robot JSON truncated" "truncated.json" --robot truncated.json --pressures "$csv"
expect_error "unknown segment type" "unknown_type.json" --robot unknown_type.json --pressures "$csv"
expect_error "negative mass" "negative_mass.json" --robot negative_mass.json --pressures "$csv"
expect_error "missing pressure column" "missing_column.csv" --robot "$robot" --pressures missing_column.csv
expect_error "time not increasing" "time_backwards.csv" --robot "$robot" --pressures time_backwards.csv
expect_error "NaN pressure" "nan_pressure.csv" --robot "$robot" --pressures nan_pressure.csv
expect_error "extra chamber column" "extra_chamber.csv" --robot "$robot" --pressures extra_chamber.csv
expect_error "wrong number of chambers" "test.csv" --robot three_chambers.json --pressures "$csv"
expect_error "effect on an unknown joint" "bad_effect.json" --robot bad_effect.json --pressures "$csv"
expect_error "empty CSV" "empty.csv" --robot "$robot" --pressures empty.csv
expect_error "comment-only CSV" "comment_only.csv" --robot "$robot" --pressures comment_only.csv
expect_error "single data row" "one_row.csv" --robot "$robot" --pressures one_row.csv
expect_error "directory as CSV" "a_directory.csv" --robot "$robot" --pressures a_directory.csv
expect_error "unwritable output" "no_such_dir/out.csv" --robot "$robot" --pressures "$csv" \
  --out no_such_dir/out.csv --quiet
expect_error "simulation failure" "CVODE failed at t =" --robot "$robot" --pressures "$csv" \
  --max-steps 20
expect_error "bad number option" "--rtol" --robot "$robot" --pressures "$csv" --rtol abc
expect_error "out-of-range option" "--atol" --robot "$robot" --pressures "$csv" --atol -1
expect_error "bad interpolation" "--interpolation" --robot "$robot" --pressures "$csv" \
  --interpolation cubic
expect_error "unknown option" "--frobnicate" --robot "$robot" --pressures "$csv" --frobnicate
expect_error "missing required option" "--robot" --pressures "$csv"
expect_error "option without value" "--out" --robot "$robot" --pressures "$csv" --out

# ---- --help --------------------------------------------------------------------------
if "$tool" --help >help.txt 2>help_err.txt && grep -q "usage: softrne-sim" help.txt &&
  [[ ! -s help_err.txt ]]; then
  echo "ok   --help"
else
  fail "--help: exit status or text wrong"
fi

# ---- one good run --------------------------------------------------------------------
if "$tool" --robot "$robot" --pressures "$csv" --out sim.csv >report.txt 2>err.txt </dev/null; then
  rows_in=$(($(wc -l <"$csv") - header_line))
  rows_out=$(($(wc -l <sim.csv) - 1))
  if [[ $(head -1 sim.csv) != "t,u1,v1,u2,v2,u3,v3" ]]; then
    fail "good run: header of sim.csv is '$(head -1 sim.csv)'"
  elif [[ $rows_out -ne $rows_in ]]; then
    fail "good run: sim.csv has $rows_out rows, the input $rows_in"
  elif ! grep -q "total" report.txt || ! grep -q "real time" report.txt ||
    ! grep -q "CVODE:" report.txt; then
    fail "good run: report lacks the error table, real-time factor or CVODE statistics:"$'\n'"$(cat report.txt)"
  elif [[ -s err.txt ]]; then
    fail "good run: unexpected stderr: $(cat err.txt)"
  else
    echo "ok   good run ($rows_out rows): $(grep 'real time' report.txt)"
  fi
else
  fail "good run: exit status $?; stderr: $(cat err.txt)"
fi

# ---- a tool never overwrites its input; outputs are replaced whole ---------------------
cp "$csv" own.csv
sum_before=$(cksum <own.csv)
expect_error "--out is the input" "refusing to overwrite an input" --robot "$robot" --pressures own.csv \
  --out ./own.csv
ln -s own.csv link.csv
expect_error "--out is a link to the input" "refusing to overwrite an input" --robot "$robot" \
  --pressures own.csv --out link.csv
if [[ $(cksum <own.csv) != "$sum_before" ]]; then
  fail "the input was changed by a refused run"
else
  echo "ok   the input is intact after the refused runs"
fi
printf 'old content that is longer than nothing\n' >old.csv
if "$tool" --robot "$robot" --pressures own.csv --out old.csv >/dev/null 2>err.txt </dev/null &&
  [[ $(head -1 old.csv) == "t,u1,v1,u2,v2,u3,v3" ]] && ! ls ./*.part-* >/dev/null 2>&1; then
  echo "ok   an existing output is replaced whole, no temporary file left"
else
  fail "replacing old.csv: $(cat err.txt); $(ls)"
fi
if "$tool" --robot "$robot" --pressures own.csv --out /dev/null >/dev/null 2>err.txt </dev/null &&
  [[ -c /dev/null ]]; then
  echo "ok   --out /dev/null writes to the device (not over it)"
else
  fail "--out /dev/null: $(cat err.txt)"
fi
expect_error "unwritable output folder" "no-such-dir/s.csv" --robot "$robot" --pressures own.csv \
  --out no-such-dir/s.csv

finish
