# guide.sh -- every ```lua block of doc/guide.md runs at the prompt, in
# order, in one session: no error, no line printing `false` (the guide's
# checks print true), and the files the tutorial writes exist.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
D="$DMECH"
T="$DMECH_TESTTMP/guide"; rm -rf "$T"; mkdir -p "$T"; cd "$T" || exit 1
"$D" "$DMECH_SRCDIR/tests/sh/guide_input.lua" "$DMECH_SRCDIR/doc/guide.md" > input.lua
"$D" -e "_PROMPT='' _PROMPT2=''" -i < input.lua > out.txt 2>&1
blocks=$(grep -c '^@@block ' out.txt)
like "$blocks" '^[1-9][0-9]+$' "the guide has code blocks ($blocks)"
# one line per block: "<line> ok" or "<line> bad <first offending output>"
awk -v prog="$D: " '
  /^@@block / { if (line) report(); line = $2; bad = ""; next }
  /^@@end/ { if (line) report(); line = ""; next }
  (index($0, prog) == 1 || $0 == "false") && bad == "" { bad = $0 }
  function report() { print line, (bad == "" ? "ok" : "bad " bad) }' out.txt > blocks.txt
fails=0
while read -r line verdict rest; do
  if [ "$verdict" = ok ]; then ok 0 "doc/guide.md:$line"
  else ok 1 "doc/guide.md:$line"; echo "#   $rest"; fails=$((fails + 1)); fi
done < blocks.txt
is "$fails" 0 "every block ran without error"
is "$(grep -c '^@@end' out.txt)" 1 "the session reached the end"
for f in orbit.png reduced.png both.png rz.svg decay.png orbit.csv; do
  if [ -s "$f" ]; then ok 0 "the guide wrote $f"; else ok 1 "the guide wrote $f"; fi
done
like "$(cat out.txt)" "^wrote orbit.png$" "the prompt reports the file a plot wrote"
done_testing
