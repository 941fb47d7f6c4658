# The DG solver's fast defaults (--model 1d: --degree auto, the step at 0.9 of the stability
# limit, ETD2) against the reference discretization of issue 5 (p = 7 in every vessel, half
# the step) on a 31-vessel microvascular tree, with the pulse ten times faster than the
# paper's (a harder test, and ten times cheaper): every vessel's mean pressure and flow within
# 0.5 %, its pulsatility index within 2 %. (The default --model auto is not held to it here:
# at this pulse its 0D arterioles miss the pulsatility by up to 3.4 %, docs/solver.md §10, and
# it takes --lumped-rc 0.1 (every 0D vessel in sections, below) to hold it;
# tests/cli/hemosolve_hybrid.sh holds it to the tolerances at the paper's pulse.) Two threads against one: the same to round-off (the
# element loops split rows, which changes no sum; measured 0 difference). And the capacitor
# balance towards the periodic state against plain cycling.
source "$(dirname "$0")/lib.sh"
VPRUNE=$BUILD/pruner/vprune
HEMOSOLVE=$BUILD/solver/hemosolve
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
PY=/usr/bin/python3

"$VGEN" --root-diameter 150um --min-diameter 8.5um | "$VPRUNE" --budget 31 --mean-flow 0.01ml/min \
  -o "$WORK/slow.json" 2>/dev/null
"$PY" - "$WORK/slow.json" "$WORK/net.json" <<'PY'
import json, sys
net = json.load(open(sys.argv[1]))
w = net["inlet"]["waveform"]
w["period"], w["systole"] = w["period"] / 10, w["systole"] / 10
json.dump(net, open(sys.argv[2], "w"))
PY

"$HEMOSOLVE" "$WORK/net.json" --out "$WORK/reference" --cycles 2 --model 1d --degree 7 --cfl 0.45 --quiet \
  && "$HEMOSOLVE" "$WORK/net.json" --out "$WORK/fast" --cycles 2 --model 1d --quiet \
  && "$HEMOSOLVE" "$WORK/net.json" --out "$WORK/threads" --cycles 2 --model 1d --threads 2 --quiet \
  || fail "hemosolve runs"

"$PY" "$ROOT/bench/compare-summaries" "$WORK/reference/summary.json" "$WORK/fast/summary.json" >"$WORK/cmp" \
  && pass "defaults against p = 7 at half the step: $(grep -c ok "$WORK/cmp") of 3 quantities within tolerance" \
  || fail "defaults against the reference: $(cat "$WORK/cmp")"
cat "$WORK/cmp"

# 0D vessels in pi sections (docs/solver.md §10): at this pulse, --model auto with
# --lumped-rc 0.1 cuts every 0D vessel (arterioles and capillaries, w R C 0.1 to 4.2) into
# sections that each keep below it, and holds the same tolerances against the reference
# (measured: pulsatility within 0.80 % after two cycles, where one section a vessel at the default --lumped-rc
# missed by 3.4 %). A run in sections resumed from its checkpoint goes on bit for bit (the
# inner nodes' state is in checkpoint.bin). With a tracer, one section each: a vessel that
# needs more is 1D (the transport's cells are the network's nodes).
"$HEMOSOLVE" "$WORK/net.json" --out "$WORK/sections" --cycles 2 --lumped-rc 0.1 2>"$WORK/sections.log" \
  && "$HEMOSOLVE" "$WORK/net.json" --out "$WORK/sections_part" --cycles 1 --lumped-rc 0.1 --checkpoint-every 1 --quiet \
  && "$HEMOSOLVE" "$WORK/net.json" --resume "$WORK/sections_part" --cycles 2 --lumped-rc 0.1 --quiet \
  && "$HEMOSOLVE" "$WORK/net.json" --out "$WORK/sections_tracer" --cycles 1 --lumped-rc 0.1 \
    --tracer name=dye,start=0,duration=0.01 --quiet \
  || fail "hemosolve in sections: $(cat "$WORK/sections.log")"
grep -q "0D (--model auto, [0-9]* of them in pi sections)" "$WORK/sections.log" \
  && pass "the run says how many 0D vessels are in sections" || fail "sections not said: $(cat "$WORK/sections.log")"
"$PY" "$ROOT/bench/compare-summaries" "$WORK/reference/summary.json" "$WORK/sections/summary.json" >"$WORK/sections-cmp" \
  && pass "every 0D vessel in sections: within the tolerances ($(grep pulsatility "$WORK/sections-cmp" | xargs))" \
  || fail "sections against the reference: $(cat "$WORK/sections-cmp")"
"$PY" - "$WORK/sections/summary.json" "$WORK/sections_part/summary.json" "$WORK/sections_tracer/summary.json" <<'PY' \
  && pass "in sections: resumed bit for bit; with a tracer one section each" || fail "sections: resume or tracer"
import json, sys
a, b, t = (json.load(open(f)) for f in sys.argv[1:])
print(f"0D vessels {a['vessels_0d']}, in sections {a['vessels_0d_in_sections']}; with a tracer {t['vessels_0d']} 0D, "
      f"{t['vessels_0d_in_sections']} in sections")
