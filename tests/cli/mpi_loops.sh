# hemosolve under mpirun on networks with loops (issue 24): the rat mesentery and capillary beds,
# whose sums PETSc takes over the ranks in its own order: the steady state, the phase
# separation, the pulsatile run with its 0D system spread over the ranks (a halo), red cells
# and tracers across that cut, checkpoints resumed at other rank counts, --linear; each within
# its tolerance of the plain run. (Apart from mpi.sh for the time: each has its own limit.)
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/lib_mpi.sh"
# A network with loops and pressures prescribed at nodes (the rat mesentery): PETSc's
# conjugate gradients over the ranks, within 1e-10 of the plain run (relative to each
# column's largest value).
if [ -f "$NETWORKS/mesentery-rat/network.dat" ]; then
  "$BUILD/exchange/vimport" secomb "$NETWORKS/mesentery-rat/network.dat" -o "$WORK/mesentery.json" 2>/dev/null
  "$HEMOSOLVE" "$WORK/mesentery.json" --steady --out "$WORK/mesentery-one" 2>/dev/null || fail "the mesentery, plain"
  for ranks in 2 3; do
    $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/mesentery.json" --steady --out "$WORK/mesentery-$ranks" >"$WORK/m-out" 2>&1
    status=$?
    grep -q "^hemosolve: $ranks ranks by METIS: .*; PETSc's cg with hypre in [0-9]* iterations" "$WORK/m-out" \
      && [ $status -eq 0 ] && /usr/bin/python3 - "$WORK/mesentery-one/vessels.csv" "$WORK/mesentery-$ranks/vessels.csv" <<'PY' \
      && pass "the mesentery over $ranks ranks (METIS, PETSc): the plain run's within 1e-10" \
      || fail "the mesentery over $ranks ranks: status $status: $(head -3 "$WORK/m-out")"
import sys, pandas as pd, numpy as np
a, b = pd.read_csv(sys.argv[1]), pd.read_csv(sys.argv[2])
assert list(a.columns) == list(b.columns) and len(a) == len(b)
for c in ("mean_flow", "mean_pressure", "mean_wss", "reynolds"):
    x, y = a[c].to_numpy(), b[c].to_numpy()
    assert np.abs(x - y).max() <= 1e-10 * np.abs(x).max(), c
assert (a["id"] == b["id"]).all()
PY
  done
  # Its red cells separated at the bifurcations (121 passes of flows over the ranks): within
  # 1e-10 too, the hematocrits with them.
  "$HEMOSOLVE" "$WORK/mesentery.json" --steady --red-cells transport --out "$WORK/mesentery-rbc-one" 2>/dev/null \
    || fail "the mesentery with phase separation, plain"
  $MPIRUN -np 2 "$HEMOSOLVE" "$WORK/mesentery.json" --steady --red-cells transport --out "$WORK/mesentery-rbc-2" >/dev/null 2>&1
  /usr/bin/python3 - "$WORK/mesentery-rbc-one/vessels.csv" "$WORK/mesentery-rbc-2/vessels.csv" <<'PY' \
    && pass "the mesentery with phase separation over 2 ranks: the plain run's within 1e-10" \
    || fail "the mesentery with phase separation over 2 ranks: not the plain run's"
import sys, pandas as pd, numpy as np
a, b = pd.read_csv(sys.argv[1]), pd.read_csv(sys.argv[2])
assert list(a.columns) == list(b.columns) and len(a) == len(b)
for c in ("mean_flow", "mean_pressure", "discharge_hematocrit"):
    x, y = a[c].to_numpy(), b[c].to_numpy()
    assert np.abs(x - y).max() <= 1e-10 * np.abs(x).max(), c
