# scripts/plot-results on synthetic hemosolve summaries: every figure as PNG and SVG, the
# fitted flow exponent of a known power law, --compare, an older summary without some fields,
# and its refusals (one line on stderr, exit 2). Skipped (77) without python3-matplotlib.
source "$(dirname "$0")/lib.sh"
PY=/usr/bin/python3
PLOT=$(cd "$(dirname "$0")/../../scripts" && pwd)/plot-results

if ! "$PY" -c "import matplotlib, numpy" 2>/dev/null; then
  echo "skip: $PY cannot import matplotlib and numpy"
  exit 77
fi

FIGURES=(flow-vs-diameter pressure-by-diameter pulsatility-by-diameter wss-vs-diameter
         pwv-vs-diameter tree-generations)

# synthetic DIR RHEOLOGY WSS_SCALE [DROP_FIELD...]: DIR/summary.json with 60 vessels whose
# flow follows Q = 1e-3 D^2.7 exactly (SI), the other fields smooth in D plus some noise, a
# few null wave speeds; DROP_FIELD is left out of every vessel (an older summary).
synthetic() {
  "$PY" - "$@" <<'PY'
import json, math, os, random, sys
folder, rheology, wss_scale, drop = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4:]
rng = random.Random(7)
vessels = []
for i in range(60):
    d = 5e-6 * (1000e-6 / 5e-6) ** (i / 59) * (1 + 0.05 * rng.uniform(-1, 1))
    cls = ("artery" if d >= 500e-6 else "small_artery" if d >= 100e-6
           else "arteriole" if d >= 10e-6 else "capillary")
    p = 133.322 * (30 + 60 * math.log10(d / 5e-6) / 2.3 + rng.uniform(-3, 3))
    pi = 0.05 + 0.6 * math.log10(d / 5e-6) / 2.3 + rng.uniform(-0.02, 0.02)
    c = 0.5 * (d / 1e-6) ** 0.3
    v = {"id": i + 1, "diameter": d, "length": 20 * d, "class": cls,
         "mean_flow": 1e-3 * d ** 2.7, "mean_pressure": p,
         "systolic_pressure": p * (1 + pi / 2), "diastolic_pressure": p * (1 - pi / 2),
         "pulsatility_index": pi, "mean_wss": wss_scale * (2 + 3e4 * d) * rng.uniform(0.8, 1.2),
         "pwv_pressure": None if i % 13 == 5 else c * rng.uniform(0.9, 1.1),
         "pwv_velocity": float("nan") if i % 17 == 3 else c * rng.uniform(0.9, 1.1),
         "womersley": 1e3 * d, "pwv_elastic": 0.9 * c, "pwv_theory": c, "reynolds": 1e4 * d}
    for key in drop:
        del v[key]
    vessels.append(v)
os.makedirs(folder, exist_ok=True)
summary = {"tool": "hemosolve", "version": "test", "rheology": rheology, "degree": 2,
           "cycles": 1, "period": 1.0, "time_step": 1e-4, "inlet_mean_flow": vessels[0]["mean_flow"],
           "outlets_mean_flow": vessels[0]["mean_flow"],
           "units": {"flow": "m^3/s", "pressure": "Pa", "length": "m"}, "vessels": vessels}
with open(os.path.join(folder, "summary.json"), "w") as f:
    json.dump(summary, f, allow_nan=True)  # NaN as hemosolve would never write it: tolerated
PY
}

# figures_exist "description" DIR NAME...: every NAME.png and NAME.svg in DIR/figures, non-empty.
figures_exist() {
  local what=$1 dir=$2 name ext missing=""
  shift 2
  for name in "$@"; do
    for ext in png svg; do
      [ -s "$dir/figures/$name.$ext" ] || missing="$missing $name.$ext"
    done
  done
  [ -z "$missing" ] && pass "$what" || fail "$what: missing or empty:$missing"
}

# stderr_is "description" EXPECTED: stderr of the last run (Matplotlib's own first-run
# font-cache lines aside) is exactly EXPECTED.
stderr_is() {
  local got
  got=$(grep -v '^Matplotlib' "$WORK/err")
  [ "$got" = "$2" ] && pass "$1" || fail "$1: stderr was: $(cat "$WORK/err")"
}

