# repl.sh -- REPL transcripts: tests/repl/<name>.in piped through `dmech -i`
# with empty prompts must print exactly tests/repl/<name>.out.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
T="$DMECH_TESTTMP/repl"; mkdir -p "$T"
for in in "$DMECH_SRCDIR"/tests/repl/*.in; do
  name=$(basename "$in" .in)
  "$DMECH" -e "_PROMPT='' _PROMPT2=''" -i < "$in" 2>&1 | grep -v '^dmech [0-9]' \
    | sed "s|$DMECH|dmech|g" > "$T/$name.got"
  if cmp -s "$T/$name.got" "$DMECH_SRCDIR/tests/repl/$name.out"; then
    ok 0 "transcript $name"
  else
    ok 1 "transcript $name"
    diff "$DMECH_SRCDIR/tests/repl/$name.out" "$T/$name.got" | head -20 | sed 's/^/#   /'
  fi
done
done_testing
