# Shared by the tests/cli scripts (source it): a scratch folder removed on exit, fail() that
# counts, finish() that reports and sets the exit status.
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
finish() {
  if [[ $failures -ne 0 ]]; then
    echo "$failures check(s) failed"
    exit 1
  fi
  echo "all checks passed"
  exit 0
}
