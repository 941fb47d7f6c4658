# Bad input: one clear line on stderr, a non-zero exit, and no file that looks complete.
source "$(dirname "$0")/lib.sh"

expect_error "unknown flag" 2 "--frobnicate" -- "$VGEN" --frobnicate
expect_error "bad length unit" 2 "--min-diameter" -- "$VGEN" --min-diameter 7parsec
expect_error "min not below root" 2 "must be below" -- "$VGEN" --root-diameter 10um --min-diameter 20um
expect_error "unknown format" 2 "--format" -- "$VGEN" --format pdf
expect_error "missing rules file" 1 "nothing.json" -- "$VGEN" --rules "$WORK/nothing.json"
echo '{"ranges": [{"diameter_min": 0, "diameter_max": 1, "kappa_min": 0.5, "kappa_max": 1.5,
  "murray_exponent": 3, "length": {"law": "uniform", "min": 1e-4, "max": 2e-4}}]}' >"$WORK/bad.json"
expect_error "kappa outside (0, 1)" 2 "(0, 1)" -- "$VGEN" --rules "$WORK/bad.json"
echo '{"ranges": [' >"$WORK/broken.json"
expect_error "rules not JSON" 2 "broken.json" -- "$VGEN" --rules "$WORK/broken.json"
expect_error "tree larger than memory" 2 "--force" -- "$VGEN" --root-diameter 2.5cm --min-diameter 5um

expect_error "vstats: missing file" 1 "cannot open" -- "$VSTATS" "$WORK/none.json"
printf '{"format": "vnet",\n "vessels": [}' >"$WORK/bad-net.json"
expect_error "vstats: syntax error position" 2 "bad-net.json:2:" -- "$VSTATS" "$WORK/bad-net.json"

# A write that fails leaves nothing behind that looks complete.
if [ -c /dev/full ]; then
  expect_error "disk full" 1 "cannot write" -- "$VGEN" --root-diameter 150um -o /dev/full
fi
mkdir "$WORK/ro" && chmod 500 "$WORK/ro"
if [ "$(id -u)" -ne 0 ]; then
  expect_error "unwritable folder" 1 "cannot create" -- "$VGEN" --root-diameter 150um -o "$WORK/ro/t.json"
fi
# A closed pipe: vgen must stop with a non-zero status, not hang or claim success.
"$VGEN" --root-diameter 300um 2>"$WORK/err" | head -c 100 >/dev/null
status=${PIPESTATUS[0]}
[ "$status" -ne 0 ] && pass "closed pipe exits $status" || fail "closed pipe exit 0"
# Interrupted output to a file: the partial file never takes the final name.
"$VGEN" --root-diameter 1mm -o "$WORK/big.json" & pid=$!
sleep 0.5; kill -TERM $pid; wait $pid 2>/dev/null
[ -e "$WORK/big.json" ] && fail "killed vgen left big.json" || pass "killed vgen left no final file"
ls "$WORK" | grep -q partial && fail "killed vgen left its partial file" || pass "killed vgen cleaned up"
# Under mpirun with several ranks every rank would run the whole command: refused, said once.
if command -v mpirun >/dev/null; then
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout 120 mpirun --oversubscribe -np 2 \
    "$VGEN" --root-diameter 150um -o "$WORK/mpi.json" >"$WORK/mpi.out" 2>&1
  status=$?
  count=$(grep -c "started on 2 MPI ranks: vgen runs as one process" "$WORK/mpi.out")
  [ "$status" -ne 0 ] && [ "$count" -eq 1 ] && [ ! -e "$WORK/mpi.json" ] \
    && pass "mpirun -np 2 vgen: refused, said once, nothing written" \
    || fail "mpirun -np 2 vgen: status $status, said $count times: $(cat "$WORK/mpi.out")"
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout 120 mpirun --oversubscribe -np 1 \
    "$VGEN" --root-diameter 150um -o "$WORK/mpi1.json" >"$WORK/mpi1.out" 2>&1 \
    && cmp -s "$WORK/mpi1.json" <("$VGEN" --root-diameter 150um 2>/dev/null) \
    && pass "mpirun -np 1 vgen: the plain command's network" || fail "mpirun -np 1 vgen: $(cat "$WORK/mpi1.out")"
else
  echo "skip: mpirun (no Open MPI)"
fi
finish
