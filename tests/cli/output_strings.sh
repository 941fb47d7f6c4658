# Every string a user gives hemosolve passes through its outputs and they still parse
# (issue 21, item 18): the network file's name (summary.json "network"), the --out folder's
# name, the network's provenance and other members the vnet format carries through, tracer
# names and probe specs. For each hostile string (newline, tab, quotes, backslash, control
# bytes, a byte that is not UTF-8, UTF-8 multibyte, comma, <&>, a format directive, a long
# name, a leading '-') hemosolve runs a tiny network named with it, in a folder named with
# it, with --vtk --frames 2 --probe 1 and a tracer, and every output must parse: summary.json
# as strict JSON (UTF-8, no raw control characters) holding the file name back (bytes JSON
# cannot hold replaced, one character each), vessels.csv and probes.csv as CSV with one
# column per header field, results.vtp, frames/frames.pvd and each frame as XML.
# A tracer name that is not a word (letters, digits, '_', '-', '.') is refused with exit 2 and
# one line; an accepted one appears verbatim in every output. A probe spec is refused the
# same way or gives its column.
source "$(dirname "$0")/lib.sh"
HEMOSOLVE=$(cd "$BUILD" && pwd)/solver/hemosolve
PY=/usr/bin/python3

# The network: three vessels with coordinates (for --vtk and --frames), flow in at node 0,
# pressures at nodes 2 and 3; the string goes into its provenance and an extra member.
cat >"$WORK/network.py" <<'PY'
import json, os, sys
s = os.fsencode(sys.argv[1]).decode("utf-8", "replace")  # JSON text is UTF-8: U+FFFD for a byte that is not
net = {"format": "vnet", "version": 2,
       "provenance": {"tool": "output_strings.sh", "label": s, "parameters": {s: [s]}},
       "user_note": s,
       "nodes": [{"id": 0, "x": 0, "y": 0, "z": 0}, {"id": 1, "x": 0.01, "y": 0.001, "z": 0},
                 {"id": 2, "x": 0.02, "y": 0.002, "z": 0}, {"id": 3, "x": 0.03, "y": 0, "z": 0}],
       "vessels": [{"id": 0, "from": 0, "to": 1, "length": 0.01, "diameter": 0.001, "wall_thickness": 1e-4, "youngs_modulus": 4e5},
                   {"id": 1, "from": 1, "to": 2, "length": 0.01, "diameter": 8e-4, "wall_thickness": 8e-5, "youngs_modulus": 4e5},
                   {"id": 2, "from": 1, "to": 3, "length": 0.01, "diameter": 7e-4, "wall_thickness": 7e-5, "youngs_modulus": 4e5}],
       "boundaries": [{"node": 0, "type": "flow", "flow": 1e-7, "hematocrit": 0.45},
                      {"node": 2, "type": "pressure", "pressure": 1000},
                      {"node": 3, "type": "pressure", "pressure": 1000}]}
with open(sys.argv[2], "w", encoding="ascii") as f:
    json.dump(net, f)
PY

# check.py OUT NETWORK TRACER [PROBES]: every output of the run in OUT parses; summary.json's
# "network" is NETWORK (its bytes that are not UTF-8 replaced, one character each), and the
# tracer's name appears verbatim in summary.json, vessels.csv, probes.csv, results.vtp.
cat >"$WORK/check.py" <<'PY'
import csv, io, json, math, os, re, sys
import xml.etree.ElementTree as ET
out, network, tracer = sys.argv[1], os.fsencode(sys.argv[2]), sys.argv[3]
probes = int(sys.argv[4]) if len(sys.argv) > 4 else 1
problems = []
def check(ok, what):
    if not ok: problems.append(what)

def read(name):
    with open(os.path.join(out, name), "rb") as f:
        return f.read()

def strict_json(name):
    raw = read(name)
    text = raw.decode("utf-8")  # UnicodeDecodeError: not UTF-8
    return json.loads(text)     # strict: a raw control character in a string is an error

