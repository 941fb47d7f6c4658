#!/usr/bin/env bash
# Runs one fuzz harness: first its saved reproducers (tests/fuzz/regressions/NAME, each must
# pass now), then libFuzzer for SECONDS from the seed corpus (tests/fuzz/corpus/NAME) and
# what earlier runs found (a scratch corpus outside the repository). Prints one line:
#   NAME: N executions in S s, no finding
# and exits non-zero on a finding, naming the reproducer and the log.
# usage: run_harness.sh HARNESS NAME SECONDS
set -uo pipefail
harness=$1 name=$2 seconds=$3
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
scratch=${HEMOTREE_FUZZ_SCRATCH:-${TMPDIR:-/tmp}/hemotree-fuzz}
corpus=$scratch/corpus/$name artifacts=$scratch/findings/$name log=$scratch/$name.log
mkdir -p "$corpus" "$artifacts" || exit 1

options=(-timeout=10 -rss_limit_mb=2048 -print_final_stats=1)
# The tools' own messages (thousands a second) would bury libFuzzer's; findings still show.
case $name in cli_* | inflow_table) options+=(-close_fd_mask=3) ;; esac
# The importers: inputs of a small file's size (openBF's: a model and its inlet table), and
# no single allocation above 512 MB (what an 8 KB input asks for beyond that is a finding).
case $name in
  import_openbf) options+=(-max_len=8192 -malloc_limit_mb=512) ;;
  import_*) options+=(-max_len=4096 -malloc_limit_mb=512) ;;
esac
[ -f "$here/dict/$name.dict" ] && options+=(-dict="$here/dict/$name.dict")

shopt -s nullglob
regressions=("$here/regressions/$name"/*)
if ((${#regressions[@]})); then
  if ! "$harness" "${options[@]}" "${regressions[@]}" >"$log" 2>&1; then
    echo "$name: FINDING: a saved reproducer in tests/fuzz/regressions/$name fails again (log: $log)"
    grep -E "FUZZ FINDING|ERROR: |Running: " "$log" | tail -n 4
    exit 1
  fi
fi

# HEMOTREE_FUZZ_RUNS=N stops after N executions (SECONDS still caps the time).
[ -n "${HEMOTREE_FUZZ_RUNS:-}" ] && options+=(-runs="$HEMOTREE_FUZZ_RUNS")
OMP_NUM_THREADS=1 "$harness" "${options[@]}" -max_total_time="$seconds" -artifact_prefix="$artifacts/" \
  "$corpus" "$here/corpus/$name" >"$log" 2>&1
status=$?
executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
wall=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$log" | tail -n 1)
if ((status == 0)); then
  echo "$name: ${executions:-?} executions in ${wall:-$seconds} s, no finding"
  exit 0
fi
reproducer=$(ls -t "$artifacts" 2>/dev/null | head -n 1)
echo "$name: FINDING after ${executions:-?} executions: $artifacts/$reproducer (log: $log;" \
     "keep it in tests/fuzz/regressions/$name/)"
grep -E "FUZZ FINDING|ERROR: |SUMMARY: " "$log" | head -n 3
exit 1
