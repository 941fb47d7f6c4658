# hemosolve as a hostile user or a killed job would find it (issue 11): values that give
# nothing computed are refused before any work; a run is "complete" only when its numbers
# say so; the output folder never mixes two runs; a run killed and resumed gives the same
# bits as one never stopped, a damaged checkpoint is refused, two runs into one folder never
# collide. About 60 s.
source "$(dirname "$0")/lib.sh"
VPRUNE=$BUILD/pruner/vprune
HEMOSOLVE=$BUILD/solver/hemosolve
CCA=$(cd "$(dirname "$0")/../../examples/boileau2015" && pwd)/cca.json
PY=/usr/bin/python3

# Refused before any work: one line, status 2, and neither OUT nor OUT.partial created.
n=0
refused() {
  local what=$1 fragment=$2
  shift 2
  local out=$WORK/refused-$n
  expect_error "$what" 2 "$fragment" -- "$HEMOSOLVE" "$CCA" --out "$out" --quiet "$@"
  if [ -e "$out" ] || [ -e "$out.partial" ]; then fail "$what: left $out or $out.partial"; fi
  n=$((n + 1))
}
refused "--dt 1e-300" "no run can finish" --dt 1e-300
refused "--cfl 1e-300" "no run can finish" --cfl 1e-300
refused "--cfl inf" "--cfl must lie in (0, 1]" --cfl inf
refused "--cfl nan" "--cfl must lie in (0, 1]" --cfl nan
refused "--cfl above 1" "--cfl must lie in (0, 1]" --cfl 1.5
refused "--dt above the stability limit" "times the stability limit" --dt 1s
refused "--until-periodic -1" "--until-periodic must lie in (0, 1)" --until-periodic -1
refused "--until-periodic nan" "--until-periodic must lie in (0, 1)" --until-periodic nan
refused "--max-cycles 0" "--max-cycles must lie in [1, 100000]" --until-periodic 1e-3 --max-cycles 0
refused "--max-cycles -3" "--max-cycles must lie in [1, 100000]" --until-periodic 1e-3 --max-cycles -3
refused "--sample-interval -1ms" "--sample-interval" --sample-interval -1ms
refused "--sample-interval 1e300" "--sample-interval: '1e300' lies outside" --sample-interval 1e300
refused "--sample-interval beyond the period" "--sample-interval must lie in (0, 1.1] s" --sample-interval 2s
refused "--threads 1000" "--threads must lie in [1, $(nproc)]" --threads 1000
refused "--elements 100000" "--elements must lie in [1, 1000]" --elements 100000
refused "--external-pressure 1e300Pa" "--external-pressure" --external-pressure 1e300Pa
refused "--thick-wall-ratio 0" "--thick-wall-ratio must lie in (0, 10]" --thick-wall-ratio 0
refused "--frames beyond the steps of a cycle" "exceeds the 5500 steps of a cycle" --frames 10000 --dt 0.2ms
# 5e10 steps: the estimate (more than a day) is printed and the run refused unless forced.
refused "a run of more than a day" "refused, more than a day" --cfl 1e-7
expect_error "--resume without a checkpoint" 2 "no checkpoint.bin" -- "$HEMOSOLVE" "$CCA" --resume "$WORK/nothing"

# Forced past the limit, the run is never reported complete.
"$HEMOSOLVE" "$CCA" --out "$WORK/forced" --dt 0.5s --force --quiet 2>"$WORK/err"
status=$?
if [ "$status" -ne 0 ] && [ "$(wc -l <"$WORK/err")" -eq 1 ] \
   && { [ ! -e "$WORK/forced/summary.json" ] || ! grep -q '"status": "complete"' "$WORK/forced/summary.json"; }; then
  pass "--dt 0.5s --force: exit $status, not complete ($(cat "$WORK/err"))"
else
  fail "--dt 0.5s --force: exit $status: $(cat "$WORK/err")"
fi

# A file name that is not UTF-8 is reported, not an internal error after the run.
odd=$WORK/$'\xff\xfe'.json
cp "$CCA" "$odd"
"$HEMOSOLVE" "$odd" --out "$WORK/odd-name" --quiet 2>"$WORK/err" \
  && "$PY" -c 'import json,sys; s=json.load(open(sys.argv[1])); assert s["status"]=="complete"' "$WORK/odd-name/summary.json" \
  && pass "non-UTF-8 file name: complete, summary readable" || fail "non-UTF-8 file name: $(cat "$WORK/err")"

