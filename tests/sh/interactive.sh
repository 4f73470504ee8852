# interactive.sh -- `dmech -i script.lua`: the script's top-level locals and
# globals are there at the prompt, also after an error in the script (shown
# with its traceback; the exit status is then 1, as python -i does).
. "$DMECH_SRCDIR/tests/sh/tap.sh"
D="$DMECH"
T="$DMECH_TESTTMP/interactive"; mkdir -p "$T"

cat > "$T/ok.lua" <<'LUA'
local sys = dm.systems.kepler()
local h = 2.385
g = 7
local function twice(x) return 2 * x end
LUA
out=$(printf 'h\ng\ntwice(h)\nsys.coords\n' | "$D" -e "_PROMPT='' _PROMPT2=''" -i "$T/ok.lua" 2>&1 | grep -v '^dmech [0-9]')
is "$out" "2.385
7
4.77
{\"x\", \"y\"}" "the script's locals and globals at the prompt"

cat > "$T/fail.lua" <<'LUA'
local mass = 2.385
local function inner(t) return t.missing.field end
inner({})
local after = 1
LUA
out=$(printf 'mass\nafter\n' | "$D" -e "_PROMPT='' _PROMPT2=''" -i "$T/fail.lua" 2>&1 | grep -v '^dmech [0-9]'); st=$?
like "$out" "fail.lua:2: attempt to index a nil value \(field 'missing'\)" "the script's error is shown"
like "$out" "in (local|upvalue|function) 'inner'" "with its traceback"
like "$out" "^2.385$" "the prompt follows, with the locals defined before the error"
like "$out" "^nil$" "a local after the error is not defined"
printf 'x = 1\n' | "$D" -i "$T/fail.lua" >/dev/null 2>&1; st=$?
is "$st" 1 "exit status 1 after a failed script"
printf 'x = 1\n' | "$D" -i "$T/ok.lua" >/dev/null 2>&1; st=$?
is "$st" 0 "exit status 0 after a good one"
out=$("$D" "$T/fail.lua" 2>&1); st=$?
is "$st" 1 "without -i the failed script ends the program"

# a prompt chunk's top-level locals stay, as in IPython
out=$(printf 'local a = 2.385\na * 2\nlocal function f() return 6 * 7 end\nf()\n' | "$D" -e "_PROMPT='' _PROMPT2=''" -i 2>&1 | grep -v '^dmech [0-9]')
is "$out" "4.77
42" "locals of prompt chunks stay defined"
done_testing
