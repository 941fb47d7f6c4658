#!/usr/bin/env bash
# Runs one Boileau et al. (2015) benchmark case (examples/boileau2015/CASE.json) with
# hemosolve and compares it with the 1D reference (compare_boileau.py).
#
# usage: run_case.sh BUILD_DIR CASE        (CASE: cca or ibif)
# Exit status: 0 within the thresholds, 1 beyond them, 77 reference not found (skipped),
# 2 the run failed. Set HEMOTREE_VALIDATION_OUT=DIR to keep the run (probes.csv and a plot
# CASE-vs-reference.png) in DIR/CASE; otherwise it goes to a temporary folder, removed after.
# The reference is looked up as compare_boileau.py does (HEMOTREE_VALIDATION_DIR, or
# ../shared/validation/boileau2015 from the project root).
set -uo pipefail

# hemosolve's flags for the validation runs, all here. The --probe ID:x flags are added from
# `compare_boileau.py CASE --print-probes`, so they are always the locations it compares.
HEMOSOLVE_FLAGS=(--until-periodic 1e-4 --quiet)

BUILD=${1:?usage: run_case.sh BUILD_DIR CASE}
CASE=${2:?usage: run_case.sh BUILD_DIR CASE}
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
PYTHON=${PYTHON:-/usr/bin/python3}
COMPARE=("$PYTHON" "$HERE/compare_boileau.py" "$CASE")

# Skip (77) before a long run when there is nothing to compare with.
"${COMPARE[@]}" --check-reference
status=$?
[ "$status" -eq 0 ] || exit "$status"

HEMOSOLVE=$BUILD/solver/hemosolve
CASE_FILE=$ROOT/examples/boileau2015/$CASE.json
[ -x "$HEMOSOLVE" ] || { echo "run_case: $HEMOSOLVE not found (build it first)" >&2; exit 2; }
[ -f "$CASE_FILE" ] || { echo "run_case: $CASE_FILE not found" >&2; exit 2; }
mapfile -t PROBES < <("${COMPARE[@]}" --print-probes)

if [ -n "${HEMOTREE_VALIDATION_OUT:-}" ]; then
  OUT=$HEMOTREE_VALIDATION_OUT/$CASE
  mkdir -p "$OUT" || exit 2
  PLOT=(--plot "$OUT/$CASE-vs-reference.png")
else
  OUT=$(mktemp -d) || exit 2
  trap 'rm -rf "$OUT"' EXIT
  PLOT=()
fi

echo "+ $HEMOSOLVE $CASE_FILE --out $OUT ${HEMOSOLVE_FLAGS[*]} ${PROBES[*]}"
"$HEMOSOLVE" "$CASE_FILE" --out "$OUT" "${HEMOSOLVE_FLAGS[@]}" "${PROBES[@]}"
status=$?
if [ "$status" -ne 0 ]; then
  echo "run_case: hemosolve failed (exit $status)" >&2
  exit 2
fi
"${COMPARE[@]}" "$OUT" "${PLOT[@]}"