# No steady solution (a reflection outlet): said on stderr and recorded as it was.
"$PY" - "$CCA" "$WORK/reflection.json" <<'PY'
import json, sys
net = json.load(open(sys.argv[1]))
net["vessels"][0]["outlet"] = {"type": "reflection", "coefficient": 0.3}
json.dump(net, open(sys.argv[2], "w"))
PY
"$HEMOSOLVE" "$WORK/reflection.json" --out "$WORK/reflection" --quiet 2>"$WORK/err"
grep -q "no steady solution to start from" "$WORK/err" \
  && "$PY" -c 'import json,sys; s=json.load(open(sys.argv[1])); assert s["start"]=="rest" and s["start_requested"]=="periodic" and not s["balance_compliances"] and s["steady_refusal"], s["start"]' "$WORK/reflection/summary.json" \
  && pass "no steady solution: warned, start recorded as rest" || fail "no steady solution: $(cat "$WORK/err")"

# Pressures far outside the physiological range are warned about, with the likely cause.
"$VGEN" --root-diameter 60um 2>/dev/null | "$VPRUNE" --budget 31 2>/dev/null >"$WORK/tiny.json"
"$HEMOSOLVE" "$WORK/tiny.json" --out "$WORK/tiny" --quiet --degree 1 2>"$WORK/err"
grep -q "outside a physiological 0 to 300 mmHg" "$WORK/err" && grep -q -- "--mean-flow" "$WORK/err" \
  && pass "unphysiological pressures warned" || fail "unphysiological pressures: $(cat "$WORK/err")"

# ---- interrupted runs: the benchmark's carotid, 30 cycles of 0.05 s or so each -------------
ARGS=(--probe 1:0.5 --frames 3 --vtk --cycles 30)

# The scheme's own mass balance, from the fluxes it exchanged, to round-off.
"$HEMOSOLVE" "$CCA" "${ARGS[@]}" --out "$WORK/whole" --checkpoint-every 1 2>"$WORK/whole.err" \
  || fail "uninterrupted run: $(cat "$WORK/whole.err")"
grep -q "cycle 1/30 done" "$WORK/whole.err" && pass "a plain progress line per cycle in a log" \
  || fail "no progress lines: $(cat "$WORK/whole.err")"
"$PY" - "$WORK/whole/summary.json" <<'PY' && pass "mass balance from the exchanged fluxes" || fail "mass balance"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["status"] == "complete" and s["cycles"] == 30, s["status"]
assert abs(s["conservation_error"]) < 1e-10, s["conservation_error"]
# Over the cycle, in - out is what the vessel stored.
stored = (s["inlet_mean_flow"] - s["outlets_mean_flow"]) * s["period"]
assert abs(stored - s["volume_change"]) <= 1e-9 * s["inlet_mean_flow"] * s["period"], (stored, s["volume_change"])
assert abs(s["mass_balance"] - (s["inlet_mean_flow"] - s["outlets_mean_flow"]) / s["inlet_mean_flow"]) < 1e-15
# The inlet passes the prescribed waveform's mean.
assert abs(s["inlet_mean_flow"] - 6.5e-6) < 1e-3 * 6.5e-6, s["inlet_mean_flow"]
PY

same_summary() {  # summary.json without the wall time
  "$PY" - "$1" "$2" <<'PY'
import json, sys, os
a, b = (json.load(open(os.path.join(d, "summary.json"))) for d in sys.argv[1:3])
for s in (a, b):
    s.pop("wall_time")
assert a == b, [k for k in a if a.get(k) != b.get(k)]
PY
}

same_results() {  # summary.json without the wall time, probes.csv, results.vtp and frames, bit for bit
  "$PY" - "$1" "$2" <<'PY'
import json, sys, filecmp, os
a, b = (json.load(open(os.path.join(d, "summary.json"))) for d in sys.argv[1:3])
for s in (a, b):
    s.pop("wall_time")
assert a == b, [k for k in a if a.get(k) != b.get(k)]
for f in ["probes.csv", "results.vtp"] + ["frames/" + f for f in sorted(os.listdir(os.path.join(sys.argv[1], "frames")))]:
    assert filecmp.cmp(os.path.join(sys.argv[1], f), os.path.join(sys.argv[2], f), shallow=False), f
PY
}

