# vgen | vprune | hemosolve through a real pipe; hemosolve's summary.json and probes.csv; its
# refusals (one line on stderr, non-zero exit, no summary.json left behind).
source "$(dirname "$0")/lib.sh"
VPRUNE=$BUILD/pruner/vprune
HEMOSOLVE=$BUILD/solver/hemosolve
EXAMPLES=$(cd "$(dirname "$0")/../../examples/boileau2015" && pwd)
PY=/usr/bin/python3

# ---- the pipeline: a 31-vessel microvascular tree, one cycle at p = 2 (about 4 s) ----------

"$VGEN" --root-diameter 150um --min-diameter 8.5um \
  | "$VPRUNE" --budget 31 --mean-flow 0.01ml/min 2>"$WORK/prune.log" \
  | tee "$WORK/net.json" \
  | "$HEMOSOLVE" - --out "$WORK/run" --cycles 1 --model 1d --degree 2 --quiet --probe 0:0 --probe 1:1 --vtk --frames 4 \
    >"$WORK/solve.out" 2>"$WORK/solve.err"
status=("${PIPESTATUS[@]}")
if [ "${status[0]}" -eq 0 ] && [ "${status[1]}" -eq 0 ] && [ "${status[2]}" -eq 0 ] && [ "${status[3]}" -eq 0 ]; then
  pass "vgen | vprune | hemosolve -"
else
  fail "pipe status ${status[*]}: $(cat "$WORK/prune.log" "$WORK/solve.err")"
fi
[ ! -s "$WORK/solve.err" ] && [ ! -s "$WORK/solve.out" ] && pass "--quiet prints nothing" \
  || fail "--quiet printed: $(cat "$WORK/solve.out" "$WORK/solve.err")"

"$PY" - "$WORK/net.json" "$WORK/run/summary.json" <<'PY' && pass "summary.json: run fields and every vessel's statistics" || fail "summary.json"
import json, math, sys
net = json.load(open(sys.argv[1]))
s = json.load(open(sys.argv[2]))
assert s["tool"] == "hemosolve" and s["status"] == "complete", s.get("status")
assert s["cycles"] == 1 and s["degree"] == 2 and s["elements_per_vessel"] == 1
assert s["network"] == "-" and s["start"] == "periodic" and s["start_requested"] == "periodic"
assert s["period"] == net["inlet"]["waveform"]["period"]
assert s["time_step"] > 0
assert abs(s["steps"] * s["time_step"] - s["period"]) <= 1e-9 * s["period"], (s["steps"], s["time_step"])
# The real limit, not the rebuild's "given by --dt".
assert "wave speed" in s["time_step_limit"] or "friction" in s["time_step_limit"], s["time_step_limit"]
assert s["units"]["flow"] == "m^3/s" and s["units"]["pressure"] == "Pa" and s["units"]["wss"] == "Pa", s["units"]
# The half sine of 0.3 s in a 1 s cycle: 3.33 Hz, analysed at the nearest harmonic, 3 Hz.
assert abs(s["pulse_frequency"] - 1 / 0.3) < 1e-9 and s["analysis_frequency"] == 3.0, s["analysis_frequency"]
q_in = net["inlet"]["waveform"]["mean"]
assert abs(s["inlet_mean_flow"] - q_in) <= 1e-3 * q_in, (s["inlet_mean_flow"], q_in)
# The first cycle changes the stored volume by what its start missed of the periodic state:
# -10 % from the steady start (the pulse's mean pressures differ from the steady ones),
# -7e-4 from the periodic start (the default); periodic, it is 8e-5 (6 cycles, measured).
assert abs(s["mass_balance"] - (s["inlet_mean_flow"] - s["outlets_mean_flow"]) / s["inlet_mean_flow"]) < 1e-12
assert abs(s["mass_balance"]) < 5e-3, s["mass_balance"]

keys = {"id", "diameter", "length", "class", "model", "degree", "mean_flow", "mean_pressure", "systolic_pressure",
        "diastolic_pressure", "pulsatility_index", "peak_flow", "least_flow", "mean_wss", "reynolds", "womersley", "pwv_pressure",
        "pwv_velocity", "pwv_elastic", "pwv_theory"}
