# Hostile network files (issue 11, items 1, 2 and 5): each of vstats, vprune and hemosolve
# refuses them before any work with one line naming the field, the vessel and the range,
# exit 2; none ends in an internal error (exit 70), a crash or a file that looks complete.
source "$(dirname "$0")/lib.sh"
VPRUNE=$BUILD/pruner/vprune
HEMOSOLVE=$BUILD/solver/hemosolve
PY=/usr/bin/python3

# A valid two-vessel network with blood, inlet and an outlet; each case replaces one value.
cat >"$WORK/base.json" <<'JSON'
{"format":"vnet","version":1,
"provenance":{"tool":"test"},
"blood":{"density":1050,"rheology":"pries"},
"inlet":{"vessel":1,"type":"flow","waveform":{"shape":"half_sine","period":1,"systole":0.3,"mean":1e-9}},
"vessels":[
{"id":1,"from":0,"to":1,"length":0.001,"diameter":0.0001,"wall_thickness":0.00001,"youngs_modulus":400000,"generation":0},
{"id":2,"from":1,"to":2,"length":0.001,"diameter":0.00008,"wall_thickness":0.000008,"youngs_modulus":400000,"generation":1,"outlet":{"type":"R","R":1e12}}]}
JSON
"$VSTATS" "$WORK/base.json" >/dev/null && pass "the base network reads" || fail "base network refused"

# case NAME FROM TO: writes $WORK/NAME.json with the first FROM replaced by TO (bytes as
# Python escapes them).
case_file() {
  "$PY" - "$WORK/base.json" "$WORK/$1.json" "$2" "$3" <<'PY'
import sys
text = open(sys.argv[1], "rb").read()
old = sys.argv[3].encode().decode("unicode_escape").encode("latin-1")
new = sys.argv[4].encode().decode("unicode_escape").encode("latin-1")
assert old in text, sys.argv[3]
open(sys.argv[2], "wb").write(text.replace(old, new, 1))
PY
}

# refused NAME FRAGMENT: all three tools refuse $WORK/NAME.json with exit 2, one line.
refused() {
  local name=$1 fragment=$2
  expect_error "vstats: $name" 2 "$fragment" -- "$VSTATS" "$WORK/$name.json"
  expect_error "vprune: $name" 2 "$fragment" -- "$VPRUNE" --budget 3 "$WORK/$name.json" -o "$WORK/$name.out.json"
  [ -e "$WORK/$name.out.json" ] && fail "vprune: $name left an output file"
  expect_error "hemosolve: $name" 2 "$fragment" -- "$HEMOSOLVE" "$WORK/$name.json" --out "$WORK/$name.run" --cycles 1 --quiet
  [ -e "$WORK/$name.run/summary.json" ] && fail "hemosolve: $name left a summary"
}

case_file youngs '"youngs_modulus":400000,"generation":1' '"youngs_modulus":1e300,"generation":1'
refused youngs 'vessel 2: "youngs_modulus" must lie in [1000, 1e10] Pa (got 1e300)'
case_file short '"length":0.001,"diameter":0.00008' '"length":1e-320,"diameter":0.00008'
refused short 'vessel 2: "length" must lie in [1e-7, 10] m (got 1e-320)'
case_file long '"length":0.001,"diameter":0.00008' '"length":1e300,"diameter":0.00008'
refused long 'vessel 2: "length" must lie in [1e-7, 10] m (got 1e300)'
case_file wall '"wall_thickness":0.000008' '"wall_thickness":1e300'
refused wall 'vessel 2: "wall_thickness" must lie in [1e-8, 0.1] m (got 1e300)'
case_file density '"density":1050' '"density":1e-300'
refused density 'blood: "density" must lie in [500, 2000] kg/m^3 (got 1e-300)'
case_file period_huge '"period":1,' '"period":1e300,'
refused period_huge 'inlet.waveform: "period" must lie in [0.01, 100] s (got 1e300)'
case_file period_tiny '"period":1,' '"period":1e-300,'
refused period_tiny 'inlet.waveform: "period" must lie in [0.01, 100] s (got 1e-300)'
case_file type_number '"type":"flow"' '"type":5'
refused type_number 'inlet: "type" must be a string'
case_file shape_array '"shape":"half_sine"' '"shape":[1]'
refused shape_array 'inlet.waveform: "shape" must be a string'
case_file not_utf8 '"tool":"test"' '"tool":"te\xffst"'
refused not_utf8 'not_utf8.json:2:25: invalid UTF-8 in string'
case_file gen_2_32 '"generation":1' '"generation":4294967296'
refused gen_2_32 'vessel 2: "generation" must lie in [0, vessel count - 1] (got 4294967296)'
case_file gen_2_31 '"generation":1' '"generation":2147483648'
refused gen_2_31 'gen_2_31.json:7:122: vessel 2: "generation" must lie in [0, vessel count - 1] (got 2147483648)'
case_file gen_minus '"generation":1' '"generation":-1'
refused gen_minus 'vessel 2: "generation" must lie in [0, vessel count - 1] (got -1)'
case_file gen_deep '"generation":1' '"generation":999999'
refused gen_deep 'vessel 2: "generation" must lie in [0, 1] (the vessel count - 1) (got 999999)'
case_file duplicate '{"id":2,"from":1' '{"id":1,"from":1'
refused duplicate 'vessel id 1 appears twice: vessels[0] and vessels[1]'
case_file no_version '"version":1,' ''
refused no_version 'missing "version"'
case_file inlet_huge '"inlet":{"vessel":1' '"inlet":{"vessel":18446744073709551615'
refused inlet_huge 'inlet: unknown vessel 18446744073709551615'

