# hemosolve --red-cells transport in a pulsatile run: red cells carried by the flow through a
# looped network of microvessels, split at its diverging nodes; what summary.json and
# vessels.csv report of them, and the refusals of the option's values.
source "$(dirname "$0")/lib.sh"
HEMOSOLVE=$BUILD/solver/hemosolve
PY=/usr/bin/python3

# A diamond of microvessels (0D): an inflow of 60 nl/min at hematocrit 0.45 into node 10, a
# pressure at node 15; vessels 1 and 2 leave node 11 (a diverging bifurcation), the bridge
# 5 closes a loop.
cat >"$WORK/diamond.json" <<'JSON'
{"format": "vnet", "version": 2,
 "blood": {"hematocrit": 0.45},
 "boundaries": [{"node": 10, "type": "flow", "flow": 1e-12, "hematocrit": 0.45},
                {"node": 15, "type": "pressure", "pressure": 2666}],
 "vessels": [
  {"id": 0, "from": 10, "to": 11, "length": 2e-4, "diameter": 20e-6, "wall_thickness": 4e-06, "youngs_modulus": 4e5},
  {"id": 1, "from": 11, "to": 12, "length": 8e-4, "diameter": 12e-6, "wall_thickness": 2.4e-06, "youngs_modulus": 4e5},
  {"id": 2, "from": 11, "to": 13, "length": 2e-4, "diameter": 15e-6, "wall_thickness": 3e-06, "youngs_modulus": 4e5},
  {"id": 3, "from": 12, "to": 14, "length": 2e-4, "diameter": 9e-6, "wall_thickness": 1.8e-06, "youngs_modulus": 4e5},
  {"id": 4, "from": 14, "to": 13, "length": 4e-4, "diameter": 8e-6, "wall_thickness": 1.6e-06, "youngs_modulus": 4e5},
  {"id": 5, "from": 12, "to": 13, "length": 2e-4, "diameter": 6e-6, "wall_thickness": 1.2e-06, "youngs_modulus": 4e5},
  {"id": 6, "from": 13, "to": 15, "length": 2e-4, "diameter": 20e-6, "wall_thickness": 4e-06, "youngs_modulus": 4e5}]}
JSON
TRACER=name=dye,start=0.5,duration=0.5
"$HEMOSOLVE" "$WORK/diamond.json" --red-cells transport --cycles 4 --probe 6 --tracer "$TRACER" --out "$WORK/run" 2>"$WORK/err" \
  && pass "--red-cells transport, pulsatile" || fail "--red-cells transport: $(cat "$WORK/err")"
grep -q "red cells and 1 tracer carried on [0-9]* cells ([0-9.]* kB), a transport step every" "$WORK/err" \
  && pass "the transport is announced, with the memory it holds" || fail "no note of the transport: $(grep carried "$WORK/err")"
"$PY" - "$WORK/run/summary.json" "$WORK/run/vessels.csv" <<'PY' && pass "summary.json and vessels.csv: hematocrits, red-cell balance" || fail "red-cell results"
import csv, json, sys
s = json.load(open(sys.argv[1]))
assert s["status"] == "complete" and s["red_cells"] == "transport", s["status"]
r = s["red_cell_transport"]
assert abs(r["balance_error"]) < 1e-12, r
assert r["separating_nodes"] >= 1, r
rows = {v["id"]: v for v in s["vessels"]}
for v in rows.values():
    assert 0 <= v["discharge_hematocrit_min"] <= v["discharge_hematocrit"] <= v["discharge_hematocrit_max"] < 1, v
    assert 0 <= v["tube_hematocrit"] <= v["discharge_hematocrit"], v  # Fahraeus: H_T < H_D above 3 um
# Red cells balance at the bifurcation node 11 (vessel 0 in, 1 and 2 out), over the cycle.
flux = lambda i: rows[i]["mean_flow"] * rows[i]["discharge_hematocrit"]
assert abs(flux(0) - flux(1) - flux(2)) < 1e-3 * flux(0), (flux(0), flux(1), flux(2))
# Plasma skimming: the narrower, slower daughter gets the lower hematocrit.
assert rows[1]["discharge_hematocrit"] < rows[2]["discharge_hematocrit"]
header = next(csv.reader(open(sys.argv[2])))
assert "discharge_hematocrit" in header and "tube_hematocrit" in header, header
PY
# Stopped after 2 cycles and resumed to 4: the same bits as 4 cycles at once (the red cells,
# the tracer and its curves, the outlets' memories and the viscosities are in the checkpoint).
"$HEMOSOLVE" "$WORK/diamond.json" --red-cells transport --cycles 2 --probe 6 --tracer "$TRACER" --checkpoint-every 1 \
  --out "$WORK/part" --quiet &&
  cp -r "$WORK/part" "$WORK/stopped" &&
  "$HEMOSOLVE" "$WORK/diamond.json" --red-cells transport --cycles 4 --probe 6 --tracer "$TRACER" --resume "$WORK/part" \
    --quiet &&
  "$PY" - "$WORK/run/summary.json" "$WORK/part/summary.json" <<'PY' && pass "a resumed transport continues bit for bit" || fail "resumed transport differs"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert a["red_cell_transport"] == b["red_cell_transport"], (a["red_cell_transport"], b["red_cell_transport"])
assert a["tracers"] == b["tracers"], (a["tracers"], b["tracers"])
for x, y in zip(a["vessels"], b["vessels"]):
    assert x == y, (x, y)
PY
# probes.csv too: probe 6 is a 0D vessel, whose hematocrit is its upstream node's by the last
# transport step's flow (a resumed run read the other node until its first step).
cmp "$WORK/run/probes.csv" "$WORK/part/probes.csv" && pass "a resumed transport's probes.csv: the same bytes" \
  || fail "a resumed transport's probes.csv differs"