# ---- one run with the network's generation statistics: all six figures ---------------------

synthetic "$WORK/pries" pries 1
"$VGEN" --root-diameter 150um --min-diameter 8.5um | "$VSTATS" --json >"$WORK/pries/network-stats.json" \
  || fail "vgen | vstats --json for network-stats.json"
"$PY" "$PLOT" "$WORK/pries" >"$WORK/out" 2>"$WORK/err" \
  && pass "plot-results DIR: exit 0" || fail "plot-results DIR: exit $?: $(cat "$WORK/err")"
figures_exist "six figures as PNG and SVG" "$WORK/pries" "${FIGURES[@]}"
stderr_is "quiet but for the summary line" "plot-results: wrote 6 figures to $WORK/pries/figures"
[ ! -s "$WORK/out" ] && pass "nothing on stdout" || fail "stdout: $(cat "$WORK/out")"
grep -q "k = 2.70, r^2 = 1.00" "$WORK/pries/figures/flow-vs-diameter.svg" \
  && pass "fitted exponent 2.70 in the SVG legend" \
  || fail "no 'k = 2.70, r^2 = 1.00' in flow-vs-diameter.svg: $(grep -o 'k = [^<]*' "$WORK/pries/figures/flow-vs-diameter.svg")"
for name in pressure pulsatility; do
  svg=$WORK/pries/figures/$name-by-diameter.svg
  total=$(grep -o '>n=[0-9]*' "$svg" | awk -F= '{ s += $2 } END { print s }')
  grep -q '>&lt;10' "$svg" && grep -q '>&gt;=500' "$svg" && [ "$total" = 60 ] \
    && pass "$name box plots: bins labelled, counts add up to 60 vessels" \
    || fail "$name-by-diameter.svg: bin labels or counts (total ${total:-none})"
done
[ ! -e "$(dirname "$PLOT")/__pycache__" ] \
  && pass "no __pycache__ left in scripts/" || fail "__pycache__ left in scripts/"

# ---- --compare: the second run's WSS overlaid, labels from the rheology or the options -----

synthetic "$WORK/newtonian" newtonian 0.6
"$PY" "$PLOT" "$WORK/pries" --compare "$WORK/newtonian" >"$WORK/out" 2>"$WORK/err" \
  && pass "--compare: exit 0" || fail "--compare: exit $?: $(cat "$WORK/err")"
stderr_is "--compare: quiet" "plot-results: wrote 6 figures to $WORK/pries/figures"
svg=$WORK/pries/figures/wss-vs-diameter.svg
grep -q "pries (60 vessels)" "$svg" && grep -q "newtonian (60 vessels)" "$svg" \
  && grep -q "newtonian, binned median" "$svg" \
  && pass "--compare: both runs in the WSS legend, labelled by rheology" \
  || fail "--compare: legend of wss-vs-diameter.svg: $(grep -o '[a-z]* (60 vessels)' "$svg")"
"$PY" "$PLOT" "$WORK/pries" --compare "$WORK/newtonian" --label "Pries 2005" \
  --compare-label "plasma only" 2>"$WORK/err" \
  && grep -q "Pries 2005 (60 vessels)" "$svg" && grep -q "plasma only (60 vessels)" "$svg" \
  && pass "--label and --compare-label" || fail "--label/--compare-label: $(cat "$WORK/err")"

# ---- an older summary: no wave speeds and no WSS, no network-stats.json --------------------

synthetic "$WORK/old" pries 1 mean_wss pwv_pressure pwv_velocity pwv_elastic pwv_theory
"$PY" "$PLOT" "$WORK/old" >"$WORK/out" 2>"$WORK/err" \
  && pass "older summary: exit 0" || fail "older summary: exit $?: $(cat "$WORK/err")"
figures_exist "older summary: the figures it has data for" "$WORK/old" \
  flow-vs-diameter pressure-by-diameter pulsatility-by-diameter
[ ! -e "$WORK/old/figures/wss-vs-diameter.png" ] && [ ! -e "$WORK/old/figures/pwv-vs-diameter.png" ] \
  && [ ! -e "$WORK/old/figures/tree-generations.png" ] \
  && pass "older summary: figures without data skipped" || fail "older summary: drew figures without data"