# Killed with SIGKILL after its first checkpoint: the folder keeps the previous complete
# results, the partial one says it is partial, and --resume gives the uninterrupted bits.
cp -r "$WORK/whole" "$WORK/killed"
rm "$WORK/killed/checkpoint.bin"
cp "$WORK/whole/summary.json" "$WORK/previous-summary.json"
"$HEMOSOLVE" "$CCA" "${ARGS[@]}" --out "$WORK/killed" --checkpoint-every 1 --quiet 2>/dev/null & pid=$!
for _ in $(seq 600); do [ -e "$WORK/killed.partial/checkpoint.bin" ] && break; sleep 0.02; done
kill -9 $pid; wait $pid 2>/dev/null
cmp -s "$WORK/killed/summary.json" "$WORK/previous-summary.json" && [ -e "$WORK/killed.partial/checkpoint.bin" ] \
  && pass "kill -9: the previous results intact, the new run's checkpoint in killed.partial" \
  || fail "kill -9 mixed the folder"
# Its checkpoint is not thrown away by running the same command again.
expect_error "a new run over a killed run's checkpoint" 2 "holds the checkpoint of a run that was killed" -- \
  "$HEMOSOLVE" "$CCA" "${ARGS[@]}" --out "$WORK/killed" --checkpoint-every 1 --quiet
"$HEMOSOLVE" "$CCA" "${ARGS[@]}" --resume "$WORK/killed" --checkpoint-every 1 2>"$WORK/err" \
  && grep -q "resuming from .*killed.partial/checkpoint.bin after [1-9]" "$WORK/err" && [ ! -e "$WORK/killed.partial" ] \
  && same_results "$WORK/whole" "$WORK/killed" \
  && pass "kill -9 and --resume: bit-identical to the uninterrupted run" || fail "resume after kill -9: $(cat "$WORK/err")"

# SIGTERM: a checkpoint and a summary marked interrupted, exit 143; resumed, the same bits.
"$HEMOSOLVE" "$CCA" "${ARGS[@]}" --out "$WORK/term" 2>"$WORK/err" & pid=$!
for _ in $(seq 600); do grep -q "cycle 2/30 done" "$WORK/err" && break; sleep 0.02; done
kill -TERM $pid; wait $pid; status=$?
"$PY" -c 'import json,sys; s=json.load(open(sys.argv[1])); assert s["status"]=="interrupted" and 2 <= s["cycles"] < 30, s["status"]' "$WORK/term/summary.json" \
  && [ "$status" -eq 143 ] && [ -e "$WORK/term/checkpoint.bin" ] && grep -q "interrupted by SIGTERM" "$WORK/err" \
  && pass "SIGTERM: checkpoint, summary interrupted, exit 143" || fail "SIGTERM: exit $status: $(cat "$WORK/err")"
"$HEMOSOLVE" "$CCA" "${ARGS[@]}" --resume "$WORK/term" --quiet 2>"$WORK/err" && same_results "$WORK/whole" "$WORK/term" \
  && pass "SIGTERM and --resume: bit-identical" || fail "resume after SIGTERM: $(cat "$WORK/err")"

# A checkpoint changed after it was written is refused, whatever byte changed (issue 21): a
# bit flipped at 40 places spread over the file (the format, each section's name, length,
# payload and checksum, the file's checksum), and the folder is left as it was.
cp -r "$WORK/whole" "$WORK/flip"
MORE=(--probe 1:0.5 --frames 3 --vtk --cycles 31)
size=$(stat -c %s "$WORK/whole/checkpoint.bin")
flips_refused=0
for k in $(seq 0 39); do
  at=$(( k == 39 ? size - 203 : k * size / 39 + k ))
  "$PY" -c 'import sys; p, a = sys.argv[1], int(sys.argv[2]); b = bytearray(open(sys.argv[3], "rb").read()); b[a] ^= 0x04; open(p, "wb").write(b)' \
    "$WORK/flip/checkpoint.bin" "$at" "$WORK/whole/checkpoint.bin"
  "$HEMOSOLVE" "$CCA" "${MORE[@]}" --resume "$WORK/flip" --quiet 2>"$WORK/err"
  status=$?
  if [ "$status" -eq 2 ] && [ "$(wc -l <"$WORK/err")" -eq 1 ] && grep -q "flip/checkpoint.bin: " "$WORK/err" \
     && cmp -s "$WORK/flip/summary.json" "$WORK/whole/summary.json" && [ ! -e "$WORK/flip.partial" ]; then
    flips_refused=$((flips_refused + 1))
  else
    fail "byte $at of $size flipped: exit $status: $(cat "$WORK/err")"
  fi