by_id = {v["id"]: v for v in net["vessels"]}
rows = s["vessels"]
assert len(rows) == len(net["vessels"]) == len(by_id), (len(rows), len(net["vessels"]))
assert [r["id"] for r in rows] == [v["id"] for v in net["vessels"]]
for r in rows:
    assert set(r) == keys, (r["id"], set(r) ^ keys)
    v = by_id[r["id"]]
    assert r["diameter"] == v["diameter"] and r["length"] == v["length"], r["id"]
    d = r["diameter"]
    expected = ("artery" if d >= 500e-6 else "small_artery" if d >= 100e-6
                else "arteriole" if d >= 10e-6 else "capillary")
    assert r["class"] == expected, (r["id"], r["class"], d)
    assert r["degree"] == 2 and r["model"] == "1d", r
    for k in keys - {"id", "class", "model", "degree", "pwv_pressure", "pwv_velocity"}:
        assert isinstance(r[k], (int, float)) and math.isfinite(r[k]), (r["id"], k, r[k])
    for k in ("pwv_pressure", "pwv_velocity"):  # null where no forward wave is measurable
        assert r[k] is None or (math.isfinite(r[k]) and r[k] > 0), (r["id"], k, r[k])
    # Poiseuille: WSS = 4 mu u / R > 0 with forward flow; the theory lies below c0 (W < 1).
    assert r["mean_wss"] > 0 and r["reynolds"] > 0 and 0 < r["womersley"] < 1, r
    assert r["least_flow"] <= r["mean_flow"] <= r["peak_flow"], r
    assert 0 < r["pwv_theory"] < r["pwv_elastic"], r
    assert 0 < r["diastolic_pressure"] <= r["mean_pressure"] <= r["systolic_pressure"] < 40000, r
    pi = (r["systolic_pressure"] - r["diastolic_pressure"]) / r["mean_pressure"]
    assert abs(r["pulsatility_index"] - pi) <= 1e-12 * max(1, pi), r
    assert r["mean_flow"] > 0, r  # a tree fed at its root: every vessel carries flow forward
# One cycle from the steady start: the root carries the inflow's mean within 10 %.
root = rows[0]
q_in = net["inlet"]["waveform"]["mean"]
assert abs(root["mean_flow"] - q_in) <= 0.1 * q_in, (root["mean_flow"], q_in)
# Pressure falls from the root to every terminal vessel.
assert all(r["mean_pressure"] < root["mean_pressure"] for r in rows[1:])
PY

"$PY" - "$WORK/run/probes.csv" "$WORK/run/summary.json" <<'PY' && pass "probes.csv: header, units and samples" || fail "probes.csv"
import csv, json, math, sys
rows = list(csv.reader(open(sys.argv[1])))
s = json.load(open(sys.argv[2]))
header = rows[0]
expected = ["t [s]"]
for vessel, x in ((0, "0"), (1, "1")):
    at = f" vessel {vessel} x {x}"
    expected += [f"p{at} [Pa]", f"Q{at} [m^3/s]", f"A{at} [m^2]", f"u{at} [m/s]"]
assert header == expected, header
data = [[float(x) for x in r] for r in rows[1:]]
assert all(len(r) == 9 for r in data)
assert all(math.isfinite(x) for r in data for x in r)
t = [r[0] for r in data]
assert t[0] == 0 and all(b > a for a, b in zip(t, t[1:]))
assert abs(t[-1] - s["period"]) <= 2e-3 and 900 <= len(t) <= 1100, (t[-1], len(t))  # every 1 ms
for r in data:
    for k in (1, 5):
        p, q, a, u = r[k:k + 4]
        assert p > 0 and a > 0
        assert abs(u - q / a) <= 1e-7 * abs(q / a) + 1e-300, r
# The inlet probe (vessel 0, x = 0) sees the prescribed half sine: zero in diastole.
q_inlet = [r[2] for r in data]
assert max(q_inlet) > 0 and abs(q_inlet[-2]) < 1e-3 * max(q_inlet)
PY

