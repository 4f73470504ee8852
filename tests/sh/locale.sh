# locale.sh -- dmech loaded into a host program that sets LC_NUMERIC to a
# decimal-comma locale (de_DE): stock lua5.4 with os.setlocale, then
# require "dmech".  Every number dmech prints, writes into files, emits as
# native C source or puts into messages keeps '.', and reads back bit for
# bit.  The locale is generated with localedef when the system has none.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
LUA=${LUA54:-$(command -v lua5.4)}
if [ -z "$LUA" ]; then skip "lua5.4 not installed"; done_testing; fi
tmp="${DMECH_TESTTMP:-/tmp}/locale.$$"
mkdir -p "$tmp" || exit 1
trap 'rm -rf "$tmp"' EXIT
loc=""
for l in de_DE.UTF-8 de_DE.utf8 fr_FR.UTF-8 fr_FR.utf8 de_DE; do
  if "$LUA" -e "os.exit(os.setlocale('$l', 'numeric') and string.format('%.1f', 0.5) == '0,5' and 0 or 1)"; then
    loc=$l; break
  fi
done
if [ -z "$loc" ] && command -v localedef >/dev/null 2>&1 \
   && localedef -i de_DE -f UTF-8 "$tmp/de_DE.UTF-8" >/dev/null 2>&1; then
  LOCPATH=$tmp; export LOCPATH
  loc=de_DE.UTF-8
fi
if [ -z "$loc" ]; then
  skip "no decimal-comma locale on this system and localedef could not make one"
  done_testing
fi
XDG_CACHE_HOME="$tmp/cache"; export XDG_CACHE_HOME
so="$DMECH_BUILDDIR/src/.libs"
out=$("$LUA" -e "package.cpath='$so/?.so;'..package.cpath" -e "
  assert(os.setlocale('$loc', 'numeric'))
  local dm = require 'dmech'
  local function say(k, v) print(k .. '=' .. tostring(v)) end
  say('host', string.format('%.1f', 0.5))
  say('vec', dm.vec{0.5, 2.385})
  say('format_number', dm.format_number(2.385))
  say('pretty', dm.pretty(0.5))
  say('expr', dm.sym('x') * 2.385)
  -- native code with a constant whose hex form has a fraction (%a)
  local L = function(q, v) return 0.5 * v.x^2 - 2.385 * q.x^2 end
  local nat = dm.system{name = 'osc', coords = {'x'}, L = L, native = 'always'}
  local tape = dm.system{name = 'osc', coords = {'x'}, L = L, native = 'never'}
  local a = dm.integrator(nat, {method = 'gauss', h = 0.1}):run({q = {1}, p = {0}}, {steps = 50})
  local b = dm.integrator(tape, {method = 'gauss', h = 0.1}):run({q = {1}, p = {0}}, {steps = 50})
  say('native', tostring(nat.native) .. ' ' .. tostring(math.abs(a:column('x')[51] - b:column('x')[51]) < 1e-13))
  -- a message with numbers from the core
  local kep = dm.systems.kepler()
  local _, msg = dm.integrator(kep, {method = 'gauss', h = 0.8}):run({q = {-1.6, 0}, p = {0, 0.5}}, {steps = 100})
  say('message', msg:match('t = [^ ]*'))
  local ok, err = pcall(dm.integrator, kep, {tol = 0.5})
  say('option', err:match('= [^ ]*'))
  -- a file: numbers and numeric metadata round-trip
  local tr = dm.integrator(kep, {method = 'gauss', h = 0.05}):run({q = {0.4, 0}, p = {0, 2}}, {steps = 20})
  assert(tr:save('$tmp/t.csv'))
  local back = dm.load_trajectory('$tmp/t.csv')
  local same = #back == #tr
  for _, c in ipairs(tr:names()) do
    local x, y = tr:column(c), back:column(c)
    for k = 1, #tr do same = same and x[k] == y[k] end
  end
  say('roundtrip', tostring(same) .. ' ' .. tostring(back:meta().h == 0.05))
  local f = io.open('$tmp/t.csv'):read('a')
  say('file', f:find('%d,%d+e') == nil and f:find('# number h=0.05', 1, true) ~= nil)
" 2>&1)
printf '%s\n' "$out" | sed 's/^/# /'
val() { printf '%s\n' "$out" | sed -n "s/^$1=//p"; }
is "$(val host)" "0,5" "the host's LC_NUMERIC=$loc prints 0.5 as 0,5"
is "$(val vec)" "vec{0.5, 2.385}" "tostring(vec) keeps '.'"
is "$(val format_number)" "2.385" "dm.format_number keeps '.'"
is "$(val pretty)" "0.5" "the pretty printer keeps '.'"
is "$(val expr)" "2.385*x" "expressions print with '.'"
is "$(val native)" "true true" "native code with a constant 2.385 compiles and equals the tape"
is "$(val message)" "t = 2.4000000000000004" "core messages format numbers with '.'"
is "$(val option)" "= 0.5" "option range messages too"
is "$(val roundtrip)" "true true" "save and load round-trip every number and numeric metadata"
is "$(val file)" "true" "the file has '.' decimals and a '# number h=0.05' line"
done_testing
