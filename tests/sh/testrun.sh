# testrun.sh -- `dmech test`: a directory of passing, failing, erroring and
# skipped files gives the counts, the exit status, the same report serially
# and in parallel, TAP that prove accepts; options, odd endings, interrupts,
# and the example suite in examples/tests passes.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
D="$DMECH"
# hidden: `dmech test` at the top of an in-tree build must not find these
T="$DMECH_TESTTMP/.testrun"; rm -rf "$T"; mkdir -p "$T/suite/sub" "$T/suite/.hidden"
cd "$T" || exit 1

cat > suite/pass_test.lua <<'LUA'
local T = dm.test
T.near(2.385 * 2, 4.77, 1e-15, "doubling")
T.near(dm.vec{1, 2.385}, {1, 2.385}, {abs = 0}, "vector")
T.skip("nothing to do here")
T.todo("known", function() T.ok(false, "not yet") end)
LUA
cat > suite/fail_test.lua <<'LUA'
local T = dm.test
T.ok(true, "fine")
T.near(0.1 + 0.2, 0.3, 1e-17, "sum")
io.stderr:write("a warning on stderr\n")
T.is(2.385, 2.386, "equal")
LUA
cat > suite/error_test.lua <<'LUA'
local T = dm.test
T.ok(true, "before")
local x = nil
print(x.field)
LUA
cat > suite/skip_test.lua <<'LUA'
dm.test.skip_all("needs a quantum computer")
LUA
cat > suite/sub/nested_test.lua <<'LUA'
dm.test.group("nested", function()
  dm.test.is(#"2.385", 5, "length")
end)
LUA
echo 'error("not a test file: must not run")' > suite/helper.lua
echo 'error("in a hidden directory: must not run")' > suite/.hidden/x_test.lua

norm() { sed -E 's/[0-9]+\.[0-9]+ s/T s/g; s/[0-9]+ jobs?\)/J jobs)/' | grep -v '^slowest: '; }

cat > want.txt <<'EOF'
ERROR suite/error_test.lua (raised an error after 1 test; T s)
      stderr:
      | suite/error_test.lua:4: attempt to index a nil value (local 'x')
      | stack traceback:
      | 	suite/error_test.lua:4: in main chunk
FAIL  suite/fail_test.lua (2 of 3 tests failed; T s)
      not ok 2 - sum
      #   at suite/fail_test.lua:3
      #   got:     0.30000000000000004
      #   want:    0.3
      #   |diff|:  5.55e-17
      #   allowed: 1e-17 = tol 1e-17 x max(1, |want|)
      not ok 3 - equal
      #   at suite/fail_test.lua:5
      #   got:  2.385
      #   want: 2.386
      stderr:
      | a warning on stderr
PASS  suite/pass_test.lua (4 tests, 1 skipped, 1 todo; T s)
SKIP  suite/skip_test.lua (needs a quantum computer)
PASS  suite/sub/nested_test.lua (1 test; T s)
5 passed, 2 failed, 1 skipped, 1 todo; 5 files: 2 passed, 1 failed, 1 errored, 1 skipped (T s, J jobs)
EOF

"$D" test -j 2 suite > par.txt 2> par.err; st=$?
is "$st" 1 "a failing suite exits 1"
norm < par.txt > par.norm
if cmp -s want.txt par.norm; then ok 0 "the report: per file in order, failures with file:line, values, tolerance; summary"
else ok 1 "the report"; diff want.txt par.norm | head -30 | sed 's/^/#   /'; fi
is "$(cat par.err)" "" "nothing on stderr"
like "$(cat par.txt)" "^slowest: [0-9]+\.[0-9]{2} s suite/[a-z/]+_test\.lua, [0-9.]+ s suite/[a-z/]+_test\.lua, [0-9.]+ s suite/[a-z/]+_test\.lua$" \
  "the three slowest files"
like "$(cat par.txt)" "\(T? ?[0-9.]+ s, 2 jobs\)" "two jobs"
"$D" test -j1 suite > ser.txt 2>&1; st=$?
is "$st" 1 "serial run exits 1"
norm < ser.txt > ser.norm
if cmp -s par.norm ser.norm; then ok 0 "serial and parallel runs give the same report"
else ok 1 "serial and parallel runs give the same report"; diff par.norm ser.norm | head | sed 's/^/#   /'; fi
like "$(cat ser.txt)" "\(T? ?[0-9.]+ s, 1 job\)" "one job"

# files run at the same time: two files that wait for each other pass with -j2
mkdir -p meet
for me in a b; do
  other=$([ $me = a ] && echo b || echo a)
  cat > meet/${me}_test.lua <<LUA
io.open("$T/meet/$me.here", "w"):close()
local seen = false
for _ = 1, 500 do
  local f = io.open("$T/meet/$other.here")
  if f then f:close(); seen = true; break end
  os.execute("sleep 0.02")
end
dm.test.ok(seen, "$me met $other")
LUA
done
out=$("$D" test -j2 meet 2>&1); st=$?
is "$st" 0 "-j2 runs two files at once (they wait for each other)"
like "$out" "^2 passed, 0 failed; 2 files: 2 passed" "both met"

# TAP: one stream, renumbered, named by file; prove reads it
"$D" test --tap suite > tap.txt 2>&1; st=$?
is "$st" 1 "--tap exits 1 on failure"
is "$(grep -c '^ok \|^not ok ' tap.txt)" 11 "--tap: 11 test lines"
like "$(cat tap.txt)" "^1\.\.11$" "--tap: plan 1..11"
like "$(cat tap.txt)" "^not ok 2 - suite/error_test\.lua: raised an error after 1 test$" "--tap: an error is a failing test"
like "$(cat tap.txt)" "^not ok 4 - suite/fail_test\.lua: sum$" "--tap: failures named by file"
like "$(cat tap.txt)" "^not ok 9 - suite/pass_test\.lua: not yet # TODO known$" "--tap: TODO kept"
like "$(cat tap.txt)" "^ok 10 - suite/skip_test\.lua # SKIP needs a quantum computer$" "--tap: a skipped file"
if command -v prove > /dev/null 2>&1; then
out=$(prove -e cat tap.txt 2>&1); st=$?
is "$st" 1 "prove reads the stream and fails"
like "$out" "Failed tests:  2, 4-5" "prove sees the failures (the TODO is not one)"
like "$out" "Tests=11" "prove counts 11 tests"
if printf '%s\n' "$out" | grep -q "Parse errors"; then ok 1 "no parse errors"; else ok 0 "no parse errors"; fi
out=$(prove -e "$D test --tap" suite/*_test.lua suite/sub/*_test.lua 2>&1); st=$?
is "$st" 1 "prove -e 'dmech test --tap' over the files fails"
like "$out" "Files=5, Tests=11" "prove: 5 files, 11 tests"
like "$out" "suite/error_test.lua +\(Wstat: 256 \(exited 1\) Tests: 2 Failed: 1\)" "prove: the erroring file"
out=$(prove -e "$D test --tap" suite/pass_test.lua suite/skip_test.lua suite/sub/nested_test.lua 2>&1); st=$?
is "$st" 0 "prove passes the passing files"
like "$out" "Result: PASS" "prove: Result: PASS"
else
  for k in 1 2 3 4 5 6 7 8 9 10; do skip "prove not installed"; done
fi

# options
out=$("$D" test --filter sub/ suite 2>&1); st=$?
is "$st" 0 "--filter keeps the matching files"
like "$out" "^1 passed, 0 failed; 1 file: 1 passed" "--filter: one file ran"
out=$("$D" test --filter=nothing suite 2>&1); st=$?
is "$st" 1 "--filter matching nothing exits 1"
is "$out" "dmech test: no *_test.lua files in suite whose path contains 'nothing'" "--filter matching nothing: message"
out=$("$D" test -v suite/pass_test.lua 2>&1); st=$?
is "$st" 0 "a passing file exits 0"
like "$out" "^      ok 1 - doubling$" "--verbose shows passing tests"
like "$out" "^      1\.\.4$" "--verbose shows the plan"
out=$("$D" test suite/pass_test.lua 2>&1)
if printf '%s\n' "$out" | grep -q "ok 1 - doubling"; then ok 1 "without -v passing tests are not listed"; else ok 0 "without -v passing tests are not listed"; fi
out=$("$D" test suite/sub/nested_test.lua suite/pass_test.lua suite/sub/nested_test.lua 2>&1)
is "$(printf '%s\n' "$out" | grep -c '^PASS')" 2 "a file named twice runs once"
like "$(printf '%s\n' "$out" | head -1)" "^PASS  suite/sub/nested_test.lua" "named files keep their order"
out=$("$D" test suite/helper.lua 2>&1); st=$?
like "$out" "^ERROR suite/helper.lua \(raised an error after 0 tests" "a file named explicitly runs whatever its name"
out=$("$D" test --help 2>&1); st=$?
is "$st" 0 "--help exits 0"
like "$out" "^usage: dmech test \[options\] \[files or directories\]" "--help: usage"
like "$out" "usable cores, [0-9]+\)" "--help: the default number of jobs"
out=$("$D" test --bogus 2>&1); st=$?
is "$st" 2 "unknown option exits 2"
like "$out" "^dmech test: unrecognized option '--bogus'" "unknown option: message"
out=$("$D" test -j 0 suite 2>&1); st=$?
is "$st" 2 "-j 0 exits 2"
like "$out" "^dmech test: -j expects a positive integer, got '0'" "-j 0: message"
out=$("$D" test -j 2>&1); st=$?
like "$out" "^dmech test: option '-j' needs an argument" "-j without a number"; is "$st" 2 "exit 2"
out=$("$D" test nowhere 2>&1); st=$?
is "$st" 2 "a missing path exits 2"
like "$out" "^dmech test: cannot find nowhere: No such file or directory" "a missing path: message"
mkdir -p empty
out=$("$D" test empty 2>&1); st=$?
is "$st" 1 "a directory without test files exits 1"
is "$out" "dmech test: no *_test.lua files in empty" "no test files: message"
out=$("$D" --help 2>&1)
like "$out" "dmech test \[options\] \[files or directories\]" "dmech --help names dmech test"

# odd endings: each is an error with its reason
mkdir -p odd
cat > odd/exit_test.lua <<'LUA'
dm.test.ok(true, "one"); os.exit(0)
LUA
cat > odd/killed_test.lua <<'LUA'
dm.test.ok(true, "one")
local pid = io.open("/proc/self/stat"):read("l"):match("^(%d+)")
os.execute("kill -KILL " .. pid)
LUA
cat > odd/none_test.lua <<'LUA'
local x = 2.385
LUA
cat > odd/plan_test.lua <<'LUA'
dm.test.plan(3); dm.test.ok(true, "one")
LUA
printf 'x = = 1\n' > odd/syntax_test.lua
cat > odd/status_test.lua <<'LUA'
dm.test.plan(1); dm.test.ok(true, "one"); os.exit(3)
LUA
cat > want_odd.txt <<'EOF'
ERROR odd/exit_test.lua (exit status 0 without a plan after 1 test; T s)
ERROR odd/killed_test.lua (killed by signal 9 after 1 test; T s)
ERROR odd/none_test.lua (ran no tests; T s)
ERROR odd/plan_test.lua (planned 3 tests, ran 1; T s)
ERROR odd/status_test.lua (exit status 3; T s)
ERROR odd/syntax_test.lua (raised an error after 0 tests; T s)
      stderr:
      | odd/syntax_test.lua:1: unexpected symbol near '='
4 passed, 0 failed; 6 files: 6 errored (T s, J jobs)
EOF
"$D" test odd > odd.txt 2>&1; st=$?
is "$st" 1 "odd endings exit 1"
norm < odd.txt > odd.norm
if cmp -s want_odd.txt odd.norm; then ok 0 "exit without plan, signal, no tests, plan not met, syntax error, exit status"
else ok 1 "odd endings"; diff want_odd.txt odd.norm | head -30 | sed 's/^/#   /'; fi

# what a file prints never counts as a test (the TAP has its own descriptor)
mkdir -p noisy
cat > noisy/print_test.lua <<'LUA'
print("ok 7 - looks like a test")
print("not ok 8 - looks like a failure")
print("1..99")
print("Bail out! not really")
dm.test.ok(true, "the real one")
LUA
out=$("$D" test -v noisy 2>&1); st=$?
is "$st" 0 "printed TAP-like lines do not count"
like "$out" "^PASS  noisy/print_test.lua \(1 test; " "one test"
like "$out" "^      stdout:$" "--verbose shows the file's stdout"
like "$out" "^      \| not ok 8 - looks like a failure$" "as its output"
out=$("$D" noisy/print_test.lua 2>&1)
like "$out" "^ok 1 - the real one$" "run alone, the file prints its TAP on stdout"

# Ctrl-C: the running file stops, nothing new starts, exit 130
mkdir -p intr
cat > intr/a_test.lua <<LUA
dm.test.ok(true, "started")
io.open("$T/intr/running", "w"):close()
while true do end
LUA
echo 'dm.test.ok(true, "never")' > intr/b_test.lua
rm -f intr/running
"$D" test -j1 intr > intr.txt 2>&1 &
pid=$!
i=0
while [ $i -lt 400 ] && [ ! -e intr/running ]; do sleep 0.025; i=$((i + 1)); done
kill -INT $pid
wait $pid; st=$?
is "$st" 130 "interrupted run exits 130"
like "$(cat intr.txt)" "^ERROR intr/a_test.lua \((raised an error|exit status 130 without a plan) after 1 test" "the running file stopped"
like "$(cat intr.txt)" "interrupted" "with the interrupt as its error"
like "$(cat intr.txt)" "^interrupted after 1 of 2 files$" "the other one never started"

# the example suite users copy
out=$(cd "$DMECH_SRCDIR" && "$D" test examples/tests 2>&1); st=$?
is "$st" 0 "dmech test examples/tests passes"
like "$out" "^[1-9][0-9]* passed, 0 failed; " "examples/tests: every test passed"
done_testing
