#!/bin/sh
# sanitize.sh -- the whole suite under AddressSanitizer + UndefinedBehavior-
# Sanitizer, then the fuzzer for a fixed budget under them.
#
#   tests/sanitize.sh <distdir> <calls> <files>      (make check-sanitize)
#
# <distdir> is a fresh `make distdir` tree: it is configured and built there
# with $SANITIZE_CC (default clang; gcc works too) and
#   -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined
#   -fno-sanitize-recover=undefined
# and `make check` runs with
#   ASAN_OPTIONS  detect_leaks=1 (leaks fail), allocator_may_return_null=1
#                 (a huge request returns NULL and must be reported as
#                 "out of memory", not abort), detect_stack_use_after_return,
#                 check_initialization_order, exitcode=86;
#   UBSAN_OPTIONS print_stacktrace=1, halt_on_error=1;
#   LSAN_OPTIONS  tests/lsan.supp: leaks inside the HDF5 library (its
#                 metadata cache on corrupted files);
#   LUA54         a wrapper preloading the sanitizer runtime into stock
#                 lua5.4 for the Lua C module test (an uninstrumented
#                 interpreter loading an instrumented dmech.so);
#   MPIRUN        a wrapper of mpirun with leak checking off in the ranks.
# Tests that interpose malloc themselves skip that part (ASan has its own
# allocator).  Then `make fuzz-ci` with FUZZ_CALLS=<calls>, FUZZ_FILES=<files>.
# Exit status: non-zero on any failure; the TAP totals of the sanitized
# suite are in <distdir>/tests/**/*.trs for .ci/run to count.
set -u
dist=$1 calls=$2 files=$3
cc=${SANITIZE_CC:-clang}
san="-fsanitize=address,undefined -fno-sanitize-recover=undefined"
if $cc --version 2>/dev/null | grep -q clang; then
  rt=$($cc -print-file-name=libclang_rt.asan-x86_64.so)
  cc="$cc $san -shared-libasan -Wl,-rpath,$(dirname "$rt")"
else
  cc="$cc $san"
  rt=$($cc -print-file-name=libasan.so)
fi
cd "$dist" || exit 2
./configure -q CC="$cc" CFLAGS="-O1 -g -fno-omit-frame-pointer" > sanitize-configure.log 2>&1 \
  || { cat sanitize-configure.log; exit 2; }
make -j2 > sanitize-build.log 2>&1 || { tail -30 sanitize-build.log; exit 2; }
cat > lua5.4-asan <<WRAP
#!/bin/sh
LD_PRELOAD=$rt ASAN_OPTIONS=detect_leaks=0 exec $(command -v lua5.4 || echo lua5.4) "\$@"
WRAP
chmod +x lua5.4-asan
# ranks under mpirun: Open MPI's own allocations are still held at exit
# (stacks one frame deep, through uninstrumented code: no suppression
# can name them), so leak checking is off for the ranks only
mpirun=$(command -v mpirun || echo mpirun)
cat > mpirun-asan <<WRAP
#!/bin/sh
ASAN_OPTIONS="\$ASAN_OPTIONS:detect_leaks=0" exec $mpirun "\$@"
WRAP
chmod +x mpirun-asan
ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1:detect_stack_use_after_return=1:check_initialization_order=1:exitcode=86
UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
LSAN_OPTIONS=suppressions=$(pwd)/tests/lsan.supp:print_suppressions=0
LUA54=$(pwd)/lua5.4-asan
MPIRUN=$(pwd)/mpirun-asan
export ASAN_OPTIONS UBSAN_OPTIONS LSAN_OPTIONS LUA54 MPIRUN
status=0
# on the command line: configure's LUA54 and MPIRUN in the Makefile would win otherwise
make -j2 check LUA54="$LUA54" MPIRUN="$MPIRUN" || status=1
make fuzz-ci FUZZ_CALLS="$calls" FUZZ_FILES="$files" || status=1
exit $status
