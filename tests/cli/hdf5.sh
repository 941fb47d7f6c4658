# HDF5 networks and results through the real tools: vgen, vprune and vimport write .h5, every
# reader reads it from a file or a pipe, vexport converts both ways byte for byte; hemosolve
# --format h5 writes results.h5, which h5py and pandas read to the same numbers as the text
# outputs (and hemotree_io reads either form alike); damaged files are refused in one line.
source "$(dirname "$0")/lib.sh"
PY=/usr/bin/python3
PYTHON_DIR=$(cd "$(dirname "$0")/../../python" && pwd)
VPRUNE=$BUILD/pruner/vprune
VEXPORT=$BUILD/exchange/vexport
VIMPORT=$BUILD/exchange/vimport
HEMOSOLVE=$BUILD/solver/hemosolve
NETWORKS=${HEMOTREE_NETWORKS_DIR:-$(dirname "$0")/../../../shared/networks}

# ---- networks -------------------------------------------------------------------------------
"$VGEN" --seed 3 --root-diameter 150um --min-diameter 8.5um -o "$WORK/tree.h5" 2>/dev/null \
  && head -c 8 "$WORK/tree.h5" | od -An -c | grep -q 'H   D   F' && pass "vgen -o tree.h5 writes HDF5" \
  || fail "vgen -o tree.h5"
"$VGEN" --seed 3 --root-diameter 150um --min-diameter 8.5um --format h5 2>/dev/null \
  | "$VPRUNE" --seed 1 --budget 31 --mean-flow 0.01ml/min - -o "$WORK/piped.json" 2>/dev/null \
  && "$VPRUNE" --seed 1 --budget 31 --mean-flow 0.01ml/min "$WORK/tree.h5" -o "$WORK/net.json" 2>/dev/null \
  && cmp -s <(grep -v '"provenance"' "$WORK/piped.json") <(grep -v '"provenance"' "$WORK/net.json") \
  && pass "vgen --format h5 | vprune -: the network a file gives" || fail "HDF5 through a pipe"
"$VSTATS" "$WORK/tree.h5" >"$WORK/stats.h5.txt" && "$VGEN" --seed 3 --root-diameter 150um --min-diameter 8.5um \
  | "$VSTATS" - >"$WORK/stats.json.txt" && [ -s "$WORK/stats.h5.txt" ] \
  && pass "vstats reads HDF5" || fail "vstats tree.h5"

round_trip() {  # round_trip NAME FILE.json: JSON -> HDF5 -> JSON, the same bytes
  "$VEXPORT" h5 "$2" -o "$WORK/$1.h5" 2>/dev/null && "$VEXPORT" json "$WORK/$1.h5" -o "$WORK/$1.back.json" 2>/dev/null \
    && cmp -s "$2" "$WORK/$1.back.json" && pass "$1: JSON -> HDF5 -> JSON byte for byte" || fail "$1 round trip"
}
round_trip pruned "$WORK/net.json"
if [ -f "$NETWORKS/openbf/boileau2015/adan56/adan56.yaml" ]; then
  "$VIMPORT" openbf "$NETWORKS/openbf/boileau2015/adan56/adan56.yaml" -o "$WORK/adan56.json" 2>/dev/null
  round_trip adan56 "$WORK/adan56.json"
  "$VIMPORT" openbf "$NETWORKS/openbf/boileau2015/adan56/adan56.yaml" -o "$WORK/adan56_direct.h5" 2>/dev/null \
    && "$VEXPORT" json "$WORK/adan56_direct.h5" -o "$WORK/adan56_direct.json" 2>/dev/null \
    && cmp -s "$WORK/adan56.json" "$WORK/adan56_direct.json" \
    && pass "vimport -o adan56.h5: the network vimport writes as JSON" || fail "vimport -o .h5"
else
  echo "skip: ADAN56 round trip (no shared networks)"
fi
"$VEXPORT" h5 "$WORK/net.json" -o "$WORK/net.h5" 2>/dev/null
"$VEXPORT" h5 "$WORK/net.json" 2>/dev/null | "$VEXPORT" json - >"$WORK/net.stdout.json" 2>/dev/null \
  && cmp -s "$WORK/net.json" "$WORK/net.stdout.json" && pass "HDF5 on standard output and back" \
  || fail "vexport h5 to a pipe"

# ---- refusals ---------------------------------------------------------------------------------
head -c 3000 "$WORK/net.h5" >"$WORK/truncated.h5"
expect_error "a truncated HDF5 network" 2 "truncated.h5: not a complete HDF5 file (truncated or damaged)" \
  -- "$HEMOSOLVE" "$WORK/truncated.h5" --out "$WORK/never"
[ ! -e "$WORK/never" ] && pass "nothing written for it" || fail "a folder was written for a truncated network"
head -c 3000 "$WORK/net.h5" | expect_error "a truncated HDF5 network on standard input" 2 \
  "standard input: not a complete HDF5 file" -- "$VPRUNE" --budget 10 -
