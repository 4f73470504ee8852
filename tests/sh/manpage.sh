# manpage.sh -- doc/dmech.1 renders without warnings and documents every
# option `dmech --help` lists, and every environment variable the guide's
# table names.
. "$DMECH_SRCDIR/tests/sh/tap.sh"
M="$DMECH_SRCDIR/doc/dmech.1"
if command -v groff > /dev/null 2>&1; then
  out=$(groff -man -Tutf8 -ww -z "$M" 2>&1); is "$out" "" "groff renders the man page without warnings"
else
  skip "groff not installed"
fi
opts=$("$DMECH" --help | sed -n 's/^  \(-[-a-zA-Z]*\).*/\1/p')
missing=""
for o in $opts; do
  esc=$(printf '%s' "$o" | sed 's/-/\\\\-/g')
  grep -q "^\.BI\{0,1\} $esc\b\|^\.B $esc$\|^\.BI $esc " "$M" || missing="$missing $o"
done
like "$opts" "-e" "--help lists options"
is "$missing" "" "every option of --help is in the man page"
vars=$(sed -n 's/^| `\([A-Z_0-9]*\)`.*/\1/p' "$DMECH_SRCDIR/doc/guide.md")
missing=""
for v in $vars; do grep -q "^\.B $v\b" "$M" || missing="$missing $v"; done
like "$vars" "DMECH_PATH" "the guide's table names variables"
is "$missing" "" "every variable of the guide's table is in the man page"
done_testing
