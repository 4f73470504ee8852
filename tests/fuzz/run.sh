#!/bin/sh
# run.sh -- run the fuzzer once and keep what it found.
#
#   tests/fuzz/run.sh <dmech-fuzz> <srcdir> <outdir> api <calls> <seed>
#   tests/fuzz/run.sh <dmech-fuzz> <srcdir> <outdir> files <files> <seed>
#   tests/fuzz/run.sh <dmech-fuzz> <srcdir> <outdir> replay <dir>
#
# The fuzzer works in a scratch directory (in /dev/shm when there is one:
# it writes a reproducer before every call) and writes the cases of the
# failures it judged to <outdir>.  When the process itself dies -- a crash,
# a sanitizer report, a hang (exit 3) -- the reproducer of the call that
# killed it is copied to <outdir> too.  Cases go to tests/data/fuzz/ once
# the bug is fixed, and every `make check` replays them.  TAP on stdout;
# exit status 0 when nothing was found.
host=$1 srcdir=$2 out=$3; shift 3
mkdir -p "$out" || exit 2
out=$(cd "$out" && pwd)
base=/dev/shm; [ -d "$base" ] && [ -w "$base" ] || base=${TMPDIR:-/tmp}
work=$(mktemp -d "$base/dmech-fuzz.XXXXXX") || exit 2
trap 'rm -rf "$work"' EXIT
case $1 in replay) set -- replay "$(cd "$2" && pwd)";; esac
(cd "$work" && FUZZ_OUT=$out DMECH_SRCDIR=$srcdir "$host" "$srcdir/tests/fuzz/fuzz.lua" "$@")
st=$?
if [ "$st" -gt 1 ]; then
  case $st in 3) why="hang";; 86) why="sanitizer report";; *) why="crash (exit $st)";; esac
  if [ -f "$work/last.lua" ]; then
    keep="$out/$1-$why-$(date +%s).lua"; keep=$(echo "$keep" | tr ' ()' '___')
    { echo "-- $why"; cat "$work/last.lua"; } > "$keep"
    file=$(sed -n 's/^-- crash or hang reading \([^ ]*\) with reader.*/\1/p' "$work/last.lua")
    [ -n "$file" ] && [ -f "$work/$file" ] && cp "$work/$file" "$out/"
    echo "not ok - $why; the call that caused it: $keep"
  else
    echo "not ok - $why"
  fi
  echo "1..1"
fi
exit $st