"$PY" - "$WORK/net.h5" "$WORK/bad.h5" <<'PY' || fail "h5py could not write the damaged copy"
import shutil, sys, h5py
shutil.copy(sys.argv[1], sys.argv[2])
with h5py.File(sys.argv[2], "r+") as f:
    length = f["vessels/length"][:]
    length[4] = 25.0
    f["vessels/length"][:] = length
PY
expect_error "a length out of range, written by h5py" 2 \
  "bad.h5: /vessels/length: row 4 (vessel 4): \"length\" must lie in [1e-7, 10] m (got 25)" \
  -- "$VEXPORT" json "$WORK/bad.h5"
# Files a hostile or careless program could write (found in review): each refused in one line.
"$PY" - "$WORK/net.h5" "$WORK" <<'PY' || fail "h5py could not write the hostile files"
import shutil, sys, h5py, numpy as np
src, work = sys.argv[1], sys.argv[2]
def copy(name, change):
    path = f"{work}/{name}.h5"
    shutil.copy(src, path)
    with h5py.File(path, "r+") as f:
        change(f)
def many_versions(f):
    del f.attrs["version"]
    f.attrs["version"] = np.arange(4096, dtype=np.int64)
def class_out_of_names(f):
    c = f["vessels/class"][:]
    c[2] = 9
    dt = f["vessels/class"].dtype
    del f["vessels/class"]
    f.create_dataset("vessels/class", data=c.astype(np.uint8), dtype=dt)
def outlet_type_seven(f):
    t = f["outlets/type"][:]
    t[0] = 7
    dt = f["outlets/type"].dtype
    del f["outlets/type"]
    f.create_dataset("outlets/type", data=t.astype(np.uint8), dtype=dt)
def extra_vessels(f):
    f.create_dataset("extra", data=np.array([b'{"vessels": [1, 2]}']))
def external_length(f):
    del f["vessels/length"]
    f["vessels/length"] = h5py.ExternalLink(src, "/vessels/length")
def huge_rows(f):
    del f["nodes/id"]
    f.create_dataset("nodes/id", shape=(2**40,), dtype=np.int64, chunks=(65536,))
def unsigned_ids(f):
    ids = f["vessels/id"][:]
    del f["vessels/id"]
    f.create_dataset("vessels/id", data=ids.astype(np.uint64))
for name, change in [("many_versions", many_versions), ("class_out_of_names", class_out_of_names),
                     ("outlet_type_seven", outlet_type_seven), ("extra_vessels", extra_vessels),
                     ("external_length", external_length), ("huge_rows", huge_rows),
                     ("unsigned_ids", unsigned_ids)]:
    copy(name, change)
PY
expect_error "a version attribute of 4096 values" 2 "many_versions.h5: /: the attribute \"version\" must be one integer" \
  -- "$VEXPORT" json "$WORK/many_versions.h5"
expect_error "a class value outside the names" 2 "class_out_of_names.h5: /vessels/class: row 2: a value that names none" \
  -- "$VEXPORT" json "$WORK/class_out_of_names.h5"
expect_error "an outlet type outside the names" 2 "outlet_type_seven.h5: /outlets/type: row 0" \
  -- "$VEXPORT" json "$WORK/outlet_type_seven.h5"
expect_error "/extra holding the format's own vessels" 2 "extra_vessels.h5: /extra: holds \"vessels\"" \
  -- "$VEXPORT" json "$WORK/extra_vessels.h5"
expect_error "a column linked to another file" 2 "external_length.h5: /vessels/length: a link to outside the file" \
  -- "$VEXPORT" json "$WORK/external_length.h5"
expect_error "2^40 rows declared, nothing stored" 2 "huge_rows.h5: /nodes/id: declares 1099511627776 rows" \
  -- "$VEXPORT" json "$WORK/huge_rows.h5"
expect_error "unsigned 64-bit ids" 2 "unsigned_ids.h5: /vessels/id: must hold signed integers" \
  -- "$VEXPORT" json "$WORK/unsigned_ids.h5"
expect_error "hemosolve --format xml" 2 "--format must be text or h5 (got 'xml')" \
  -- "$HEMOSOLVE" "$WORK/net.h5" --out "$WORK/never" --format xml

# ---- results ------------------------------------------------------------------------------------
"$HEMOSOLVE" "$WORK/net.json" --out "$WORK/text" --cycles 1 --probe 1 --probe 2:0.25 --quiet \
  && "$HEMOSOLVE" "$WORK/net.h5" --out "$WORK/h5" --cycles 1 --probe 1 --probe 2:0.25 --format h5 --quiet \
  && [ -f "$WORK/h5/results.h5" ] && [ ! -e "$WORK/h5/vessels.csv" ] && [ ! -e "$WORK/h5/probes.csv" ] \
  && pass "hemosolve --format h5 writes results.h5 and summary.json" || fail "hemosolve --format h5"
