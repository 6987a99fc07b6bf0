# Shared by the tests/cli scripts (source it): a scratch folder removed on exit, fail() that
# counts, expect_failure() that checks a failing run's status and one-line message, finish()
# that reports and sets the exit status.
#
#   source "$(dirname "$0")/common.sh"; make_scratch softrne-x; ...; fail "what"; ...; finish
failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}
# make_scratch <name>: sets $tmp to a new folder, removed when the script exits.
make_scratch() {
  tmp=$(mktemp -d "${TMPDIR:-/tmp}/$1.XXXXXX")
  trap 'rm -rf "$tmp"' EXIT
}
# expect_failure <status> <tool> <name> <text the one line must contain> <args...>: runs the
# tool (stdin closed, output in $tmp/stdout.txt and $tmp/stderr.txt) and checks that it fails
# with the exit status <status> ("any": any status in 1..127, not a crash or signal) and
# exactly one line on stderr, "<tool's name>: ...", containing the text.
expect_failure() {
  local want=$1 tool=$2 name=$3 needle=$4
  shift 4
  local prefix rc lines msg
  prefix="$(basename "$tool"): "
  "$tool" "$@" >"$tmp/stdout.txt" 2>"$tmp/stderr.txt" </dev/null
  rc=$?
  lines=$(wc -l <"$tmp/stderr.txt")
  msg=$(cat "$tmp/stderr.txt")
  if [[ $rc -eq 0 ]]; then
    fail "$name: exit status 0 (expected an error); stderr: $msg"
  elif [[ $rc -ge 128 ]]; then
    fail "$name: exit status $rc >= 128 (crash or signal); stderr: $msg"
  elif [[ $want != any && $rc -ne $want ]]; then
    fail "$name: exit status $rc, expected $want; stderr: $msg"
  elif [[ $lines -ne 1 ]]; then
    fail "$name: stderr has $lines lines, expected 1:"$'\n'"$msg"
  elif [[ $msg != "$prefix"* ]]; then
    fail "$name: stderr does not start with '$prefix': $msg"
  elif [[ $msg != *"$needle"* ]]; then
    fail "$name: stderr does not name '$needle': $msg"
  else
    echo "ok   $name (exit $rc): $msg"
  fi
}
finish() {
  if [[ $failures -ne 0 ]]; then
    echo "$failures check(s) failed"
    exit 1
  fi
  echo "all checks passed"
  exit 0
}
