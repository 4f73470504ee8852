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
is "$out" "function" "the build tree's module finds the source lua/ (dmech-uninstalled.path)"
tmp="${DMECH_TESTTMP:-/tmp}/luamodule.$$"
mkdir -p "$tmp/lib" && cp "$so/dmech.so" "$tmp/lib/dmech.so"
out=$(DMECH_PATH= "$LUA" -e "package.cpath='$tmp/lib/?.so'" -e 'pcall(require, "dmech") io.write(package.path)' 2>&1)
case "$out" in
  *"$DMECH_SRCDIR/lua/"*) ok 1 "a copy of dmech.so outside the build tree does not search it";
    printf '%s\n' "$out" | head -3 | sed 's/^/#   /';;
  *) ok 0 "a copy of dmech.so outside the build tree does not search it";;
esac
out=$(DMECH_PATH="$DMECH_SRCDIR/lua" "$LUA" -e "package.cpath='$tmp/lib/?.so'" -e 'print(type(require("dmech").pretty))' 2>&1)
is "$out" "function" "the copy works with DMECH_PATH"
rm -rf "$tmp"
done_testing
