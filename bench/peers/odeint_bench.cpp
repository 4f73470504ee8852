// odeint_bench.cpp -- Boost.Odeint peers for B2 and B3 (C++, header-only
// Boost; compiled by bench/bench.am only when the headers exist).
//
//   odeint_bench workprec <kepler|j2|all> <outdir> <reference.txt>
//     velocity_verlet (order 2), symplectic_rkn_sb3a_m4_mclachlan (order 4,
//     5 stages), symplectic_rkn_sb3a_mclachlan (order 4, 6 stages) at the
//     step sizes dmech's Stormer-Verlet and order-4 composition use in B2;
//     writes <outdir>/b2_<problem>_odeint.tsv (same columns as b2_workprec).
//   odeint_bench long <periods> <outfile>
//     Kepler e = 0.6, sb3a_m4_mclachlan h = 0.01 and runge_kutta4 h = 0.01
//     over <periods> periods: per-period max |H - H0| (B3 trace format:
//     method <TAB> period <TAB> max_dH) and the CPU time of an unmonitored run.
//
// The force is the hand-written one of problems.h; the state is std::array.
// Timing: CPU time, median of up to BENCH_REPEAT = 3 runs (one run when a
// run takes over 2 s); the energy error comes from a separate run that
// samples every step.
#include <config.h>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>
#include <boost/numeric/odeint.hpp>
#include <boost/numeric/odeint/stepper/symplectic_rkn_sb3a_m4_mclachlan.hpp>

extern "C" {
#include "problems.h"
#include "benchutil.h"
#include "refdata.h"
}

namespace ode = boost::numeric::odeint;

template <int N> struct prob;
template <> struct prob<2> {
  static void force(const double *q, double *f) { kep_force(q, f); }
  static double energy(const double *q, const double *p) { return kep_energy(q, p); }
  static const double *q0() { return kep_q0; }
  static const double *p0() { return kep_p0; }
  static double T() { return KEP_T1000; }
  static const char *name() { return "kepler"; }
};
template <> struct prob<3> {
  static void force(const double *q, double *f) { j2_force(q, f); }
  static double energy(const double *q, const double *p) { return j2_energy(q, p); }
  static const double *q0() { return j2_q0; }
  static const double *p0() { return j2_p0; }
  static double T() { return J2_T1000; }
  static const char *name() { return "j2"; }
};

template <int N> struct momentum_rhs {   // dp/dt = f(q)
  void operator()(const std::array<double, N> &q, std::array<double, N> &dpdt) const
  {
    prob<N>::force(q.data(), dpdt.data());
  }
};

template <int N> struct accel_rhs {      // velocity_verlet: a = f(q)
  void operator()(const std::array<double, N> &q, const std::array<double, N> &,
                  std::array<double, N> &a, double) const
  {
    prob<N>::force(q.data(), a.data());
  }
};

template <int N> struct full_rhs {       // first-order form for runge_kutta4
  void operator()(const std::array<double, 2 * N> &y, std::array<double, 2 * N> &dy, double) const
  {
    for (int i = 0; i < N; i++)
      dy[i] = y[N + i];
    prob<N>::force(y.data(), dy.data() + N);
  }
};

enum { VV, M4, M6 };
static const char *labels[] = {"odeint velocity_verlet", "odeint sb3a_m4_mclachlan",
                               "odeint sb3a_mclachlan"};

