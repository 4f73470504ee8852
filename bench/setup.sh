#!/bin/sh
# bench/setup.sh -- install the benchmark peers from Debian's archive.
# Not part of dmech's build or bootstrap: only `make bench` uses them, and
# every peer that is missing is reported as skipped there.
#   libboost-dev   Boost.Odeint (header-only C++) for bench/peers/odeint_*.cpp
#   python3-scipy  SciPy solve_ivp (DOP853), run with Debian's /usr/bin/python3
#   g++            to compile the Boost harness
# Optional (BENCH_OPTIONAL=1): octave (ode45 cross-check), valgrind, linux-perf.
# As root it runs apt-get; otherwise it prints the command to run.
set -e
PKGS="libboost-dev python3-scipy python3-numpy g++"
[ "${BENCH_OPTIONAL:-0}" = 1 ] && PKGS="$PKGS octave valgrind linux-perf"
if [ "$(id -u)" -eq 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends $PKGS
else
  echo "not root; run:"
  echo "  sudo apt-get update && sudo apt-get install -y --no-install-recommends $PKGS"
fi
# report what the benchmark will find
[ -f /usr/include/boost/numeric/odeint.hpp ] && echo "Boost.Odeint: yes" || echo "Boost.Odeint: no"
if /usr/bin/python3 -c 'import scipy' 2>/dev/null; then
  echo "SciPy: $(/usr/bin/python3 -c 'import scipy; print(scipy.__version__)') (/usr/bin/python3)"
else
  echo "SciPy: no"
fi
command -v octave >/dev/null 2>&1 && echo "Octave: yes" || echo "Octave: no (optional)"