"$HEMOSOLVE" "$WORK/net.h5" --out "$WORK/linear" --linear --format h5 --quiet \
  && "$HEMOSOLVE" "$WORK/net.h5" --out "$WORK/steady" --steady --format h5 --quiet \
  && pass "--linear and --steady write results.h5" || fail "--linear/--steady --format h5"

# h5py and pandas alone, then hemotree_io: the same numbers as the text outputs.
PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$PYTHON_DIR" "$PY" - "$WORK" >"$WORK/checks" 2>&1 <<'PY'
import json, sys
from pathlib import Path
import h5py, numpy as np, pandas as pd
import hemotree_io as hio

work = Path(sys.argv[1])
failed = False


def check(what, ok, detail=""):
    global failed
    print(f"ok: {what}" if ok else f"FAIL: {what}{': ' + str(detail) if detail else ''}")
    failed |= not ok


text = pd.read_csv(work / "text" / "vessels.csv", float_precision="round_trip")
with h5py.File(work / "h5" / "results.h5", "r") as f:
    check("results.h5 says what it is", f.attrs["format"] in (b"hemotree-results", "hemotree-results"))
    columns = {}
    for name, dataset in f["vessels"].items():
        labels = h5py.check_enum_dtype(dataset.dtype)
        if labels:
            names = {code: label for label, code in labels.items()}
            columns[name] = [names[c] for c in dataset[:]]
        else:
            columns[name] = dataset[:]
    table = pd.DataFrame(columns)
    check("the vessel columns in vessels.csv's order", list(table.columns) == list(text.columns),
          (list(table.columns), list(text.columns)))
    for name in text.columns:
        a, b = text[name].to_numpy(), table[name].to_numpy()
        same = (np.array_equal(a.astype(float), b.astype(float), equal_nan=True) if a.dtype.kind in "fi"
                else list(a) == list(b))
        check(f"vessels: {name} value for value", same)
    summary = json.load(open(work / "text" / "summary.json"))
    facts = json.loads(f["summary"][0])
    for key in ("mass_balance", "inlet_mean_flow", "conservation_error", "statistics", "cycles"):
        check(f"summary: {key}", facts.get(key) == summary.get(key), (facts.get(key), summary.get(key)))
    flows = [b["flow"] for b in summary["boundaries"]]
    check("boundaries: every mean flow", np.array_equal(f["boundaries/flow"][:], np.array(flows)))
    probes = pd.read_csv(work / "text" / "probes.csv", float_precision="round_trip")
    check("probes: the columns' names", json.loads(f["probes/columns"][0]) == list(probes.columns))
    check("probes: every sample", np.array_equal(f["probes/values"][:], probes.to_numpy()))
small = json.load(open(work / "h5" / "summary.json"))
check("summary.json names results.h5", small.get("results", {}).get("file") == "results.h5"
      and "vessels" not in small and small.get("status") == "complete", small.get("results"))

# hemotree_io: either form, the same frames.
pd.testing.assert_frame_equal(hio.read_vessels(work / "h5").astype({"class": str, "model": str}),
                              hio.read_vessels(work / "text").astype({"class": str, "model": str}),
                              check_dtype=False)
check("hemotree_io.read_vessels: the same frame from results.h5 and vessels.csv", True)
pd.testing.assert_frame_equal(hio.read_probes(work / "h5"), hio.read_probes(work / "text"), check_dtype=False)
check("hemotree_io.read_probes: the same frame from either", True)
sa, sb = hio.read_summary(work / "h5"), hio.read_summary(work / "text")
check("hemotree_io.read_summary: the same boundaries from results.h5 and summary.json",
      sa["boundaries"] == sb["boundaries"] and len(sa["boundaries"]) > 0)
check("hemotree_io.read_summary: the same vessels from results.h5 and summary.json",
      sa["vessels"] == sb["vessels"] and len(sa["vessels"]) == len(text))
a, b = hio.read_network(work / "net.h5"), hio.read_network(work / "net.json")
pd.testing.assert_frame_equal(a.vessels, b.vessels, check_dtype=False)
pd.testing.assert_frame_equal(a.nodes, b.nodes, check_dtype=False)
check("hemotree_io.read_network: the same network from net.h5 and net.json",
      a.blood == b.blood and a.inlet == b.inlet and a.provenance == b.provenance)
linear = hio.read_vessels(work / "linear")
check("--linear's results.h5 read", len(linear) == len(text) and linear["mean_pressure"].notna().all())
sys.exit(1 if failed else 0)
PY
status=$?
cat "$WORK/checks"
[ "$status" -eq 0 ] || fail "the Python checks of results.h5 (above)"

finish