"$PY" - "$WORK/run" "$WORK/run/summary.json" <<'PY' && pass "--vtk and --frames: well-formed VTK with every result" || fail "--vtk/--frames"
import json, math, os, sys
import xml.etree.ElementTree as ET
run, s = sys.argv[1], json.load(open(sys.argv[2]))
n = len(s["vessels"])
def cell_arrays(path):
    root = ET.parse(path).getroot()  # raises on malformed XML
    piece = root.find("./PolyData/Piece")
    assert int(piece.get("NumberOfLines")) == n, piece.attrib
    return {a.get("Name"): [float(x) for x in a.text.split()] for a in piece.find("CellData")}
results = cell_arrays(os.path.join(run, "results.vtp"))
for key in ("mean_flow", "mean_pressure", "pulsatility_index", "mean_wss", "pwv_pressure", "pwv_theory",
            "womersley", "reynolds", "degree", "model_0d"):
    assert key in results and len(results[key]) == n, key
for row, value in zip(s["vessels"], results["mean_pressure"]):
    assert abs(value - row["mean_pressure"]) <= 1e-8 * row["mean_pressure"], (row["id"], value)
pvd = ET.parse(os.path.join(run, "frames", "frames.pvd")).getroot()
sets = pvd.findall("./Collection/DataSet")
times = [float(d.get("timestep")) for d in sets]
assert len(sets) == 4 and times == sorted(times) and abs(times[-1] - s["period"]) < 1e-9, times
for d in sets:
    frame = cell_arrays(os.path.join(run, "frames", d.get("file")))
    assert {"p", "Q", "A", "u"} <= set(frame), frame.keys()
    assert all(math.isfinite(x) and x > 0 for x in frame["p"] + frame["A"])
PY

# ---- refusals ------------------------------------------------------------------------------

"$PY" - "$EXAMPLES" "$WORK" <<'PY'
import copy, json, sys
examples, work = sys.argv[1], sys.argv[2]
cca = json.load(open(f"{examples}/cca.json"))
ibif = json.load(open(f"{examples}/ibif.json"))
def save(net, name):
    json.dump(net, open(f"{work}/{name}.json", "w"))
n = copy.deepcopy(cca); del n["inlet"]; save(n, "no-inlet")
n = copy.deepcopy(ibif); del n["vessels"][2]["outlet"]; save(n, "no-outlet")       # vessel 3
n = copy.deepcopy(cca); n["vessels"][0]["length"] = 0; save(n, "zero-length")
n = copy.deepcopy(cca); n["vessels"][0]["length"] = -0.1; save(n, "negative-length")
n = copy.deepcopy(cca)
for k in ("beta", "reference_pressure", "wall_thickness"):
    del n["vessels"][0][k]
save(n, "no-wall")
PY
CCA=$EXAMPLES/cca.json
refusal=0
# refuse "description" STATUS FRAGMENT -- command...: expect_error, and no summary.json or
# probes.csv in the run's folder (its --out is $WORK/refused-N, given by the caller).
refuse() {
  local what=$1 out=$WORK/refused-$refusal
  expect_error "$@"
  if [ -e "$out/summary.json" ] || [ -e "$out/probes.csv" ]; then fail "$what: left output in $out"
  else pass "$what: no output left"; fi
  refusal=$((refusal + 1))
}
out() { echo "$WORK/refused-$refusal"; }

refuse "no inlet" 2 "has no \"inlet\"" -- "$HEMOSOLVE" "$WORK/no-inlet.json" --out "$(out)" --probe 1
refuse "terminal vessel without outlet" 2 "vessel 3 is terminal but has no outlet" -- \
  "$HEMOSOLVE" "$WORK/no-outlet.json" --out "$(out)"
refuse "zero length (reader)" 2 'vessel 1: "length" must lie in' -- \
  "$HEMOSOLVE" "$WORK/zero-length.json" --out "$(out)"
refuse "negative length (reader)" 2 'vessel 1: "length" must lie in' -- \
  "$HEMOSOLVE" "$WORK/negative-length.json" --out "$(out)"
