# ensemble_interrupt.sh -- Ctrl-C during dm.ensemble: the members in flight
# stop, no more start, and the table of every finished member comes back
# (with dm.config.interrupt = "run"; by default the script then stops with
# status 130, as after any run).  progress = true draws the progress line.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
T="$DMECH_TESTTMP/ensemble_interrupt"; mkdir -p "$T"
cat > "$T/long.lua" <<'LUA'
dm.config.interrupt = "run"
local I = dm.integrator(dm.systems.kepler{impl = "c"}, {method = "gauss", h = 0.01})
local res, msg = dm.ensemble{integrator = I, members = 400, threads = 2, progress = true,
  run = {steps = 300000}, reduce = {"final"},
  states = function(k) return {q = {0.5 + 0.001 * k, 0}, p = {0, 1.3}} end}
local done, stopped, notrun = 0, 0, 0
for k = 1, #res do
  if res[k].status == 0 then done = done + 1
  elseif res[k].t == res[k].t then stopped = stopped + 1 else notrun = notrun + 1 end
end
print(#res, done + stopped + notrun, msg)
print("finished", done, "stopped", stopped, "not run", notrun)
LUA
rm -f "$T/out" "$T/err"
"$DMECH" "$T/long.lua" > "$T/out" 2> "$T/err" &
pid=$!
i=0
while [ $i -lt 600 ] && ! grep -q "ensemble: [1-9][0-9]*/400 members" "$T/err" 2>/dev/null; do
  sleep 0.05; i=$((i + 1)); done
kill -INT $pid 2>/dev/null
wait $pid; st=$?
out=$(cat "$T/out"); err=$(cat "$T/err")
like "$err" "ensemble: [0-9]+/400 members \( *[0-9.]+%\), 0 failed .* members/s  ETA" \
  "a progress line on stderr"
is "$st" 0 "with dm.config.interrupt = \"run\" the script goes on"
like "$out" "^400	400	dm.ensemble: interrupted: [0-9]+ of 400 members finished; they are kept" \
  "the whole table comes back with the message"
like "$out" "finished	[1-9][0-9]*	stopped	[0-9]+	not run	[1-9][0-9]*" \
  "finished members kept, the members in flight stopped, the rest not run"
like "$err" "warning: dm.ensemble: interrupted" "a warning on stderr"
rm -rf "$T"
done_testing