PY
  # Its pulsatile run: no 1D vessel meets its 0D vessels, so they spread over the ranks, each
  # rank with a halo of the others' at its nodes, every step solved by PETSc (GMRES with
  # BoomerAMG to 1e-15 of the scaled residual; pulse/lumped_halo.hpp). Within 1e-7 of the plain
  # run (one pi section a vessel) in every column of vessels.csv and probes.csv, relative to
  # the column's largest; the pulsatility index, a difference of nearly equal flows in these
  # capillaries (1e-4), within 1e-7 of itself. Measured: 5e-9 at most.
  pulse="--cycles 2 --probe 100 --probe 700:0.3"
  "$HEMOSOLVE" "$WORK/mesentery.json" $pulse --lumped-sections 1 --out "$WORK/mes-pulse-one" 2>/dev/null \
    || fail "the mesentery's pulsatile run, plain"
  for ranks in 2 3; do
    $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/mesentery.json" $pulse --out "$WORK/mes-pulse-$ranks" >"$WORK/mp-out" 2>&1
    grep -q "^hemosolve: $ranks ranks by METIS: .*the 0D vessels spread over the ranks" "$WORK/mp-out" \
      && grep -q "^hemosolve: the 0D steps' solves on rank 0: 2000 solves" "$WORK/mp-out" \
      && near_files "the mesentery's pulsatile run over $ranks ranks, its 0D vessels spread (PETSc)" \
           "$WORK/mes-pulse-one" "$WORK/mes-pulse-$ranks" 1e-7 vessels.csv probes.csv \
      || fail "the mesentery's pulsatile run over $ranks ranks: $(grep -m2 'error\|METIS' "$WORK/mp-out")"
  done
  # Its checkpoint: a cycle over 2 ranks, resumed over 3 ranks and by the plain command for the
  # second: both near the uninterrupted plain run.
  $MPIRUN -np 2 "$HEMOSOLVE" "$WORK/mesentery.json" --cycles 1 --probe 100 --probe 700:0.3 --checkpoint-every 1 \
    --out "$WORK/mes-ck" >/dev/null 2>&1
  cp -r "$WORK/mes-ck" "$WORK/mes-ck-plain"
  $MPIRUN -np 3 "$HEMOSOLVE" "$WORK/mesentery.json" $pulse --checkpoint-every 1 --resume "$WORK/mes-ck" >/dev/null 2>&1 \
    && near_files "the mesentery's checkpoint over 2 ranks resumed over 3" "$WORK/mes-pulse-one" "$WORK/mes-ck" 1e-7 vessels.csv probes.csv \
    || fail "the mesentery's checkpoint over 2 ranks resumed over 3"
  "$HEMOSOLVE" "$WORK/mesentery.json" $pulse --lumped-sections 1 --checkpoint-every 1 --resume "$WORK/mes-ck-plain" >/dev/null 2>&1 \
    && near_files "the mesentery's checkpoint over 2 ranks resumed by the plain command" \
         "$WORK/mes-pulse-one" "$WORK/mes-ck-plain" 1e-7 vessels.csv probes.csv \
    || fail "the mesentery's checkpoint over 2 ranks resumed by the plain command"
  # Red cells (phase separation, Fahraeus, the viscosity followed) and a tracer across the
  # spread 0D system: a vessel's face on each rank that owns one of its nodes, the other node
  # a ghost taking its owner's s_f H_D and H_D in rounds (solver/flow_transport_spread.cpp).
  # Within 1e-7 of the plain run, as the flow (measured: 1e-8); a checkpoint over 2 ranks
  # resumed by the plain command (the faces' places: a probe reads a 0D vessel's upwind
  # node from them), and the plain run's resumed over 3.
  cells="--red-cells transport --tracer name=dye,at=inlet,start=0,duration=0.1 --probe 100 --probe 700:0.3"
  "$HEMOSOLVE" "$WORK/mesentery.json" $cells --cycles 2 --lumped-sections 1 --out "$WORK/mes-rbc-one" 2>/dev/null \
    || fail "the mesentery's red cells, plain"
  for ranks in 2 3; do
    $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/mesentery.json" $cells --cycles 2 --out "$WORK/mes-rbc-$ranks" >"$WORK/mr-out" 2>&1
    grep -q "^hemosolve: the transport's exchanges on rank 0: " "$WORK/mr-out" \
      && near_files "the mesentery's red cells and a tracer over $ranks ranks, its 0D vessels spread" \
           "$WORK/mes-rbc-one" "$WORK/mes-rbc-$ranks" 1e-7 vessels.csv probes.csv \
      || fail "the mesentery's red cells over $ranks ranks: $(grep -m2 'error' "$WORK/mr-out")"
  done
  $MPIRUN -np 2 "$HEMOSOLVE" "$WORK/mesentery.json" $cells --cycles 1 --checkpoint-every 1 --out "$WORK/mes-rbc-ck" >/dev/null 2>&1
  "$HEMOSOLVE" "$WORK/mesentery.json" $cells --cycles 2 --lumped-sections 1 --checkpoint-every 1 --resume "$WORK/mes-rbc-ck" \
    >/dev/null 2>&1 \
    && near_files "the mesentery's red cells checkpointed over 2 ranks, resumed by the plain command" \
         "$WORK/mes-rbc-one" "$WORK/mes-rbc-ck" 1e-7 vessels.csv probes.csv \
    || fail "the mesentery's red cells checkpointed over 2 ranks, resumed by the plain command"
  "$HEMOSOLVE" "$WORK/mesentery.json" $cells --cycles 1 --lumped-sections 1 --checkpoint-every 1 --out "$WORK/mes-rbc-ck1" \
    >/dev/null 2>&1
  $MPIRUN -np 3 "$HEMOSOLVE" "$WORK/mesentery.json" $cells --cycles 2 --checkpoint-every 1 --resume "$WORK/mes-rbc-ck1" \
    >/dev/null 2>&1 \
    && near_files "the mesentery's red cells checkpointed by the plain command, resumed over 3 ranks" \
         "$WORK/mes-rbc-one" "$WORK/mes-rbc-ck1" 1e-7 vessels.csv probes.csv \
    || fail "the mesentery's red cells checkpointed by the plain command, resumed over 3 ranks"
