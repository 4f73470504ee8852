# replay.sh -- every case of the fuzz corpus (tests/data/fuzz) replayed:
# no crash, no hang, well-formed messages.  TAP from tests/fuzz/fuzz.lua.
exec "$SHELL" "$DMECH_SRCDIR/tests/fuzz/run.sh" "$DMECH_BUILDDIR/tests/fuzz/dmech-fuzz" \
  "$DMECH_SRCDIR" "$DMECH_TESTTMP/fuzz-findings" replay "$DMECH_SRCDIR/tests/data/fuzz"
