# hemosolve's pulsatile run on networks with boundary conditions at nodes (format version 2):
# a looped network with its boundary vessels written against the flow agrees with --steady
# under constant boundaries (0D and 1D); two pulsatile inflows, a pressure and an outlet at a
# vessel's `from` end balance once periodic; boundaries where two vessels meet and waveforms
# of two periods are refused; and the rat mesentery (when ../shared/networks is there) runs
# to its periodic state in about a second, its mean flows near --steady's.
source "$(dirname "$0")/lib.sh"
HEMOSOLVE=$BUILD/solver/hemosolve
VIMPORT=$BUILD/exchange/vimport
PY=/usr/bin/python3

# The bridged diamond of tests/test_steady_flow.cpp (nodes 10..13, vessel 3 written against
# its flow) with a lead vessel to each boundary node: vessel 5 written 10 -> 14 (the inflow at its
# `to` end) and vessel 6 written 15 -> 13 (the pressure at its `from` end). Vessels of 1 mm
# and 1 cm; the pressure at the walls' reference (10 mmHg), so that they barely distend.
vessels='
  {"id": 0, "from": 10, "to": 11, "length": 0.01, "diameter": 0.001, "wall_thickness": 1e-4, "youngs_modulus": 1e6},
  {"id": 1, "from": 10, "to": 12, "length": 0.01, "diameter": 0.001, "wall_thickness": 1e-4, "youngs_modulus": 1e6},
  {"id": 2, "from": 11, "to": 13, "length": 0.01, "diameter": 0.001, "wall_thickness": 1e-4, "youngs_modulus": 1e6},
  {"id": 3, "from": 13, "to": 12, "length": 0.02, "diameter": 0.001, "wall_thickness": 1e-4, "youngs_modulus": 1e6},
  {"id": 4, "from": 11, "to": 12, "length": 0.01, "diameter": 0.001, "wall_thickness": 1e-4, "youngs_modulus": 1e6},
  {"id": 5, "from": 10, "to": 14, "length": 0.01, "diameter": 0.001, "wall_thickness": 1e-4, "youngs_modulus": 1e6},
  {"id": 6, "from": 15, "to": 13, "length": 0.01, "diameter": 0.001, "wall_thickness": 1e-4, "youngs_modulus": 1e6}'
cat >"$WORK/loop.json" <<JSON
{"format": "vnet", "version": 2,
 "blood": {"rheology": "newtonian", "newtonian_viscosity": 0.0034},
 "boundaries": [{"node": 14, "type": "flow", "flow": 1e-8},
                {"node": 15, "type": "pressure", "pressure": 1333.22}],
 "vessels": [$vessels]}
JSON
"$HEMOSOLVE" "$WORK/loop.json" --steady --out "$WORK/steady" --quiet 2>"$WORK/err" \
  && pass "--steady on the looped network" || fail "--steady: $(cat "$WORK/err")"
for model in auto 0d 1d; do
  "$HEMOSOLVE" "$WORK/loop.json" --model $model --cycles 2 --out "$WORK/run-$model" --quiet 2>"$WORK/err" \
    && pass "pulsatile run of the looped network, --model $model" || fail "--model $model: $(cat "$WORK/err")"
  # Constant boundaries: the steady state. Flows within 1e-3 of the inflow, pressures within
  # 1e-2 of the network's drop (14 Pa; the 1D junctions add rho u^2 / 2 = 0.1 Pa).
  "$PY" - "$WORK/run-$model/summary.json" "$WORK/steady/summary.json" <<'PY' \
    && pass "--model $model agrees with --steady" || fail "--model $model against --steady"
import json, sys
run, steady = (json.load(open(f)) for f in sys.argv[1:3])
assert run["status"] == "complete", run.get("error")
q = 1e-8
drop = max(v["mean_pressure"] for v in steady["vessels"]) - 1333.22
rows = {v["id"]: v for v in steady["vessels"]}
for v in run["vessels"]:
    s = rows[v["id"]]
    assert abs(v["mean_flow"] - s["mean_flow"]) < 1e-3 * q, (v["id"], v["mean_flow"], s["mean_flow"])
    assert abs(v["mean_pressure"] - s["mean_pressure"]) < 1e-2 * drop, (v["id"], v["mean_pressure"], s["mean_pressure"])
# The reversed lead vessels carry the flow against their from -> to.
assert rows[5]["mean_flow"] < 0 and rows[6]["mean_flow"] < 0
bounds = {b["node"]: b for b in run["boundaries"]}
assert abs(bounds[14]["flow"] - q) < 1e-9 * q and abs(bounds[15]["flow"] + q) < 1e-4 * q, bounds
assert abs(run["inlet_mean_flow"] - q) < 1e-9 * q and abs(run["outlets_mean_flow"] - q) < 1e-4 * q
PY
done