else
  echo "skip: the mesentery over ranks (no shared networks)"
fi
# A capillary bed with loops fed by a 1D artery (bench/capillary-mesh: 400 nodes, 781 0D
# vessels). Over 2 ranks the artery has a rank and the bed the other: the plain run's files
# byte for byte. Over 3 the bed whole would leave a rank empty: its 0D vessels spread,
# the artery's end coupled to a node of the spread system (each step a response K^-1 e for
# its impedance and its departures, pulse/lumped_halo.hpp), within 1e-7 of the plain run
# (measured: 6e-10).
"$(dirname "$0")/../../bench/capillary-mesh" 20 --artery -o "$WORK/fed-bed.json"
fed="--cycles 1 --probe 762 --probe 100"
"$HEMOSOLVE" "$WORK/fed-bed.json" $fed --lumped-sections 1 --out "$WORK/fed-one" 2>/dev/null || fail "the fed capillary bed, plain"
$MPIRUN -np 2 "$HEMOSOLVE" "$WORK/fed-bed.json" $fed --out "$WORK/fed-2" >"$WORK/fed-out" 2>&1
grep -q "the 1D vessels spread over the ranks (the 0D vessels meeting at a node on one rank)" "$WORK/fed-out" \
  && same_files "$WORK/fed-one" "$WORK/fed-2" \
  && pass "a capillary bed fed by a 1D artery over 2 ranks, each whole: the plain run's files byte for byte" \
  || fail "the fed capillary bed over 2 ranks: $(grep -m2 'error\|METIS' "$WORK/fed-out")"
# The same bed drained through RCR and R outlets over 2 ranks: a capacitor node is a row of
# its outlet node's owner; an R outlet none.
"$(dirname "$0")/../../bench/capillary-mesh" 20 --windkessels -o "$WORK/wk-bed.json"
"$HEMOSOLVE" "$WORK/wk-bed.json" --cycles 2 --probe 100 --lumped-sections 1 --out "$WORK/wk-one" 2>/dev/null || fail "the windkessel bed, plain"
$MPIRUN -np 2 "$HEMOSOLVE" "$WORK/wk-bed.json" --cycles 2 --probe 100 --out "$WORK/wk-2" >"$WORK/wk-out" 2>&1
grep -q "the 0D vessels spread over the ranks" "$WORK/wk-out" \
  && near_files "a capillary bed drained through RCR and R outlets over 2 ranks, spread" "$WORK/wk-one" "$WORK/wk-2" 1e-7 \
       vessels.csv probes.csv \
  || fail "the windkessel bed over 2 ranks: $(grep -m2 'error\|METIS' "$WORK/wk-out")"
for ranks in 3; do  # (and 4 by hand: 6e-10)
  $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/fed-bed.json" $fed --out "$WORK/fed-$ranks" >"$WORK/fed-out" 2>&1
  grep -q "^hemosolve: $ranks ranks by METIS: .*the 0D vessels spread over the ranks" "$WORK/fed-out" \
    && near_files "a capillary bed fed by a 1D artery over $ranks ranks, the bed spread and coupled across the cut" \
         "$WORK/fed-one" "$WORK/fed-$ranks" 1e-7 vessels.csv probes.csv \
    || fail "the fed capillary bed over $ranks ranks: $(grep -m2 'error\|METIS' "$WORK/fed-out")"
done
# Its red cells and a tracer over 3 ranks: the artery's end meets a node another rank owns
# (a ghost here), so its face goes to a cut that node's owner answers (measured: 8e-9).
fed_cells="$fed --red-cells transport --tracer name=dye,at=inlet,start=0,duration=0.1"
"$HEMOSOLVE" "$WORK/fed-bed.json" $fed_cells --lumped-sections 1 --out "$WORK/fed-rbc-one" 2>/dev/null || fail "the fed bed's red cells, plain"
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/fed-bed.json" $fed_cells --out "$WORK/fed-rbc-3" >"$WORK/fed-out" 2>&1
grep -q "the 0D vessels spread over the ranks" "$WORK/fed-out" \
  && near_files "a fed capillary bed's red cells and a tracer over 3 ranks, the bed spread" \
       "$WORK/fed-rbc-one" "$WORK/fed-rbc-3" 1e-7 vessels.csv probes.csv \
  || fail "the fed bed's red cells over 3 ranks: $(grep -m2 'error\|METIS' "$WORK/fed-out")"
[ -f "$WORK/mesentery.json" ] && linear_by_petsc "--linear over 2 ranks on the mesentery (pressures at nodes, loops)" "$WORK/mesentery.json" 2
finish