// N steps of h from the start; fills q, p; returns max |dH| when monitor
template <int N>
static double run(int which, double h, long steps, std::array<double, N> &q, std::array<double, N> &p,
                  bool monitor)
{
  typedef std::array<double, N> S;
  std::memcpy(q.data(), prob<N>::q0(), N * sizeof(double));
  std::memcpy(p.data(), prob<N>::p0(), N * sizeof(double));
  double H0 = prob<N>::energy(q.data(), p.data()), m = 0.0, t = 0.0;
  if (which == VV) {
    ode::velocity_verlet<S> st;
    std::pair<S, S> x(q, p);
    for (long k = 0; k < steps; k++, t += h) {
      st.do_step(accel_rhs<N>(), x, t, h);
      if (monitor)
        m = std::fmax(m, std::fabs(prob<N>::energy(x.first.data(), x.second.data()) - H0));
    }
    q = x.first;
    p = x.second;
  } else if (which == M4) {
    ode::symplectic_rkn_sb3a_m4_mclachlan<S> st;
    for (long k = 0; k < steps; k++, t += h) {
      st.do_step(momentum_rhs<N>(), std::make_pair(std::ref(q), std::ref(p)), t, h);
      if (monitor)
        m = std::fmax(m, std::fabs(prob<N>::energy(q.data(), p.data()) - H0));
    }
  } else {
    ode::symplectic_rkn_sb3a_mclachlan<S> st;
    for (long k = 0; k < steps; k++, t += h) {
      st.do_step(momentum_rhs<N>(), std::make_pair(std::ref(q), std::ref(p)), t, h);
      if (monitor)
        m = std::fmax(m, std::fabs(prob<N>::energy(q.data(), p.data()) - H0));
    }
  }
  return m;
}

template <int N> static void workprec(const char *outdir, const char *refpath, int R)
{
  const char *pn = prob<N>::name();
  const double T = prob<N>::T();
  // the step sizes of dmech's SV (VV) and order-4 composition (M4, M6) sweeps
  static const double hk_vv[] = {0.05, 0.02, 0.01, 0.005, 0.002, 0.001, 0};
  static const double hk_4[] = {0.05, 0.02, 0.01, 0.005, 0.002, 0};
  static const double hj_vv[] = {0.2, 0.1, 0.05, 0.02, 0.01, 0.005, 0};
  static const double hj_4[] = {0.2, 0.1, 0.05, 0.02, 0.01, 0};
  ref_point ref;
  std::memset(&ref, 0, sizeof ref);
  bool have_ref = ref_load(refpath, pn, &ref) == 0;
  std::string path = std::string(outdir) + "/b2_" + pn + "_odeint.tsv";
  FILE *out = std::fopen(path.c_str(), "w");
  if (!out) {
    std::perror(path.c_str());
    std::exit(1);
  }
  std::fprintf(out, "problem\timpl\tmethod\tpar\tvalue\tsteps\tcpu_s\treps\terr_end\tmax_dH\n");
  std::printf("\n## B2 %s, Boost.Odeint\n", pn);
  for (int w = VV; w <= M6; w++) {
    const double *hs = N == 2 ? (w == VV ? hk_vv : hk_4) : (w == VV ? hj_vv : hj_4);
    for (int k = 0; hs[k] > 0; k++) {
      long steps = std::lround(T / hs[k]);
      double h = T / steps, t[16], err = NAN;
      std::array<double, N> q, p;
      int reps = 0;
      for (int r = 0; r < R; r++) {
        double t0 = bu_cpu();
        run<N>(w, h, steps, q, p, false);
        t[reps++] = bu_cpu() - t0;
        if (t[reps - 1] > 2.0)
          break;
      }
      if (have_ref)
        err = ref_error(&ref, (long double)steps * h, q.data(), p.data());
      double cpu = bu_median(t, reps);
      double dH = run<N>(w, h, steps, q, p, true);
      std::printf("%-8s %-24s h    %-9.3g %10ld %10.4f %4d %11.3e %11.3e\n", pn, labels[w], hs[k],
                  steps, cpu, reps, err, dH);
      std::fprintf(out, "%s\todeint\t%s\th\t%.17g\t%ld\t%.6g\t%d\t%.6e\t%.6e\n", pn, labels[w], hs[k],
                   steps, cpu, reps, err, dH);
    }
  }
  std::fclose(out);
}

