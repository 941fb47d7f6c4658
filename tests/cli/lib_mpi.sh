# Helpers for the tests under mpirun (mpi.sh, mpi_loops.sh), sourced after lib.sh: mpirun
# itself (a test without Open MPI skips), and comparisons of a run's folder with the plain run's.
HEMOSOLVE=$BUILD/solver/hemosolve
if ! command -v mpirun >/dev/null; then
  echo "skip: mpirun (no Open MPI)"
  finish
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
MPIRUN="timeout 120 mpirun --oversubscribe"
NETWORKS=${HEMOTREE_NETWORKS_DIR:-$(dirname "$0")/../../../shared/networks}  # ../shared, beside the clone
same_files() {  # REFERENCE RUN [PATTERN]: vessels.csv and probes.csv byte for byte, summary.json but
  # its wall time (and the lines PATTERN matches)
  local skip='"wall_time"'${3:+"\\|$3"}
  cmp -s "$1/vessels.csv" "$2/vessels.csv" && { [ ! -e "$1/probes.csv" ] || cmp -s "$1/probes.csv" "$2/probes.csv"; } \
    && diff <(grep -v "$skip" "$1/summary.json") <(grep -v "$skip" "$2/summary.json") >/dev/null
}
# Runs over ranks whose sums PETSc takes in its own order (loops): NAME REFERENCE RUN TOLERANCE
# FILE...: every number of each file within TOLERANCE of its column's largest (the
# pulsatility index, a ratio, within TOLERANCE of 1), the rest of the text the same.
near_files() {
  local name=$1 reference=$2 run=$3 tolerance=$4
  shift 4
  /usr/bin/python3 - "$reference" "$run" "$tolerance" "$@" <<'PY' && pass "$name: the plain run's within $tolerance" \
    || fail "$name: beyond $tolerance of the plain run"
import sys, numpy as np, pandas as pd
reference, run, tolerance = sys.argv[1], sys.argv[2], float(sys.argv[3])
for name in sys.argv[4:]:
    a, b = pd.read_csv(f"{reference}/{name}"), pd.read_csv(f"{run}/{name}")
    assert list(a.columns) == list(b.columns) and len(a) == len(b), name
    for c in a.columns:
        if a[c].dtype.kind != "f":
            assert (a[c].astype(str) == b[c].astype(str)).all(), (name, c)
            continue
        x, y = a[c].to_numpy(), b[c].to_numpy()
        assert (np.isfinite(x) == np.isfinite(y)).all(), (name, c)
        f = np.isfinite(x)
        scale = 1.0 if c == "pulsatility_index" else max(np.abs(x[f]).max(initial=0), 1e-300)
        assert np.abs(x[f] - y[f]).max(initial=0) <= tolerance * scale, (name, c)
PY
}
# --linear where a tree's distributed elimination does not apply (pressures at nodes, loops, a
# tree whose wave-carrying vessels would leave a rank empty on its top): each harmonic's
# system over the ranks by PETSc (distributed/petsc_harmonic_network), the plain run's within
# 1e-10 in every column of vessels.csv.
linear_by_petsc() {  # NAME NETWORK RANKS
  "$HEMOSOLVE" "$2" --linear --out "$WORK/linear-graph-one" 2>/dev/null
  $MPIRUN -np "$3" "$HEMOSOLVE" "$2" --linear --out "$WORK/linear-graph-$3" >"$WORK/linear-graph-out" 2>&1
  grep -q "every harmonic's nodal system by PETSc's" "$WORK/linear-graph-out" \
    && near_files "$1" "$WORK/linear-graph-one" "$WORK/linear-graph-$3" 1e-10 vessels.csv \
    || fail "$1: $(grep -m2 hemosolve "$WORK/linear-graph-out")"
  rm -rf "$WORK/linear-graph-one" "$WORK/linear-graph-$3"
}
