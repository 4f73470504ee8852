# ensemble_mpi_balance.sh -- under mpirun the ranks take the members in
# batches from a shared counter (MPI one-sided communication), so members of
# very unequal cost are balanced; the table stays bit for bit the table of
# one process for 2 ranks x 1 thread and 3 ranks x 2 threads.  Without
# one-sided communication (Open MPI's osc components switched off) the
# members are dealt cyclically, with a warning, and the table is the same.
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
tmp="${DMECH_TESTTMP:-/tmp}/ensemble_mpi_balance.$$"
mkdir -p "$tmp"
run_mpi() {
  np=$1; shift
  timeout 120 "$MPIRUN" --allow-run-as-root --oversubscribe --mca btl self,vader -np "$np" "$@"
}

# Odd members fall radially from r = 0.02 k and end when the step fails near
# the centre (most after 1 to ~100 of the 300 steps, later for larger k); even
# members orbit for all 300 steps with the MEGNO Jacobians: costs differ by
# factors up to several hundred.  The second ensemble records which rank
# ran each member (a reduce function runs on the member's rank).
cat > "$tmp/unequal.lua" <<'LUA'
dm.config.warn = arg[3] == "warn"
local dir, threads = arg[1], tonumber(arg[2])
local I = dm.integrator(dm.systems.kepler{impl = "c"}, {method = "gauss", stages = 2, h = 0.01})
local function start(k)
  if k % 2 == 1 then return {q = {0.02 * k, 0}, p = {0, 0}} end
  return {q = {0.5 + 0.01 * k, 0.0385 * k}, p = {-0.01 * k, 1.3}} end
local res = dm.ensemble{integrator = I, members = 48, threads = threads, run = {t = 3},
  states = start, reduce = {"final", "energy_error", "megno", "fli"}}
res:save(dir .. "/unequal.h5")
local who = dm.ensemble{integrator = I, members = 48, threads = threads, run = {t = 3},
  states = start, reduce = function(tr, k) return dm.mpi.rank() end, columns = {"rank"}}
local s = {}
for k = 1, #who do s[k] = ("%d"):format(who[k].rank) end
if dm.mpi.rank() == 0 then print(#res .. " " .. table.concat(s)) end
LUA
cat > "$tmp/same.lua" <<'LUA'
local a, b = dm.load_trajectory(arg[1]), dm.load_trajectory(arg[2])
local ok = #a == #b and #a == 48 and #a:names() == 9
for _, c in ipairs(a:names()) do
  local x, y = a:column(c), b:column(c)
  for i = 1, #x do ok = ok and (x[i] == y[i] or (x[i] ~= x[i] and y[i] ~= y[i])) end
end
local ma, mb = a:meta(), b:meta()
for k, v in pairs(ma) do ok = ok and mb[k] == v end
local short, long = 0, 0
for i = 1, #a do if a[i].t < 1.5 then short = short + 1 elseif a[i].t == 3 then long = long + 1 end end
-- unequal costs: many members end before half the run, the others run it all
io.write(ok and short >= 15 and long >= 24 and "same, unequal" or
  ("different (%d short, %d long)"):format(short, long))
LUA
mkdir -p "$tmp/one" "$tmp/two" "$tmp/three" "$tmp/cyclic"
out=$("$DMECH" "$tmp/unequal.lua" "$tmp/one" 1 2>&1)
is "$out" "48 000000000000000000000000000000000000000000000000" "one process runs all 48"
out=$(run_mpi 2 "$DMECH" "$tmp/unequal.lua" "$tmp/two" 1 2>&1)
like "$out" "^48 [01]{48}$" "2 ranks x 1 thread: every member run by one rank"
case "$out" in
  "48 00"*|"48 11"*) ok 0 "taken in batches, not dealt cyclically: ${out#48 }" ;;
  *) ok 1 "taken in batches, not dealt cyclically: ${out#48 }" ;;
esac
is "$("$DMECH" "$tmp/same.lua" "$tmp/one/unequal.h5" "$tmp/two/unequal.h5" 2>&1)" \
  "same, unequal" "2 ranks x 1 thread = 1 process, bit for bit, with costs from 1 to 300 steps"
