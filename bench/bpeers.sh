#!/bin/sh
# bpeers.sh -- run benchmarks B1, B2, B3, B5 against the peers, one after the
# other (never in parallel: they time CPU), and write the report.
# Called by `make bench-peers` (bench/bench.am) with:
#   SRCDIR BUILDDIR DMECH RESULTS PYTHON B3_PERIODS B3_SCIPY_PERIODS
# in the environment.  Every missing peer is reported as "skipped".
# Outputs in $RESULTS: b1.txt, b1_lua.txt, b2_*.tsv, b2_*.txt, b3_*.tsv,
# b3_*.txt, b4.txt (the reduction module's bench_reduce), b5.txt, b2_*.png, b3_energy.png, tables.md, machine.txt.
set -u
: "${SRCDIR:?}" "${BUILDDIR:?}" "${DMECH:?}" "${RESULTS:?}"
PYTHON=${PYTHON:-/usr/bin/python3}
B3_PERIODS=${B3_PERIODS:-10000}
B3_SCIPY_PERIODS=${B3_SCIPY_PERIODS:-1000}
REF=$SRCDIR/bench/data/reference.txt
mkdir -p "$RESULTS" || exit 1
export DMECH_PATH="$SRCDIR/lua" LC_ALL=C
# native objects of the benchmark go to a private cache (B5 empties it)
CACHE=$BUILDDIR/bench/tmp/cache
mkdir -p "$CACHE"
export XDG_CACHE_HOME="$CACHE"
status=0
t_start=$(date +%s)

section() { printf '\n==== %s  [%s s] ====\n' "$*" "$(( $(date +%s) - t_start ))"; }
run() { # run <name> <logfile> cmd... : tee output, record failure
  name=$1; log=$2; shift 2
  if "$@" > "$log.tmp" 2>&1; then
    mv "$log.tmp" "$log"; cat "$log"
  else
    mv "$log.tmp" "$log"; cat "$log"; echo "$name: FAILED (see $log)"; status=1
  fi
}

{
  echo "date: $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo "host: $(uname -srm)"
  echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores online"
  echo "memory: $(awk '/MemTotal/ {printf "%.1f GiB", $2/1048576}' /proc/meminfo)"
  echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "cc: $(${CC:-cc} --version 2>/dev/null | head -1)"
  echo "CFLAGS: ${BENCH_CFLAGS:-?}"
  echo "GSL: $(gsl-config --version 2>/dev/null || echo ?)"
  echo "dmech: ${DMECH_REV:-$(cd "$SRCDIR" && git describe --always --dirty 2>/dev/null || echo ?)}"
  if [ -x "$BUILDDIR/bench/peers/odeint_bench" ]; then echo "Boost.Odeint: $(sed -n 's/^#define BOOST_LIB_VERSION "\(.*\)"/\1/p' /usr/include/boost/version.hpp 2>/dev/null)"; else echo "Boost.Odeint: skipped (no headers or no C++ compiler; bench/setup.sh installs them)"; fi
  if "$PYTHON" -c 'import scipy' 2>/dev/null; then echo "SciPy: $("$PYTHON" -c 'import scipy, numpy, sys; print(scipy.__version__, "numpy", numpy.__version__, "python", sys.version.split()[0])')"; else echo "SciPy: skipped ($PYTHON has no scipy; bench/setup.sh installs python3-scipy)"; fi
} > "$RESULTS/machine.txt"
section "machine"; cat "$RESULTS/machine.txt"

section "B1 per-step cost (C harness)"
run B1 "$RESULTS/b1.txt" "$BUILDDIR/bench/b1_step"
section "B1 per-step cost (through src/dmech)"
run B1-lua "$RESULTS/b1_lua.txt" "$DMECH" "$SRCDIR/bench/b1_lua.lua"

section "B2 work-precision"
[ -f "$REF" ] || echo "B2: no $REF (make bench-ref): errors at T are NaN"
run B2-c "$RESULTS/b2_c.txt" "$BUILDDIR/bench/b2_workprec" all "$RESULTS" "$REF"
if [ -x "$BUILDDIR/bench/peers/odeint_bench" ]; then
  run B2-odeint "$RESULTS/b2_odeint.txt" "$BUILDDIR/bench/peers/odeint_bench" workprec all "$RESULTS" "$REF"
else
  echo "B2 Boost.Odeint: skipped"; rm -f "$RESULTS"/b2_*_odeint.tsv
fi
if "$PYTHON" -c 'import scipy' 2>/dev/null; then
  run B2-scipy "$RESULTS/b2_scipy.txt" "$PYTHON" "$SRCDIR/bench/peers/scipy_bench.py" workprec all "$RESULTS" "$REF"
else
  echo "B2 SciPy: skipped"; rm -f "$RESULTS"/b2_*_scipy.tsv
fi

section "B3 long time: $B3_PERIODS periods (SciPy: $B3_SCIPY_PERIODS)"
run B3-c "$RESULTS/b3_c.txt" "$BUILDDIR/bench/b3_long" "$B3_PERIODS" "$RESULTS/b3_trace_c.tsv"
if [ -x "$BUILDDIR/bench/peers/odeint_bench" ]; then
  run B3-odeint "$RESULTS/b3_odeint.txt" "$BUILDDIR/bench/peers/odeint_bench" long "$B3_PERIODS" "$RESULTS/b3_trace_odeint.tsv"
else
  echo "B3 Boost.Odeint: skipped"; rm -f "$RESULTS/b3_trace_odeint.tsv" "$RESULTS/b3_odeint.txt"
fi
if "$PYTHON" -c 'import scipy' 2>/dev/null; then
  run B3-scipy "$RESULTS/b3_scipy.txt" "$PYTHON" "$SRCDIR/bench/peers/scipy_bench.py" long "$B3_SCIPY_PERIODS" "$RESULTS/b3_trace_scipy.tsv"
else
  echo "B3 SciPy: skipped"; rm -f "$RESULTS/b3_trace_scipy.tsv" "$RESULTS/b3_scipy.txt"
fi
cat "$RESULTS"/b3_c.txt "$RESULTS"/b3_odeint.txt "$RESULTS"/b3_scipy.txt 2>/dev/null | grep '^B3SUMMARY' > "$RESULTS/b3_summary.tsv"

section "B5 interactive"
{
  sh "$SRCDIR/bench/startup.sh" "$DMECH" 20
  rm -rf "$CACHE/dmech"
  "$DMECH" "$SRCDIR/bench/b5_compile.lua"
} > "$RESULTS/b5.txt" 2>&1 || status=1
cat "$RESULTS/b5.txt"
section "B4 reduction (bench/bench_reduce, from bench-reduce)"
if [ -x "$BUILDDIR/bench/bench_reduce" ]; then
  run B4 "$RESULTS/b4.txt" "$BUILDDIR/bench/bench_reduce"
else
  echo "B4: skipped (bench/bench_reduce not built)"
fi

section "report"
run report "$RESULTS/report.log" "$DMECH" "$SRCDIR/bench/b_report.lua" "$RESULTS"
echo "total wall time: $(( $(date +%s) - t_start )) s; results in $RESULTS"
exit $status
