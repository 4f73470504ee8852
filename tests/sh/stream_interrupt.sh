# stream_interrupt.sh -- Ctrl-C during integ:run{sink = "file.h5"}: the HDF5
# file written in blocks appears at its path, complete up to the last sample
# streamed (every block, then the samples held at the interrupt), and says
# that the run was interrupted (status, message, steps), also when the
# script itself stops there (exit 130); no temporary file is left.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
D="$DMECH"
T="$DMECH_TESTTMP/stream_interrupt"; mkdir -p "$T"

# Run the script $1 in the background, Ctrl-C once the progress line shows.
interrupt() {
  rm -f "$T/out" "$T/err"
  "$D" "$1" > "$T/out" 2> "$T/err" &
  pid=$!
  i=0
  while [ $i -lt 200 ] && ! grep -q "run: step" "$T/err" 2>/dev/null; do sleep 0.05; i=$((i + 1)); done
  sleep 0.3
  kill -INT $pid 2>/dev/null
  wait $pid; st=$?
}

# the file: samples every 50 steps (t = 0, 0.5, 1, ...) without a gap, then
# the state at the interrupt (step m.steps, at most 50 steps later), the
# run's status and message
check='local tr = dm.load_trajectory(arg[1])
local m, n = tr:meta(), #tr
local good, t = n > 10, tr:column("t")     -- once: tr.t builds the column at each use
for k = 1, n - 1 do good = good and math.abs(t[k] - (k - 1) * 0.5) <= 1e-12 * k end
local last = math.abs(t[n] - m.steps * 0.01) <= 1e-12 * m.steps
  and m.steps > (n - 2) * 50 and m.steps <= (n - 1) * 50
print(n > 10, good, tr.status, (m.message or ""):match("interrupted") ~= nil, last)'
printf '%s\n' "$check" > "$T/check.lua"

for mode in script run; do
  rm -f "$T/$mode.h5"
  cat > "$T/$mode.lua" <<LUA
dm.config.native = "never"
if "$mode" == "run" then dm.config.interrupt = "run" end
local I = dm.integrator(dm.systems.kepler{impl = "c"}, {method = "trapezoid", h = 0.01})
local tr, msg = I:run({q = {0.4, 0}, p = {0, 2}}, {steps = 4000000000, every = 50, progress = true,
                      sink = "$T/$mode.h5", sink_every = 1000})
print("after the run", #tr)
LUA
  interrupt "$T/$mode.lua"
  if [ "$mode" = script ]; then
    is "$st" 130 "a script stops at Ctrl-C (exit 130)"
  else
    is "$st" 0 "with interrupt = \"run\" the script goes on"
    like "$(cat "$T/out")" "^after the run	1$" "the run returns the last sample"
  fi
  out=$("$D" "$T/check.lua" "$T/$mode.h5" 2>&1)
  is "$out" "true	true	interrupted	true	true" \
    "$mode: the streamed file holds every sample up to the interrupt and says so"
  left=$(ls -a "$T" | grep -c '\.tmp' || true)
  is "$left" 0 "$mode: no temporary file left"
done
done_testing
