# hemosolve on inputs that once broke it (issue 21; shared/hostile-inputs, one finding each):
# a closed end with red cells, a forced 0D step, tracer names, the exit status of every
# outcome, no-flow parts, a tracer that never enters, the pulse wave speeds of 0D vessels.
# The networks are written here, small, so that the test stands without ../shared.
source "$(dirname "$0")/lib.sh"
HEMOSOLVE=$BUILD/solver/hemosolve
PY=/usr/bin/python3

# 00: three vessels, flow in at node 0 (H 0.45), a pressure at node 2, node 3 closed.
branch() {  # the boundary of node 3 as JSON, then extra vessels and boundaries
  cat <<JSON
{"format": "vnet", "version": 2,
 "nodes": [{"id": 0, "x": 0, "y": 0, "z": 0}, {"id": 1, "x": 0.01, "y": 0.001, "z": 0},
           {"id": 2, "x": 0.02, "y": 0.002, "z": 0}, {"id": 3, "x": 0.03, "y": 0, "z": 0}${3-}],
 "vessels": [{"id": 0, "from": 0, "to": 1, "length": 0.01, "diameter": 0.001, "wall_thickness": 0.0001, "youngs_modulus": 4e5},
             {"id": 1, "from": 1, "to": 2, "length": 0.01, "diameter": 0.0008, "wall_thickness": 8e-05, "youngs_modulus": 4e5},
             {"id": 2, "from": 1, "to": 3, "length": 0.01, "diameter": 0.0007, "wall_thickness": 7e-05, "youngs_modulus": 4e5}${4-}],
 "boundaries": [{"node": 0, "type": "flow", "flow": $2, "hematocrit": 0.45},
                {"node": 2, "type": "pressure", "pressure": 1000}, $1${5-}]}
JSON
}
branch '{"node": 3, "type": "flow", "flow": 0}' 1e-7 >"$WORK/closed_end.json"
for model in auto 0d 1d; do
  "$HEMOSOLVE" "$WORK/closed_end.json" --out "$WORK/ce-$model" --red-cells transport --model $model --quiet 2>"$WORK/err"
  status=$?
  if [ $status -eq 0 ] && "$PY" - "$WORK/ce-$model/summary.json" <<'PY'; then
import json, math, sys
s = json.load(open(sys.argv[1]))
assert s["status"] == "complete", s["status"]
for v in s["vessels"]:
    h = v["discharge_hematocrit"]
    assert h is not None and 0 <= h < 1 and math.isfinite(v["mean_pressure"]), v
PY
    pass "00 closed end, --red-cells transport --model $model: complete, every hematocrit in [0, 1)"
  else
    fail "00 closed end --model $model: exit $status: $(cat "$WORK/err")"
  fi
done

# 04: a hybrid network's 0D step is refused beyond its accuracy limit, and a forced one is
# never complete (one step a cycle stored 16 % of the inflow and was called complete).
"$BUILD/generator/vgen" --min-diameter 40um 2>/dev/null | "$BUILD/pruner/vprune" --budget 201 >"$WORK/n201.json" 2>/dev/null
expect_error "04 --dt 1s on a hybrid network: refused" 2 "0D step's accuracy limit" -- \
  "$HEMOSOLVE" "$WORK/n201.json" --out "$WORK/dt" --dt 1s --quiet
"$HEMOSOLVE" "$WORK/n201.json" --out "$WORK/dt" --dt 0.1s --force --quiet 2>"$WORK/err"
status=$?
if [ $status -eq 2 ] && "$PY" -c "import json,sys; s=json.load(open(sys.argv[1])); assert s['status']=='failed' and 'forced' in s['error']" "$WORK/dt/summary.json"; then
  pass "04 --dt 0.1s --force on a hybrid network: written, failed, exit 2"
else
  fail "04 forced 0D step: exit $status, $(cat "$WORK/err")"
fi

# 07: a tracer's name is a word; what is not is refused on one line (the bytes shown escaped).
for name in "$(printf 'a\nb')" "$(printf 'a\001b')" "$(printf 'a\377b')" 'a/b' "$(printf '%070d' 0)"; do
  expect_error "07 --tracer name=$(printf %q "$name") refused" 2 "--tracer 'name=" -- \
    "$HEMOSOLVE" "$WORK/closed_end.json" --out "$WORK/tn" --quiet --tracer "name=$name"
