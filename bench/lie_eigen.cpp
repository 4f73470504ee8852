// lie_eigen.cpp -- SO(3) exp, log and compose of src/lie against Eigen hand
// code (AngleAxisd(|w|, w/|w|).toRotationMatrix(), AngleAxisd(R) back to
// angle * axis, Matrix3d products), in one run: ns per operation on the same
// 4096 random inputs (angles up to pi), thread CPU time, median of 5 runs,
// and the largest difference between the two results (they must agree).
//
// usage: lie_eigen
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <vector>

extern "C" {
#include "lie/lie.h"
}

static double now()
{
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int main()
{
  const int N = 4096, REP = 200, RUNS = 5;
  dm_lie_group *G = dm_lie_so3(nullptr);
  std::vector<double> w(3 * N), Rd(9 * N), Rd2(9 * N), out(9 * N);
  std::vector<Eigen::Vector3d> we(N);
  std::vector<Eigen::Matrix3d> Re(N), Re2(N), Re3(N);
  unsigned long long s = 2385;
  auto rnd = [&s]() {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(s >> 11) / 9007199254740992.0;
  };
  for (int i = 0; i < N; i++) {
    double a = M_PI * rnd(), x = 2 * rnd() - 1, y = 2 * rnd() - 1, z = 2 * rnd() - 1;
    double n = std::sqrt(x * x + y * y + z * z);
    w[3 * i] = a * x / n, w[3 * i + 1] = a * y / n, w[3 * i + 2] = a * z / n;
    we[i] = Eigen::Vector3d(w[3 * i], w[3 * i + 1], w[3 * i + 2]);
  }
  volatile double sink = 0;
  std::printf("# lie_eigen: SO(3) kernels, ns per operation (median of %d runs of %d x %d)\n",
              RUNS, REP, N);
  // exp
  std::vector<double> td, te;
  for (int r = 0; r < RUNS; r++) {
    double t0 = now();
    for (int k = 0; k < REP; k++)
      for (int i = 0; i < N; i++)
        dm_lie_exp(G, &w[3 * i], &Rd[9 * i]);
    td.push_back(now() - t0);
    t0 = now();
    for (int k = 0; k < REP; k++)
      for (int i = 0; i < N; i++) {
        double a = we[i].norm();
        Re[i] = a > 0 ? Eigen::AngleAxisd(a, we[i] / a).toRotationMatrix()
                      : Eigen::Matrix3d::Identity();
      }
    te.push_back(now() - t0);
  }
  double dexp = 0;
  for (int i = 0; i < N; i++)
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++)
        dexp = std::max(dexp, std::fabs(Rd[9 * i + 3 * a + b] - Re[i](a, b)));
  std::printf("  exp      dmech %6.1f  Eigen %6.1f  ratio %.2f  (max difference %.2g)\n",
              1e9 * median(td) / (REP * N), 1e9 * median(te) / (REP * N),
              median(td) / median(te), dexp);
  // log
  td.clear(), te.clear();
  std::vector<Eigen::Vector3d> le(N);
  for (int r = 0; r < RUNS; r++) {
    double t0 = now();
    for (int k = 0; k < REP; k++)
      for (int i = 0; i < N; i++)
        dm_lie_log(G, &Rd[9 * i], &out[3 * i]);
    td.push_back(now() - t0);
    t0 = now();
    for (int k = 0; k < REP; k++)
      for (int i = 0; i < N; i++) {
        Eigen::AngleAxisd aa(Re[i]);
        le[i] = aa.angle() * aa.axis();
      }
    te.push_back(now() - t0);
  }
  double dlog = 0, dlw = 0;
  for (int i = 0; i < N; i++)
    for (int a = 0; a < 3; a++) {
      dlog = std::max(dlog, std::fabs(out[3 * i + a] - le[i](a)));
      dlw = std::max(dlw, std::fabs(out[3 * i + a] - w[3 * i + a]));
    }
  std::printf("  log      dmech %6.1f  Eigen %6.1f  ratio %.2f  (max difference %.2g; "
              "dmech log(exp w) - w %.2g)\n",
              1e9 * median(td) / (REP * N), 1e9 * median(te) / (REP * N),
              median(td) / median(te), dlog, dlw);
  // compose
  td.clear(), te.clear();
  for (int i = 0; i < N; i++)
    Re2[i] = Re[(i * 7 + 3) % N];
  for (int i = 0; i < N; i++)
    for (int a = 0; a < 9; a++)
      Rd2[9 * i + a] = Rd[9 * ((i * 7 + 3) % N) + a];
  for (int r = 0; r < RUNS; r++) {
    double t0 = now();
    for (int k = 0; k < REP; k++)
      for (int i = 0; i < N; i++)
        dm_lie_compose(G, &Rd[9 * i], &Rd2[9 * i], &out[9 * i]);
    td.push_back(now() - t0);
    t0 = now();
    for (int k = 0; k < REP; k++)
      for (int i = 0; i < N; i++)
        Re3[i] = Re[i] * Re2[i];
    te.push_back(now() - t0);
    sink = sink + out[0] + Re3[0](0, 0);
  }
  std::printf("  compose  dmech %6.1f  Eigen %6.1f  ratio %.2f\n", 1e9 * median(td) / (REP * N),
              1e9 * median(te) / (REP * N), median(td) / median(te));
  dm_lie_group_free(G);
  return sink == 12345.0;
}
