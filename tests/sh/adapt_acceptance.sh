# adapt_acceptance.sh -- the variable-step acceptance script, run as a user
# writes it (a file given to dmech, dm global): the time-transformed Gauss
# method on the Kepler orbit e = 0.9 ends at t = 20 pi with a bounded energy
# error, and the energy-momentum method prints positive, bounded steps.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
T="$DMECH_TESTTMP/adapt_acceptance"; rm -rf "$T"; mkdir -p "$T"; cd "$T" || exit 1
cat > accept.lua <<'EOF'
local kep = dm.systems.kepler()
local I = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.02,
  adapt = {monitor = function(q, p) return dm.sqrt(q.x^2 + q.y^2)^1.5 end}})   -- Sundman-type
local tr = I:run({q = {0.1, 0}, p = {0, math.sqrt(19)}}, {t = 20*math.pi})    -- e = 0.9, 10 periods
print(#tr, tr:column("t")[#tr], tr:energy():max() - tr:energy():min())
local pend = dm.system{coords = {"q"}, L = function(q, v) return 0.5*v.q^2 + dm.cos(q.q) end}
local S = dm.integrator(pend, {method = "sem", h = 0.1}):run({q = {1}, p = {0.5}}, {t = 10})
print(S:column("h"))            -- the variable steps; the discrete energy is constant
EOF
"$DMECH" accept.lua > out.txt 2> err.txt
is "$?" 0 "the script runs"
is "$(cat err.txt)" "" "nothing on stderr"
is "$(wc -l < out.txt | tr -d ' ')" 2 "two lines printed"
line1=$(sed -n 1p out.txt)
like "$line1" '^[0-9]+	62\.831853071796	[0-9.e+-]+$' "samples, t = 20 pi, energy spread: $line1"
set -- $line1
awk -v n="$1" 'BEGIN { exit !(n > 1000 && n < 10000) }'; ok $? "between 1000 and 10000 samples ($1)"
awk -v d="$3" 'BEGIN { exit !(d > 0 && d < 1e-8) }'; ok $? "energy error over 10 periods below 1e-8 ($3)"
line2=$(sed -n 2p out.txt)
like "$line2" '^vec\{0\.1, [0-9]' "the h column is a vec starting at h0 = 0.1"
# a long vec prints its first 100 entries and "... (length)"
printf '%s\n' "$line2" | sed 's/^vec{//; s/}$//' | tr ',' '\n' | grep -v '\.\.\.' > h.txt
len=$(printf '%s\n' "$line2" | sed -n 's/.*\.\.\. (\([0-9]*\)).*/\1/p')
awk -v n="$len" 'BEGIN { exit !(n > 95 && n < 130) }'; ok $? "about 100 steps to t = 10 ($len)"
awk '{ if ($1 <= 0.08 || $1 > 0.11) bad++ } END { print NR, bad + 0 }' h.txt > hstat.txt
read -r nh bad < hstat.txt
is "$nh" 100 "100 steps printed"
is "$bad" 0 "every printed step in (0.08, 0.11]"
done_testing