refuse "no wall and no beta" 2 "vessel 1" -- "$HEMOSOLVE" "$WORK/no-wall.json" --out "$(out)"
refuse "--probe of an unknown vessel" 2 "--probe: no vessel 7" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --probe 7
refuse "--probe x beyond the vessel" 2 "x must lie in [0, 1]" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --probe 1:1.5
refuse "--probe not ID:x" 2 "is not ID or ID:x" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --probe abc
refuse "--probe with a bad x" 2 "is not ID or ID:x" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --probe 1:x
# --cycles 0 once ran one cycle silently; it is bad input.
refuse "--cycles 0" 2 "--cycles must lie in [1, 100000] (got 0)" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --cycles 0
refuse "--linear-error negative" 2 "--linear-error must lie in [0, inf] (got -1)" -- \
  "$HEMOSOLVE" "$CCA" --out "$(out)" --linear-error -1
refuse "missing network file" 1 "cannot open" -- "$HEMOSOLVE" "$WORK/missing.json" --out "$(out)"
refuse "empty standard input" 2 "standard input" -- \
  bash -c '"$0" - --out "$1" </dev/null' "$HEMOSOLVE" "$(out)"
refuse "no inlet through standard input" 2 "has no \"inlet\"" -- \
  bash -c '"$0" - --out "$1" <"$2"' "$HEMOSOLVE" "$(out)" "$WORK/no-inlet.json"
# A step far above the stability limit is refused, naming the limit and what sets it.
refuse "--dt above the stability limit" 2 "times the stability limit" -- \
  "$HEMOSOLVE" "$CCA" --out "$(out)" --dt 20ms --quiet
# Forced, it breaks down in its first cycle: one line naming the vessel, no summary.
refuse "breakdown (time step far too long, forced)" 2 "broke down in vessel 1" -- \
  "$HEMOSOLVE" "$CCA" --out "$(out)" --dt 20ms --force --quiet
# A lone 1D vessel meets no 0D vessel: the advice about their coupling is not given.
"$HEMOSOLVE" "$CCA" --out "$WORK/cca-broken" --dt 20ms --force --quiet 2>"$WORK/err"
grep -q "broke down in vessel 1" "$WORK/err" && ! grep -q "meets 0D vessels" "$WORK/err" \
  && pass "breakdown of a lone 1D vessel: no coupling advice" || fail "breakdown of the CCA: $(cat "$WORK/err")"
# A failed upstream stage: hemosolve refuses the empty pipe on its own line.
"$VPRUNE" --budget 0 "$WORK/net.json" 2>/dev/null | "$HEMOSOLVE" - --out "$WORK/after-vprune" 2>"$WORK/err"
status=("${PIPESTATUS[@]}")
[ "${status[0]}" -eq 2 ] && [ "${status[1]}" -eq 2 ] && [ "$(wc -l <"$WORK/err")" -eq 1 ] \
  && [ ! -e "$WORK/after-vprune/summary.json" ] && pass "refused vprune | hemosolve: both fail, one line" \
  || fail "vprune --budget 0 | hemosolve: status ${status[*]}: $(cat "$WORK/err")"

# A degree outside 0..30 is bad input, not an internal error (it was exit 70 before b442c97).
refuse "--degree -1" 2 "degree" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --degree -1
refuse "--degree 31" 2 "degree" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --degree 31
refuse "--degree two" 2 "degree" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --degree two
refuse "--frames -1" 2 "frames" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --frames -1
# High degree on coupled elements runs with the defaults (it broke down at t = 3 ms before the
# step followed (p + 1)^2 above p = 7).
"$HEMOSOLVE" "$CCA" --out "$WORK/high-degree" --degree 12 --elements 8 --cycles 1 --quiet 2>"$WORK/err" \
  && [ -s "$WORK/high-degree/summary.json" ] && pass "p = 12 with 8 elements runs with the defaults" \
  || fail "p = 12, 8 elements: $(cat "$WORK/err")"

# Trailing characters after x are refused, not ignored.
refuse "--probe 1:0.5x is refused" 2 "--probe" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --probe 1:0.5x
refuse "--probe 1:0.5:3 is refused" 2 "--probe" -- "$HEMOSOLVE" "$CCA" --out "$(out)" --probe 1:0.5:3
finish
