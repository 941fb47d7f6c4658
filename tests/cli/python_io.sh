# python/hemotree_io.py, the one reader of hemotree's files that the scripts share: a small
# real run (vgen | vprune | hemosolve with probes, a tracer and red cells), read back through
# the module and checked against the same files read with the json and csv modules alone
# (shapes, names, every value of vessels.csv and probes.csv, the network's vessels); then
# what it refuses (a short row, a word for a number) and the one line it says without pandas.
source "$(dirname "$0")/lib.sh"
PY=/usr/bin/python3
PYTHON_DIR=$(cd "$(dirname "$0")/../../python" && pwd)

"$VGEN" --seed 1 --root-diameter 150um --min-diameter 8.5um \
  | "$BUILD/pruner/vprune" --seed 1 --budget 31 --mean-flow 0.01ml/min --profile-report "$WORK/profile.json" \
    -o "$WORK/net.json" 2>/dev/null || fail "vgen | vprune"
"$VSTATS" --json "$WORK/net.json" >"$WORK/stats.json" || fail "vstats --json"
"$BUILD/solver/hemosolve" "$WORK/net.json" --out "$WORK/run" --cycles 1 --degree 1 --probe 1 --probe 2:0.25 \
  --tracer name=dye,start=0.1,duration=0.2 --red-cells transport --quiet || fail "hemosolve"

# Each check prints "ok: ..." or "FAIL: ...", one line.
PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$PYTHON_DIR" "$PY" - "$WORK" >"$WORK/checks" 2>&1 <<'PY'
import csv, json, math, sys
from pathlib import Path
import hemotree_io as hio

work = Path(sys.argv[1])
run = work / "run"
failed = False


def check(what, ok, detail=""):
    global failed
    print(f"ok: {what}" if ok else f"FAIL: {what}{': ' + str(detail) if detail else ''}")
    failed |= not ok


def same(a, b):
    """Equal numbers, NaN equal to NaN (a float and its text read with float())."""
    return all((x == y) or (math.isnan(x) and math.isnan(y)) for x, y in zip(a, b)) and len(a) == len(b)