done

# 11: the exit status of each outcome (solver/run_outcome.hpp).
branch '{"node": 3, "type": "pressure", "pressure": 1000}' 1e-7 >"$WORK/open.json"
"$HEMOSOLVE" "$WORK/open.json" --out "$WORK/st" --quiet
[ $? -eq 0 ] && pass "11 complete: exit 0" || fail "11 complete: not exit 0"
"$HEMOSOLVE" "$WORK/open.json" --out "$WORK/st" --quiet --until-periodic 1e-14 --max-cycles 2 2>"$WORK/err"
status=$?
if [ $status -eq 3 ] && grep -q "not periodic" "$WORK/err" &&
   "$PY" -c "import json,sys; assert json.load(open(sys.argv[1]))['status']=='not periodic'" "$WORK/st/summary.json"; then
  pass "11 not periodic: exit 3, status 'not periodic', one warning"
else
  fail "11 not periodic: exit $status: $(cat "$WORK/err")"
fi
"$HEMOSOLVE" "$WORK/open.json" --out "$WORK/st" --quiet --dt 0.01s --force 2>"$WORK/err"
status=$?
if [ $status -eq 2 ] && "$PY" -c "import json,sys; assert json.load(open(sys.argv[1]))['status'] in ('failed', 'broken down')" "$WORK/st/summary.json" 2>/dev/null ||
   { [ $status -eq 2 ] && grep -q "broke down" "$WORK/err"; }; then
  pass "11 failed or broken down: exit 2"
else
  fail "11 forced step: exit $status: $(cat "$WORK/err")"
fi
"$HEMOSOLVE" "$WORK/open.json" --out "$WORK/int" --cycles 100000 --quiet --force 2>"$WORK/err" &
pid=$!
sleep 1
kill -TERM $pid
wait $pid
status=$?
[ $status -eq 143 ] && pass "11 interrupted by SIGTERM: exit 143" || fail "11 SIGTERM: exit $status: $(cat "$WORK/err")"

# 05: nothing flows in (zero boundary flow, equal pressures): complete, the balance defined.
branch '{"node": 3, "type": "pressure", "pressure": 1000}' 0 >"$WORK/zero.json"
"$HEMOSOLVE" "$WORK/zero.json" --out "$WORK/zero" --cycles 2 --quiet 2>"$WORK/err"
status=$?
if [ $status -eq 0 ] && "$PY" - "$WORK/zero/summary.json" <<'PY'; then
import json, sys
s = json.load(open(sys.argv[1]))
assert s["status"] == "complete", s
assert s["mass_balance"] is None, s["mass_balance"]          # no inflow: no fraction of it
assert abs(s["conservation_error"]) < 1e-8, s["conservation_error"]
PY
  pass "05 zero inflow: complete, mass_balance null, conservation_error defined"
else
  fail "05 zero inflow: exit $status: $(cat "$WORK/err")"
fi

# 05/03: a part with flow boundaries only has no pressure level: the pulsatile run refuses it
# as the steady solve does, naming every such part (it ran "complete", or ended in exit 70).
cat >"$WORK/flows_only.json" <<'JSON'
{"format": "vnet", "version": 2,
 "vessels": [{"id": 0, "from": 0, "to": 1, "length": 0.01, "diameter": 0.001, "wall_thickness": 0.0001, "youngs_modulus": 4e5},
             {"id": 1, "from": 1, "to": 2, "length": 0.01, "diameter": 0.0008, "wall_thickness": 8e-05, "youngs_modulus": 4e5},
             {"id": 2, "from": 1, "to": 3, "length": 0.01, "diameter": 0.0007, "wall_thickness": 7e-05, "youngs_modulus": 4e5}],
 "boundaries": [{"node": 0, "type": "flow", "flow": 1e-7}, {"node": 2, "type": "flow", "flow": -5e-8},
                {"node": 3, "type": "flow", "flow": -5e-8}]}
JSON
for model in auto 0d 1d; do
  expect_error "05 flows only, --model $model: refused, naming the part" 2 \
    "the part with vessel 0 (3 vessels) has flow boundaries only" -- \
    "$HEMOSOLVE" "$WORK/flows_only.json" --out "$WORK/fo" --model $model --quiet
