# ensemble_mpi.sh -- dm.ensemble under `mpirun -np 2`: the same script,
# the members split over the ranks, every rank holding the whole table, bit
# for bit the table of one process with one thread; the collective HDF5
# output; a Lua error on one rank ends both (no rank left waiting).
# Skips when dmech was built without MPI or mpirun is missing.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
MPIRUN=${MPIRUN:-$(command -v mpirun)}
built=$("$DMECH" -e 'io.write(tostring(dm.mpi.info().built))' 2>&1)
if [ "$built" != true ]; then
  skip "dmech was built without MPI (configure --without-mpi, or no usable mpicc): MPI tests skipped"
  done_testing
fi
if [ -z "$MPIRUN" ]; then
  skip "mpirun not found (install openmpi-bin): MPI tests skipped"
  done_testing
fi
tmp="${DMECH_TESTTMP:-/tmp}/ensemble_mpi.$$"
mkdir -p "$tmp"
# Open MPI as root, more ranks than cores, no network probing
run_mpi() {
  timeout 120 "$MPIRUN" --allow-run-as-root --oversubscribe --mca btl self,vader -np 2 "$@"
}

cat > "$tmp/sweep.lua" <<'EOF'
dm.config.warn = false            -- the message is printed below
local dir, threads = arg[1], tonumber(arg[2])
local I = dm.integrator(dm.systems.kepler{impl = "c"}, {method = "gauss", stages = 2, h = 0.01})
local res, msg = dm.ensemble{integrator = I, members = 37, threads = threads, run = {t = 2},
  seed = 2385, output = dir .. "/out.h5",
  states = function(k, rng)
    if k == 20 then return {q = {1e-3, 0}, p = {0, 0}} end   -- falls into the centre
    return {q = {0.5 + 0.01 * k + rng:uniform(0, 1e-3), 0}, p = {0, 1.3}} end,
  reduce = {"final", "energy_error", "megno", "fli"}}
res:save(dir .. "/saved.h5")
print(("rank %d of %d: %d members, member 20 status %d, %s"):format(dm.mpi.rank(), dm.mpi.size(),
  #res, res[20].status, msg and msg:match("1 of 37 members failed") or msg))
EOF
cat > "$tmp/same.lua" <<'EOF'
local a, b = dm.load_trajectory(arg[1]), dm.load_trajectory(arg[2])
local ok = #a == #b and #a == 37
for _, c in ipairs(a:names()) do
  local x, y = a:column(c), b:column(c)
  for i = 1, #x do ok = ok and (x[i] == y[i] or (x[i] ~= x[i] and y[i] ~= y[i])) end
end
local ma, mb = a:meta(), b:meta()
for k, v in pairs(ma) do ok = ok and mb[k] == v end
io.write(ok and "same" or "different")
EOF

mkdir -p "$tmp/one" "$tmp/two"
out=$("$DMECH" "$tmp/sweep.lua" "$tmp/one" 1 2>&1)
is "$out" "rank 0 of 1: 37 members, member 20 status 3, 1 of 37 members failed" "one process"
out=$(run_mpi "$DMECH" "$tmp/sweep.lua" "$tmp/two" 2 2>&1 | sort)
is "$out" "rank 0 of 2: 37 members, member 20 status 3, 1 of 37 members failed
rank 1 of 2: 37 members, member 20 status 3, 1 of 37 members failed" \
  "two ranks: every rank gets the whole table"
is "$("$DMECH" "$tmp/same.lua" "$tmp/one/saved.h5" "$tmp/two/saved.h5" 2>&1)" same \
  "2 ranks x 2 threads = 1 process x 1 thread, bit for bit (values and metadata)"
is "$("$DMECH" "$tmp/same.lua" "$tmp/one/out.h5" "$tmp/two/out.h5" 2>&1)" same \
  "the collective output file too"
is "$(ls "$tmp/two")" "out.h5
saved.h5" "one file each, no temporary files left"

cat > "$tmp/fail.lua" <<'EOF'
local I = dm.integrator(dm.systems.kepler{impl = "c"}, {method = "gauss", h = 0.01})
dm.ensemble{integrator = I, members = 6, run = {steps = 10},
  states = function(k)
    if k == 4 then error("no start for member 4 on rank " .. dm.mpi.rank()) end
    return {q = {1, 0}, p = {0, 1}} end}
EOF
out=$(run_mpi "$DMECH" "$tmp/fail.lua" 2>&1)
status=$?
like "$out" "no start for member 4 on rank [01]" "a Lua error on the rank that took member 4 is reported"
ok "$([ $status -ne 0 ] && [ $status -ne 124 ] && echo 0 || echo 1)" \
  "and the job ends with a failure, not a hang (status $status)"
printf '%s\n' 'if dm.mpi.rank() == 1 then error("rank 1 gives up") end' \
  'dm.mpi.barrier()' 'print("rank " .. dm.mpi.rank() .. " passed the barrier")' > "$tmp/gives_up.lua"
out=$(run_mpi "$DMECH" "$tmp/gives_up.lua" 2>&1)
status=$?
like "$out" "rank 1 gives up" "an error outside dm.ensemble on one rank"
ok "$([ $status -ne 0 ] && [ $status -ne 124 ] && ! printf '%s' "$out" | grep -q passed && echo 0 || echo 1)" \
  "ends the job (MPI_Abort) instead of leaving rank 0 at the barrier (status $status)"
rm -rf "$tmp"
done_testing
