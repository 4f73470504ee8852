#!/bin/sh
# startup.sh -- start-up time and resident memory of `dmech -e ''` against
# stock `lua5.4 -e ''` (the floor: same interpreter, no dmech), measured in
# one run.  Median of N runs each.  Usage: bench/startup.sh [dmech] [N]
DMECH=${1:-src/dmech}
N=${2:-20}
LUA=$(command -v lua5.4)

median_ms() { # command... ; prints the median wall time in ms of N runs
  i=0
  while [ $i -lt "$N" ]; do
    t0=$(date +%s%N); "$@" >/dev/null 2>&1; t1=$(date +%s%N)
    echo $(( (t1 - t0) / 1000 ))
    i=$((i + 1))
  done | sort -n | awk '{a[NR]=$1} END {m = (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2; printf "%.2f", m / 1000}'
}
rss_kb() { /usr/bin/time -f %M "$@" 2>&1 >/dev/null | tail -1; }

echo "machine: $(uname -m), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
d=$(median_ms "$DMECH" -e '')
echo "dmech -e ''     median of $N: $d ms   max RSS $(rss_kb "$DMECH" -e '') KB"
if [ -n "$LUA" ]; then
  l=$(median_ms "$LUA" -e '')
  echo "lua5.4 -e ''    median of $N: $l ms   max RSS $(rss_kb "$LUA" -e '') KB"
  awk -v d="$d" -v l="$l" 'BEGIN { printf "ratio dmech / lua5.4: %.2f (target: dmech under 30 ms)\n", d / l }'
fi
i=$(median_ms "$DMECH" -e 'local v = dm.vec{1, 2}; help "vec:dot"')
echo "dmech with a help lookup: $i ms"
