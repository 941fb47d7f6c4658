# vgen | vprune through a real pipe; vprune's checks and refusals.
source "$(dirname "$0")/lib.sh"
VPRUNE=$BUILD/pruner/vprune

"$VGEN" --root-diameter 300um --min-diameter 8.5um --seed 2 -o "$WORK/full.json"
"$VGEN" --root-diameter 300um --min-diameter 8.5um --seed 2 | "$VPRUNE" --budget 301 --seed 5 \
  >"$WORK/net.json" 2>"$WORK/log"
status=("${PIPESTATUS[@]}")
[ "${status[0]}" -eq 0 ] && [ "${status[1]}" -eq 0 ] && pass "vgen | vprune" || fail "pipe status ${status[*]}: $(cat "$WORK/log")"
grep -q "steady inlet pressure" "$WORK/log" && pass "reports the steady inlet pressure" || fail "no report: $(cat "$WORK/log")"
/usr/bin/python3 - "$WORK/net.json" <<'PY' && pass "pruned network content" || fail "pruned network content"
import json, sys
net = json.load(open(sys.argv[1]))
vessels = net["vessels"]
assert abs(len(vessels) - 301) <= 3, len(vessels)
prov = net["provenance"]
full, pruned = prov["steady_inlet_pressure_full"], prov["steady_inlet_pressure_pruned"]
assert abs(pruned - full) <= 1e-3 * full
starts = {v["from"] for v in vessels}
terminals = [v for v in vessels if v["to"] not in starts]
assert all("outlet" in v for v in terminals)
assert all("outlet" not in v for v in vessels if v["to"] in starts)
for v in terminals:
    kind = v["outlet"]["type"]
    assert kind in ("RCR", "R"), v
    if kind == "RCR":                  # RCR only on terminals of at least 100 um
        assert v["diameter"] >= 100e-6, v
assert net["inlet"]["type"] == "flow" and net["inlet"]["vessel"] == vessels[0]["id"]
assert abs(net["inlet"]["waveform"]["mean"] - 1.74e-6 / 60) < 1e-15
assert net["blood"]["rheology"] == "pries"
PY

"$VPRUNE" --budget 301 --seed 5 "$WORK/full.json" -o "$WORK/a.json" 2>/dev/null
"$VPRUNE" --budget 301 --seed 5 "$WORK/full.json" -o "$WORK/b.json" 2>/dev/null
cmp -s "$WORK/a.json" "$WORK/b.json" && pass "same seed, same network" || fail "vprune not deterministic"
cmp -s "$WORK/a.json" "$WORK/net.json" && pass "file and pipe agree" || fail "file and pipe differ"

"$VPRUNE" --budget 99999999 "$WORK/full.json" -o "$WORK/all.json" 2>"$WORK/log"
grep -q "keeping every vessel" "$WORK/log" && pass "budget above the tree keeps all" || fail "big budget: $(cat "$WORK/log")"
"$VPRUNE" --budget all "$WORK/full.json" -o "$WORK/all2.json" 2>"$WORK/log"
grep -q "keeping every one of the tree's" "$WORK/log" && /usr/bin/python3 - "$WORK/all.json" "$WORK/all2.json" <<'PY' \
  && pass "--budget all keeps the whole tree, as a budget above its size" || fail "--budget all: $(cat "$WORK/log")"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:])
assert a["vessels"] == b["vessels"] and a["inlet"] == b["inlet"], "networks differ"
assert b["provenance"]["parameters"]["budget"] == "all", b["provenance"]["parameters"]
PY
"$VPRUNE" --strategy generation --max-generation 3 "$WORK/full.json" -o "$WORK/g.json" 2>/dev/null \
  && [ "$("$VSTATS" --json "$WORK/g.json" | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["vessels"])')" -eq 15 ] \
  && pass "generation strategy" || fail "generation strategy"
printf '0, 0\n0.1, 2e-9\n0.5, 1e-9\n' >"$WORK/inflow.csv"
"$VPRUNE" --budget 101 --inflow-table "$WORK/inflow.csv" --period 1s "$WORK/full.json" -o "$WORK/t.json" 2>/dev/null \
  && grep -q '"shape":"table"' "$WORK/t.json" && pass "tabulated inflow" || fail "tabulated inflow"

expect_error "budget 0" 2 "--budget" -- "$VPRUNE" --budget 0 "$WORK/full.json"
expect_error "budget missing" 2 "--budget" -- "$VPRUNE" "$WORK/full.json"
expect_error "bad hematocrit" 2 "hematocrit" -- "$VPRUNE" --budget 11 --hematocrit 1.5 "$WORK/full.json"
expect_error "bad mean flow" 2 "--mean-flow" -- "$VPRUNE" --budget 11 --mean-flow 2parsec "$WORK/full.json"
cat >"$WORK/loop.json" <<'JSON'
{"format": "vnet", "version": 1, "vessels": [
 {"id": 1, "from": 0, "to": 1, "length": 0.01, "diameter": 1e-4},
 {"id": 2, "from": 1, "to": 2, "length": 0.01, "diameter": 1e-4},
 {"id": 3, "from": 2, "to": 3, "length": 0.01, "diameter": 1e-4},
 {"id": 4, "from": 3, "to": 2, "length": 0.01, "diameter": 1e-4}]}
JSON
expect_error "not a tree" 2 "vessel" -- "$VPRUNE" --budget 3 "$WORK/loop.json"
cat >"$WORK/roots.json" <<'JSON'
{"format": "vnet", "version": 1, "vessels": [
 {"id": 1, "from": 0, "to": 1, "length": 0.01, "diameter": 1e-4},
 {"id": 2, "from": 5, "to": 6, "length": 0.01, "diameter": 1e-4}]}
JSON
expect_error "several roots" 2 "several roots" -- "$VPRUNE" --budget 1 "$WORK/roots.json"
"$VPRUNE" --budget 0 "$WORK/full.json" -o "$WORK/none.json" 2>/dev/null
[ -e "$WORK/none.json" ] && fail "refused run left a file" || pass "refused run leaves no file"

# A looped network (format version 2) is not vprune's: one line saying what to use instead.
"$VGEN" --root-diameter 60um --min-diameter 8.5um --venous --mean-flow 1e-3ml/min -o "$WORK/venous.json"
expect_error "looped network" 2 "vprune cuts trees (hemosolve --steady solves any network whole)" -- \
  "$VPRUNE" --budget 5 "$WORK/venous.json"
finish
