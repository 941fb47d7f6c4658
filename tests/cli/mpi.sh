# hemosolve under mpirun (issue 24): the tree's nodal system solved over 1 to 4 ranks gives the
# plain command's outputs byte for byte (but the wall time), text or HDF5, and so do the linear
# periodic state over 2 and 3 and a pulsatile run over 2 to 4; a looped network (PETSc) the
# plain run's to 1e-10; the partition is said in one line; an interrupt of one rank stops all;
# what does not run over ranks yet is refused in one line, said once, nothing written;
# checkpoints and frames over ranks are the plain run's bytes; the Slurm script runs.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/lib_mpi.sh"
"$VGEN" --seed 3 --root-diameter 200um --min-diameter 8um 2>/dev/null | "$BUILD/pruner/vprune" --budget all \
  -o "$WORK/tree.json" 2>/dev/null || fail "vgen | vprune"
"$HEMOSOLVE" "$WORK/tree.json" --steady --out "$WORK/one" 2>/dev/null || fail "hemosolve --steady"
"$HEMOSOLVE" "$WORK/tree.json" --steady --format h5 --out "$WORK/one-h5" 2>/dev/null || fail "hemosolve --steady --format h5"
same_run() { same_files "$WORK/one" "$1"; }  # the plain steady run's files
for ranks in 1 2 3 4; do
  $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/tree.json" --steady --out "$WORK/ranks$ranks" >"$WORK/out$ranks" 2>&1
  status=$?
  said=$(grep -c "^hemosolve: $ranks ranks by subtrees: .* cut nodes, the top's" "$WORK/out$ranks")
  if [ $ranks -eq 1 ]; then said=1; fi  # one rank: the plain command
  [ $status -eq 0 ] && [ "$said" -eq 1 ] && same_run "$WORK/ranks$ranks" \
    && pass "mpirun -np $ranks hemosolve --steady: the plain run's bytes, the partition said once" \
    || fail "mpirun -np $ranks: status $status, partition said $said times: $(head -3 "$WORK/out$ranks")"
done
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/tree.json" --steady --format h5 --out "$WORK/ranks-h5" >/dev/null 2>&1
/usr/bin/python3 - "$WORK/one-h5/results.h5" "$WORK/ranks-h5/results.h5" <<'PY' && pass "mpirun -np 3 --format h5: the plain run's values" || fail "--format h5 over ranks"
import sys, h5py, numpy as np
a, b = h5py.File(sys.argv[1]), h5py.File(sys.argv[2])
for group in ("vessels", "boundaries"):
    assert list(a[group]) == list(b[group]), group
    for name in a[group]:
        x, y = a[group][name][()], b[group][name][()]
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert np.array_equal(x.view(np.uint8), y.view(np.uint8)), name  # bit for bit, NaNs too
PY
# Each rank its slice (distributed/steady_on_slices): from an HDF5 network every rank but the
# lead reads the topology and its own vessels' rows alone; the plain run's bytes over 2 and 3
# ranks. A value out of range in one rank's rows: refused in the plain run's words, said once,
# nothing written.
"$BUILD/exchange/vexport" h5 "$WORK/tree.json" -o "$WORK/tree.h5" 2>/dev/null || fail "vexport h5"
"$HEMOSOLVE" "$WORK/tree.h5" --steady --out "$WORK/one-from-h5" 2>/dev/null || fail "hemosolve tree.h5 --steady"
for ranks in 2 3; do
  $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/tree.h5" --steady --out "$WORK/sliced$ranks" >"$WORK/sliced-out" 2>&1
  status=$?
  [ $status -eq 0 ] && grep -q "each rank its slice of the network" "$WORK/sliced-out" \
    && same_files "$WORK/one-from-h5" "$WORK/sliced$ranks" \
    && pass "mpirun -np $ranks hemosolve NET.h5 --steady, each rank its slice: the plain run's bytes" \
    || fail "slices over $ranks ranks: status $status: $(head -3 "$WORK/sliced-out")"
done
# The steady state with phase separation on slices: each pass's hematocrits sent to each rank
# for its slice's vessels; the plain run's bytes.
"$HEMOSOLVE" "$WORK/tree.h5" --steady --red-cells transport --out "$WORK/separated-from-h5" 2>/dev/null \
  || fail "hemosolve tree.h5 --steady --red-cells transport"
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/tree.h5" --steady --red-cells transport --out "$WORK/separated-sliced" >"$WORK/sliced-out" 2>&1
status=$?
[ $status -eq 0 ] && grep -q "each rank its slice of the network" "$WORK/sliced-out" \
  && same_files "$WORK/separated-from-h5" "$WORK/separated-sliced" \
  && pass "mpirun -np 3 NET.h5 --steady --red-cells transport, each rank its slice: the plain run's bytes" \
  || fail "phase separation on slices over 3 ranks: status $status: $(head -3 "$WORK/sliced-out")"
cp "$WORK/tree.h5" "$WORK/bad.h5"
/usr/bin/python3 -c "import h5py, sys; f = h5py.File(sys.argv[1], 'r+'); f['vessels/length'][-3] = 20.0" "$WORK/bad.h5"
plain_words=$("$HEMOSOLVE" "$WORK/bad.h5" --steady --out "$WORK/bad-one" 2>&1)
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/bad.h5" --steady --out "$WORK/bad-3" >"$WORK/bad-out" 2>&1
status=$?
[ $status -eq 2 ] && [ "$(grep -c '^hemosolve: error: ' "$WORK/bad-out")" -eq 1 ] \
  && grep -qxF -- "$plain_words" "$WORK/bad-out" && [ ! -e "$WORK/bad-3" ] \
  && pass "a value out of range in a slice's rows: the plain run's one line, status 2, nothing written" \
  || fail "a bad slice over 3 ranks: status $status: $(head -3 "$WORK/bad-out") (plain: $plain_words)"