out=$(run_mpi 3 "$DMECH" "$tmp/unequal.lua" "$tmp/three" 2 2>&1)
like "$out" "^48 [012]{48}$" "3 ranks x 2 threads: every member run by one rank"
is "$("$DMECH" "$tmp/same.lua" "$tmp/one/unequal.h5" "$tmp/three/unequal.h5" 2>&1)" \
  "same, unequal" "3 ranks x 2 threads = 1 process, bit for bit"
# no one-sided communication: every osc component of Open MPI switched off
out=$(OMPI_MCA_osc="^sm,rdma,ucx,pt2pt,monitoring" run_mpi 2 "$DMECH" \
  "$tmp/unequal.lua" "$tmp/cyclic" 1 warn 2>&1)
like "$out" "warning: dm.ensemble: members dealt cyclically over the ranks, not balanced \(MPI one-sided communication unavailable: MPI_Win_allocate failed" \
  "without one-sided communication: a warning says the members are dealt cyclically"
like "$out" "48 (01){24}" "and they are: member k on rank (k - 1) mod 2"
is "$("$DMECH" "$tmp/same.lua" "$tmp/one/unequal.h5" "$tmp/cyclic/unequal.h5" 2>&1)" \
  "same, unequal" "the same table, bit for bit"

# Ctrl-C on one rank (SIGINT to that process): it stops its members, closes
# the counter, the other rank sees it within a quarter of a second and
# starts no more (without that it would finish its first batch of 100);
# both return the whole table with the finished members kept and the rest
# "not run".
cat > "$tmp/long.lua" <<'LUA'
dm.config.interrupt = "run"
do   -- each rank leaves its process id for the shell (no pgrep on a minimal system)
  local pid = io.open("/proc/self/stat"):read("n")
  local f = io.open(arg[1] .. "/pid." .. dm.mpi.rank(), "w")
  f:write(pid, "\n")
  f:close()
end
local I = dm.integrator(dm.systems.kepler{impl = "c"}, {method = "gauss", h = 0.01})
local res, msg = dm.ensemble{integrator = I, members = 400, threads = 1, progress = true,
  run = {steps = 300000}, reduce = {"final"},
  states = function(k) return {q = {0.5 + 0.001 * k, 0}, p = {0, 1.3}} end}
local done, notrun = 0, 0
for k = 1, #res do
  if res[k].status == 0 then done = done + 1 elseif res[k].t ~= res[k].t then notrun = notrun + 1 end
end
print(("rank %d: %d rows, %s, not run %s"):format(dm.mpi.rank(), #res, msg,
  notrun >= 350 and ">= 350" or notrun))
LUA
timeout 120 "$MPIRUN" --allow-run-as-root --oversubscribe --mca btl self,vader -np 2 \
  "$DMECH" "$tmp/long.lua" "$tmp" > "$tmp/out" 2> "$tmp/err" &
mpid=$!
i=0
while [ $i -lt 600 ] && ! grep -q "ensemble: [1-9][0-9]*/400 members" "$tmp/err" 2>/dev/null; do
  sleep 0.05; i=$((i + 1)); done
rank=$(cat "$tmp/pid.1" 2>/dev/null)
kill -INT "$rank" 2>/dev/null
wait $mpid; st=$?
out=$(sort "$tmp/out")
is "$st" 0 "SIGINT to one rank: the job goes on to the end of the script"
n0=$(printf '%s\n' "$out" | sed -n 's/^rank 0: 400 rows, dm.ensemble: interrupted: \([0-9]*\) of 400 members finished; they are kept, not run >= 350$/\1/p')
n1=$(printf '%s\n' "$out" | sed -n 's/^rank 1: 400 rows, dm.ensemble: interrupted: \([0-9]*\) of 400 members finished; they are kept, not run >= 350$/\1/p')
ok "$([ -n "$n0" ] && [ "$n0" = "$n1" ] && echo 0 || echo 1)" \
  "both ranks return the whole table ($n0 and $n1 finished): the rest stopped soon, not run"
[ -n "$n0" ] && [ "$n0" = "$n1" ] || printf '%s\n' "$out" | sed 's/^/#   /'
rm -rf "$tmp"
done_testing
