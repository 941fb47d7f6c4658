# hemosolve --steady on a network with boundaries at nodes (format version 2): a loop, a
# vessel written against its flow, a pressure and a flow boundary; the same summary.json and
# vessels.csv fields as a pulsatile run; the refusals of networks without a pressure reference.
source "$(dirname "$0")/lib.sh"
HEMOSOLVE=$BUILD/solver/hemosolve
PY=/usr/bin/python3

# The bridged diamond of tests/test_steady_flow.cpp, Newtonian blood (3.4 mPa s), vessels of
# 1 mm and 1 cm with alpha 4/3: r = 128 mu l / (pi D^4) each (vessel 3 twice as long).
cat >"$WORK/diamond.json" <<'JSON'
{"format": "vnet", "version": 2,
 "blood": {"rheology": "newtonian", "newtonian_viscosity": 0.0034},
 "boundaries": [{"node": 10, "type": "flow", "flow": 1e-6, "hematocrit": 0.4},
                {"node": 13, "type": "pressure", "pressure": 1000}],
 "vessels": [
  {"id": 0, "from": 10, "to": 11, "length": 0.01, "diameter": 0.001},
  {"id": 1, "from": 10, "to": 12, "length": 0.01, "diameter": 0.001},
  {"id": 2, "from": 11, "to": 13, "length": 0.01, "diameter": 0.001},
  {"id": 3, "from": 13, "to": 12, "length": 0.02, "diameter": 0.001},
  {"id": 4, "from": 11, "to": 12, "length": 0.01, "diameter": 0.001}]}
JSON
"$HEMOSOLVE" "$WORK/diamond.json" --steady --out "$WORK/run" 2>"$WORK/err" \
  && pass "--steady on a looped network" || fail "--steady: $(cat "$WORK/err")"
"$PY" - "$WORK/run/summary.json" "$WORK/run/vessels.csv" <<'PY' && pass "summary.json: steady values, signed flows, boundaries" || fail "summary.json"
import csv, json, math, sys
s = json.load(open(sys.argv[1]))
assert s["status"] == "complete" and s["mode"] == "steady", s["status"]
r = 128 * 0.0034 * 0.01 / (math.pi * 0.001 ** 4)
q = 1e-6
# Kirchhoff by hand (tests/test_steady_flow.cpp): node pressures above 1000 Pa in units of q r.
p = {10: 13 / 11, 11: 7 / 11, 12: 8 / 11, 13: 0}
flows = {0: 6 / 11, 1: 5 / 11, 2: 7 / 11, 3: -4 / 11, 4: -1 / 11}
ends = {0: (10, 11), 1: (10, 12), 2: (11, 13), 3: (13, 12), 4: (11, 12)}
rows = {v["id"]: v for v in s["vessels"]}
for v, f in flows.items():
    row = rows[v]
    assert abs(row["mean_flow"] - f * q) < 1e-9 * q, (v, row["mean_flow"])
    a, b = ends[v]
    mid = 1000 + q * r * (p[a] + p[b]) / 2
    assert abs(row["mean_pressure"] - mid) < 1e-9 * mid, (v, row["mean_pressure"], mid)
    assert row["systolic_pressure"] == row["diastolic_pressure"] == row["mean_pressure"]
    assert row["pulsatility_index"] == 0 and row["peak_flow"] == row["least_flow"] == row["mean_flow"]
    # Poiseuille: tau = 4 mu u / R, signed with the flow
    u = row["mean_flow"] / (math.pi * 0.0005 ** 2)
    assert abs(row["mean_wss"] - 4 * 0.0034 * u / 0.0005) < 1e-9 * abs(row["mean_wss"]), v
    assert row["model"] == "steady" and row["degree"] is None and row["pwv_pressure"] is None
assert abs(s["inlet_mean_flow"] - q) < 1e-12 * q and abs(s["outlets_mean_flow"] - q) < 1e-12 * q
assert abs(s["mass_balance"]) < 1e-12
b = {x["node"]: x for x in s["boundaries"]}
assert b[10]["type"] == "flow" and abs(b[10]["flow"] - q) < 1e-12 * q
assert b[13]["type"] == "pressure" and b[13]["pressure"] == 1000 and abs(b[13]["flow"] + q) < 1e-12 * q
header = next(csv.reader(open(sys.argv[2])))
assert header[:6] == ["id", "diameter", "length", "class", "model", "degree"], header
PY

# ---- refusals: one line, exit 2, nothing written -----------------------------------------
"$PY" - "$WORK/diamond.json" "$WORK" <<'PY'
import json, sys
net = json.load(open(sys.argv[1]))
flows = json.loads(json.dumps(net)); flows["boundaries"][1] = {"node": 13, "type": "flow", "flow": -1e-6}
json.dump(flows, open(sys.argv[2] + "/flows.json", "w"))
dead = json.loads(json.dumps(net)); dead["vessels"].append({"id": 5, "from": 12, "to": 14, "length": 0.01, "diameter": 0.001})
json.dump(dead, open(sys.argv[2] + "/dead.json", "w"))
twice = json.loads(json.dumps(net)); twice["boundaries"].append({"node": 13, "type": "R", "R": 1e9})
json.dump(twice, open(sys.argv[2] + "/twice.json", "w"))
PY
expect_error "flows only" 2 "has flow boundaries only: its pressure is undetermined" -- \
  "$HEMOSOLVE" "$WORK/flows.json" --steady --out "$WORK/flows"