// B3: per-period maxima of |dH| for Kepler, h = 0.01
static void long_run(long periods, const char *outfile)
{
  typedef std::array<double, 2> S;
  typedef std::array<double, 4> Y;
  const double h = 0.01, P = 2 * M_PI;
  const long steps = std::lround(periods * P / h);
  FILE *out = std::fopen(outfile, "w");
  if (!out) {
    std::perror(outfile);
    std::exit(1);
  }
  std::printf("\n## B3 Boost.Odeint, Kepler e=0.6, %ld periods, h = 0.01 (%ld steps)\n", periods, steps);
  for (int w = 0; w < 2; w++) {
    const char *label = w == 0 ? "odeint sb3a_m4_mclachlan" : "odeint runge_kutta4";
    std::vector<double> pm(periods + 1, 0.0);
    double cpu[2];
    for (int pass = 0; pass < 2; pass++) {   // pass 0 timed, unmonitored; pass 1 monitored
      S q, p;
      Y y;
      std::memcpy(q.data(), kep_q0, sizeof kep_q0);
      std::memcpy(p.data(), kep_p0, sizeof kep_p0);
      y = {kep_q0[0], kep_q0[1], kep_p0[0], kep_p0[1]};
      double H0 = kep_energy(q.data(), p.data()), t0 = bu_cpu();
      ode::symplectic_rkn_sb3a_m4_mclachlan<S> sm;
      ode::runge_kutta4<Y> rk;
      for (long k = 0; k < steps; k++) {
        double t = k * h;
        if (w == 0)
          sm.do_step(momentum_rhs<2>(), std::make_pair(std::ref(q), std::ref(p)), t, h);
        else
          rk.do_step(full_rhs<2>(), y, t, h);
        if (pass == 1) {
          double dH = w == 0 ? kep_energy(q.data(), p.data()) - H0 : kep_energy(y.data(), y.data() + 2) - H0;
          long per = (long)((k + 1) * h / P);
          if (per > periods)
            per = periods;
          pm[per] = std::fmax(pm[per], std::fabs(dH));
        }
      }
      cpu[pass] = bu_cpu() - t0;
    }
    double mx = 0.0;
    for (long i = 0; i < periods; i++) {
      std::fprintf(out, "%s\t%ld\t%.6e\n", label, i + 1, pm[i]);
      mx = std::fmax(mx, pm[i]);
    }
    std::printf("%-28s cpu %.3f s (unmonitored), %.3f s (monitored), max|dH| %.3e, last period %.3e\n",
                label, cpu[0], cpu[1], mx, pm[periods - 1]);
    std::fprintf(stdout, "B3SUMMARY\t%s\t%ld\t%.4f\t%.4f\t%.6e\t%.6e\n", label, steps, cpu[0], cpu[1], mx,
                 pm[periods - 1]);
  }
  std::fclose(out);
}

int main(int argc, char **argv)
{
  int R = bu_env_int("BENCH_REPEAT", 3);
  if (R < 1)
    R = 1;
  if (R > 16)
    R = 16;
  if (argc >= 5 && std::strcmp(argv[1], "workprec") == 0) {
    bu_machine("B2 work-precision, Boost.Odeint " BOOST_LIB_VERSION " (bench/peers/odeint_bench.cpp)");
    if (std::strcmp(argv[2], "j2") != 0)
      workprec<2>(argv[3], argv[4], R);
    if (std::strcmp(argv[2], "kepler") != 0)
      workprec<3>(argv[3], argv[4], R);
    return 0;
  }
  if (argc >= 4 && std::strcmp(argv[1], "long") == 0) {
    bu_machine("B3 long time, Boost.Odeint (bench/peers/odeint_bench.cpp)");
    long_run(std::atol(argv[2]), argv[3]);
    return 0;
  }
  std::fprintf(stderr, "usage: odeint_bench workprec <kepler|j2|all> <outdir> <ref> | long <periods> <out>\n");
  return 2;
}