done
branch '{"node": 3, "type": "pressure", "pressure": 1000}' 1e-7 \
  ', {"id": 4, "x": 0.2, "y": 0, "z": 0}, {"id": 5, "x": 0.3, "y": 0, "z": 0}' \
  ', {"id": 3, "from": 4, "to": 5, "length": 0.01, "diameter": 0.001, "wall_thickness": 0.0001, "youngs_modulus": 4e5}' \
  ', {"node": 4, "type": "flow", "flow": 0}, {"node": 5, "type": "flow", "flow": 0}' >"$WORK/cut_closed.json"
expect_error "05 a detached closed vessel: refused, naming it" 2 \
  "1 of the network's 2 connected parts has no pressure to refer to" -- \
  "$HEMOSOLVE" "$WORK/cut_closed.json" --out "$WORK/cc" --quiet
"$HEMOSOLVE" "$WORK/flows_only.json" --out "$WORK/fo" --steady --pressure-at 1=10mmHg --quiet 2>"$WORK/err" \
  && "$PY" -c "
import json, sys
s = json.load(open(sys.argv[1]))
q = {v['id']: v['mean_flow'] for v in s['vessels']}
assert abs(q[0] - 1e-7) < 1e-18 and abs(q[1] - 5e-8) < 1e-18 and abs(q[2] - 5e-8) < 1e-18, q" "$WORK/fo/summary.json" \
  && pass "05 --steady --pressure-at 1=10mmHg: the balanced flows solved" || fail "05 --pressure-at: $(cat "$WORK/err")"

# 13g: --steady --red-cells transport where a part carries nothing (a detached vessel with a
# pressure and a closed end; a ring with one pressure) settles at once.
branch '{"node": 3, "type": "pressure", "pressure": 1000}' 1e-7 \
  ', {"id": 4, "x": 0.2, "y": 0, "z": 0}, {"id": 5, "x": 0.3, "y": 0, "z": 0}' \
  ', {"id": 3, "from": 4, "to": 5, "length": 0.01, "diameter": 0.001, "wall_thickness": 0.0001, "youngs_modulus": 4e5}' \
  ', {"node": 4, "type": "flow", "flow": 0}, {"node": 5, "type": "pressure", "pressure": 800}' >"$WORK/two_parts.json"
for net in two_parts zero; do
  "$HEMOSOLVE" "$WORK/$net.json" --out "$WORK/s-$net" --steady --red-cells transport --quiet 2>"$WORK/err" \
    && pass "13g --steady --red-cells transport, $net: converged" || fail "13g $net: $(cat "$WORK/err")"
done

# 13f: a tracer the run never reaches is said.
"$HEMOSOLVE" "$WORK/open.json" --out "$WORK/late" --quiet --tracer name=late,start=5 2>"$WORK/err"
grep -q "tracer late never entered the network" "$WORK/err" && pass "13f a tracer that never enters: warned" \
  || fail "13f no warning: $(cat "$WORK/err")"

# 16: a measured wave speed only where a wave travels: never in a 0D vessel.
"$HEMOSOLVE" "$WORK/n201.json" --out "$WORK/pwv" --quiet 2>"$WORK/err"
"$PY" - "$WORK/pwv/vessels.csv" <<'PY' && pass "16 pwv_pressure/pwv_velocity null in every 0D vessel, measured in some 1D ones" || fail "16 wave speeds"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
zero_d = [r for r in rows if r["model"] == "0d"]
assert zero_d and all(r["pwv_pressure"] == "" and r["pwv_velocity"] == "" for r in zero_d)
assert any(r["pwv_velocity"] != "" for r in rows if r["model"] == "1d")
PY

# 13e: --resume compares the options that shape the state to the last bit, not to 6 digits.
"$HEMOSOLVE" "$WORK/open.json" --out "$WORK/res" --cycles 1 --checkpoint-every 1 --thick-wall-ratio 0.1 --quiet
expect_error "13e --resume with --thick-wall-ratio 0.10000001 against 0.1: refused" 2 "thick wall ratio" -- \
  "$HEMOSOLVE" "$WORK/open.json" --resume "$WORK/res" --cycles 2 --thick-wall-ratio 0.10000001 --quiet

finish