# The issue's reproduction of item 1 (a use after free that printed garbage as the key).
"$PY" -c 'import sys;sys.stdout.write("{\"format\":\"vnet\",\"version\":1,\"provenance\":{\"a\":\""+"p"*40+"\\n\"},\"vessels\":[{\"\\u0069d\":\""+"v"*200+"\\n\"}]}")' >"$WORK/uaf.json"
expect_error "vstats: key name after a moved buffer" 2 'standard input:1:116: vessels[0]: "id" must be an integer' \
  -- sh -c "\"$VSTATS\" - <\"$WORK/uaf.json\""
# Hostile foreign files (issue 21, defects 1, 2, 9 and 13c): vimport refuses each with one
# line and exit 2; never exit 70, a crash, or gigabytes allocated for a count in a few bytes
# (each runs under a 500 MB address-space limit, where such an allocation fails with exit 1).
VIMPORT=$BUILD/exchange/vimport
limited() { bash -c 'ulimit -v 500000 && exec "$0" "$@"' "$@"; }
refused_import() {  # refused_import NAME FORMAT FRAGMENT
  expect_error "vimport: $1" 2 "$3" -- limited "$VIMPORT" "$2" "$WORK/$1" -o "$WORK/$1.out.json"
  [ -e "$WORK/$1.out.json" ] && fail "vimport: $1 left an output file"
}
printf '{"nodes": [{"id": 1}, {"id": 2}],\n "links": [\n {"source": 1, "target": 2, "length": 1e400, "diameter": 1e-4}]}\n' \
  >"$WORK/overflow.json"
refused_import overflow.json networkx "overflow.json:3: number overflow parsing '1e400': numbers must lie within +-1.8e308"
printf '{"nodes": [], "links": []}\n' >"$WORK/empty.json"
refused_import empty.json networkx "empty.json: the graph: has no link (0 nodes): a network needs one vessel at least"
printf '<graphml><graph edgedefault="undirected"><node id="a"/></graph></graphml>\n' >"$WORK/lonely.graphml"
refused_import lonely.graphml graphml "lonely.graphml: the graph: has no edge (1 node)"
"$PY" -c "n=200000; print('<?xml version=\"1.0\"?><graphml><graph edgedefault=\"undirected\">' + '<a>'*n + '</a>'*n + '</graph></graphml>')" \
  >"$WORK/deep.graphml"
refused_import deep.graphml graphml "deep.graphml:1: <a> lies 257 elements deep: hemotree reads XML nested at most 256 deep"
"$PY" -c "n=200000; print('<?xml version=\"1.0\"?><VTKFile type=\"PolyData\" version=\"0.1\"><PolyData>' + '<PolyData>'*n + '</PolyData>'*n + '</PolyData></VTKFile>')" \
  >"$WORK/deep.vtp"
refused_import deep.vtp vtk "deep.vtp:1: <PolyData> lies 257 elements deep"
legacy='# vtk DataFile Version 3.0\ncenterlines\nASCII\nDATASET POLYDATA\n'
printf "${legacy}POINTS 100000000 double\n0 0 0\n" >"$WORK/points.vtk"
refused_import points.vtk vtk "points.vtk:5: POINTS: 300000000 numbers cannot fit in the 7 bytes left in the file"
printf "${legacy}POINTS 1099511627776 double\n0 0 0\n" >"$WORK/points_max.vtk"
refused_import points_max.vtk vtk "points_max.vtk:5: POINTS: 3298534883328 numbers cannot fit"
printf "${legacy}POINTS 2 double\n0 0 0 0 0 1\nLINES 1 300000000\n2 0 1\n" >"$WORK/lines.vtk"
refused_import lines.vtk vtk "lines.vtk:7: LINES: 300000000 numbers cannot fit"
# .vtp, zlib: 1e8 points (2.4e9 bytes) announced in 2e8 blocks, or in one block of 2.4e9.
vtp() {  # vtp FILE HEADER_WORDS...: a Points array whose base64 data are those UInt64 words
  "$PY" - "$@" <<'PY'
import base64, struct, sys
data = base64.b64encode(b"".join(struct.pack("<Q", int(w)) for w in sys.argv[2:])).decode()
open(sys.argv[1], "w").write('<?xml version="1.0"?>\n<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" '
    'header_type="UInt64" compressor="vtkZLibDataCompressor">\n<PolyData><Piece NumberOfPoints="100000000" '
    'NumberOfLines="1"><Points><DataArray type="Float64" NumberOfComponents="3" format="binary">' + data +
    '</DataArray></Points></Piece></PolyData></VTKFile>\n')
PY
}
vtp "$WORK/blocks.vtp" 200000000 12 0
refused_import blocks.vtp vtk "its compression header gives 200000000 blocks, but the data hold at most 0 block sizes"
vtp "$WORK/oneblock.vtp" 1 2400000000 0 2400000000
refused_import oneblock.vtp vtk "its compressed blocks take more than the 0 bytes the data hold"
finish