# Two pulsatile inflows (tables of one period), the pressure, and an R outlet at the `from`
# end of vessel 7 (written 16 -> 12): once periodic, each inflow's mean is its table's, and
# what enters leaves.
cat >"$WORK/pulsatile.json" <<JSON
{"format": "vnet", "version": 2,
 "blood": {"rheology": "newtonian", "newtonian_viscosity": 0.0034},
 "boundaries": [
   {"node": 14, "type": "flow", "waveform": {"shape": "table", "period": 0.8, "time": [0, 0.2, 0.4, 0.6], "flow": [1e-8, 3e-8, 1e-8, 1e-8]}},
   {"node": 15, "type": "pressure", "pressure": 1333.22},
   {"node": 16, "type": "R", "R": 2e9, "p_out": 1333.22},
   {"node": 17, "type": "flow", "waveform": {"shape": "table", "period": 0.8, "time": [0, 0.4], "flow": [0.5e-8, 1.5e-8]}}],
 "vessels": [$vessels,
  {"id": 7, "from": 16, "to": 12, "length": 0.01, "diameter": 0.001, "wall_thickness": 1e-4, "youngs_modulus": 1e6},
  {"id": 8, "from": 17, "to": 11, "length": 0.01, "diameter": 0.001, "wall_thickness": 1e-4, "youngs_modulus": 1e6}]}
JSON
"$HEMOSOLVE" "$WORK/pulsatile.json" --until-periodic 1e-4 --out "$WORK/pulsatile" --quiet 2>"$WORK/err" \
  && pass "two pulsatile inflows run to the periodic state" || fail "two inflows: $(cat "$WORK/err")"
"$PY" - "$WORK/pulsatile/summary.json" <<'PY' && pass "the inflows' means and the balance" || fail "the inflows' balance"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["status"] == "complete" and abs(s["period"] - 0.8) < 1e-12, (s["status"], s["period"])
b = {x["node"]: x["flow"] for x in s["boundaries"]}
# The tables' trapezoidal means: (1+3)/2 .2 + (3+1)/2 .2 + .2 + .2 over 0.8 s, and (0.5+1.5)/2.
assert abs(b[14] - 1.5e-8) < 1e-3 * 1.5e-8 and abs(b[17] - 1e-8) < 1e-3 * 1e-8, b
assert b[15] < 0 and b[16] < 0, b
assert abs(sum(b.values())) < 1e-4 * 2.5e-8, b
assert abs(s["mass_balance"]) < 1e-4 and abs(s["conservation_error"]) < 1e-9, (s["mass_balance"], s["conservation_error"])
PY

# Refusals: a boundary where two vessels meet (the diamond without its lead vessels), and two
# pulsatile boundaries of different periods.
"$PY" - "$WORK/loop.json" "$WORK/junction.json" <<'PY'
import json, sys
net = json.load(open(sys.argv[1]))
net["vessels"] = [v for v in net["vessels"] if v["id"] < 5]
net["boundaries"] = [{"node": 10, "type": "flow", "flow": 1e-8}, {"node": 13, "type": "pressure", "pressure": 1333.22}]
json.dump(net, open(sys.argv[2], "w"))
PY
expect_error "a boundary where two vessels meet" 2 \
  "hemosolve's pulsatile run takes boundary conditions where one vessel ends; node 10 joins 2 vessels; --steady takes any" \
  -- "$HEMOSOLVE" "$WORK/junction.json" --out "$WORK/refused-1"
[ -e "$WORK/refused-1/summary.json" ] && fail "refused run left a summary" || pass "refused run left no summary"
"$HEMOSOLVE" "$WORK/junction.json" --steady --out "$WORK/junction-steady" --quiet 2>"$WORK/err" \
  && pass "--steady takes it" || fail "--steady on the junction boundaries: $(cat "$WORK/err")"
sed 's/"period": 0.8, "time": \[0, 0.4\]/"period": 1, "time": [0, 0.4]/' "$WORK/pulsatile.json" >"$WORK/periods.json"
expect_error "waveforms of different periods" 2 "have different periods" \
  -- "$HEMOSOLVE" "$WORK/periods.json" --out "$WORK/refused-2"

# The rat mesentery: 1130 vessels, 159 loops, 31 inflows, 4 prescribed outflows, a pressure.
NETWORKS=${HEMOTREE_NETWORKS_DIR:-$(dirname "$0")/../../../shared/networks}
MESENTERY=$NETWORKS/mesentery-rat/network.dat
if [ -f "$MESENTERY" ]; then
  "$VIMPORT" secomb "$MESENTERY" --mean-cell-volume 55fl --plasma-viscosity 1.0466cP --hematocrit 0.4 \
    -o "$WORK/mes.json" 2>/dev/null && pass "vimport of the mesentery" || fail "vimport of the mesentery"
  "$HEMOSOLVE" "$WORK/mes.json" --steady --out "$WORK/mes-steady" --quiet 2>"$WORK/err" || fail "mesentery --steady: $(cat "$WORK/err")"
  "$HEMOSOLVE" "$WORK/mes.json" --out "$WORK/mes-run" --until-periodic 1e-3 --quiet 2>"$WORK/err" \
    && pass "the mesentery runs to its periodic state" || fail "mesentery: $(cat "$WORK/err")"
  # Its compliant vessels distend (the rigid --steady keeps the reference lumens): the mean
  # flows differ by a few per cent (median 3 %, at most 34 % in a few low-flow vessels);
  # with 10 GPa walls they agree to 5e-6 (tests/test_network_graphs_pulsatile.cpp).
  "$PY" - "$WORK/mes-run/summary.json" "$WORK/mes-steady/summary.json" <<'PY' \
    && pass "the mesentery's mean flows near --steady's" || fail "the mesentery against --steady"
