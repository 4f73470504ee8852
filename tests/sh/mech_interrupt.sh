# mech_interrupt.sh -- Ctrl-C during integ:run stops the C loop, returns the
# partial trajectory and a message saying where it stopped, and the script
# goes on; progress=true draws a progress line on stderr for long runs.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
D="$DMECH"
T="$DMECH_TESTTMP/mech_interrupt"; mkdir -p "$T"

cat > "$T/long.lua" <<'LUA'
local I = dm.integrator(dm.systems.kepler{impl = "c"}, {method = "trapezoid", h = 0.01})
local tr, msg = I:run({q = {0.4, 0}, p = {0, 2}}, {steps = 4000000000, every = 1000000, progress = true})
print(tr ~= nil, #tr > 1, tr:column("t")[#tr] > 0)
print(msg)
local x = I:step{q = {0.4, 0}, p = {0, 2}}
print("after the run", x.t)
LUA
rm -f "$T/out" "$T/err"     # the child creates them: never read a stale file
"$D" "$T/long.lua" > "$T/out" 2> "$T/err" &
pid=$!
i=0
while [ $i -lt 200 ] && ! grep -q "run: step" "$T/err" 2>/dev/null; do sleep 0.05; i=$((i + 1)); done
kill -INT $pid 2>/dev/null
wait $pid; st=$?
out=$(cat "$T/out"); err=$(cat "$T/err")
like "$err" "run: step [0-9]+/4000000000 \( *[0-9.]+%\)  t = .* steps/s  ETA" "progress line on stderr"
is "$st" 0 "the script finished normally after Ctrl-C"
like "$out" "^true	true	true" "the partial trajectory is returned"
like "$out" "run: interrupted after step [0-9]+ of 4000000000 \(t = [0-9.e+]+\); the trajectory up to there is kept" \
  "the message says where the run stopped"
like "$out" "after the run	0.01" "the session goes on (the interrupt was consumed)"
if printf '%s\n' "$err" | grep -q "interrupted!"; then ok 1 "no Lua 'interrupted!' error"; else ok 0 "no Lua 'interrupted!' error"; fi

out=$("$D" -e 'local tr = dm.integrator(dm.systems.kepler{impl = "c"}, {h = 0.01, method = "trapezoid"}):run({q = {0.4, 0}, p = {0, 2}}, {steps = 1000}); print(#tr)' 2>&1)
is "$out" "1001" "short runs print no progress (stdout not a terminal)"
done_testing