# summary.json
try:
    s = json.loads(read("summary.json").decode("utf-8"))
    got = s.get("network")
    # What JSON can hold of the name: its UTF-8 runs as they are, each other byte as one
    # replacement ('?', U+FFFD) or an escape spelt out ("\xff").
    pattern = ""
    rest = network
    while rest:
        try:
            pattern += re.escape(rest.decode("utf-8")); rest = b""
        except UnicodeDecodeError as e:
            pattern += re.escape(rest[:e.start].decode("utf-8"))
            pattern += r"(?:\?|\ufffd|\\x%02x|\\x%02X)" % (rest[e.start], rest[e.start])
            rest = rest[e.start + 1:]
    check(isinstance(got, str) and re.fullmatch(pattern, got, re.S) is not None,
          "summary.json: network is %r, wanted %r" % (got, network))
    names = [t.get("name") for t in s.get("tracers", [])]
    check(names == [tracer], "summary.json: tracers named %r, wanted [%r]" % (names, tracer))
    check(s.get("status") == "complete", "summary.json: status %r" % s.get("status"))
except Exception as e:
    problems.append("summary.json does not parse: %s: %s" % (type(e).__name__, e))

def table(name):
    text = read(name).decode("utf-8")
    rows = list(csv.reader(io.StringIO(text, newline="")))
    check(len(rows) >= 2, name + ": no data rows")
    for k, row in enumerate(rows[1:], 2):
        check(len(row) == len(rows[0]), "%s: row %d has %d fields, the header %d" % (name, k, len(row), len(rows[0])))
    return rows

try:
    v = table("vessels.csv")
    check([r[0] for r in v[1:]] == ["0", "1", "2"], "vessels.csv: ids %r" % [r[0] for r in v[1:]])
    for col in ("arrival_time", "peak_time", "peak", "mean_transit_time"):
        check(tracer + "_" + col in v[0], "vessels.csv: no column %s_%s in %r" % (tracer, col, v[0]))
except Exception as e:
    problems.append("vessels.csv does not parse: %s: %s" % (type(e).__name__, e))
try:
    p = table("probes.csv")
    check(len(p[0]) == 1 + 5 * probes, "probes.csv: %d columns for %d probes and a tracer" % (len(p[0]), probes))
    check(sum(h.startswith("c_" + tracer + " ") for h in p[0]) == probes,
          "probes.csv: no column c_%s in %r" % (tracer, p[0]))
    for row in p[1:]:
        for field in row:
            check(math.isfinite(float(field)), "probes.csv: %r is not a finite number" % field)
except Exception as e:
    problems.append("probes.csv does not parse: %s: %s" % (type(e).__name__, e))

def vtk(name):
    root = ET.fromstring(read(name))
    return [a.get("Name") for a in root.iter("DataArray")]
try:
    arrays = vtk("results.vtp")
    check(tracer + "_arrival_time" in arrays, "results.vtp: no array %s_arrival_time" % tracer)
except Exception as e:
    problems.append("results.vtp does not parse: %s: %s" % (type(e).__name__, e))
try:
    pvd = ET.fromstring(read("frames/frames.pvd"))
    files = [d.get("file") for d in pvd.iter("DataSet")]
    check(len(files) == 2, "frames.pvd: %d frames, wanted 2" % len(files))
    for f in files:
        check("Q" in vtk(os.path.join("frames", f)), "frames/%s: no array Q" % f)
except Exception as e:
    problems.append("the frames do not parse: %s: %s" % (type(e).__name__, e))
for p in problems:
    print(p)
sys.exit(1 if problems else 0)
PY

shown() { printf %q "$1"; }

# --- the hostile strings: a network file, its folder and --out named with each --------------
long=$(printf 'x%.0s' {1..200})
strings=($'new\nline' $'tab\there' 'double"quote' "single'quote" 'back\slash' $'ctl\x01one' $'ctl\x1funit'
         $'del\x7fete' $'not\xffutf8' 'utf8 äé€𝄞' 'comma,here' 'xml<&>here' 'format %s %n %%' "$long" '-o' '--help')
