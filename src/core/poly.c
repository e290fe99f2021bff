/* poly.c: evaluation, Taylor shift and crossings of real polynomials of
 * degree <= 6. See poly.h for the conventions (crossings, states). */
#include "core/poly.h"

#include <complex.h>
#include <float.h>
#include <math.h>
#include <stddef.h>

#define U (DBL_EPSILON / 2)  /* unit roundoff */

int poly_degree(const double *c, int deg) {
  while (deg > 0 && c[deg] == 0.0) deg--;
  return deg;
}

/* Horner with Higham's running error bound (Accuracy and Stability of
 * Numerical Algorithms, Alg. 5.1): |fl(p(x)) - p(x)| <= u (2 mu - |y|). */
double poly_eval(const double *c, int deg, double x, double *err) {
  double y = c[deg], mu = fabs(y) / 2, ax = fabs(x);
  for (int i = deg - 1; i >= 0; i--) {
    y = x * y + c[i];
    mu = ax * mu + fabs(y);
  }
  if (err) *err = U * (2 * mu - fabs(y)) + DBL_MIN;
  return y;
}

double poly_eval_d(const double *c, int deg, double x, double *dp, double *err) {
  double y = c[deg], d = 0, mu = fabs(y) / 2, ax = fabs(x);
  for (int i = deg - 1; i >= 0; i--) {
    d = x * d + y;
    y = x * y + c[i];
    mu = ax * mu + fabs(y);
  }
  if (dp) *dp = d;
  if (err) *err = U * (2 * mu - fabs(y)) + DBL_MIN;
  return y;
}

int poly_deriv(const double *c, int deg, double *out) {
  if (deg <= 0) { out[0] = 0; return 0; }
  for (int i = 1; i <= deg; i++) out[i - 1] = i * c[i];
  return deg - 1;
}

/* Repeated synthetic division by (x - x0): after pass k, t[k] holds
 * p^(k)(x0)/k!. */
void poly_shift(const double *c, int deg, double x0, double *out) {
  double t[POLY_MAX_DEG + 1];
  for (int i = 0; i <= deg; i++) t[i] = c[i];
  for (int k = 0; k < deg; k++)
    for (int j = deg - 1; j >= k; j--) t[j] += x0 * t[j + 1];
  for (int i = 0; i <= deg; i++) out[i] = t[i];
}

/* ---- safeguarded Newton / bisection on one monotone bracket ---------- */

/* The crossing of p in (lo, hi) given the states at the ends (slo != shi).
 * Newton steps that stay inside the bracket and shrink it fast enough are
 * taken, else bisection (as Numerical Recipes' rtsafe); the bracket only
 * ever shrinks, so a sign change cannot be lost. Stops when p is zero to
 * within its rounding bound or the bracket is a few ulps wide. */
static double bracket_root(const double *c, int n, double lo, double hi,
                           int slo, long *steps) {
  double x = 0.5 * (lo + hi), dxold = hi - lo, dx = dxold;
  for (int it = 0; it < 200; it++) {
    ++*steps;
    double dp, err, p = poly_eval_d(c, n, x, &dp, &err);
    if (fabs(p) <= err) return x;
    if ((p > 0) == slo) lo = x; else hi = x;
    if (hi - lo <= 4 * DBL_EPSILON * fmax(fabs(lo), fabs(hi)) + DBL_MIN)
      return 0.5 * (lo + hi);
    double xn = dp != 0 ? x - p / dp : lo - 1;
    if (!(xn > lo && xn < hi) || fabs(2 * p) > fabs(dxold * dp)) {
      dxold = dx;
      dx = 0.5 * (hi - lo);
      x = lo + dx;
    } else {
      dxold = dx;
      dx = x - xn;
      if (xn == x) return x;
      x = xn;
    }
  }
  return x;
}

/* ---- derivative cascade ---------------------------------------------- */

/* Crossings of p in (a, b) with imposed end states: the crossings of p'
 * (found recursively) cut [a, b] into pieces on which p is monotone, so each
 * piece holds a crossing exactly when its end states differ. */