# --linear, the linear periodic state, over 2 and 3 ranks: the plain run's files byte for byte
# (but the wall time), text and HDF5, probes included.
"$HEMOSOLVE" "$WORK/tree.json" --linear --probe 1 --probe 40:0.3 --out "$WORK/linear-one" 2>/dev/null || fail "hemosolve --linear"
"$HEMOSOLVE" "$WORK/tree.json" --linear --format h5 --out "$WORK/linear-one-h5" 2>/dev/null || fail "hemosolve --linear --format h5"
for ranks in 2 3; do
  $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/tree.json" --linear --probe 1 --probe 40:0.3 --out "$WORK/linear$ranks" \
    >"$WORK/lout$ranks" 2>&1
  status=$?
  said=$(grep -c "^hemosolve: $ranks ranks by subtrees: .*; the harmonics' exchanges on rank 0: " "$WORK/lout$ranks")
  [ $status -eq 0 ] && [ "$said" -eq 1 ] && same_files "$WORK/linear-one" "$WORK/linear$ranks" \
    && pass "mpirun -np $ranks hemosolve --linear: the plain run's bytes, probes too, the partition said once" \
    || fail "mpirun -np $ranks --linear: status $status, partition said $said times: $(head -3 "$WORK/lout$ranks")"
done
# A tree whose larger vessels carry waves (855 of 875): their mean shift is forced, they are
# moved to the top (the partition said so), the wave speeds are measured; probes given out of
# the ranks' order; over 2 to 4 ranks, text and HDF5.
"$VGEN" --seed 3 --root-diameter 3mm --min-diameter 300um 2>/dev/null | "$BUILD/pruner/vprune" --budget all \
  -o "$WORK/waves.json" 2>/dev/null || fail "vgen | vprune (waves)"
probes="--probe 870:0.2 --probe 3 --probe 431:0.9"
"$HEMOSOLVE" "$WORK/waves.json" --linear $probes --out "$WORK/waves-one" 2>/dev/null || fail "hemosolve --linear (waves)"
"$HEMOSOLVE" "$WORK/waves.json" --linear $probes --format h5 --out "$WORK/waves-one-h5" 2>/dev/null || fail "--format h5 (waves)"
[ "$(cut -d, -f16 "$WORK/waves-one/vessels.csv" | grep -c '[0-9]')" -gt 100 ] || fail "the wave tree measures no wave speeds"
for ranks in 2 3 4; do
  $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/waves.json" --linear $probes --out "$WORK/waves$ranks" >"$WORK/wout$ranks" 2>&1
  status=$?
  [ $status -eq 0 ] && grep -q "the top's 855 vessels" "$WORK/wout$ranks" && same_files "$WORK/waves-one" "$WORK/waves$ranks" \
    && pass "mpirun -np $ranks --linear, a tree with waves (its 1D vessels moved to the top): the plain run's bytes" \
    || fail "mpirun -np $ranks --linear (waves): status $status: $(head -3 "$WORK/wout$ranks")"
done
same_h5() {  # every dataset of /vessels, /boundaries and /probes bit for bit, NaNs too
  /usr/bin/python3 - "$1" "$2" <<'PY'
import sys, h5py, numpy as np
a, b = h5py.File(sys.argv[1]), h5py.File(sys.argv[2])
for group in ("vessels", "boundaries", "probes"):
    if group not in a:
        continue
    assert list(a[group]) == list(b[group]), group
    for name in a[group]:
        x, y = a[group][name][()], b[group][name][()]
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert np.array_equal(x.view(np.uint8), y.view(np.uint8)), name
PY
}
$MPIRUN -np 2 "$HEMOSOLVE" "$WORK/tree.json" --linear --format h5 --out "$WORK/linear-h5" >/dev/null 2>&1
same_h5 "$WORK/linear-one-h5/results.h5" "$WORK/linear-h5/results.h5" \
  && pass "mpirun -np 2 --linear --format h5: the plain run's values" || fail "--linear --format h5 over ranks"
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/waves.json" --linear $probes --format h5 --out "$WORK/waves-h5" >/dev/null 2>&1
same_h5 "$WORK/waves-one-h5/results.h5" "$WORK/waves-h5/results.h5" \
  && pass "mpirun -np 3 --linear --format h5, the tree with waves and probes: the plain run's values" || fail "--linear --format h5 (waves) over ranks"
# A pulsatile run over 2 to 4 ranks (2,345 vessels, 85 of them 1D: spread over the ranks where
# that balances the step, else on the top's rank with every vessel above them, the others whole
# subtrees of 0D vessels; with red cells below, always the top's): until periodic, with
# the compliance balance and probes on 1D and 0D vessels, the plain run's files byte for byte
# (but the wall time) with one pi section a 0D vessel, as a run over ranks takes them.
"$VGEN" --seed 3 --root-diameter 1mm --min-diameter 80um 2>/dev/null | "$BUILD/pruner/vprune" --budget all \
  -o "$WORK/pulse.json" 2>/dev/null || fail "vgen | vprune (pulse)"
pulse="--until-periodic 1e-3 --probe 1 --probe 2000:0.3 --probe 40"
"$HEMOSOLVE" "$WORK/pulse.json" $pulse --lumped-sections 1 --out "$WORK/pulse-one" 2>/dev/null || fail "hemosolve (pulse)"
"$HEMOSOLVE" "$WORK/pulse.json" $pulse --lumped-sections 1 --format h5 --out "$WORK/pulse-one-h5" 2>/dev/null \
  || fail "hemosolve --format h5 (pulse)"