done
[ "$flips_refused" -eq 40 ] && pass "a flipped bit in the checkpoint: 40 of 40 refused, the folder untouched"
grep -q 'section "pulse solver" does not match its checksum' "$WORK/err" || fail "the damaged section not named: $(cat "$WORK/err")"
: >"$WORK/flip/checkpoint.bin"
expect_error "an empty checkpoint" 2 "empty checkpoint" -- \
  "$HEMOSOLVE" "$CCA" "${MORE[@]}" --resume "$WORK/flip" --quiet

# Resumed with no cycle left to run: a published run's results stand as they are (refused);
# a run killed between its last checkpoint and publishing its folder (its staging folder
# holds that checkpoint and the last cycle's frames, nothing else yet) ends with the bits of
# the uninterrupted run, frames included.
cp -r "$WORK/whole" "$WORK/ended"
expect_error "--resume a run that has its cycles" 2 "the run already has its 30 cycles; raise --cycles to continue" -- \
  "$HEMOSOLVE" "$CCA" "${ARGS[@]}" --resume "$WORK/ended" --quiet
diff -r "$WORK/whole" "$WORK/ended" >/dev/null && [ ! -e "$WORK/ended.partial" ] \
  && pass "the published run untouched" || fail "--resume at the run's end changed the folder"
mkdir "$WORK/late.partial"
cp -r "$WORK/whole/checkpoint.bin" "$WORK/whole/frames" "$WORK/late.partial/"
"$HEMOSOLVE" "$CCA" "${ARGS[@]}" --resume "$WORK/late" --checkpoint-every 1 --quiet 2>"$WORK/err" \
  && same_results "$WORK/whole" "$WORK/late" && cmp -s "$WORK/whole/checkpoint.bin" "$WORK/late/checkpoint.bin" \
  && [ "$(ls "$WORK/late/frames" | wc -l)" -eq 4 ] && [ ! -e "$WORK/late.partial" ] \
  && pass "killed before publishing, resumed: the uninterrupted run's bits, frames and checkpoint" \
  || fail "resume after the last checkpoint: $(cat "$WORK/err")"
mkdir "$WORK/late2.partial"
cp "$WORK/whole/checkpoint.bin" "$WORK/late2.partial/"
expect_error "--resume at the run's end without its frames" 2 "the frames of that last cycle are not in" -- \
  "$HEMOSOLVE" "$CCA" "${ARGS[@]}" --resume "$WORK/late2" --quiet
[ -e "$WORK/late2.partial/checkpoint.bin" ] && pass "the killed run's checkpoint kept" || fail "the checkpoint was lost"

# Two runs started at once into one --out, 20 times: one writes it, the other is refused at
# once with one line, and the winner's results are a lone run's.
RACE=(--cycles 8 --probe 1:0.5 --checkpoint-every 1 --quiet)
"$HEMOSOLVE" "$CCA" "${RACE[@]}" --out "$WORK/lone" 2>"$WORK/err" || fail "lone run: $(cat "$WORK/err")"
pairs_right=0
for i in $(seq 20); do
  rm -rf "$WORK/race"
  "$HEMOSOLVE" "$CCA" "${RACE[@]}" --out "$WORK/race" 2>"$WORK/race-1.err" & a=$!
  "$HEMOSOLVE" "$CCA" "${RACE[@]}" --out "$WORK/race" 2>"$WORK/race-2.err" & b=$!
  wait $a; sa=$?
  wait $b; sb=$?
  loser=$WORK/race-2.err
  [ "$sa" -ne 0 ] && loser=$WORK/race-1.err
  if [ $((sa + sb)) -eq 2 ] && [ $((sa * sb)) -eq 0 ] && [ "$(wc -l <"$loser")" -eq 1 ] \
     && grep -q "^hemosolve: error: --out .*/race: hemosolve (process [0-9]*) is writing .*/race.partial; wait for it or choose another folder$" "$loser" \
     && same_summary "$WORK/lone" "$WORK/race" && cmp -s "$WORK/lone/probes.csv" "$WORK/race/probes.csv" \
     && cmp -s "$WORK/lone/vessels.csv" "$WORK/race/vessels.csv" && cmp -s "$WORK/lone/checkpoint.bin" "$WORK/race/checkpoint.bin" \
     && [ ! -e "$WORK/race.partial" ]; then
    pairs_right=$((pairs_right + 1))
  else
    fail "two runs into one --out: exits $sa and $sb: $(cat "$WORK/race-1.err" "$WORK/race-2.err")"
  fi