import json, statistics, sys
run, steady = (json.load(open(f)) for f in sys.argv[1:3])
assert run["status"] == "complete", run.get("error")
rows = {v["id"]: v["mean_flow"] for v in steady["vessels"]}
rel = sorted(abs(v["mean_flow"] - rows[v["id"]]) / abs(rows[v["id"]]) for v in run["vessels"] if rows[v["id"]] != 0)
median, largest = statistics.median(rel), rel[-1]
per_cycle = run["wall_time"] / run["cycles"]
print(f"mesentery: {run['cycles']} cycles, {per_cycle:.3f} s a cycle; mean flows against --steady: "
      f"median {median:.3g}, largest {largest:.3g}")
assert median < 0.1 and largest < 0.6, (median, largest)
assert abs(run["mass_balance"]) < 1e-4, run["mass_balance"]
assert per_cycle < 10, per_cycle
PY
else
  echo "skip: $MESENTERY is absent"
fi

# ADAN56 (openBF's): 64 1D arteries and 13 short 0D segments between them. Until periodic it
# takes no settling cycle of a longer 0D step (most of its vessels are 1D: that saves nothing
# there, and at three times the run's it broke down in those segments, where the run broke
# with an internal error) but one with its 1D vessels at degree 2 (--settling-degree auto:
# the large arteries' nonlinear pulse leaves the linear start's first cycle 2.4e-3 off), and
# it is periodic to 1e-3 in two cycles (1.8e-4), where without that settling cycle it takes
# three.
ADAN56=$NETWORKS/openbf/boileau2015/adan56/adan56.yaml
if [ -f "$ADAN56" ]; then
  "$VIMPORT" openbf "$ADAN56" -o "$WORK/adan56.json" 2>/dev/null || fail "vimport of ADAN56"
  "$HEMOSOLVE" "$WORK/adan56.json" --out "$WORK/adan56-run" --until-periodic 1e-3 2>"$WORK/err" \
    && grep -q "settling cycle: .* steps with the 1D vessels at degree 2 at most" "$WORK/err" \
    && grep -q "vessels 1D, 13 0D" "$WORK/err" \
    && pass "ADAN56 runs until periodic, after a settling cycle at degree 2" || fail "ADAN56: $(cat "$WORK/err")"
  "$HEMOSOLVE" "$WORK/adan56.json" --out "$WORK/adan56-unsettled" --until-periodic 1e-3 --settling-degree 0 --quiet \
    || fail "ADAN56 --settling-degree 0"
  "$PY" - "$WORK/adan56-run/summary.json" "$WORK/adan56-unsettled/summary.json" <<'PY' \
    && pass "ADAN56 periodic to 1e-3 in 2 cycles after the settling cycle, 3 without" || fail "ADAN56 settling cycle"
import json, sys
settled, unsettled = (json.load(open(f)) for f in sys.argv[1:3])
assert settled["settling_cycle"]["degree"] == 2, settled["settling_cycle"]
assert settled["settling_cycle"]["steps"] > 0, settled["settling_cycle"]
assert settled["cycles"] == 2 and settled["periodic_change"] < 5e-4, (settled["cycles"], settled["periodic_change"])
assert "settling_cycle" not in unsettled
assert unsettled["cycles"] == 3 and unsettled["periodic_change"] < 5e-4, (unsettled["cycles"], unsettled["periodic_change"])
# The same periodic state: every vessel's mean pressure within the tolerance of each other.
a = {v["id"]: v for v in settled["vessels"]}
for v in unsettled["vessels"]:
    assert abs(a[v["id"]]["mean_pressure"] - v["mean_pressure"]) < 1e-3 * abs(v["mean_pressure"]), v["id"]
PY
  # At a quarter of its step the coupling of aortic segment 36 (1D) to the 0D segments beside
  # it diverges (docs/solver.md, section 10, "A known limit"), where a still shorter step, the
  # usual advice, does not help: the one line says so.
  "$HEMOSOLVE" "$WORK/adan56.json" --out "$WORK/adan56-short" --dt 0.25ms --quiet 2>"$WORK/err"
  status=$?
  [ $status -eq 2 ] && [ "$(wc -l <"$WORK/err")" -eq 1 ] && grep -q "broke down in vessel 36" "$WORK/err" \
    && grep -q "its end meets 0D vessels, whose coupling to it a shorter step can itself break" "$WORK/err" \
    && [ ! -e "$WORK/adan56-short/summary.json" ] \
    && pass "ADAN56 at a quarter of its step: the breakdown names the 1D-0D coupling" \
    || fail "ADAN56 --dt 0.25ms: status $status: $(cat "$WORK/err")"
else
  echo "skip: $ADAN56 is absent"
fi

finish