expect_error "a checkpoint without transport" 2 "written by a run with other options" -- \
  "$HEMOSOLVE" "$WORK/diamond.json" --cycles 4 --resume "$WORK/stopped" --quiet
# Tracers: a plasma bolus at the inlet and a red-cell step into vessel 1, with the red cells
# fixed (a uniform carrier); their curves at two probes and their landmarks per vessel.
"$HEMOSOLVE" "$WORK/diamond.json" --cycles 3 --probe 0 --probe 6 \
  --tracer name=dye,shape=bolus,start=0.1,duration=50ms --tracer name=label,carrier=cells,at=vessel:1,shape=step,start=0.2 \
  --out "$WORK/tracer" --quiet && pass "--tracer, twice" || fail "--tracer"
"$PY" - "$WORK/tracer/summary.json" "$WORK/tracer/probes.csv" <<'PY' && pass "tracer curves, landmarks and balances" || fail "tracer results"
import csv, json, math, sys
s = json.load(open(sys.argv[1]))
assert s["red_cells"] == "fixed" and "red_cell_transport" not in s
dye, label = s["tracers"]
assert dye["name"] == "dye" and dye["carrier"] == "plasma" and label["carrier"] == "cells", s["tracers"]
for t in (dye, label):
    assert abs(t["balance_error"]) < 1e-12, t
# The whole bolus (1 x 50 ms of plasma) entered; by 3 s most of it has left again.
plasma_flow = 1e-12 * (1 - 0.45)
assert abs(dye["entered"] - 0.05 * plasma_flow) < 1e-9 * dye["entered"], dye
assert dye["left"] > 0.95 * dye["entered"], dye
assert label["entered"] == 0 and label["injected"] > 0
rows = {v["id"]: v for v in s["vessels"]}
# Downstream later: the feed, then the drain.
assert rows[0]["dye_arrival_time"] < rows[6]["dye_arrival_time"] < rows[6]["dye_peak_time"], rows[6]
assert rows[0]["dye_mean_transit_time"] < rows[6]["dye_mean_transit_time"]
# Upstream of the label's injection nothing arrives.
assert rows[0]["label_arrival_time"] is None and rows[0]["label_peak"] == 0
with open(sys.argv[2]) as f:
    table = list(csv.reader(f))
header = table[0]
dye_col = header.index("c_dye vessel 6 x 0.5 [per plasma volume]")
assert "c_label vessel 0 x 0.5 [per red-cell volume]" in header, header
assert not any(h.startswith("H_D") for h in header)  # red cells fixed: not reported
curve = [float(r[dye_col]) for r in table[1:]]
assert max(curve) > 0.05 and curve[0] == 0 and curve[-1] < 0.01 * max(curve), (max(curve), curve[-1])
PY
# The figures of red cells and tracers.
/usr/bin/python3 "$(dirname "$0")/../../scripts/plot-results" "$WORK/run" 2>"$WORK/err" || fail "plot-results: $(cat "$WORK/err")"
drawn=""
for name in hematocrit-vs-diameter capillary-hematocrit transit-dye curves-dye; do
  for ext in png svg; do [ -s "$WORK/run/figures/$name.$ext" ] || drawn="$drawn $name.$ext"; done
done
[ -z "$drawn" ] && pass "plot-results: the red-cell and tracer figures" || fail "plot-results did not draw:$drawn"
expect_error "--tracer unknown key" 2 "--tracer 'colour=red': unknown key 'colour'" -- \
  "$HEMOSOLVE" "$WORK/diamond.json" --tracer colour=red --out "$WORK/x"
expect_error "--tracer at a node without a boundary" 2 "node 12 has no flow or pressure boundary" -- \
  "$HEMOSOLVE" "$WORK/diamond.json" --tracer at=node:12 --out "$WORK/x" --quiet
expect_error "--tracer bad duration" 2 "duration=-1: accepted range (0, inf) s" -- \
  "$HEMOSOLVE" "$WORK/diamond.json" --tracer duration=-1 --out "$WORK/x"
expect_error "--transport-step out of range" 2 "--transport-step 0: accepted range (0, 0.5] of the period" -- \
  "$HEMOSOLVE" "$WORK/diamond.json" --red-cells transport --transport-step 0 --out "$WORK/x"
expect_error "--transport-step with --steady" 2 "--steady excludes --transport-step" -- \
  "$HEMOSOLVE" "$WORK/diamond.json" --steady --transport-step 0.01 --out "$WORK/x"
# Seeking the periodic state with --settling-step 3, the run takes a settling cycle first (its
# 0D vessels at three times the step); the cells do not move with it, and start counting after it: the red-cell
# balance stays at round-off (the first transport step once took the settling cycle's
# volumes too: a discharge hematocrit of -1.1, refused).
"$HEMOSOLVE" "$WORK/diamond.json" --red-cells transport --until-periodic 1e-3 --max-cycles 3 --tracer "$TRACER" \
  --settling-step 3 --out "$WORK/settled" --quiet 2>"$WORK/err"
status=$?  # 3: not periodic within the 3 cycles, with its results
[ $status -eq 0 ] || [ $status -eq 3 ] || fail "--red-cells transport --until-periodic: $(cat "$WORK/err")"
"$PY" - "$WORK/settled/summary.json" <<'PY' && pass "red cells after a settling cycle: balanced to round-off" || fail "red cells after a settling cycle"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["settling_cycle"]["steps"] > 0, s.get("settling_cycle")
r = s["red_cell_transport"]
assert abs(r["balance_error"]) < 1e-12, r["balance_error"]
assert all(0 <= v["discharge_hematocrit"] < 1 for v in s["vessels"]), "a hematocrit out of [0, 1)"
PY

finish
