# exit_paths.sh -- what dmech leaves behind and reports when it ends:
# output that could not be written is an error (exit 1), and temporary
# directories and compiler processes go away on every exit path (normal
# end, os.exit, Ctrl-C, SIGTERM).
. "$DMECH_SRCDIR/tests/sh/tap.sh"
D="$DMECH"
T="$DMECH_TESTTMP/exit_paths"; rm -rf "$T"; mkdir -p "$T/tmp"
export TMPDIR="$T/tmp"
count_tmp() { ls -A "$TMPDIR" | grep -c '^dmech-'; }
alive() { [ -e "/proc/$1/stat" ] && ! awk '{ exit !($3 == "Z") }' "/proc/$1/stat"; }
wait_gone() { i=0; while alive "$1" && [ $i -lt 200 ]; do sleep 0.01; i=$((i + 1)); done; ! alive "$1"; }
wait_file() { i=0; while [ ! -s "$1" ] && [ $i -lt 1000 ]; do sleep 0.01; i=$((i + 1)); done; [ -s "$1" ]; }

# ---- lost output -------------------------------------------------------------
out=$("$D" -e 'print("2.385")' 2>&1 >/dev/full); st=$?
is "$st" 1 "print to a full stdout: exit 1"
like "$out" "write error on standard output" "... with a message on stderr"
out=$("$D" -e 'io.write(string.rep("x", 100000)) os.exit(0)' 2>&1 >/dev/full); st=$?
is "$st" 1 "os.exit(0) after output to a full stdout: exit 1"
out=$("$D" -e 'print("2.385")' 2>&1 >&-); st=$?
is "$st" 1 "print with stdout closed: exit 1"
like "$out" "write error on standard output" "... with a message"
"$D" -e 'local x = 2.385' >&-; is $? 0 "stdout closed but never written: exit 0"
"$D" -e 'print(2.385)' > "$T/ok.txt"; is "$?$(cat "$T/ok.txt")" "02.385" "normal output: exit 0"

# ---- plot data directories ---------------------------------------------------------
have_png=$("$D" -e 'local ok, t = pcall(dm._gp.terminals); print(ok and t:find("png") ~= nil)' 2>/dev/null)
if [ "$have_png" = true ]; then
  big='local x, y = {}, {} for i = 1, 3000 do x[i] = i / 3000; y[i] = math.sin(7 * x[i]) end'
  "$D" -e "$big dm.plot{ {x, y}, output = '$T/a.png' } os.exit(0)"
  is "$?$(count_tmp)" "00" "os.exit after a large plot: no plot data directory left"
  "$D" -e "$big dm.plot{ {x, y}, output = '$T/b.png' } os.exit(3, true)"
  is "$?$(count_tmp)" "30" "os.exit(3, true): exit 3, nothing left"
  "$D" -e "$big dm.plot{ {x, y}, output = '$T/c.png' } io.write('ready\n') io.flush() while true do end" > "$T/ready" &
  pid=$!
  wait_file "$T/ready"; kill -TERM $pid; wait $pid; st=$?
  is "$st/$(count_tmp)" "143/0" "SIGTERM after a large plot: dies of SIGTERM, no directory left"
else
  for i in 1 2 3; do skip "gnuplot without png"; done
fi

# ---- a compiler that is stopped ------------------------------------------------------
cat > "$T/fakecc" <<EOF
#!/bin/sh
case "\$*" in *--version*) echo "fakecc \$\$ 1.0"; exit 0;; esac
sleep 300 &
echo \$! > "$T/cc1.pid"
wait
EOF
chmod +x "$T/fakecc"
cat > "$T/compile.lua" <<'LUA'
local ok, err = pcall(dm.system, {coords = {"q"}, native = "always",
  L = function(q, v) return 0.5 * v.q^2 - 2.385 * q.q^4 end})
print(ok, err)
print("still here", dm.vec{3, 4}:norm())
LUA
rm -f "$T/cc1.pid"
CC="$T/fakecc" "$D" "$T/compile.lua" > "$T/int.out" 2>&1 & pid=$!
wait_file "$T/cc1.pid"; cc1=$(cat "$T/cc1.pid")
kill -INT $pid; wait $pid; st=$?
is "$st" 130 "Ctrl-C during a compile stops the script (also through its pcall): exit 130"
like "$(cat "$T/int.out")" "compile.lua:1: interrupted \(Ctrl-C\)" "... with 'interrupted (Ctrl-C)'"
wait_gone "$cc1"; ok $? "... the compiler's child is killed"
is "$(count_tmp)" 0 "... no build directory left"
rm -f "$T/cc1.pid"
CC="$T/fakecc" "$D" "$T/compile.lua" > /dev/null 2>&1 & pid=$!
wait_file "$T/cc1.pid"; cc1=$(cat "$T/cc1.pid")
kill -TERM $pid; wait $pid; st=$?
is "$st" 143 "SIGTERM during a compile: dmech dies of SIGTERM"
wait_gone "$cc1"; ok $? "... and the compiler's child with it"
is "$(count_tmp)" 0 "... no build directory left"
done_testing
