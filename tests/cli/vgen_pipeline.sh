# vgen | vstats --json through a real pipe, determinism by seed, and the exports.
source "$(dirname "$0")/lib.sh"

args=(--root-diameter 150um --min-diameter 7um)

"$VGEN" "${args[@]}" --seed 3 | "$VSTATS" --json >"$WORK/stats.json"
status=("${PIPESTATUS[@]}")
[ "${status[0]}" -eq 0 ] && [ "${status[1]}" -eq 0 ] || fail "pipe exit status ${status[*]}"
/usr/bin/python3 - "$WORK/stats.json" <<'PY' && pass "vgen | vstats --json" || fail "vstats --json content"
import json, sys
s = json.load(open(sys.argv[1]))
for key in ("vessels", "bifurcations", "terminals", "total_length", "total_volume",
            "classes", "generations"):
    assert key in s, key
assert s["vessels"] == 2 * s["bifurcations"] + 1          # a full binary tree
assert s["terminals"] == s["bifurcations"] + 1
assert sum(s["classes"].values()) == s["vessels"]
assert sum(g["vessels"] for g in s["generations"]) == s["vessels"]
assert s["generations"][0]["vessels"] == 1
assert abs(s["generations"][0]["diameter"]["median"] - 150e-6) < 1e-12
PY

"$VGEN" "${args[@]}" --seed 3 -o "$WORK/a.json"
"$VGEN" "${args[@]}" --seed 3 -o "$WORK/b.json"
"$VGEN" "${args[@]}" --seed 4 -o "$WORK/c.json"
cmp -s "$WORK/a.json" "$WORK/b.json" && pass "same seed, same bytes" || fail "same seed differs"
cmp -s "$WORK/a.json" "$WORK/c.json" && fail "other seed, same bytes" || pass "other seed, other tree"
OMP_NUM_THREADS=1 "$VGEN" "${args[@]}" --seed 3 -o "$WORK/d.json"
cmp -s "$WORK/a.json" "$WORK/d.json" && pass "one thread, same bytes" || fail "thread count changes output"

"$VSTATS" "$WORK/a.json" | grep -q "^vessels" && pass "vstats table" || fail "vstats table"

for format in vtk graphml dot csv; do
  "$VGEN" "${args[@]}" --format "$format" -o "$WORK/tree.$format" && [ -s "$WORK/tree.$format" ] \
    && pass "--format $format" || fail "--format $format"
done
head -c 5 "$WORK/tree.vtk" | grep -q "<?xml" || fail "vtk is not XML"

"$VGEN" --print-rules >"$WORK/rules.json" && "$VGEN" "${args[@]}" --rules "$WORK/rules.json" \
  --seed 3 -o "$WORK/e.json" && cmp -s "$WORK/a.json" "$WORK/e.json" \
  && pass "--print-rules feeds --rules unchanged" || fail "printed rules change the tree"
finish