notes=$(grep -c "^plot-results: note: .*skipping" "$WORK/err")
[ "$notes" -eq 3 ] && grep -q "^plot-results: wrote 3 figures to" "$WORK/err" \
  && pass "older summary: one note per skipped figure" || fail "older summary: stderr: $(cat "$WORK/err")"

# ---- a real run: vgen | vprune | hemosolve, Pries against Newtonian -------------------------

"$BUILD/generator/vgen" --root-diameter 150um --min-diameter 8.5um \
  | "$BUILD/pruner/vprune" --budget 31 --mean-flow 0.01ml/min -o "$WORK/real-net.json" 2>/dev/null
for rheology in pries newtonian; do
  "$BUILD/solver/hemosolve" "$WORK/real-net.json" --out "$WORK/real-$rheology" --cycles 1 --degree 1 \
    --rheology "$rheology" --quiet
done
"$BUILD/stats/vstats" --json "$WORK/real-net.json" >"$WORK/real-pries/network-stats.json"
if "$PY" "$PLOT" "$WORK/real-pries" --compare "$WORK/real-newtonian" 2>"$WORK/real.err"; then
  missing=""
  for f in "${FIGURES[@]}"; do
    for ext in png svg; do [ -s "$WORK/real-pries/figures/$f.$ext" ] || missing+=" $f.$ext"; done
  done
  [ -z "$missing" ] && pass "a real hemosolve run (31 vessels, Pries vs Newtonian): every figure" \
    || fail "real run: missing$missing"
else
  fail "real run: $(cat "$WORK/real.err")"
fi
# A run's folder is read from vessels.csv (columns: what a full tree needs); without it, from
# summary.json's vessel objects. Both hold the same doubles: the same figures, byte for byte.
mkdir -p "$WORK/real-json"
cp "$WORK/real-pries/summary.json" "$WORK/real-json/"
if "$PY" "$PLOT" "$WORK/real-pries" 2>/dev/null && "$PY" "$PLOT" "$WORK/real-json" 2>/dev/null; then
  differ=""
  for f in flow-vs-diameter pressure-by-diameter pulsatility-by-diameter wss-vs-diameter pwv-vs-diameter; do
    # (but for the time of writing in the SVG's metadata)
    cmp -s <(grep -v "<dc:date>" "$WORK/real-pries/figures/$f.svg") <(grep -v "<dc:date>" "$WORK/real-json/figures/$f.svg") \
      || differ+=" $f"
  done
  [ -z "$differ" ] && pass "vessels.csv and summary.json give the same figures" \
    || fail "figures from vessels.csv and from summary.json differ:$differ"
else
  fail "plot-results from vessels.csv or from summary.json alone failed"
fi

# ---- refusals ------------------------------------------------------------------------------

mkdir -p "$WORK/empty" "$WORK/bad" "$WORK/novessels"
echo '{"tool": "hemosolve", "vessels": [' >"$WORK/bad/summary.json"
echo '{"tool": "hemosolve", "vessels": []}' >"$WORK/novessels/summary.json"
expect_error "missing summary.json" 2 "plot-results: $WORK/empty/summary.json: no such file" -- \
  "$PY" "$PLOT" "$WORK/empty"
[ ! -e "$WORK/empty/figures" ] && pass "missing summary.json: no figures folder made" \
  || fail "missing summary.json: made $WORK/empty/figures"
expect_error "missing folder" 2 "no such file" -- "$PY" "$PLOT" "$WORK/nowhere"
expect_error "invalid JSON" 2 "invalid JSON" -- "$PY" "$PLOT" "$WORK/bad"
expect_error "no vessels" 2 "no vessels" -- "$PY" "$PLOT" "$WORK/novessels"
expect_error "--compare with a missing summary" 2 "$WORK/empty/summary.json" -- \
  "$PY" "$PLOT" "$WORK/pries" --compare "$WORK/empty"
expect_error "no DIR" 2 "plot-results: " -- "$PY" "$PLOT"
expect_error "unknown option" 2 "--bogus" -- "$PY" "$PLOT" "$WORK/pries" --bogus
echo '{"generations": ' >"$WORK/old/network-stats.json"
expect_error "invalid network-stats.json" 2 "network-stats.json: invalid JSON" -- "$PY" "$PLOT" "$WORK/old"
finish