done
[ "$pairs_right" -eq 20 ] && pass "two runs into one --out: 20 of 20 pairs, one refused, the other a lone run's results"
[ -z "$(ls -A "$WORK" | grep hemosolve-lock)" ] && pass "no lock file left" || fail "lock files left: $(ls -a "$WORK" | grep lock)"

# A checkpoint of other options or another network is refused, naming what differs.
expect_error "resume with another scheme" 2 "other options" -- \
  "$HEMOSOLVE" "$CCA" "${ARGS[@]}" --scheme ab2 --resume "$WORK/whole" --quiet
"$PY" - "$CCA" "$WORK/other.json" <<'PY'
import json, sys
net = json.load(open(sys.argv[1]))
net["vessels"][0]["length"] *= 1.01
json.dump(net, open(sys.argv[2], "w"))
PY
expect_error "resume with another network" 2 "another network" -- \
  "$HEMOSOLVE" "$WORK/other.json" "${ARGS[@]}" --resume "$WORK/whole" --quiet
# The identity is the whole network at full precision (solver/run_identity.hpp): one field
# 1e-12 away, or one the solver never reads, is another network.
for change in 'net["vessels"][0]["reference_pressure"] *= 1 + 1e-12' 'net["nodes"][1]["x"] += 1e-6'; do
  "$PY" - "$CCA" "$WORK/other.json" "$change" <<'PY'
import json, sys
net = json.load(open(sys.argv[1]))
exec(sys.argv[3])
json.dump(net, open(sys.argv[2], "w"))
PY
  expect_error "resume with one field changed: $change" 2 "written for another network" -- \
    "$HEMOSOLVE" "$WORK/other.json" "${ARGS[@]}" --resume "$WORK/whole" --quiet
done
# A checkpoint of an earlier format is said to be one, not taken for another network's.
cp -r "$WORK/whole" "$WORK/old-format"
"$PY" - "$WORK/old-format/checkpoint.bin" <<'PY'
import struct, sys
data = bytearray(open(sys.argv[1], "rb").read())
at = len(b"hemotree checkpoint\n")
data[at:at + 8] = struct.pack("<Q", 6)
open(sys.argv[1], "wb").write(data)
PY
expect_error "resume from a format 6 checkpoint" 2 "checkpoint format 6 of an earlier hemosolve" -- \
  "$HEMOSOLVE" "$CCA" "${ARGS[@]}" --resume "$WORK/old-format" --quiet

# What a tool prints to a full disk is an error, not a success.
if [ -c /dev/full ]; then
  expect_error "hemosolve --help to a full disk" 1 "cannot write standard output" -- bash -c '"$0" --help >/dev/full' "$HEMOSOLVE"
  expect_error "vstats to a full disk" 1 "cannot write" -- bash -c '"$0" "$1" >/dev/full' "$VSTATS" "$CCA"
  expect_error "vstats --version to a full disk" 1 "cannot write standard output" -- bash -c '"$0" --version >/dev/full' "$VSTATS"
fi

# A folder that is not hemosolve's is never replaced.
mkdir "$WORK/mine" && echo precious >"$WORK/mine/notes.txt"
expect_error "--out a folder of other files" 2 "not a hemosolve results folder" -- \
  "$HEMOSOLVE" "$CCA" --out "$WORK/mine" --quiet
[ "$(cat "$WORK/mine/notes.txt")" = precious ] && pass "the user's folder untouched" || fail "the user's folder changed"
finish
