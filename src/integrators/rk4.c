/* rk4.c -- classical Runge-Kutta 4 on the Hamiltonian form of the system
 * (non-symplectic reference): y = (q, p), ydot = (v(q, p), Lq + F) with v
 * from the Legendre map by Newton (legendre.c).  The step Jacobian is exact:
 * the variational equation is propagated through the four stages. */
#include <config.h>
#include "integrators/integ_impl.h"

#include <stdlib.h>
#include <string.h>

typedef struct rk4_state {
  double *y, *k, *Y;          /* 2n, 4 x 2n, 2n */
  double *Jf, *K, *dY;        /* 4n^2, 4 x 4n^2, 4n^2 */
} rk4_state;

static const char *const rk4_options[] = {"h", NULL};

static void rk4_free(dm_integrator *I)
{
  rk4_state *R = I->state;
  if (R) {
    free(R->y);
    free(R);
  }
  I->state = NULL;
}

static int rk4_alloc(dm_integrator *I, dm_err *e)
{
  size_t N = 2 * I->n;
  rk4_state *R = calloc(1, sizeof *R);
  if (R == NULL || (R->y = calloc(6 * N + 6 * N * N, sizeof(double))) == NULL) {
    free(R);
    return dm_err_set(e, DM_ENOMEM, "rk4: out of memory");
  }
  R->k = R->y + N;
  R->Y = R->k + 4 * N;
  R->Jf = R->Y + N;
  R->K = R->Jf + N * N;
  R->dY = R->K + 4 * N * N;
  I->state = R;
  I->order = 4;
  I->flags = DM_INTEG_EXPLICIT | DM_INTEG_FORCES | DM_INTEG_EXACT_JAC;
  return DM_OK;
}

static const double rk4_c[4] = {0.0, 0.5, 0.5, 1.0};
static const double rk4_w[4] = {1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6};

/* Stage i evaluates at Y = y + h c_i k_{i-1}; with jac, also K_i = Jf(Y) dY,
 * dY = I + h c_i K_{i-1}. */
static int rk4_run(dm_integrator *I, double h, const double *q0, const double *p0,
                   double *q1, double *p1, double *DPhi, dm_err *e)
{
  rk4_state *R = I->state;
  size_t n = I->n, N = 2 * n, i, a, b, c;
  int st;
  dm_vcopy(R->y, q0, n);
  dm_vcopy(R->y + n, p0, n);
  for (i = 0; i < 4; i++) {
    double *ki = R->k + i * N;
    if (i == 0)
      dm_vcopy(R->Y, R->y, N);
    else
      for (a = 0; a < N; a++)
        R->Y[a] = R->y[a] + h * rk4_c[i] * R->k[(i - 1) * N + a];
    if ((st = dm_legendre_field(I->leg, R->Y, R->Y + n, ki, ki + n, e)) != DM_OK)
      return st;
    if (DPhi) {
      double *Ki = R->K + i * N * N;
      if ((st = dm_legendre_field_jac(I->leg, R->Y, R->Y + n, R->Jf, e)) != DM_OK)
        return st;
      for (a = 0; a < N; a++)
        for (b = 0; b < N; b++)
          R->dY[a * N + b] = (a == b) + (i ? h * rk4_c[i] * R->K[(i - 1) * N * N + a * N + b] : 0.0);
      for (a = 0; a < N; a++)
        for (b = 0; b < N; b++) {
          double acc = 0.0;
          for (c = 0; c < N; c++)
            acc += R->Jf[a * N + c] * R->dY[c * N + b];
          Ki[a * N + b] = acc;
        }
    }
  }
  for (a = 0; a < N; a++) {
    double acc = 0.0;
    for (i = 0; i < 4; i++)
      acc += rk4_w[i] * R->k[i * N + a];
    R->Y[a] = R->y[a] + h * acc;
  }
  if (DPhi)
    for (a = 0; a < N * N; a++) {
      double acc = 0.0;
      for (i = 0; i < 4; i++)
        acc += rk4_w[i] * R->K[i * N * N + a];
      DPhi[a] = (a / N == a % N) + h * acc;
    }
  if (q1) {
    dm_vcopy(q1, R->Y, n);
    dm_vcopy(p1, R->Y + n, n);
  }
  I->stats.iters = 0;
  I->stats.steps++;
  return DM_OK;
}

static int rk4_step(dm_integrator *I, double h, const double *q0, const double *p0,
                    double *q1, double *p1, dm_err *e)
{
  return rk4_run(I, h, q0, p0, q1, p1, NULL, e);
}

static int rk4_jacobian(dm_integrator *I, double h, const double *q0, const double *p0,
                        double *DPhi, dm_err *e)
{
  return rk4_run(I, h, q0, p0, NULL, NULL, DPhi, e);
}

const dm_integrator_type dm_integ_rk4 = {
  .name = "rk4",
  .summary = "classical 4th-order Runge-Kutta on (q, p) (non-symplectic reference)",
  .order = 4,
  .flags = DM_INTEG_EXPLICIT | DM_INTEG_FORCES | DM_INTEG_EXACT_JAC,
  .options = rk4_options,
  .alloc = rk4_alloc,
  .step = rk4_step,
  .jacobian = rk4_jacobian,
  .dlegendre = NULL,
  .advance = NULL,
  .reset = NULL,
  .free = rk4_free,
};