assert a["vessels_0d"] > 10 and a["vessels_0d_in_sections"] == a["vessels_0d"], "not all in sections"
assert a["vessels"] == b["vessels"], "resumed results differ"
assert t["vessels_0d_in_sections"] == 0 and t["vessels_0d"] < a["vessels_0d"], "a tracer over sections"
PY

"$PY" - "$WORK/fast/summary.json" "$WORK/threads/summary.json" <<'PY' && pass "two threads give the one-thread results" || fail "threads differ"
import json, sys
a, b = (json.load(open(p))["vessels"] for p in sys.argv[1:])
keys = ("mean_flow", "mean_pressure", "systolic_pressure", "diastolic_pressure", "mean_wss")
worst = max(abs(x[k] - y[k]) / max(abs(x[k]), 1e-300) for x, y in zip(a, b) for k in keys)
print(f"largest relative difference, 2 threads against 1: {worst:.2g}")
assert worst <= 1e-12, worst
PY
# Narrow capillaries (5.5 to 10 um) at the real pulse, one cycle: where the pressure drop
# narrows the lumen along a capillary, its pressure profile bends, and a linear one (degree 1)
# misses the pulsatility at the centre (measured 5.4 % here, 10.6 % on the 1001-vessel
# network). The DG solver's defaults (--model 1d) give such vessels degree 2 (--linear-error)
# and pass; without that rule the same network fails. The reference's step halved changes it by < 2e-8.
"$VGEN" --seed 1 --root-diameter 80um --min-diameter 5.5um | "$VPRUNE" --seed 1 --budget 31 \
  --mean-flow 0.0006ml/min -o "$WORK/capillaries.json" 2>/dev/null
"$HEMOSOLVE" "$WORK/capillaries.json" --out "$WORK/cap-reference" --cycles 1 --model 1d --degree 7 --quiet \
  && "$HEMOSOLVE" "$WORK/capillaries.json" --out "$WORK/cap-fast" --cycles 1 --model 1d --quiet \
  && "$HEMOSOLVE" "$WORK/capillaries.json" --out "$WORK/cap-linear" --cycles 1 --model 1d --linear-error 1e9 --quiet \
  || fail "capillary runs"
"$PY" "$ROOT/bench/compare-summaries" "$WORK/cap-reference/summary.json" "$WORK/cap-fast/summary.json" \
  >"$WORK/cap-cmp" && pass "narrow capillaries: defaults within tolerance of p = 7" \
  || fail "narrow capillaries, defaults against the reference: $(cat "$WORK/cap-cmp")"
cat "$WORK/cap-cmp"
"$PY" "$ROOT/bench/compare-summaries" "$WORK/cap-reference/summary.json" "$WORK/cap-linear/summary.json" \
  >"$WORK/cap-linear-cmp"; linear=$?
# compare-summaries exits 1 when a quantity misses its tolerance (2 when it cannot compare).
[ "$linear" -eq 1 ] && grep -q "pulsatility.*EXCEEDED" "$WORK/cap-linear-cmp" \
  && pass "narrow capillaries: without the degree-2 rule the pulsatility misses ($(grep pulsatility "$WORK/cap-linear-cmp" | xargs))" \
  || fail "narrow capillaries: linear profiles not told apart (exit $linear): $(cat "$WORK/cap-linear-cmp")"

# The compliance balance (on by default) against plain cycling (--no-balance-compliances), on
# a 101-vessel tree with 13 RCR outlets at the real pulse: the same periodic state (within
# 1e-3: plain cycling at a change of 1e-4 per cycle is still a few 1e-4 from its limit), in
# at most half the cycles (measured: 4 against 17 to 1e-4), and a mass balance (mean inflow
# against outflow) that closes, as a periodic state's must. Both from the steady start, whose
# slow drift the balance is for (from the periodic start, the default, plain cycling took 5
# cycles and the balance 3).
"$VGEN" --root-diameter 400um | "$VPRUNE" --budget 101 --mean-flow 0.15ml/min -o "$WORK/rcr.json" 2>/dev/null
"$HEMOSOLVE" "$WORK/rcr.json" --out "$WORK/balanced" --until-periodic 1e-4 --start steady --quiet \
  && "$HEMOSOLVE" "$WORK/rcr.json" --out "$WORK/plain" --until-periodic 1e-4 --max-cycles 40 --no-balance-compliances \
    --start steady --quiet \
  || fail "periodic runs"
"$PY" - "$WORK/balanced/summary.json" "$WORK/plain/summary.json" <<'PY' && pass "balanced compliances: the same periodic state in at most half the cycles" || fail "compliance balance"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
print(f"cycles to 1e-4: {a['cycles']} balanced ({a['compliance_balances']} moves), {b['cycles']} plain; "
      f"mass balance {a['mass_balance']:.2g} and {b['mass_balance']:.2g}")
assert a["status"] == b["status"] == "complete" and 2 * a["cycles"] <= b["cycles"]
assert a["balance_compliances"] and not b["balance_compliances"]
assert abs(a["mass_balance"]) < 1e-4, a["mass_balance"]
worst = max(abs(x[k] / y[k] - 1) for x, y in zip(a["vessels"], b["vessels"])
            for k in ("mean_pressure", "mean_flow", "pulsatility_index"))
print(f"largest relative difference of the periodic states: {worst:.2g}")
assert worst < 1e-3, worst
PY
finish
