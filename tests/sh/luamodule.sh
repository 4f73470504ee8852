# luamodule.sh -- stock lua5.4 can `require "dmech"` through the C module.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
LUA=${LUA54:-$(command -v lua5.4)}
if [ -z "$LUA" ]; then skip "lua5.4 not installed"; done_testing; fi
so="$DMECH_BUILDDIR/src/.libs"
out=$("$LUA" -e "package.cpath='$so/?.so;'..package.cpath" -e '
  local dm = require "dmech"
  local v = dm.vec{3, 4}
  print(v:norm(), type(dm.help), dm == require "dmech", dm.mat{{2,1},{1,3}}:det())' 2>&1)
is "$out" "5.0	function	true	5.0" "require \"dmech\" from lua5.4"
out=$("$LUA" -e "package.cpath='$so/?.so;'..package.cpath" -e 'print(require("dmech").vec(2):norm())' 2>&1)
is "$out" "0.0" "module functions work"
out=$(DMECH_PATH=/nonexistent "$LUA" -e "package.cpath='$so/?.so;'..package.cpath" -e 'print(type(require("dmech").pretty))' 2>&1)
is "$out" "function" "Lua-side library found through the compiled-in directories"
done_testing