def csv_rows(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


# ---- the network ----
doc = json.load(open(work / "net.json"))
net = hio.read_network(work / "net.json")
check("read_network: one row per vessel", len(net.vessels) == len(doc["vessels"]) > 1,
      f"{len(net.vessels)} rows, {len(doc['vessels'])} vessels")
check("read_network: one row per node", len(net.nodes) == len(doc["nodes"]), len(net.nodes))
check("read_network: the vessels' columns",
      {"id", "from", "to", "length", "diameter", "generation", "class"} <= set(net.vessels.columns),
      list(net.vessels.columns))
check("read_network: ids and diameters as in the file",
      list(net.vessels["id"]) == [v["id"] for v in doc["vessels"]]
      and list(net.vessels["diameter"]) == [v["diameter"] for v in doc["vessels"]])
outlets = [v.get("outlet") for v in doc["vessels"]]
check("read_network: outlets as dicts where the file has them",
      [o for o in net.vessels["outlet"] if isinstance(o, dict)] == [o for o in outlets if o])
check("read_network: blood, inlet, provenance as dicts, the version",
      net.blood == doc.get("blood", {}) and net.inlet == doc["inlet"]
      and net.provenance == doc["provenance"] and net.version == doc["version"])

# ---- summary.json ----
summary = hio.read_summary(run)
check("read_summary: as json.load reads it", summary == json.load(open(run / "summary.json")))
check("read_summary: a vessel per network vessel", len(summary["vessels"]) == len(net.vessels))
facts = hio.read_summary(run / "summary.json", vessels=False)
check("read_summary(vessels=False): the facts before the vessels, no vessels",
      "vessels" not in facts and len(facts) > 10 and all(summary[k] == v for k, v in facts.items()),
      sorted(facts))

# ---- vessels.csv ----
header, rows = csv_rows(run / "vessels.csv")
vessels = hio.read_vessels(run)
check("read_vessels: the header's names, a row per vessel",
      list(vessels.columns) == header and vessels.shape == (len(summary["vessels"]), len(header)),
      f"{vessels.shape}, {list(vessels.columns)}")
check("read_vessels: the red cells' and the tracer's columns",
      {"discharge_hematocrit", "dye_mean_transit_time", "class", "model"} <= set(header), header)
bad = []
for k, name in enumerate(header):
    text = [r[k] for r in rows]
    if name in hio.TEXT_COLUMNS:
        if list(vessels[name].astype(str)) != text:
            bad.append(name)
    elif not same(list(vessels[name].to_numpy(dtype=float)), [float(x) if x else math.nan for x in text]):
        bad.append(name)
check("read_vessels: every value as float() reads the CSV's text (NaN where empty)", not bad, bad)
check("read_vessels: ids whole numbers, as summary.json's",
      vessels["id"].dtype.kind == "i" and list(vessels["id"]) == [v["id"] for v in summary["vessels"]])
check("read_vessels: mean pressures the doubles of summary.json",
      list(vessels["mean_pressure"]) == [v["mean_pressure"] for v in summary["vessels"]])
check("read_vessels: ids those of the network", sorted(vessels["id"]) == sorted(net.vessels["id"]))
some = hio.read_vessels(run / "vessels.csv", columns=["id", "class"])
check("read_vessels(columns=...): those alone", some.shape == (len(rows), 2) and list(some.columns) == ["id", "class"])

# ---- probes.csv ----
header, rows = csv_rows(run / "probes.csv")
probes = hio.read_probes(run)
check("read_probes: the header's names, a row per sample",
      list(probes.columns) == header and probes.shape == (len(rows), len(header)) and len(rows) > 10,
      probes.shape)
check("read_probes: time first, then per probe p, Q, A, u, H_D and the tracer",
      header[0] == "t [s]" and len(header) == 1 + 2 * 6
      and sum(h.startswith("c_dye vessel ") for h in header) == 2, header)
check("read_probes: every value as float() reads it",
      all(same(list(probes.iloc[:, k]), [float(r[k]) for r in rows]) for k in range(len(header))))
j = header.index("p vessel 2 x 0.25 [Pa]")
check("probe_column: p at vessel 2, x 0.25",
      same(list(hio.probe_column(probes, "p", 2, 0.25)), [float(r[j]) for r in rows]))
check("parse_probe_name", hio.parse_probe_name("Q vessel 2 x 0.25 [m^3/s]") == ("Q", 2, 0.25, "[m^3/s]")
      and hio.parse_probe_name("t [s]") is None)
try:
    hio.probe_column(probes, "p", 3, 0.5)
    check("probe_column: refuses a probe that is not there", False)
except hio.FormatError as e:
    check("probe_column: refuses a probe that is not there, naming those there",
          "probes there: 1:0.5, 2:0.25" in str(e) and "\n" not in str(e), e)

# ---- vstats --json, vprune --profile-report ----
stats = hio.read_network_stats(work / "stats.json")
check("read_network_stats", stats["vessels"] == len(net.vessels))
report = hio.read_profile_report(work / "profile.json")
check("read_profile_report", report["total"]["achieved"] == len(net.vessels), report["total"])

# ---- refusals: one line naming the file ----
lines = open(run / "vessels.csv").read().splitlines()
word = lines[2].split(",")
word[lines[0].split(",").index("diameter")] = "abc"
cases = {"short-row.csv": lines[:2] + [lines[2].rsplit(",", 1)[0]] + lines[3:],
         "long-row.csv": lines[:2] + [lines[2] + ",7"] + lines[3:],
         "word.csv": lines[:2] + [",".join(word)] + lines[3:]}
for name, text in cases.items():
    (work / name).write_text("\n".join(text) + "\n")
    try:
        hio.read_vessels(work / name)
        check(f"read_vessels refuses {name}", False, "read without complaint")
    except hio.FormatError as e:
        check(f"read_vessels refuses {name} in one line naming the file",
              str(e).startswith(str(work / name)) and "\n" not in str(e), e)

# ---- without pandas: one line saying what to install; the JSON readers still work ----
sys.modules["pandas"] = None  # import pandas now fails
try:
    hio.read_vessels(run)
    check("without pandas: refused", False)
except hio.MissingDependency as e:
    check("without pandas: one line saying what to install", "python3-pandas" in str(e) and "\n" not in str(e), e)
check("without pandas: read_summary still reads", hio.read_summary(run, vessels=False) == facts)
sys.exit(1 if failed else 0)
PY
status=$?
cat "$WORK/checks"
[ "$status" -eq 0 ] && pass "hemotree_io reads what the tools write ($(grep -c '^ok' "$WORK/checks") checks)" \
  || fail "hemotree_io: exit $status, $(grep -c '^FAIL' "$WORK/checks") checks failed"
finish
