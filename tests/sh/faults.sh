# faults.sh -- write failures and a dying gnuplot end in a clear error, a
# usable session and nothing lost: the older file stays, no temporary file
# is left, what was computed is still there.  (Allocation failures:
# tests/c/test_fault_alloc; compiler failures: tests/c/test_native_faults;
# /dev/full and devices: tests/sh/file_targets.sh.)
. "$DMECH_SRCDIR/tests/sh/tap.sh"
D="$DMECH"
T="$DMECH_TESTTMP/faults"; rm -rf "$T"; mkdir -p "$T/tmp"
export TMPDIR="$T/tmp"
have_png=$("$D" -e 'local ok, t = pcall(dm._gp.terminals); print(ok and t:find("png") ~= nil)' 2>/dev/null)

# ---- RLIMIT_FSIZE: 40 blocks of 512 bytes ----------------------------------
cat > "$T/fsize.lua" <<'LUA'
local dir = arg[1]
local t, q = {}, {}
for i = 1, 20000 do t[i] = i * 0.001; q[i] = math.sin(2.385 * i) end
local big = dm.trajectory{t = t, coords = {"x"}, q = {x = q}}
assert(big:slice(1, 3):save(dir .. "/keep.csv"))
print("save", big:save(dir .. "/keep.csv"))
print("kept", #dm.load_trajectory(dir .. "/keep.csv"))
print("again", big:slice(1, 5):save(dir .. "/other.csv"))
if arg[2] == "true" then
  local f = io.open(dir .. "/p.png", "w") f:write("old") f:close()
  print("plot", pcall(dm.plot, { {t, q}, output = dir .. "/big.png" }))
  print("image", pcall(dm.plot, { {{0, 1, 2}, {1, 0, 1}}, output = dir .. "/p.png", size = {3000, 3000} }))
  local g = io.open(dir .. "/p.png") print("old image", g:read("a")) g:close()
  print("small", pcall(dm.plot, { {{0, 1, 2}, {1, 0, 1}}, output = dir .. "/small.png", size = {120, 90} }))
end
print("n", #big, big:column("x")[20000] == math.sin(2.385 * 20000))
LUA
out=$( (ulimit -f 40; "$D" "$T/fsize.lua" "$T" "$have_png" 2>&1) )
like "$out" "save	nil	writing '.*keep.csv': File too large" "save past RLIMIT_FSIZE: 'File too large', not killed by SIGXFSZ"
like "$out" "kept	3" "the older file is intact"
like "$out" "again	true" "the next save works"
if [ "$have_png" = true ]; then
  like "$out" "plot	false	dm.plot: cannot write plot data '.*': File too large" "plot data past the limit: clear error"
  like "$out" "image	false	dm.plot: plot output '.*p.png': the file gnuplot wrote is incomplete .*nothing was replaced" \
    "a PNG cut short by the limit is detected (gnuplot does not say)"
  like "$out" "old image	old" "... and the older image is kept"
  like "$out" "small	true" "a plot within the limit works afterwards"
else
  for i in 1 2 3 4; do skip "gnuplot without png"; done
fi
like "$out" "n	20000	true" "the trajectory computed before is intact"
is "$(ls -a "$T" | grep -c '\.tmp$')" 0 "no temporary file left"
is "$(ls -A "$TMPDIR" | grep -c '^dmech-')" 0 "no plot data directory left"

# ---- gnuplot dying: its input cut after 20 kB, then SIGKILL ---------------------
if [ "$have_png" = true ]; then
  gp=$(command -v gnuplot)
  printf '#!/bin/sh\nhead -c 20000 | %s "$@"\n' "$gp" > "$T/gp-cut"
  chmod +x "$T/gp-cut"
  cat > "$T/gpdie.lua" <<'LUA'
local dir = arg[1]
local x, y = {}, {}
for i = 1, 1500 do x[i] = i / 1500; y[i] = math.sin(2.385 * x[i]) end
local tr = dm.trajectory{t = x, coords = {"y"}, q = {y = y}}
assert(pcall(dm.plot, { {x, y}, output = dir .. "/a.png" }))
local f = io.open(dir .. "/a.png", "rb") local before = f:read("a") f:close()
dm._gp.stop()
dm._gp.program(arg[2])                    -- a gnuplot that loses its input
print("cut", pcall(dm.plot, { {x, y, with = "lines"}, output = dir .. "/a.png", title = "new" }))
f = io.open(dir .. "/a.png", "rb") print("same", f:read("a") == before) f:close()
dm._gp.stop()
dm._gp.program(false)
print("next", pcall(dm.plot, { {x, y}, output = dir .. "/b.png" }))
os.execute("kill -9 " .. dm._gp.pid() .. "; sleep 0.2")
print("killed", pcall(dm.plot, { {x, y}, output = dir .. "/c.png" }))
print("n", #tr, tr:column("y")[1500] == math.sin(2.385))
LUA
  out=$(DMECH_GNUPLOT_TIMEOUT=3 "$D" "$T/gpdie.lua" "$T" "$T/gp-cut" 2>&1)
  like "$out" "cut	false	dm.plot: gnuplot .*(did not answer within 3 s|exited)" "gnuplot losing its input mid-plot: a clear error"
  like "$out" "same	true" "... and the older PNG is untouched"
  like "$out" "next	true" "the next plot works (gnuplot restarted)"
  like "$out" "killed	true" "after gnuplot is killed the next plot restarts it and works"
  like "$out" "n	1500	true" "the data computed before are intact"
  is "$(ls -a "$T" | grep -c '\.tmp$')" 0 "no temporary file left"
else
  for i in 1 2 3 4 5 6; do skip "gnuplot without png"; done
fi
done_testing
