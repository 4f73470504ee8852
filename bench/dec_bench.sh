#!/bin/sh
# dec_bench.sh -- DEC Poisson end to end, dmech (bench/dec_poisson) against
# the same pipeline in NumPy/SciPy (bench/dec_poisson.py), on the same mesh
# files, one process per program and size (alternating), in one run.
# Prints per-phase seconds, the ratio SciPy/dmech, peak memory, and the
# growth exponents of the assembly (complex + geometry + Delta0) and of the
# total between the smallest and the largest triangle mesh.
#   BENCH=path/to/dec_poisson PYTHON=/usr/bin/python3 sh dec_bench.sh dec_poisson.py
#   BENCH_DEC_SIZES="41 130 408"  disc ring counts (about 1e4, 1e5, 1e6 triangles)
#   BENCH_DEC_BOX=26              tetrahedral box (6 * 26^3 = 105456 tetrahedra)
set -e
PY_SCRIPT=$1
: "${BENCH:?set BENCH}" "${PYTHON:=/usr/bin/python3}"
SIZES=${BENCH_DEC_SIZES:-"41 130 408"}
BOX=${BENCH_DEC_BOX:-26}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT INT TERM
if ! "$PYTHON" -c "import numpy, scipy" 2>/dev/null; then
  echo "SciPy not importable by $PYTHON: the comparison is skipped"; SCIPY=no
else SCIPY=yes; fi
printf '%-14s %9s %9s %9s %9s %9s %9s %9s %8s\n' mesh program complex geometry assembly factor solve total maxrssMB
one() {  # kind size
  f="$TMP/$1_$2.bin"
  "$BENCH" gen "$1" "$2" "$f" > "$TMP/gen.txt"
  label=$(awk '{print $2}' "$TMP/gen.txt")
  "$BENCH" run "$f" > "$TMP/c_$1_$2.txt"
  if [ $SCIPY = yes ]; then "$PYTHON" "$PY_SCRIPT" "$f" > "$TMP/py_$1_$2.txt"; fi
  rm -f "$f"
  for prog in c py; do
    [ -f "$TMP/${prog}_$1_$2.txt" ] || continue
    awk -v m="$label $1" -v p=$([ $prog = c ] && echo dmech || echo scipy) '
      {v[$1] = $2}
      END {printf "%-14s %9s %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f %8.0f\n", m, p, v["complex"],
           v["geometry"], v["assembly"], v["factor"], v["solve"], v["total"], v["maxrss_kb"] / 1024}' \
      "$TMP/${prog}_$1_$2.txt"
  done
  if [ $SCIPY = yes ]; then
    paste "$TMP/c_$1_$2.txt" "$TMP/py_$1_$2.txt" | awk -v m="$label $1" '
      $1 != "unknowns" && $1 != "simplices" && $1 != "check" && $1 != "maxrss_kb" { r[$1] = $4 / $2 }
      $1 == "check" { d = $2 - $4; if (d < 0) d = -d; chk = d }
      END {printf "%-14s %9s %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f   |u_dmech - u_scipy| %.1e\n", m, "ratio",
           r["complex"], r["geometry"], r["assembly"], r["factor"], r["solve"], r["total"], chk}'
  fi
}
for s in $SIZES; do one disc "$s"; done
one box "$BOX"
first=$(echo $SIZES | awk '{print $1}'); last=$(echo $SIZES | awk '{print $NF}')
echo
echo "growth exponents t ~ N^p between $(awk '$1 == "simplices" {print $2}' "$TMP/c_disc_$first.txt") and $(awk '$1 == "simplices" {print $2}' "$TMP/c_disc_$last.txt") triangles:"
for prog in c py; do
  [ -f "$TMP/${prog}_disc_$first.txt" ] || continue
  paste "$TMP/${prog}_disc_$first.txt" "$TMP/${prog}_disc_$last.txt" | awk -v p=$([ $prog = c ] && echo dmech || echo scipy) '
    { a[$1] = $2; b[$1] = $4 }
    END { n = log(b["simplices"] / a["simplices"]);
          asm0 = a["complex"] + a["geometry"] + a["assembly"]; asm1 = b["complex"] + b["geometry"] + b["assembly"];
          printf "  %-6s assembly %.2f  factor %.2f  solve %.2f  total %.2f\n", p, log(asm1 / asm0) / n,
                 log(b["factor"] / a["factor"]) / n, log(b["solve"] / a["solve"]) / n, log(b["total"] / a["total"]) / n }'
done