grep -q '"vessels_1d": 85,' "$WORK/pulse-one/summary.json" && grep -q '"compliance_balances": [1-9]' "$WORK/pulse-one/summary.json" \
  || fail "the pulse tree: not 85 1D vessels or no compliance balance"
for ranks in 2 3 4; do
  $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/pulse.json" $pulse --out "$WORK/pulse$ranks" >"$WORK/pout$ranks" 2>&1
  status=$?
  said=$(grep -Ec "^hemosolve: $ranks ranks by subtrees: .*(; the top's rank steps [0-9]* vessels|the 1D vessels spread over the ranks)" "$WORK/pout$ranks")
  [ $status -eq 0 ] && [ "$said" -eq 1 ] && [ "$(grep -c "cycle 1/50 done" "$WORK/pout$ranks")" -eq 1 ] \
    && same_files "$WORK/pulse-one" "$WORK/pulse$ranks" \
    && pass "mpirun -np $ranks hemosolve (pulsatile, until periodic): the plain run's bytes, probes too, said once" \
    || fail "mpirun -np $ranks (pulsatile): status $status, partition said $said times: $(head -3 "$WORK/pout$ranks")"
done
# A pruned tree (vprune --budget 3000: 174 RCR outlets, 350 R, 976 capillaries), its RCR
# capacitors balanced: over 3 ranks the plain run's files.
"$VGEN" --seed 3 --root-diameter 1mm --min-diameter 40um 2>/dev/null | "$BUILD/pruner/vprune" --budget 3000 \
  -o "$WORK/pruned.json" 2>/dev/null || fail "vgen | vprune --budget 3000"
"$HEMOSOLVE" "$WORK/pruned.json" $pulse --lumped-sections 1 --out "$WORK/pruned-one" 2>/dev/null || fail "hemosolve (pruned)"
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/pruned.json" $pulse --out "$WORK/pruned-3" >/dev/null 2>&1
grep -q '"type":"RCR"' "$WORK/pruned.json" && same_files "$WORK/pruned-one" "$WORK/pruned-3" \
  && pass "mpirun -np 3, a pruned tree with RCR and R outlets until periodic: the plain run's files" \
  || fail "a pruned tree with RCR outlets over 3 ranks: the files differ from the plain run's"
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/pulse.json" $pulse --format h5 --out "$WORK/pulse-h5" >/dev/null 2>&1
same_h5 "$WORK/pulse-one-h5/results.h5" "$WORK/pulse-h5/results.h5" \
  && pass "mpirun -np 3 hemosolve --format h5 (pulsatile): the plain run's values" || fail "pulsatile --format h5 over ranks"
