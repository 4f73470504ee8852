# cli.sh -- the dmech command line is compatible with lua's.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
D="$DMECH"
T="$DMECH_TESTTMP/cli"; mkdir -p "$T"

cat > "$T/args.lua" <<'LUA'
print(#arg, arg[0] ~= nil, arg[1], arg[2], select("#", ...), ...)
LUA
out=$("$D" "$T/args.lua" a 2.385 2>&1); is "$out" "2	true	a	2.385	2	a	2.385" "script receives arg and ..."
out=$("$D" -e 'print(1 + 1)' 2>&1); is "$out" "2" "-e runs a statement"
out=$("$D" -e 'x = 2.385' -e 'print(x * 2)' 2>&1); is "$out" "4.77" "several -e in order"
out=$("$D" -l string -e 'print(type(string.format))' 2>&1); is "$out" "function" "-l loads a module"
out=$("$D" -l m=math -e 'print(m.pi > 3)' 2>&1); is "$out" "true" "-l g=mod"
out=$("$D" -v 2>&1); like "$out" "^dmech 0\.1\.0 \(Lua 5\.4" "-v prints the version"
out=$("$D" --help 2>&1); st=$?; like "$out" "usage: .*dmech.*script" "--help prints usage"; is "$st" 0 "--help exits 0"
out=$("$D" -z 2>&1); st=$?; like "$out" "unrecognized option '-z'" "unknown option"; is "$st" 1 "unknown option exits 1"
out=$("$D" -e 2>&1); st=$?; like "$out" "'-e' needs argument" "-e without argument"; is "$st" 1 "exit 1"
out=$(echo 'print(arg and #arg, 6 * 7)' | "$D" - 2>&1); is "$out" "0	42" "- runs stdin"
out=$(echo 'print(6 * 7)' | "$D" 2>&1); is "$out" "42" "no script and piped stdin runs it"
out=$("$D" -e 'print(dm == require "dmech", type(dm.vec), type(help), type(apropos))' 2>&1)
is "$out" "true	function	function	function" "dm, help and apropos are globals; require returns dm"

cat > "$T/fail.lua" <<'LUA'
local function inner() error("density must be positive, got -2.385") end
inner()
LUA
out=$("$D" "$T/fail.lua" 2>&1 >/dev/null); st=$?
like "$out" "fail.lua:1: density must be positive, got -2.385" "error message on stderr"
like "$out" "stack traceback:" "with a traceback"
like "$out" "in (local|upvalue) 'inner'" "traceback names the function"
is "$st" 1 "error exits 1"
out=$("$D" "$T/nonexistent.lua" 2>&1); st=$?; like "$out" "cannot open .*nonexistent.lua" "missing script"; is "$st" 1 "missing script exits 1"
printf 'x = = 1\n' > "$T/syntax.lua"
out=$("$D" "$T/syntax.lua" 2>&1); st=$?; like "$out" "syntax.lua:1: unexpected symbol" "syntax error"; is "$st" 1 "syntax error exits 1"
out=$("$D" -e 'error({})' 2>&1); like "$out" "error object is a table value" "non-string error object"

out=$(DMECH_INIT='init_seen = 2.385' "$D" -e 'print(init_seen)' 2>&1); is "$out" "2.385" "DMECH_INIT runs first"
out=$(LUA_INIT='init_seen = 7' "$D" -e 'print(init_seen)' 2>&1); is "$out" "7" "LUA_INIT runs when DMECH_INIT is unset"
out=$(DMECH_INIT='a = 1' LUA_INIT='a = 2' "$D" -e 'print(a)' 2>&1); is "$out" "1" "DMECH_INIT takes precedence"
echo 'from_file = "yes"' > "$T/init.lua"
out=$(LUA_INIT="@$T/init.lua" "$D" -e 'print(from_file)' 2>&1); is "$out" "yes" "LUA_INIT=@file"
out=$(LUA_INIT='x = 1' "$D" -E -e 'print(x)' 2>&1); is "$out" "nil" "-E ignores the environment"
out=$(DMECH_INIT='error("bad init")' "$D" -e 'print(1)' 2>&1); st=$?; like "$out" "bad init" "failing init reported"; is "$st" 1 "failing init exits 1"

mkdir -p "$T/lib/dmech"
echo 'return { answer = 42 }' > "$T/lib/dmech/extra.lua"
out=$(DMECH_PATH="$T/lib:$DMECH_PATH" "$D" -e 'print(require("dmech.extra").answer)' 2>&1); is "$out" "42" "DMECH_PATH is searched for dmech modules"
out=$(DMECH_PATH= "$D" -e 'print(type(dm.help))' 2>&1); is "$out" "function" "the build tree's dmech finds the source lua/ without DMECH_PATH"
# nothing of the source or build tree is compiled in: the same binary
# outside its build tree (no dmech-uninstalled.path beside it) searches only
# the installed directory
mkdir -p "$T/bin"
cp "$D" "$T/bin/dmech"
out=$(DMECH_PATH= "$T/bin/dmech" -e 'print(package.path)' 2>&1)
case "$out" in
  *"$DMECH_SRCDIR/lua/"*) ok 1 "a copy outside the build tree does not search it";
    printf '%s\n' "$out" | head -3 | sed 's/^/#   /';;
  *) ok 0 "a copy outside the build tree does not search it";;
esac
out=$(DMECH_PATH="$DMECH_SRCDIR/lua" "$T/bin/dmech" -e 'print(type(dm.help))' 2>&1)
is "$out" "function" "the copy works with DMECH_PATH"

out=$(printf '1 + 1\n' | "$D" -i -e "_PROMPT='' _PROMPT2=''" 2>&1); like "$out" "^2$" "-i with piped stdin runs the REPL"
out=$(printf 'print(7)\n' | "$D" -e "_PROMPT='P> '" -i 2>&1); like "$out" "P> 7" "prompt from _PROMPT on a non-terminal"
done_testing
