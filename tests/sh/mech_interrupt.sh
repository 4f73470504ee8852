# mech_interrupt.sh -- Ctrl-C during integ:run stops the C loop and keeps the
# partial trajectory.  In a script (no prompt) the script then stops with
# exit status 130, after a warning saying where the run stopped; with
# dm.config.interrupt = "run" only the run ends and the script goes on with
# the partial trajectory (tr.status "interrupted", the message as second
# value).  progress=true draws a progress line on stderr for long runs.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
D="$DMECH"
T="$DMECH_TESTTMP/mech_interrupt"; mkdir -p "$T"

# Run the script $1 in the background, Ctrl-C once the progress line shows.
interrupt() {
  rm -f "$T/out" "$T/err"     # the child creates them: never read a stale file
  "$D" "$1" > "$T/out" 2> "$T/err" &
  pid=$!
  i=0
  while [ $i -lt 200 ] && ! grep -q "run: step" "$T/err" 2>/dev/null; do sleep 0.05; i=$((i + 1)); done
  kill -INT $pid 2>/dev/null
  wait $pid; st=$?
  out=$(cat "$T/out"); err=$(cat "$T/err")
}

cat > "$T/long.lua" <<'LUA'
local I = dm.integrator(dm.systems.kepler{impl = "c"}, {method = "trapezoid", h = 0.01})
local tr, msg = I:run({q = {0.4, 0}, p = {0, 2}}, {steps = 4000000000, every = 1000000, progress = true})
print("after the run")
LUA
interrupt "$T/long.lua"
like "$err" "run: step [0-9]+/4000000000 \( *[0-9.]+%\)  t = .* steps/s  ETA" "progress line on stderr"
is "$st" 130 "a script stops at Ctrl-C: exit 130"
like "$err" "interrupted \(Ctrl-C\): the script stops here" "saying why"
if printf '%s\n' "$out" | grep -q "after the run"; then ok 1 "nothing after the run ran"; else ok 0 "nothing after the run ran"; fi

cat > "$T/goon.lua" <<'LUA'
dm.config.interrupt = "run"
local I = dm.integrator(dm.systems.kepler{impl = "c"}, {method = "trapezoid", h = 0.01})
local tr, msg = I:run({q = {0.4, 0}, p = {0, 2}}, {steps = 4000000000, every = 1000000, progress = true})
print(tr ~= nil, #tr > 1, tr:column("t")[#tr] > 0)
print(msg)
print(tr.status)
local x = I:step{q = {0.4, 0}, p = {0, 2}}
print("after the run", x.t)
LUA
interrupt "$T/goon.lua"
is "$st" 0 "with dm.config.interrupt = \"run\" the script finishes normally"
like "$out" "^true	true	true" "the partial trajectory is returned"
like "$out" "run: interrupted after step [0-9]+ of 4000000000 \(t = [0-9.e+]+\); the trajectory up to there is kept" \
  "the message says where the run stopped"
like "$out" "^interrupted$" "tr.status says it was interrupted"
like "$err" "warning: run ended early \(interrupted\): interrupted after step" "a warning on stderr"
like "$out" "after the run	0.01" "the session goes on (the interrupt was consumed)"
if printf '%s\n' "$err" | grep -q "interrupted!"; then ok 1 "no Lua 'interrupted!' error"; else ok 0 "no Lua 'interrupted!' error"; fi

out=$("$D" -e 'local tr = dm.integrator(dm.systems.kepler{impl = "c"}, {h = 0.01, method = "trapezoid"}):run({q = {0.4, 0}, p = {0, 2}}, {steps = 1000}); print(#tr)' 2>&1)
is "$out" "1001" "short runs print no progress (stdout not a terminal)"
done_testing