[ ! -e "$WORK/flows" ] && pass "nothing written for a refused network" || fail "$WORK/flows exists"
expect_error "dead end" 2 "vessel 5 ends at node 14, which no other vessel meets and which has no boundary condition" -- \
  "$HEMOSOLVE" "$WORK/dead.json" --steady --out "$WORK/dead"
expect_error "two conditions at a node" 2 "node 13 has two boundary conditions" -- \
  "$HEMOSOLVE" "$WORK/twice.json" --steady --out "$WORK/twice"
expect_error "--steady with --cycles" 2 "--cycles excludes --steady" -- \
  "$HEMOSOLVE" "$WORK/diamond.json" --steady --cycles 3 --out "$WORK/x"

# ---- red cells: phase separation in steady flow (the rat mesentery, where it is shared) ----
expect_error "--red-cells unknown" 2 "--red-cells must be fixed or transport (got 'sludge')" -- \
  "$HEMOSOLVE" "$WORK/diamond.json" --steady --red-cells sludge --out "$WORK/x"
DAT=$(dirname "$0")/../../../shared/networks/mesentery-rat/network.dat
if [ -s "$DAT" ]; then
  "$BUILD/exchange/vimport" secomb "$DAT" --mean-cell-volume 55 --plasma-viscosity 1.0466cP -o "$WORK/mes.json" 2>/dev/null
  "$HEMOSOLVE" "$WORK/mes.json" --steady --red-cells transport --out "$WORK/rbc" --quiet \
    && pass "--steady --red-cells transport on the mesentery" || fail "--red-cells transport"
  "$PY" - "$WORK/mes.json" "$WORK/rbc/summary.json" <<'PY' && pass "red cells balance at every node, the law holds at every bifurcation (checked on its own); hematocrits in range" || fail "red-cell balance"
import json, sys
net, s = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert s["status"] == "complete" and s["red_cells"] == "phase_separation", s["status"]
assert s["red_cell_iterations"]["change"] < 1e-9
rows = {v["id"]: v for v in s["vessels"]}
boundary = {b["node"] for b in net["boundaries"]}
cells = {}  # net red-cell flux out of each node through its vessels
scale = 0
for v in net["vessels"]:
    r = rows[v["id"]]
    assert 0 <= r["discharge_hematocrit"] < 1 and 0 <= r["tube_hematocrit"] < 1, r["id"]
    f = r["mean_flow"] * r["discharge_hematocrit"]
    scale = max(scale, abs(f))
    cells[v["from"]] = cells.get(v["from"], 0) + f
    cells[v["to"]] = cells.get(v["to"], 0) - f
worst = max(abs(x) for n, x in cells.items() if n not in boundary)
assert worst < 1e-12 * scale, worst / scale
# The law at every diverging bifurcation, computed here on its own (Pries & Secomb 2005 with
# NetFlow's constants, diameters unscaled as in its dishem.cpp) from the solution's flows.
import math
ends = {}
for v in net["vessels"]:
    ends.setdefault(v["from"], []).append((v, -1))
    ends.setdefault(v["to"], []).append((v, +1))
checked = 0
for node, at in ends.items():
    if node in boundary or len(at) != 3:
        continue
    q = {v["id"]: sign * rows[v["id"]]["mean_flow"] for v, sign in at}  # into the node
    feeds = [i for i in q if q[i] > 0]
    if len(feeds) != 1 or any(q[i] == 0 for i in q):
        continue
    f = feeds[0]
    a, b = [i for i in q if i != f]
    diameter = {v["id"]: v["diameter"] * 1e6 for v, _ in at}
    hf = rows[f]["discharge_hematocrit"]
    x0 = 0.964 * (1 - hf) / diameter[f]
    r = (diameter[a] / diameter[b]) ** 2
    A = -13.29 * (r - 1) / (r + 1) * (1 - hf) / diameter[f]
    B = 1 + 6.98 * (1 - hf) / diameter[f]
    fqb = -q[a] / (-q[a] - q[b])
    if fqb <= x0:
        fqe = 0.0
    elif fqb >= 1 - x0:
        fqe = 1.0
    else:
        z = (fqb - x0) / (1 - 2 * x0)
        fqe = 1 / (1 + math.exp(-(A + B * math.log(z / (1 - z)))))
    assert abs(rows[a]["discharge_hematocrit"] - fqe * hf / fqb) < 1e-9, (node, rows[a]["discharge_hematocrit"], fqe * hf / fqb)
    assert abs(rows[b]["discharge_hematocrit"] - (1 - fqe) * hf / (1 - fqb)) < 1e-9, node
    checked += 1
assert checked > 100, checked  # the mesentery has some 160 such nodes
# The first segment carries the largest inflow (node 830: 362.56 nl/min at Hd 0.4338, given).
first = rows[1]
assert abs(first["mean_flow"] * 60e12 - 362.56) < 1e-3 and abs(first["discharge_hematocrit"] - 0.4338) < 1e-12
PY
else
  echo "skip: no $DAT (the shared public networks)"
fi
finish