static int cascade(const double *c, int n, double a, double b, int sa,
                   int sb, double *out, long *steps) {
  double crit[POLY_MAX_DEG];
  int m = 0;
  if (n >= 2) {
    double dc[POLY_MAX_DEG];
    int dn = poly_deriv(c, n, dc);
    int da = poly_eval(dc, dn, a, NULL) > 0;
    int db = poly_eval(dc, dn, b, NULL) > 0;
    m = cascade(dc, dn, a, b, da, db, crit, steps);
  }
  int count = 0, slo = sa;
  double lo = a;
  for (int i = 0; i <= m; i++) {
    double hi = i < m ? crit[i] : b;
    int shi = i < m ? poly_eval(c, n, hi, NULL) > 0 : sb;
    if (shi != slo && hi > lo) out[count++] = bracket_root(c, n, lo, hi, slo, steps);
    else if (shi != slo) out[count++] = lo;  /* empty piece: a point */
    lo = hi;
    slo = shi;
  }
  return count;
}

/* ---- Laguerre's method (Ralston 1965; Numerical Recipes' laguer) ------ */

static double cmag(double complex z) {
  return sqrt(creal(z) * creal(z) + cimag(z) * cimag(z));
}

/* Refine *x towards a root of the degree-m complex polynomial a. Returns 0
 * if it did not converge within the iteration limit. */
static int laguer(const double complex *a, int m, double complex *x,
                  long *steps) {
  static const double frac[9] = {0, .5, .25, .75, .13, .38, .62, .88, 1};
  for (int iter = 1; iter <= 80; iter++) {
    ++*steps;
    double complex b = a[m], d = 0, f = 0;
    double err = cmag(b), abx = cmag(*x);
    for (int j = m - 1; j >= 0; j--) {
      f = *x * f + d;
      d = *x * d + b;
      b = *x * b + a[j];
      err = cmag(b) + abx * err;
    }
    if (cmag(b) <= err * DBL_EPSILON) return 1;
    double complex g = d / b, g2 = g * g, h = g2 - 2.0 * f / b;
    double complex sq = csqrt((double)(m - 1) * ((double)m * h - g2));
    double complex gp = g + sq, gm = g - sq;
    double abp = cmag(gp), abm = cmag(gm);
    if (abp < abm) gp = gm;
    double complex dx = fmax(abp, abm) > 0 ? (double)m / gp
        : (1 + abx) * (cos((double)iter) + I * sin((double)iter));
    double complex x1 = *x - dx;
    if (x1 == *x) return 1;
    if (iter % 10) *x = x1;
    else *x -= frac[iter / 10] * dx;
  }
  return 0;
}

static void sort_doubles(double *v, int n) {
  for (int i = 1; i < n; i++) {
    double t = v[i];
    int j = i - 1;
    while (j >= 0 && v[j] > t) { v[j + 1] = v[j]; j--; }
    v[j + 1] = t;
  }
}

/* All roots of q (degree n, in v = (x - m)/h) by Laguerre with deflation,
 * each polished on the ORIGINAL p (x-space). The crossings in (a, b) are
 * accepted only if the roots are clearly real or clearly complex, not
 * clustered, and the states at a, between consecutive roots and at b
 * alternate; otherwise returns -1 and the caller falls back. */
static int laguerre_crossings(const double *c, int n, const double *q,
                              double m, double h, double a, double b,
                              int sa, int sb, double *out, long *steps) {
  double complex ad[POLY_MAX_DEG + 1], orig[POLY_MAX_DEG + 1];
  double complex z[POLY_MAX_DEG];
  for (int i = 0; i <= n; i++) { ad[i] = q[i]; orig[i] = c[i]; }
  for (int j = n; j >= 1; j--) {
    double complex x = 0;
    if (!laguer(ad, j, &x, steps)) return -1;
    z[j - 1] = x;
    double complex bb = ad[j];
    for (int jj = j - 1; jj >= 0; jj--) {
      double complex cc = ad[jj];
      ad[jj] = bb;
      bb = x * bb + cc;
    }
  }
  double cand[POLY_MAX_DEG];
  int nc = 0;
  for (int j = 0; j < n; j++) {
    double complex x = m + h * z[j];
    if (!laguer(orig, n, &x, steps)) return -1;
    double complex v = (x - m) / h;
    double re = creal(v), im = fabs(cimag(v)), scale = 1 + fabs(re);
    if (im <= 1e-9 * scale) {
      double xr = creal(x);
      if (fabs(re) < 1.5) {
        for (int k = 0; k < nc; k++)  /* clustered: let the cascade decide */
          if (fabs(cand[k] - xr) <= 1e-7 * h * scale) return -1;
      }
      if (xr > a && xr < b) cand[nc++] = xr;
    } else if (im < 1e-3 * scale && fabs(re) < 1.5) {
      return -1;  /* near-real pair: a double root or a tight cluster */
    }
  }
  sort_doubles(cand, nc);
  int prev = sa;
  for (int k = 0; k < nc; k++) {
    int next;
    if (k + 1 < nc) {
      double err, mid = 0.5 * (cand[k] + cand[k + 1]);
      double p = poly_eval(c, n, mid, &err);
      if (fabs(p) <= err) return -1;
      next = p > 0;
    } else {
      next = sb;
    }
    if (next == prev) return -1;
    prev = next;
  }
  if (nc == 0 && sa != sb) return -1;
  for (int k = 0; k < nc; k++) out[k] = cand[k];
  return nc;
}

