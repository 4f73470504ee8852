#!/usr/bin/python3
"""scipy_bench.py -- SciPy solve_ivp(DOP853) peers for B2 and B3.

  scipy_bench.py workprec <kepler|j2|all> <outdir> <reference.txt>
      DOP853 at rtol = atol = 1e-6 .. 1e-13 over 1000 Kepler periods / J2
      T = 12750; CPU time (time.process_time, median of up to BENCH_REPEAT
      = 3 runs, one when a run takes over 5 s), error of the final (q, p)
      against the reference (2-norm), max |H - H0| over the accepted steps
      (solve_ivp returns every accepted step when t_eval is None).
      Writes <outdir>/b2_<problem>_scipy.tsv.
  scipy_bench.py long <periods> <outfile>
      Kepler e = 0.6, DOP853 rtol = atol = 1e-10 over <periods> periods:
      per-period max |dH| (B3 trace format) and the CPU time.

The right-hand side is written the way a SciPy user writes it (a Python
function on a NumPy array).  Run with Debian's /usr/bin/python3.
"""
import math
import os
import platform
import sys
import time

import numpy as np
import scipy
from scipy.integrate import solve_ivp

J2 = 0.05
PROBS = {
    "kepler": dict(y0=[0.4, 0.0, 0.0, 2.0], T=2000.0 * math.pi, n=2),
    "j2": dict(y0=[2.0, 0.0, 0.3, 0.0, 0.6, 0.1], T=12750.0, n=3),
}


def rhs_kepler(t, y):
    x, yy, px, py = y
    r2 = x * x + yy * yy
    a = 1.0 / (r2 * math.sqrt(r2))
    return [px, py, -x * a, -yy * a]


def rhs_j2(t, y):
    x, yy, z, px, py, pz = y
    r2 = x * x + yy * yy + z * z
    R = math.sqrt(r2)
    a = 1.0 / (r2 * R)
    b = a / r2
    c = b / r2
    g = a + J2 * (1.5 * b - 7.5 * z * z * c)
    return [px, py, pz, -x * g, -yy * g, -z * g - 3.0 * J2 * z * b]


def energy(name, Y):
    """Y: (2n, m) array of states -> energies (m,)"""
    if name == "kepler":
        q, p = Y[:2], Y[2:]
        return 0.5 * (p * p).sum(0) - 1.0 / np.sqrt((q * q).sum(0))
    q, p = Y[:3], Y[3:]
    r2 = (q * q).sum(0)
    R = np.sqrt(r2)
    V = -1.0 / R + J2 / (r2 * R) * (1.5 * q[2] ** 2 / r2 - 0.5)
    return 0.5 * (p * p).sum(0) + V


def load_ref(path, name):
    vals = {}
    try:
        with open(path) as f:
            for line in f:
                if line.startswith("#"):
                    continue
                w = line.split()
                if w:
                    vals[w[0]] = [float(x) for x in w[1:]]
    except OSError:
        return None
    if name not in vals:
        return None
    return np.array(vals[name])


def machine(what):
    model = "?"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    print("# %s\n# machine: %s %s, %d cores online, %s\n# python %s, numpy %s, scipy %s"
          % (what, platform.system(), platform.machine(), os.cpu_count(), model,
             platform.python_version(), np.__version__, scipy.__version__))


def workprec(which, outdir, refpath, R):
    tols = [1e-6, 1e-8, 1e-10, 1e-12, 1e-13]
    if os.environ.get("BENCH_QUICK") == "1":
        tols = tols[:-1]
    for name in ("kepler", "j2"):
        if which not in ("all", name):
            continue
        P = PROBS[name]
        f = rhs_kepler if name == "kepler" else rhs_j2
        ref = load_ref(refpath, name)
        path = os.path.join(outdir, "b2_%s_scipy.tsv" % name)
        print("\n## B2 %s, SciPy DOP853" % name)
        with open(path, "w") as out:
            out.write("problem\timpl\tmethod\tpar\tvalue\tsteps\tcpu_s\treps\terr_end\tmax_dH\n")
            for tol in tols:
                times = []
                for _ in range(R):
                    t0 = time.process_time()
                    sol = solve_ivp(f, (0.0, P["T"]), P["y0"], method="DOP853", rtol=tol, atol=tol)
                    times.append(time.process_time() - t0)
                    if times[-1] > 5.0:
                        break
                times.sort()
                k = len(times)
                cpu = times[k // 2] if k % 2 else 0.5 * (times[k // 2 - 1] + times[k // 2])
                steps = sol.t.size - 1
                E = energy(name, sol.y)
                dH = float(np.max(np.abs(E - E[0])))
                err = float(np.linalg.norm(sol.y[:, -1] - ref)) if ref is not None else float("nan")
                if not sol.success:
                    print("%-8s %-24s tol=%g failed: %s" % (name, "SciPy DOP853", tol, sol.message))
                    continue
                print("%-8s %-24s tol  %-9.3g %10d %10.4f %4d %11.3e %11.3e"
                      % (name, "SciPy DOP853", tol, steps, cpu, k, err, dH))
                out.write("%s\tscipy\tSciPy DOP853\ttol\t%.17g\t%d\t%.6g\t%d\t%.6e\t%.6e\n"
                          % (name, tol, steps, cpu, k, err, dH))
                out.flush()


def long_run(periods, outfile):
    T = periods * 2.0 * math.pi
    t0 = time.process_time()
    sol = solve_ivp(rhs_kepler, (0.0, T), PROBS["kepler"]["y0"], method="DOP853",
                    rtol=1e-10, atol=1e-10)
    cpu = time.process_time() - t0
    E = energy("kepler", sol.y)
    dH = np.abs(E - E[0])
    per = np.minimum((sol.t / (2.0 * math.pi)).astype(np.int64), periods - 1)
    pm = np.zeros(periods)
    np.maximum.at(pm, per, dH)
    label = "SciPy DOP853 tol 1e-10"
    with open(outfile, "w") as out:
        for i in range(periods):
            out.write("%s\t%d\t%.6e\n" % (label, i + 1, pm[i]))
    print("\n## B3 SciPy, Kepler e=0.6, %d periods" % periods)
    print("%-28s cpu %.3f s, %d steps, max|dH| %.3e, last period %.3e"
          % (label, cpu, sol.t.size - 1, pm.max(), pm[-1]))
    print("B3SUMMARY\t%s\t%d\t%.4f\t%.4f\t%.6e\t%.6e" % (label, sol.t.size - 1, cpu, cpu, pm.max(), pm[-1]))


def main(argv):
    R = max(1, int(os.environ.get("BENCH_REPEAT", "3") or 3))
    if len(argv) >= 5 and argv[1] == "workprec":
        machine("B2 work-precision, SciPy (bench/peers/scipy_bench.py)")
        workprec(argv[2], argv[3], argv[4], R)
        return 0
    if len(argv) >= 4 and argv[1] == "long":
        machine("B3 long time, SciPy (bench/peers/scipy_bench.py)")
        long_run(int(argv[2]), argv[3])
        return 0
    sys.stderr.write("usage: scipy_bench.py workprec <kepler|j2|all> <outdir> <ref> | long <periods> <out>\n")
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
