# vstats --partition P: the split a distributed run would make, said in one line (a table) or
# as JSON; trees by whole subtrees, looped networks by METIS; too many ranks refused.
source "$(dirname "$0")/lib.sh"
VIMPORT=$BUILD/exchange/vimport
NETWORKS=${HEMOTREE_NETWORKS_DIR:-$(dirname "$0")/../../../shared/networks}

"$VGEN" --seed 2 --root-diameter 200um --min-diameter 8um -o "$WORK/tree.h5" 2>/dev/null || fail "vgen"
"$VSTATS" "$WORK/tree.h5" --partition 4 >"$WORK/table" \
  && grep -q "^partition (a cost of one a vessel): 4 ranks by subtrees: .* cut nodes, the top's" "$WORK/table" \
  && pass "vstats --partition 4: one line" || fail "vstats --partition 4: $(tail -2 "$WORK/table")"
"$VSTATS" "$WORK/tree.h5" --partition 3 --json | /usr/bin/python3 -c '
import json, sys
p = json.load(sys.stdin)["partition"]
assert p["ranks"] == 3 and p["method"] == "subtrees", p
assert len(p["vessels"]) == 3 and min(p["vessels"]) > 0, p
assert p["imbalance"] <= 1.125 and abs(max(p["cost"]) / (sum(p["cost"]) / 3) - p["imbalance"]) < 1e-12, p
' && pass "vstats --partition 3 --json" || fail "vstats --partition --json"
if [ -f "$NETWORKS/mesentery-rat/network.dat" ]; then
  "$VIMPORT" secomb "$NETWORKS/mesentery-rat/network.dat" -o "$WORK/mesentery.json" 2>/dev/null
  "$VSTATS" "$WORK/mesentery.json" --partition 4 | grep -q "4 ranks by METIS" \
    && pass "the mesentery (loops) by METIS" || fail "the mesentery's partition"
else
  echo "skip: the mesentery (no shared networks)"
fi
expect_error "more ranks than vessels" 2 "--partition 100000000: more ranks than the" \
  -- "$VSTATS" "$WORK/tree.h5" --partition 100000000
finish