/* ---- driver ---------------------------------------------------------- */

static int crossings(const double *c, int deg, double a, double b,
                     int pos_a, int pos_b, unsigned opts, double *roots,
                     poly_stats *st, long *lsteps, long *bsteps);

int poly_crossings(const double *c, int deg, double a, double b, int pos_a,
                   int pos_b, unsigned opts, double *roots, poly_stats *st) {
  pos_a = pos_a != 0;
  pos_b = pos_b != 0;
  long lsteps = 0, bsteps = 0;
  int k = crossings(c, deg, a, b, pos_a, pos_b, opts, roots, st, &lsteps,
                    &bsteps);
  if (st) {
    st->laguerre_steps += lsteps;
    st->bracket_steps += bsteps;
  }
  return k;
}

/* poly_crossings, counting its iterations into *lsteps and *bsteps. */
static int crossings(const double *c, int deg, double a, double b,
                     int pos_a, int pos_b, unsigned opts, double *roots,
                     poly_stats *st, long *lsteps, long *bsteps) {
  if (st) st->solves++;
  if (!(a < b)) return 0;
  int n = poly_degree(c, deg);
  if (n == 0) {
    /* constant: a crossing only where an imposed state disagrees */
    if (pos_a == pos_b) return 0;
    roots[0] = (c[0] > 0) == pos_a ? b : a;
    return 1;
  }

  /* Range bounds on the interval written as [m - h, m + h]. */
  double m = 0.5 * (a + b), h = 0.5 * (b - a), q[POLY_MAX_DEG + 1];
  poly_shift(c, n, m, q);
  double hp = h, big = fmax(fabs(a), fabs(b)), scale = 0, bp = 1;
  for (int i = 1; i <= n; i++) { q[i] *= hp; hp *= h; }
  for (int i = 0; i <= n; i++) { scale += fabs(c[i]) * bp; bp *= big; }
  double slack = 8 * (n + 1) * DBL_EPSILON * scale;  /* shift's rounding */
  double s1 = 0, s2 = 0;
  for (int i = 1; i <= n; i++) s1 += fabs(q[i]);
  for (int i = 2; i <= n; i++) s2 += i * fabs(q[i]);
  if (fabs(q[0]) > s1 + slack && pos_a == pos_b && (q[0] > 0) == pos_a) {
    if (st) st->quick++;
    return 0;  /* p cannot vanish on [a, b] */
  }
  if (fabs(q[1]) > s2 + slack) {  /* p' cannot vanish: p is monotone */
    if (st) st->quick++;
    if (pos_a == pos_b) return 0;
    roots[0] = bracket_root(c, n, a, b, pos_a, bsteps);
    return 1;
  }

  if (!(opts & POLY_CASCADE_ONLY)) {
    int k = laguerre_crossings(c, n, q, m, h, a, b, pos_a, pos_b, roots,
                               lsteps);
    if (k >= 0) {
      if (st) st->laguerre++;
      return k;
    }
  }
  if (st) st->fallbacks++;
  return cascade(c, n, a, b, pos_a, pos_b, roots, bsteps);
}

int poly_roots(const double *c, int deg, double a, double b, double *roots,
               poly_stats *st) {
  int sa = poly_eval(c, deg, a, NULL) > 0;
  int sb = poly_eval(c, deg, b, NULL) > 0;
  return poly_crossings(c, deg, a, b, sa, sb, 0, roots, st);
}