i=0
for s in "${strings[@]}"; do
  i=$((i + 1))
  dir=$WORK/case$i/$s
  if ! mkdir -p "$dir" 2>/dev/null; then
    echo "skip: the filesystem refuses a folder named $(shown "$s")"
    continue
  fi
  "$PY" "$WORK/network.py" "$s" "$dir/$s.json" || { fail "writing the network $(shown "$s").json"; continue; }
  # Relative names, as a user types them: what summary.json's "network" holds; "--" and
  # "--out=" so that a leading '-' is a name, not an option.
  (cd "$dir" && "$HEMOSOLVE" --out="$s" --vtk --frames 2 --probe 1 --tracer name=dye --quiet -- "$s.json") \
    >"$WORK/out" 2>"$WORK/err"
  status=$?
  if [ $status -ne 0 ]; then
    fail "network and --out named $(shown "$s"): exit $status: $(head -c 300 "$WORK/err")"
  elif problems=$("$PY" "$WORK/check.py" "$dir/$s" "$s.json" dye 2>&1); then
    pass "network, folder and --out named $(shown "$s"): every output parses, summary.json names the file"
  else
    fail "network and --out named $(shown "$s"): $problems"
  fi
done

# --- tracer names ------------------------------------------------------------------------------
"$PY" "$WORK/network.py" plain "$WORK/net.json"
max64=$(printf 'y%.0s' {1..64})
for name in dye 'a.b-c_9' '-o' '--help' '.' '..' "$max64" "${strings[@]}" "${max64}z" 'a b' 'a=b' 'a,b' \
            'name=x' 'a/b' ''; do
  out=$WORK/tracer
  rm -rf "$out"
  "$HEMOSOLVE" "$WORK/net.json" --out "$out" --vtk --frames 2 --probe 1 --tracer "name=$name" --quiet \
    >"$WORK/out" 2>"$WORK/err"
  status=$?
  lines=$(wc -l <"$WORK/err")
  if [[ $name =~ ^[A-Za-z0-9_.-]+$ ]] && [ ${#name} -le 64 ]; then
    if [ $status -ne 0 ]; then
      fail "tracer $(shown "$name") (a word): exit $status: $(head -c 300 "$WORK/err")"
    elif problems=$("$PY" "$WORK/check.py" "$out" "$WORK/net.json" "$name" 2>&1); then
      pass "tracer $(shown "$name"): accepted, verbatim in summary.json, vessels.csv, probes.csv, results.vtp"
    else
      fail "tracer $(shown "$name"): $problems"
    fi
  elif [ $status -eq 2 ] && [ "$lines" -eq 1 ] && [ ! -e "$out" ]; then
    pass "tracer $(shown "$name"): refused, exit 2, one line"
  else
    fail "tracer $(shown "$name") (not a word of at most 64): exit $status, $lines lines: $(head -c 300 "$WORK/err")"
  fi
done

# --- probe specs -------------------------------------------------------------------------------
for spec in 1 1:0 1:1 2:0.25 1:5e-1 01 '+1' ' 1' '1 ' $'1\n' $'\n1:5' $'\t1:0.5' '1,2' '1:0.5,2' '1:nan' '1:inf' '1:-0' '1:1e-400' \
            '1:0x1p-1' '1:' ':0.5' '99' '-1' '1:2' '1:0.5:1' 'vessel' $'1\xff' '9223372036854775808' "$long"; do
  out=$WORK/probe
  rm -rf "$out"
  "$HEMOSOLVE" "$WORK/net.json" --out "$out" --vtk --frames 2 --probe "$spec" --tracer name=dye --quiet \
    >"$WORK/out" 2>"$WORK/err"
  status=$?
  lines=$(wc -l <"$WORK/err")
  if [ $status -eq 0 ]; then
    if problems=$("$PY" "$WORK/check.py" "$out" "$WORK/net.json" dye 2>&1); then
      pass "--probe $(shown "$spec"): accepted, every output parses"
    else
      fail "--probe $(shown "$spec"): $problems"
    fi
  elif [ $status -eq 2 ] && [ "$lines" -eq 1 ]; then
    pass "--probe $(shown "$spec"): refused, exit 2, one line"
  else
    fail "--probe $(shown "$spec"): exit $status, $lines lines: $(head -c 300 "$WORK/err")"
  fi
done

finish