# The settling cycle over 2 ranks, with a 0D step four times the run's and at a lower degree (a
# second solver, on the run's cut): the plain run's files (but the wall times, the run's and
# the settling cycle's seconds).
for settling in "--settling-step 4|settling cycle done" "--settling-degree 1|settling cycle: .* at degree 1 at most"; do
  option=${settling%%|*} said=${settling#*|} name=settled-${option#--settling-}
  name=${name// /-}
  # shellcheck disable=SC2086  # option: a flag and its value
  "$HEMOSOLVE" "$WORK/pulse.json" $pulse $option --lumped-sections 1 --out "$WORK/$name-one" >"$WORK/$name-log" 2>&1 \
    || fail "hemosolve $option (pulse)"
  grep -q "$said" "$WORK/$name-log" || fail "the plain run with $option took no settling cycle"
  # shellcheck disable=SC2086
  $MPIRUN -np 2 "$HEMOSOLVE" "$WORK/pulse.json" $pulse $option --out "$WORK/$name-2" >/dev/null 2>&1
  same_files "$WORK/$name-one" "$WORK/$name-2" '"seconds"' \
    && pass "mpirun -np 2 $option: the plain run's files (the settling cycle over ranks)" \
    || fail "$option over 2 ranks: the files differ from the plain run's"
done
# Frames over ranks: every vessel's centre gathered on rank 0 at each frame, the plain run's
# files (ParaView's time series and results.vtp) byte for byte.
"$HEMOSOLVE" "$WORK/pulse.json" --cycles 1 --frames 4 --vtk --lumped-sections 1 --out "$WORK/frames-one" 2>/dev/null \
  || fail "hemosolve --frames (pulse)"
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/pulse.json" --cycles 1 --frames 4 --vtk --out "$WORK/frames-3" >/dev/null 2>&1
[ "$(ls "$WORK/frames-one/frames" | wc -l)" -eq 5 ] && diff -r "$WORK/frames-one/frames" "$WORK/frames-3/frames" >/dev/null \
  && cmp -s "$WORK/frames-one/results.vtp" "$WORK/frames-3/results.vtp" \
  && pass "mpirun -np 3 --frames 4 --vtk: the plain run's frames and results.vtp byte for byte" \
  || fail "--frames over 3 ranks: the frames differ from the plain run's"
# Red cells and tracers over ranks (docs/transport.md, "Over MPI ranks"): every step the
# shares solve the cells no root's inflow reaches, send each root's hematocrit and phase
# separation share up, the top answers with its nodes above the roots (then the same for the
# tracers); the plain run's files byte for byte (the hematocrit and the tracers' curves per
# vessel and at the probes, the balances), its checkpoint too, and a checkpoint resumed at
# another rank count, or as one process, ends as the uninterrupted run. One tracer enters at
# the inlet, one is injected into a deep 0D vessel.
cells="--red-cells transport --cycles 2 --probe 1 --probe 2000:0.3 --probe 40 --checkpoint-every 1
  --tracer name=dye,carrier=plasma,at=inlet,shape=bolus,start=0.1,duration=0.2
  --tracer name=mark,carrier=cells,at=vessel:2000,shape=step,start=0.05"
"$HEMOSOLVE" "$WORK/pulse.json" $cells --lumped-sections 1 --out "$WORK/cells-one" 2>/dev/null || fail "hemosolve --red-cells transport (pulse)"
grep -q '"separating_nodes": [1-9]' "$WORK/cells-one/summary.json" && grep -q '"injected": [1-9]' "$WORK/cells-one/summary.json" \
  || fail "the pulse tree: no node separates red cells, or no tracer injected"
for ranks in 2 3; do
  $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/pulse.json" $cells --out "$WORK/cells$ranks" >/dev/null 2>&1
  same_files "$WORK/cells-one" "$WORK/cells$ranks" && cmp -s "$WORK/cells-one/checkpoint.bin" "$WORK/cells$ranks/checkpoint.bin" \
    && pass "mpirun -np $ranks --red-cells transport, two tracers: the plain run's files and checkpoint byte for byte" \
    || fail "--red-cells transport and tracers over $ranks ranks: the files differ from the plain run's"
done
"$HEMOSOLVE" "$WORK/pulse.json" ${cells/--cycles 2/--cycles 1} --lumped-sections 1 --out "$WORK/cells-half" 2>/dev/null
$MPIRUN -np 4 "$HEMOSOLVE" "$WORK/pulse.json" $cells --resume "$WORK/cells-half" --out "$WORK/cells-half" >/dev/null 2>&1
$MPIRUN -np 2 "$HEMOSOLVE" "$WORK/pulse.json" ${cells/--cycles 2/--cycles 1} --out "$WORK/cells-half2" >/dev/null 2>&1
"$HEMOSOLVE" "$WORK/pulse.json" $cells --lumped-sections 1 --resume "$WORK/cells-half2" --out "$WORK/cells-half2" >/dev/null 2>&1
same_files "$WORK/cells-one" "$WORK/cells-half" && same_files "$WORK/cells-one" "$WORK/cells-half2" \
  && pass "red cells and tracers resumed: the plain run's checkpoint over 4 ranks, 2 ranks' as one process, the uninterrupted files" \
  || fail "red cells and tracers resumed at another rank count: the files differ from the uninterrupted run's"
# The pruned tree (R and RCR outlets on the shares' nodes) until periodic, red cells settled
# too, with the settling cycle: over 3 ranks the plain run's files.
periodic="--red-cells transport --until-periodic 1e-3 --probe 1 --probe 40 --settling-step 4"
"$HEMOSOLVE" "$WORK/pruned.json" $periodic --lumped-sections 1 --out "$WORK/pcells-one" 2>/dev/null || fail "hemosolve --red-cells transport (pruned)"
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/pruned.json" $periodic --out "$WORK/pcells-3" >/dev/null 2>&1
same_files "$WORK/pcells-one" "$WORK/pcells-3" '"seconds"' && grep -q '"cycles": [1-9][0-9],' "$WORK/pcells-3/summary.json" \
  && pass "mpirun -np 3 --red-cells transport --until-periodic, a pruned tree: the plain run's files" \
  || fail "red cells until periodic over 3 ranks (pruned): the files differ from the plain run's"
# Checkpoints over ranks are the one-process run's, byte for byte: rank 0 writes the top's
# state with every rank's share of the 0D vessels at the whole run's places.
six="--cycles 6 --probe 1 --probe 2000:0.3"
"$HEMOSOLVE" "$WORK/pulse.json" --cycles 2 --checkpoint-every 1 --lumped-sections 1 --out "$WORK/kept-one" 2>/dev/null \
  || fail "hemosolve --checkpoint-every (pulse)"
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/pulse.json" --cycles 2 --checkpoint-every 1 --out "$WORK/kept-3" >/dev/null 2>&1
cmp -s "$WORK/kept-one/checkpoint.bin" "$WORK/kept-3/checkpoint.bin" && cmp -s "$WORK/kept-one/vessels.csv" "$WORK/kept-3/vessels.csv" \
  && pass "mpirun -np 3 --checkpoint-every 1: the plain run's checkpoint.bin byte for byte" \
  || fail "--checkpoint-every over 3 ranks: the checkpoint differs from the plain run's"
# An interrupt of one rank stops every rank at the same step: the last whole cycle's results
# and its checkpoint written by rank 0, marked interrupted, said once; no rank left waiting.
# Resumed over 3 ranks, or as one process, the run ends as the uninterrupted one: its files.
"$HEMOSOLVE" "$WORK/pulse.json" $six --lumped-sections 1 --out "$WORK/six-one" 2>/dev/null || fail "hemosolve --cycles 6 (pulse)"
stop_after_two() {  # ranks, folder: started, one rank sent SIGTERM once two cycles are done
  $MPIRUN -np "$1" "$HEMOSOLVE" "$WORK/pulse.json" $six --out "$2" >"$WORK/stopped" 2>&1 &
  local launcher=$!
  for _ in $(seq 600); do grep -q "cycle 2/6 done" "$WORK/stopped" && break; sleep 0.1; done
  kill -TERM "$(pgrep -f -- "^$HEMOSOLVE .*--out $2" | tail -1)"  # a rank, not the launcher
  wait $launcher
}
stop_after_two 2 "$WORK/pulse-stopped"
status=$?
said=$(grep -c "warning: interrupted by SIGTERM after [0-9] cycles: .* holds the results of the last whole cycle and its checkpoint" "$WORK/stopped")
[ $status -ne 0 ] && [ $status -ne 124 ] && [ "$said" -eq 1 ] && grep -q '"status": "interrupted"' "$WORK/pulse-stopped/summary.json" \
  && [ -f "$WORK/pulse-stopped/checkpoint.bin" ] \
  && pass "one rank interrupted: every rank stopped, the last cycle's results and checkpoint kept, said once" \
  || fail "one rank interrupted: status $status, said $said times: $(tail -3 "$WORK/stopped")"
cp -r "$WORK/pulse-stopped" "$WORK/pulse-stopped-copy"
same_six() { same_files "$WORK/six-one" "$1"; }  # the uninterrupted run's files
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/pulse.json" $six --resume "$WORK/pulse-stopped" >"$WORK/resumed" 2>&1
status=$?
[ $status -eq 0 ] && grep -q "resuming from .* after [0-9] cycles" "$WORK/resumed" && same_six "$WORK/pulse-stopped" \
  && pass "a run over 2 ranks interrupted, resumed over 3: the uninterrupted run's files" \
  || fail "resumed over 3 ranks: status $status: $(tail -3 "$WORK/resumed")"
"$HEMOSOLVE" "$WORK/pulse.json" $six --lumped-sections 1 --resume "$WORK/pulse-stopped-copy" >"$WORK/resumed" 2>&1
status=$?
[ $status -eq 0 ] && same_six "$WORK/pulse-stopped-copy" \
  && pass "a run over 2 ranks interrupted, resumed as one process: the uninterrupted run's files" \
  || fail "resumed as one process: status $status: $(tail -3 "$WORK/resumed")"
# The Slurm batch script (examples/slurm/over-ranks.sbatch), its srun played by mpirun over 2
# ranks: a pulsatile run's results.h5, the plain run's values.
mkdir -p "$WORK/fake-slurm"
printf '#!/bin/bash\nshift  # --mpi=pmix\nexec %s -np 2 "$@"\n' "$MPIRUN" >"$WORK/fake-slurm/srun"
chmod +x "$WORK/fake-slurm/srun"
"$HEMOSOLVE" "$WORK/pulse.json" --cycles 2 --probe 1 --lumped-sections 1 --format h5 --out "$WORK/slurm-one" 2>/dev/null
PATH="$WORK/fake-slurm:$PATH" HEMOSOLVE="$HEMOSOLVE" bash "$(dirname "$0")/../../examples/slurm/over-ranks.sbatch" \
  "$WORK/pulse.json" "$WORK/slurm-run" --cycles 2 --probe 1 >"$WORK/slurm-log" 2>&1
same_h5 "$WORK/slurm-one/results.h5" "$WORK/slurm-run/results.h5" \
  && pass "examples/slurm/over-ranks.sbatch, a pulsatile run (srun played by mpirun -np 2): the plain run's values" \
  || fail "the Slurm script's pulsatile run: $(tail -3 "$WORK/slurm-log")"
# A rank killed (SIGKILL: nothing of it answers): mpirun ends every rank, the folder stays
# OUT.partial with the last cycle end's checkpoint, and a resume over 3 ranks ends with the
# uninterrupted run's files.
$MPIRUN -np 2 "$HEMOSOLVE" "$WORK/pulse.json" $six --checkpoint-every 1 --out "$WORK/pulse-killed" >"$WORK/killed" 2>&1 &
launcher=$!
for _ in $(seq 600); do grep -q "cycle 3/6 done" "$WORK/killed" && break; sleep 0.1; done
kill -KILL "$(pgrep -f -- "^$HEMOSOLVE .*--out $WORK/pulse-killed" | tail -1)"
wait $launcher
status=$?
[ $status -ne 0 ] && [ $status -ne 124 ] && [ ! -e "$WORK/pulse-killed" ] && [ -f "$WORK/pulse-killed.partial/checkpoint.bin" ] \
  && $MPIRUN -np 3 "$HEMOSOLVE" "$WORK/pulse.json" $six --checkpoint-every 1 --resume "$WORK/pulse-killed" >"$WORK/resumed" 2>&1 \
  && cmp -s "$WORK/six-one/vessels.csv" "$WORK/pulse-killed/vessels.csv" && cmp -s "$WORK/six-one/probes.csv" "$WORK/pulse-killed/probes.csv" \
  && pass "a rank killed: the run ends on every rank, OUT.partial keeps its checkpoint, resumed over 3 ranks to the uninterrupted files" \
  || fail "a rank killed: status $status: $(tail -3 "$WORK/killed") / $(tail -2 "$WORK/resumed" 2>/dev/null)"
expect_refused() {  # name, text, command...: status 2, said once, no folder
  local name=$1 text=$2
  shift 2
  $MPIRUN "$@" >"$WORK/refused" 2>&1
  local status=$? count
  count=$(grep -c -- "$text" "$WORK/refused")
  [ $status -ne 0 ] && [ "$count" -eq 1 ] && [ ! -e "$WORK/refused-out" ] \
    && pass "$name: refused, said once, nothing written" \
    || fail "$name: status $status, said $count times: $(head -3 "$WORK/refused")"
}
# The steady state with phase separation over ranks (distributed/steady_hematocrit_over_ranks):
# each pass's flows solved over the ranks, the hematocrits on rank 0: the plain run's files.
"$HEMOSOLVE" "$WORK/tree.json" --steady --red-cells transport --out "$WORK/separated-one" 2>/dev/null \
  || fail "hemosolve --steady --red-cells transport"
grep -q '"passes": [2-9]' "$WORK/separated-one/summary.json" || fail "the plain phase separation took fewer than 2 passes"
for ranks in 2 3; do
  $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/tree.json" --steady --red-cells transport --out "$WORK/separated-$ranks" >/dev/null 2>&1
  same_files "$WORK/separated-one" "$WORK/separated-$ranks" \
    && pass "mpirun -np $ranks --steady --red-cells transport: the plain run's files (every pass over the ranks)" \
    || fail "--steady --red-cells transport over $ranks ranks: the files differ from the plain run's"
done
# A breakdown over ranks (a 1D vessel, a step beyond its limit, forced) is
# every rank's and said as the plain run says it, once; nothing computed, nothing kept.
"$HEMOSOLVE" "$WORK/pulse.json" --cycles 2 --cfl 3 --force --lumped-sections 1 --out "$WORK/broken-one" 2>"$WORK/broken-one.err"
expect_refused "a breakdown over 2 ranks" "$(grep -o "hemosolve: error: the solution broke down in vessel [0-9]* at t = [0-9.e-]* s" "$WORK/broken-one.err")" \
  -np 2 "$HEMOSOLVE" "$WORK/pulse.json" --cycles 2 --cfl 3 --force --out "$WORK/refused-out"
grep -q "broke down" "$WORK/broken-one.err" || fail "the plain run did not break down at --cfl 3"
[ ! -e "$WORK/refused-out.partial" ] || fail "a breakdown over ranks left $WORK/refused-out.partial"
# A cycle estimated above a day: the one-process refusal, said once.
expect_refused "a pulsatile run over 2 ranks estimated above a day" "hemosolve: error: one cycle would take about" \
  -np 2 "$HEMOSOLVE" "$WORK/pulse.json" --cycles 2 --dt 1e-9 --out "$WORK/refused-out"
# A tool that runs as one process, started by Slurm's srun (its step's task count and this
# task's rank, no Open MPI variables): refused, said by rank 0 alone, nothing written.
for procid in 0 1; do
  SLURM_STEP_NUM_TASKS=2 SLURM_PROCID=$procid "$BUILD/stats/vstats" "$WORK/tree.json" >"$WORK/slurm" 2>&1
  status=$?
  said=$(grep -c "vstats: error: started on 2 MPI ranks: vstats runs as one process" "$WORK/slurm")
  [ $status -eq 2 ] && [ "$said" -eq $((1 - procid)) ] \
    && pass "vstats under srun's variables, task $procid: refused, said by task 0 alone" \
    || fail "srun's variables, task $procid: status $status, said $said times"
done
# What every rank sets up alone, refused on every rank alike and said once: a probe on no
# vessel, a vessel whose wall the tube law cannot take.
expect_refused "--linear over 2 ranks, a probe on no vessel" "hemosolve: error: --probe" \
  -np 2 "$HEMOSOLVE" "$WORK/tree.json" --linear --probe 99999999 --out "$WORK/refused-out"
/usr/bin/python3 - "$WORK/tree.json" "$WORK/no-wall.json" <<'PY'
import json, sys
net = json.load(open(sys.argv[1]))
net["vessels"][500].pop("youngs_modulus", None)
json.dump(net, open(sys.argv[2], "w"))
PY
expect_refused "--linear over 2 ranks, a vessel without a wall law" "hemosolve: error: vessel " \
  -np 2 "$HEMOSOLVE" "$WORK/no-wall.json" --linear --out "$WORK/refused-out"
mkdir -p "$WORK/not-ours" && touch "$WORK/not-ours/file"
expect_refused "an output folder rank 0 refuses" "hemosolve: error: --out $WORK/not-ours: exists and is not a hemosolve results folder" \
  -np 3 "$HEMOSOLVE" "$WORK/tree.json" --steady --out "$WORK/not-ours"
expect_refused "a network every rank refuses" "hemosolve: error: " \
  -np 2 "$HEMOSOLVE" "$WORK/missing.json" --steady --out "$WORK/refused-out"
# A failure of one rank alone (its node cannot read the network): said once, naming the rank;
# no rank left waiting (the timeout would end it with 124).
mkdir -p "$WORK/node0" "$WORK/node1"
cp "$WORK/tree.json" "$WORK/node0/net.json"
hemosolve_path=$(cd "$(dirname "$HEMOSOLVE")" && pwd)/hemosolve
$MPIRUN -np 2 bash -c "cd '$WORK'/node\$OMPI_COMM_WORLD_RANK && exec '$hemosolve_path' net.json --steady --out run" \
  >"$WORK/alone" 2>&1
status=$?
count=$(grep -c "^hemosolve: error: rank 1: cannot open net.json" "$WORK/alone")
[ $status -eq 1 ] && [ "$count" -eq 1 ] && ! grep -q MPI_ABORT "$WORK/alone" && [ ! -e "$WORK/node0/run" ] \
  && pass "one rank's own failure: said once naming the rank, no rank left waiting" \
  || fail "one rank's own failure: status $status, said $count times: $(head -3 "$WORK/alone")"
# A network whose node labels hang the tree from a leaf, not its inlet: PETSc solves it (the
# elimination's subtrees are not the partition's), the plain run's within 1e-10.
/usr/bin/python3 - "$WORK/tree.json" "$WORK/from-a-leaf.json" <<'PY'
import json, sys, collections
net = json.load(open(sys.argv[1]))
near = collections.defaultdict(list)
for v in net["vessels"]:
    near[v["from"]].append(v["to"]); near[v["to"]].append(v["from"])
order, seen = [net["vessels"][-1]["to"]], {net["vessels"][-1]["to"]}
for n in order:
    for m in near[n]:
        if m not in seen: seen.add(m); order.append(m)
by_id = {n["id"]: n for n in net["nodes"]}
net["nodes"] = [by_id[i] for i in order]
json.dump(net, open(sys.argv[2], "w"))
PY
"$HEMOSOLVE" "$WORK/from-a-leaf.json" --steady --out "$WORK/leaf-one" 2>/dev/null
$MPIRUN -np 3 "$HEMOSOLVE" "$WORK/from-a-leaf.json" --steady --out "$WORK/leaf-3" >"$WORK/leaf-out" 2>&1
grep -q "PETSc's cg with hypre" "$WORK/leaf-out" && /usr/bin/python3 - "$WORK/leaf-one/vessels.csv" "$WORK/leaf-3/vessels.csv" <<'PY' \
  && pass "a tree labelled from a leaf over 3 ranks: PETSc, the plain run's within 1e-10" || fail "a tree labelled from a leaf: $(head -2 "$WORK/leaf-out")"
import sys, pandas as pd, numpy as np
a, b = pd.read_csv(sys.argv[1]), pd.read_csv(sys.argv[2])
for c in ("mean_flow", "mean_pressure"):
    assert np.abs(a[c] - b[c]).max() <= 1e-10 * np.abs(a[c]).max(), c
PY
# The large arteries over ranks (docs/scaling.md, "1D vessels across a cut"): ADAN56, 64 of
# its 77 vessels 1D and 13 0D between them, would leave a rank without a vessel if the top held
# every 1D vessel, so they are spread: each rank steps its own, solves each junction where it
# has an end from the traces exchanged at every evaluation, and holds each 0D vessel with the
# vessels at its nodes. Until periodic (the settling cycle at degree 2, the compliance
# balance), probes, a checkpoint: the plain run's files and checkpoint byte for byte; the
# checkpoint resumed at another rank count and as one process; the circle of Willis (loops,
# METIS) the same; what does not run so is refused in one line.
if [ -f "$NETWORKS/openbf/boileau2015/adan56/adan56.yaml" ]; then
  "$BUILD/exchange/vimport" openbf "$NETWORKS/openbf/boileau2015/adan56/adan56.yaml" -o "$WORK/adan56.json" 2>/dev/null
  arteries="--until-periodic 1e-3 --probe 10 --probe 40:0.3 --checkpoint-every 1"
  "$HEMOSOLVE" "$WORK/adan56.json" $arteries --lumped-sections 1 --out "$WORK/adan-one" 2>/dev/null || fail "ADAN56, plain"
  for ranks in 2 3; do
    $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/adan56.json" $arteries --out "$WORK/adan-$ranks" >"$WORK/adan-out" 2>&1
    status=$?
    grep -q "^hemosolve: $ranks ranks by subtrees: .* the 1D vessels spread over the ranks" "$WORK/adan-out" && [ $status -eq 0 ] \
      && same_files "$WORK/adan-one" "$WORK/adan-$ranks" '"seconds"' \
      && cmp -s "$WORK/adan-one/checkpoint.bin" "$WORK/adan-$ranks/checkpoint.bin" \
      && pass "ADAN56 over $ranks ranks, its 1D vessels spread: the plain run's files and checkpoint byte for byte" \
      || fail "ADAN56 over $ranks ranks: status $status, $(grep -c ranks "$WORK/adan-out") lines on ranks: the files differ or the line is missing"
  done
  two="--cycles 2 --probe 10 --checkpoint-every 1"
  "$HEMOSOLVE" "$WORK/adan56.json" $two --lumped-sections 1 --out "$WORK/adan-two" 2>/dev/null
  "$HEMOSOLVE" "$WORK/adan56.json" ${two/--cycles 2/--cycles 1} --lumped-sections 1 --out "$WORK/adan-half" 2>/dev/null
  $MPIRUN -np 4 "$HEMOSOLVE" "$WORK/adan56.json" $two --resume "$WORK/adan-half" --out "$WORK/adan-half" >/dev/null 2>&1
  $MPIRUN -np 2 "$HEMOSOLVE" "$WORK/adan56.json" ${two/--cycles 2/--cycles 1} --out "$WORK/adan-half2" >/dev/null 2>&1
  "$HEMOSOLVE" "$WORK/adan56.json" $two --lumped-sections 1 --resume "$WORK/adan-half2" --out "$WORK/adan-half2" >/dev/null 2>&1
  same_files "$WORK/adan-two" "$WORK/adan-half" && same_files "$WORK/adan-two" "$WORK/adan-half2" \
    && cmp -s "$WORK/adan-two/checkpoint.bin" "$WORK/adan-half/checkpoint.bin" \
    && pass "ADAN56 resumed: the plain run's checkpoint over 4 ranks, 2 ranks' as one process, the uninterrupted files" \
    || fail "ADAN56 resumed at another rank count: the files differ from the uninterrupted run's"
  # Over 8 ranks a tree's top would be spread over them (refused for the top's layout): the 1D
  # vessels spread need no top.
  $MPIRUN -np 8 "$HEMOSOLVE" "$WORK/adan56.json" ${two/--cycles 2/--cycles 1} --out "$WORK/adan-8" >"$WORK/adan-out" 2>&1
  "$HEMOSOLVE" "$WORK/adan56.json" ${two/--cycles 2/--cycles 1} --lumped-sections 1 --out "$WORK/adan-one-cycle" 2>/dev/null
  grep -q "^hemosolve: 8 ranks by subtrees: .* the 1D vessels spread over the ranks" "$WORK/adan-out" \
    && same_files "$WORK/adan-one-cycle" "$WORK/adan-8" \
    && pass "ADAN56 over 8 ranks (oversubscribed), its 1D vessels spread: the plain run's files byte for byte" \
    || fail "ADAN56 over 8 ranks: $(grep -m2 hemosolve "$WORK/adan-out")"
  "$BUILD/exchange/vimport" openbf "$NETWORKS/openbf/alastruey2007/circle_of_willis.yaml" -o "$WORK/willis.json" 2>/dev/null
  "$HEMOSOLVE" "$WORK/willis.json" --cycles 2 --probe 1 --lumped-sections 1 --out "$WORK/willis-one" 2>/dev/null
  $MPIRUN -np 2 "$HEMOSOLVE" "$WORK/willis.json" --cycles 2 --probe 1 --out "$WORK/willis-2" >"$WORK/willis-out" 2>&1
  grep -q "^hemosolve: 2 ranks by METIS: .* the 1D vessels spread over the ranks" "$WORK/willis-out" \
    && same_files "$WORK/willis-one" "$WORK/willis-2" \
    && pass "the circle of Willis (loops) over 2 ranks by METIS, its 1D vessels spread: the plain run's files byte for byte" \
    || fail "the circle of Willis over 2 ranks: $(head -3 "$WORK/willis-out")"
  "$HEMOSOLVE" "$WORK/adan56.json" --cycles 1 --cfl 3 --force --lumped-sections 1 --out "$WORK/adan-broken" 2>"$WORK/adan-broken.err"
  linear_by_petsc "--linear over 3 ranks on the circle of Willis (loops, waves across the cut)" "$WORK/willis.json" 3
  linear_by_petsc "--linear over 2 ranks on ADAN56 (a tree whose wave vessels would leave a rank empty on its top)" "$WORK/adan56.json" 2
  expect_refused "a breakdown over 3 ranks, the 1D vessels spread" \
    "$(grep -o "hemosolve: error: the solution broke down in vessel [0-9]* at t = [0-9.e-]* s" "$WORK/adan-broken.err")" \
    -np 3 "$HEMOSOLVE" "$WORK/adan56.json" --cycles 1 --cfl 3 --force --out "$WORK/refused-out"
  # Red cells and tracers where the 1D vessels are spread (solver/flow_transport_spread.cpp):
  # each step in rounds across the cut; a plasma bolus from the inlet and a red-cell marker
  # injected into a 1D vessel, probes, a checkpoint: the plain run's files byte for byte over 2
  # and 3 ranks; the plain checkpoint resumed over 3 ranks; the circle of Willis (loops) too.
  carried="--red-cells transport --tracer name=dye,carrier=plasma,at=inlet,start=0.1,duration=0.2 --tracer name=mark,carrier=cells,at=vessel:30,start=0,duration=0.2 --probe 10 --probe 40:0.3 --checkpoint-every 1"
  "$HEMOSOLVE" "$WORK/adan56.json" --cycles 1 $carried --lumped-sections 1 --out "$WORK/rbc-one" 2>/dev/null
  "$HEMOSOLVE" "$WORK/adan56.json" --cycles 2 $carried --lumped-sections 1 --out "$WORK/rbc-two" 2>/dev/null
  for ranks in 2 3; do
    $MPIRUN -np $ranks "$HEMOSOLVE" "$WORK/adan56.json" --cycles 1 $carried --out "$WORK/rbc-$ranks" >"$WORK/rbc-out" 2>&1
    grep -q "^hemosolve: the transport's exchanges on rank 0: [0-9]* rounds" "$WORK/rbc-out" \
      && same_files "$WORK/rbc-one" "$WORK/rbc-$ranks" && cmp -s "$WORK/rbc-one/checkpoint.bin" "$WORK/rbc-$ranks/checkpoint.bin" \
      && pass "ADAN56's red cells and tracers over $ranks ranks, its 1D vessels spread: the plain run's files and checkpoint byte for byte" \
      || fail "ADAN56's red cells and tracers over $ranks ranks: $(grep -m2 error "$WORK/rbc-out")"
  done
  cp -r "$WORK/rbc-one" "$WORK/rbc-resumed"
  $MPIRUN -np 3 "$HEMOSOLVE" "$WORK/adan56.json" --cycles 2 $carried --resume "$WORK/rbc-resumed" --out "$WORK/rbc-resumed" >/dev/null 2>&1
  same_files "$WORK/rbc-two" "$WORK/rbc-resumed" && cmp -s "$WORK/rbc-two/checkpoint.bin" "$WORK/rbc-resumed/checkpoint.bin" \
    && pass "ADAN56's red cells and tracers: the plain checkpoint resumed over 3 ranks ends as the uninterrupted run" \
    || fail "ADAN56's red cells and tracers resumed over 3 ranks: the files differ from the uninterrupted run's"
  "$HEMOSOLVE" "$WORK/willis.json" --cycles 1 --red-cells transport --tracer name=dye,at=inlet,start=0.1,duration=0.2 --probe 1 \
    --lumped-sections 1 --out "$WORK/willis-rbc-one" 2>/dev/null
  $MPIRUN -np 2 "$HEMOSOLVE" "$WORK/willis.json" --cycles 1 --red-cells transport --tracer name=dye,at=inlet,start=0.1,duration=0.2 \
    --probe 1 --out "$WORK/willis-rbc-2" >/dev/null 2>&1
  same_files "$WORK/willis-rbc-one" "$WORK/willis-rbc-2" \
    && pass "the circle of Willis's red cells and a tracer over 2 ranks by METIS: the plain run's files byte for byte" \
    || fail "the circle of Willis's red cells and a tracer over 2 ranks: the files differ"
else
  echo "skip: ADAN56 and the circle of Willis over ranks (no shared networks)"
fi
finish
