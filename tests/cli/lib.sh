# Helpers for the command-line tests: each test script sources this with the build folder.
set -uo pipefail
BUILD=${1:?usage: test.sh BUILD_DIR}
VGEN=$BUILD/generator/vgen
VSTATS=$BUILD/stats/vstats
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
failures=0

fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
pass() { echo "ok: $*"; }

# expect_error "description" EXPECTED_STATUS FRAGMENT -- command...
# The command must exit with the status and print exactly one line on stderr containing
# the fragment.
expect_error() {
  local what=$1 status=$2 fragment=$3
  shift 4
  "$@" >"$WORK/out" 2>"$WORK/err"
  local got=$?
  local lines
  lines=$(wc -l <"$WORK/err")
  if [ "$got" -ne "$status" ]; then fail "$what: exit $got, wanted $status ($(cat "$WORK/err"))"
  elif [ "$lines" -ne 1 ]; then fail "$what: $lines lines on stderr: $(cat "$WORK/err")"
  elif ! grep -qF -- "$fragment" "$WORK/err"; then fail "$what: stderr lacks '$fragment': $(cat "$WORK/err")"
  else pass "$what"; fi
}

finish() {
  if [ "$failures" -ne 0 ]; then echo "$failures failed" >&2; exit 1; fi
  exit 0
}
