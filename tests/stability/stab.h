/* stab.h: the shared part of the numerical stability suite (issue 6).
 *
 * References, independent of the code under test and evaluated in MPFR
 * (STAB_PREC bits) straight from the papers:
 *   - Lobb eq. (1) for one halfspace: the fraction of the ball of radius r
 *     about the point that lies inside the halfspace, i.e. the spherical
 *     cap volume pi h^2 (3r - h)/3 over 4/3 pi r^3 (h = r - s, s the signed
 *     distance, outside positive); r = 0 is the sharp step 1, 1/2, 0.
 *     Sum, Product, Difference and the density union a + b - ab combine
 *     the values arithmetically (Figure 4).  The slope of a leaf, used only
 *     to scale tolerances, is the cap's cross-section: -3 (r^2 - s^2)/(4 r^3).
 *   - Wyvill and Trotman eq. (1) for a key: C(r) = -4/9 r^6/R^6 +
 *     17/9 r^4/R^4 - 22/9 r^2/R^2 + 1 inside R, 0 outside, from the
 *     distance r to the centre; the field is the weighted sum.
 * Neither builds a polynomial in the ray parameter, and the ray point
 * o + t d is formed exactly in MPFR from the double o, d and t.
 *
 * Reference crossings along a ray: the sign of f = field - level sampled
 * at nsamp uniform points plus every breakpoint (where the ray enters or
 * leaves a filter or a key), each sign change bisected to adjacent doubles,
 * and each discrete local minimum of |f| zoomed by golden-section search in
 * MPFR so that a pair of crossings far closer than the sample spacing (two
 * crossings 1e-6 apart, a near-tangent ray) is seen; a minimum that reaches
 * 0 exactly, or within STAB_TOUCH, is a touch (tangent), not a crossing.
 *
 * Tolerance for a crossing at distance s along the unit direction:
 *   |t_got - t_ref| |d|  <=  tol + 8 eps A / |df/ds|
 * with tol the root tolerance given to the code (scene units), eps =
 * 2^-52, df/ds the reference slope along the ray per unit length (MPFR
 * central difference), and A the absolute condition of f at the crossing:
 *   density: nleaves + S sum_leaves |d rho_leaf / ds|
 *   soft:    sum_keys |w| (1 + S |dC/dr|)
 * S = max(1, |o|, |p|): the size of the coordinates (their rounding).  So
 * a crossing must be as accurate as the double evaluation of the field at
 * that point allows, plus the tolerance in force; nothing looser.
 *
 * Also: building scenes from qcs text through the interpreter (as the
 * probes do), capturing warnings (stderr), and one summary line per case
 * ("# summary | case | ...") that tests/stability/README.md copies. */
#ifndef QCS_STAB_H
#define QCS_STAB_H

#include <float.h>
#include <mpfr.h>
#include <stdarg.h>
#include <stdint.h>
#include <unistd.h>

#include "check.h"
#include "lang/eval.h"
#include "bind/bind.h"
#include "lang/interp.h"
#include "lang/parse.h"
#include "scene/ray.h"
#include "bind/compile.h"

#define STAB_PREC 200
#define STAB_MAXR 256
#define STAB_EPS DBL_EPSILON

/* ---- reference density trees ---------------------------------------- */

enum { SR_LEAF, SR_SUM, SR_PROD, SR_DIFF, SR_UNION };

typedef struct {
  int op, a, b;
  double n[3], d, r;    /* raw plane n.x < d (not normalised), radius */
  mpfr_t un[3], ud;     /* normalised in MPFR (stree_ready) */
} snode;

typedef struct {
  snode nodes[128];
  int n, root, ready;
} stree;

static inline int st_leaf(stree *t, double nx, double ny, double nz, double d,
                          double r) {
  snode *x = &t->nodes[t->n];
  memset(x, 0, sizeof *x);
  x->op = SR_LEAF;
  x->n[0] = nx; x->n[1] = ny; x->n[2] = nz;
  x->d = d;
  x->r = r;
  return t->root = t->n++;
}

static inline int st_op(stree *t, int op, int a, int b) {
  snode *x = &t->nodes[t->n];
  memset(x, 0, sizeof *x);
  x->op = op;
  x->a = a;
  x->b = b;
  return t->root = t->n++;
}

/* Product of the six halfspaces of the box [lo, hi], radius r. */
static inline int st_box(stree *t, const double lo[3], const double hi[3],
                         double r) {
  int k = -1;
  for (int i = 0; i < 3; i++) {
    double np[3] = {0, 0, 0};
    np[i] = 1;
    int a = st_leaf(t, np[0], np[1], np[2], hi[i], r);
    np[i] = -1;
    int b = st_leaf(t, np[0], np[1], np[2], -lo[i], r);
    int ab = st_op(t, SR_PROD, a, b);
    k = k < 0 ? ab : st_op(t, SR_PROD, k, ab);
  }
  return t->root = k;
}

static inline void stree_ready(stree *t) {
  if (t->ready) return;
  mpfr_t len, q;
  mpfr_inits2(STAB_PREC, len, q, (mpfr_ptr)0);
  for (int i = 0; i < t->n; i++) {
    snode *x = &t->nodes[i];
    if (x->op != SR_LEAF) continue;
    mpfr_set_zero(len, 1);
    for (int j = 0; j < 3; j++) {
      mpfr_set_d(q, x->n[j], MPFR_RNDN);
      mpfr_fma(len, q, q, len, MPFR_RNDN);
    }
    mpfr_sqrt(len, len, MPFR_RNDN);
    for (int j = 0; j < 3; j++) {
      mpfr_init2(x->un[j], STAB_PREC);
      mpfr_set_d(x->un[j], x->n[j], MPFR_RNDN);
      mpfr_div(x->un[j], x->un[j], len, MPFR_RNDN);
    }
    mpfr_init2(x->ud, STAB_PREC);
    mpfr_set_d(x->ud, x->d, MPFR_RNDN);
    mpfr_div(x->ud, x->ud, len, MPFR_RNDN);
  }
  mpfr_clears(len, q, (mpfr_ptr)0);
  t->ready = 1;
}

static inline void stree_free(stree *t) {
  if (!t->ready) return;
  for (int i = 0; i < t->n; i++) {
    snode *x = &t->nodes[i];
    if (x->op != SR_LEAF) continue;
    for (int j = 0; j < 3; j++) mpfr_clear(x->un[j]);
    mpfr_clear(x->ud);
  }
  t->ready = 0;
}

/* Signed distance (outside positive) of p from leaf x, in MPFR. */
static inline void st_dist(mpfr_t s, const snode *x, mpfr_t p[3]) {
  mpfr_mul(s, x->un[0], p[0], MPFR_RNDN);
  mpfr_fma(s, x->un[1], p[1], s, MPFR_RNDN);
  mpfr_fma(s, x->un[2], p[2], s, MPFR_RNDN);
  mpfr_sub(s, s, x->ud, MPFR_RNDN);
}

/* eq. (1) for one halfspace: the cap-volume fraction. */
static inline void st_cap(mpfr_t out, const mpfr_t s, double r) {
  if (r == 0) {
    int c = mpfr_sgn(s);
    mpfr_set_d(out, c < 0 ? 1.0 : (c > 0 ? 0.0 : 0.5), MPFR_RNDN);
    return;
  }
  mpfr_t h, v, w;
  mpfr_inits2(STAB_PREC, h, v, w, (mpfr_ptr)0);
  mpfr_d_sub(h, r, s, MPFR_RNDN);               /* h = r - s */
  if (mpfr_sgn(h) <= 0) mpfr_set_zero(out, 1);
  else if (mpfr_cmp_d(h, 2 * r) >= 0) mpfr_set_ui(out, 1, MPFR_RNDN);
  else {
    /* pi h^2 (3r - h)/3 / (4/3 pi r^3) = h^2 (3r - h) / (4 r^3) */
    mpfr_set_d(v, r, MPFR_RNDN);
    mpfr_mul_ui(v, v, 3, MPFR_RNDN);
    mpfr_sub(v, v, h, MPFR_RNDN);
    mpfr_mul(v, v, h, MPFR_RNDN);
    mpfr_mul(v, v, h, MPFR_RNDN);
    mpfr_set_d(w, r, MPFR_RNDN);
    mpfr_pow_ui(w, w, 3, MPFR_RNDN);
    mpfr_mul_ui(w, w, 4, MPFR_RNDN);
    mpfr_div(out, v, w, MPFR_RNDN);
  }
  mpfr_clears(h, v, w, (mpfr_ptr)0);
}

/* |d(cap fraction)/ds| = pi (r^2 - s^2) / (4/3 pi r^3), 0 outside. */
static inline double st_cap_slope(double s, double r) {
  if (r == 0 || fabs(s) >= r) return 0;
  return 3 * (r * r - s * s) / (4 * r * r * r);
}

/* Density of node i at p; *cond += the condition terms of its leaves. */
static inline void st_eval(mpfr_t out, stree *t, int i, mpfr_t p[3],
                           double S, double *cond) {
  snode *x = &t->nodes[i];
  if (x->op == SR_LEAF) {
    mpfr_t s;
    mpfr_init2(s, STAB_PREC);
    st_dist(s, x, p);
    st_cap(out, s, x->r);
    if (cond) *cond += 1 + S * st_cap_slope(mpfr_get_d(s, MPFR_RNDN), x->r);
    mpfr_clear(s);
    return;
  }
  mpfr_t a, b;
  mpfr_inits2(STAB_PREC, a, b, (mpfr_ptr)0);
  st_eval(a, t, x->a, p, S, cond);
  st_eval(b, t, x->b, p, S, cond);
  switch (x->op) {
  case SR_SUM: mpfr_add(out, a, b, MPFR_RNDN); break;
  case SR_PROD: mpfr_mul(out, a, b, MPFR_RNDN); break;
  case SR_DIFF: mpfr_sub(out, a, b, MPFR_RNDN); break;
  default:
    mpfr_add(out, a, b, MPFR_RNDN);
    mpfr_fms(a, a, b, out, MPFR_RNDN);    /* ab - (a + b) */
    mpfr_neg(out, a, MPFR_RNDN);
  }
  mpfr_clears(a, b, (mpfr_ptr)0);
}

/* ---- reference soft objects ------------------------------------------ */

typedef struct { double c[3], R, w; } skey;

typedef struct {
  skey *keys;      /* all keys */
  int nkeys;
  double magic;
  int *act, nact;  /* the keys a ray can meet (soft_select) */
  double *te, *tx; /* and where along the ray (padded) */
  double tcur;     /* the ray parameter being evaluated (NAN: any) */
} ssoft;

/* Keys whose sphere the line o + t d passes within R of (in double with a
 * generous margin), so that 1e5 keys cost only what a ray meets. */
static inline void soft_select(ssoft *S, const double o[3], const double d[3]) {
  if (!S->act) {
    S->act = malloc(sizeof(int) * (size_t)(S->nkeys + 1));
    S->te = malloc(sizeof(double) * (size_t)(2 * S->nkeys + 2));
    S->tx = S->te + S->nkeys + 1;
  }
  double len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  S->nact = 0;
  S->tcur = NAN;
  for (int k = 0; k < S->nkeys; k++) {
    const skey *K = &S->keys[k];
    double q[3] = {K->c[0] - o[0], K->c[1] - o[1], K->c[2] - o[2]};
    double qd = q[0] * d[0] + q[1] * d[1] + q[2] * d[2];
    double q2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
    double perp2 = q2 - qd * qd / len2;
    double R = K->R * (1 + 1e-6) + 1e-9 * sqrt(q2);
    if (perp2 <= R * R) {
      double tc = qd / len2, half = sqrt(fmax(0, R * R - perp2) / len2);
      double pad = 1e-6 * half + 1e-9 * fabs(tc) + 1e-300;
      S->te[S->nact] = tc - half - pad;
      S->tx[S->nact] = tc + half + pad;
      S->act[S->nact++] = k;
    }
  }
}

/* eq. (1): the field at p over the selected keys (all if sel = 0). */
static inline void soft_eval(mpfr_t out, const ssoft *S, mpfr_t p[3], int sel,
                             double Sc, double *cond) {
  mpfr_t r2, q, x, c;
  mpfr_inits2(STAB_PREC, r2, q, x, c, (mpfr_ptr)0);
  mpfr_set_zero(out, 1);
  int n = sel ? S->nact : S->nkeys;
  for (int j = 0; j < n; j++) {
    if (sel && !isnan(S->tcur) && !(S->tcur >= S->te[j] && S->tcur <= S->tx[j]))
      continue;
    const skey *K = &S->keys[sel ? S->act[j] : j];
    mpfr_set_zero(r2, 1);
    for (int i = 0; i < 3; i++) {
      mpfr_sub_d(q, p[i], K->c[i], MPFR_RNDN);
      mpfr_fma(r2, q, q, r2, MPFR_RNDN);
    }
    mpfr_set_d(q, K->R, MPFR_RNDN);
    mpfr_sqr(q, q, MPFR_RNDN);
    mpfr_div(x, r2, q, MPFR_RNDN);               /* r^2 / R^2 */
    if (mpfr_cmp_ui(x, 1) >= 0) {
      /* a key whose bound is within rounding still conditions f */
      if (cond && mpfr_cmp_d(x, 1 + 1e-9) <= 0) *cond += fabs(K->w);
      continue;
    }
    /* -4/9 x^3 + 17/9 x^2 - 22/9 x + 1 */
    mpfr_mul_si(c, x, -4, MPFR_RNDN);
    mpfr_add_ui(c, c, 17, MPFR_RNDN);
    mpfr_mul(c, c, x, MPFR_RNDN);
    mpfr_sub_ui(c, c, 22, MPFR_RNDN);
    mpfr_mul(c, c, x, MPFR_RNDN);
    mpfr_div_ui(c, c, 9, MPFR_RNDN);
    mpfr_add_ui(c, c, 1, MPFR_RNDN);
    mpfr_mul_d(c, c, K->w, MPFR_RNDN);
    mpfr_add(out, out, c, MPFR_RNDN);
    if (cond) {
      double xs = mpfr_get_d(x, MPFR_RNDN), r = sqrt(xs) * K->R;
      /* dC/dr = (-24/9 x^2 + 68/9 x - 44/9) r / R^2 */
      double dcdr = fabs((-24.0 / 9 * xs * xs + 68.0 / 9 * xs - 44.0 / 9) * r /
                         (K->R * K->R));
      *cond += fabs(K->w) * (1 + Sc * dcdr);
    }
  }
  mpfr_clears(r2, q, x, c, (mpfr_ptr)0);
}

/* ---- a field along a ray ---------------------------------------------- */

typedef struct {
  stree *tree;          /* either a density tree ... */
  ssoft *soft;          /* ... or a soft object */
  double level;         /* 0.5 for densities, magic for soft objects */
  double o[3], d[3];
  long evals;
} sray;

/* f(p) = field(p) - level; *cond (if not NULL) receives A. */
static inline void sray_at_point(sray *R, mpfr_t p[3], mpfr_t out,
                                 double *cond) {
  double S = 1;
  if (cond) {
    for (int i = 0; i < 3; i++) S = fmax(S, fabs(mpfr_get_d(p[i], MPFR_RNDN)));
    for (int i = 0; i < 3; i++) S = fmax(S, fabs(R->o[i]));
    *cond = 0;
  }
  R->evals++;
  if (R->tree) st_eval(out, R->tree, R->tree->root, p, S, cond);
  else soft_eval(out, R->soft, p, 1, S, cond);
  mpfr_sub_d(out, out, R->level, MPFR_RNDN);
}

static inline void sray_point(const sray *R, double t, mpfr_t p[3]) {
  if (R->soft) R->soft->tcur = t;
  for (int i = 0; i < 3; i++) {
    mpfr_set_d(p[i], R->d[i], MPFR_RNDN);
    mpfr_mul_d(p[i], p[i], t, MPFR_RNDN);     /* exact at 200 bits */
    mpfr_add_d(p[i], p[i], R->o[i], MPFR_RNDN);
  }
}

/* f at o + t d as a double (sign exact: MPFR rounds to nearest, and the
 * suite's values never underflow), and the MPFR value when wanted. */
static inline double sray_f(sray *R, double t) {
  mpfr_t p[3], v;
  mpfr_inits2(STAB_PREC, p[0], p[1], p[2], v, (mpfr_ptr)0);
  sray_point(R, t, p);
  sray_at_point(R, p, v, NULL);
  double f = mpfr_get_d(v, MPFR_RNDN);
  if (f == 0 && mpfr_sgn(v) != 0) f = mpfr_sgn(v) * DBL_MIN;
  mpfr_clears(p[0], p[1], p[2], v, (mpfr_ptr)0);
  return f;
}

typedef struct {
  double t;
  int kind;       /* +1: f rises through 0 (entering), -1: falls, 0: touch */
  double slope;   /* |df/ds| per unit length along the ray */
  double cond;    /* A at the crossing */
  double allow;   /* the tolerance for this crossing in scene units */
  double lo, hi;  /* touch: where |f| <= 8 eps A around it (a pair of
                     crossings there, or none, are both right) */
} sroot;

/* Slope per unit length and condition at t. */
static inline void sray_slope(sray *R, double t, double *slope, double *cond) {
  double len = sqrt(R->d[0] * R->d[0] + R->d[1] * R->d[1] + R->d[2] * R->d[2]);
  double h = 1e-12 * fmax(fabs(t), 1 / len);
  mpfr_t p[3], v, w;
  mpfr_inits2(STAB_PREC, p[0], p[1], p[2], v, w, (mpfr_ptr)0);
  sray_point(R, t + h, p);
  sray_at_point(R, p, v, NULL);
  sray_point(R, t - h, p);
  sray_at_point(R, p, w, NULL);
  mpfr_sub(v, v, w, MPFR_RNDN);
  *slope = fabs(mpfr_get_d(v, MPFR_RNDN)) / (2 * h * len);
  sray_point(R, t, p);
  sray_at_point(R, p, v, cond);
  mpfr_clears(p[0], p[1], p[2], v, w, (mpfr_ptr)0);
}

/* Bisect a sign change of f on [a, b] (fa, fb of opposite signs) down to
 * adjacent doubles; returns the end nearer the zero of f. */
static inline double sray_bisect(sray *R, double a, double b, double fa,
                                 double fb) {
  for (int i = 0; i < 2000; i++) {
    double m = 0.5 * (a + b);
    if (!(m > a && m < b)) break;
    double fm = sray_f(R, m);
    if (fm == 0) return m;
    if ((fm < 0) == (fa < 0)) a = m, fa = fm;
    else b = m, fb = fm;
  }
  return fabs(fa) <= fabs(fb) ? a : b;
}

static inline int cmp_dbl(const void *x, const void *y) {
  double a = *(const double *)x, b = *(const double *)y;
  return (a > b) - (a < b);
}

/* A relative dip of |f| below this is a touch (an exact tangent). */
#define STAB_TOUCH 1e-40

/* Every crossing (and touch) of f on [a, b]; brk: extra sample points. */
static inline int sray_roots(sray *R, double a, double b, const double *brk,
                             int nbrk, int nsamp, sroot *out, int maxout) {
  int ns = nsamp + 1 + nbrk;
  double *x = malloc(sizeof(double) * (size_t)ns * 2), *f = x + ns;
  int n = 0;
  for (int i = 0; i <= nsamp; i++) x[n++] = a + (b - a) * i / nsamp;
  for (int i = 0; i < nbrk; i++)
    if (brk[i] > a && brk[i] < b) x[n++] = brk[i];
  qsort(x, (size_t)n, sizeof *x, cmp_dbl);
  int m = 0;
  for (int i = 0; i < n; i++)
    if (m == 0 || x[i] > x[m - 1]) x[m++] = x[i];
  n = m;
  for (int i = 0; i < n; i++) f[i] = sray_f(R, x[i]);
  int nr = 0;
#define SR_ADD(tt, kk)                                                      \
  do {                                                                      \
    if (nr < maxout) {                                                      \
      out[nr].t = out[nr].lo = out[nr].hi = (tt);                           \
      out[nr].kind = (kk);                                                  \
      nr++;                                                                 \
    }                                                                       \
  } while (0)
  for (int i = 0; i < n; i++) {
    if (f[i] == 0) {  /* a zero at a sample: crossing or touch */
      int l = i - 1, r = i + 1;
      while (l >= 0 && f[l] == 0) l--;
      while (r < n && f[r] == 0) r++;
      int sl = l >= 0 ? (f[l] > 0 ? 1 : -1) : 0, sr = r < n ? (f[r] > 0 ? 1 : -1) : 0;
      if (r - l > 2) { i = r - 1; continue; }  /* f == 0 on a stretch */
      SR_ADD(x[i], sl && sr && sl != sr ? sr : 0);
      continue;
    }
    if (i > 0 && f[i - 1] != 0 && (f[i - 1] < 0) != (f[i] < 0))
      SR_ADD(sray_bisect(R, x[i - 1], x[i], f[i - 1], f[i]), f[i] > 0 ? 1 : -1);
    if (i > 0 && i + 1 < n && f[i - 1] != 0 && f[i + 1] != 0 &&
        (f[i - 1] < 0) == (f[i] < 0) && (f[i + 1] < 0) == (f[i] < 0) &&
        fabs(f[i]) <= fabs(f[i - 1]) && fabs(f[i]) <= fabs(f[i + 1]) &&
        (fabs(f[i]) < fabs(f[i - 1]) || fabs(f[i]) < fabs(f[i + 1]))) {
      /* golden-section search for the dip of |f| */
      double sg = f[i] > 0 ? 1 : -1, lo = x[i - 1], hi = x[i + 1];
      const double gr = 0.6180339887498949;
      double c = hi - gr * (hi - lo), dd = lo + gr * (hi - lo);
      double fc = sg * sray_f(R, c), fd = sg * sray_f(R, dd);
      double best = sg * f[i], tb = x[i];
      for (int it = 0; it < 400 && hi - lo > 0; it++) {
        if (fc < best) best = fc, tb = c;
        if (fd < best) best = fd, tb = dd;
        if (best <= 0) break;
        if (fc < fd) { hi = dd; dd = c; fd = fc; c = hi - gr * (hi - lo); fc = sg * sray_f(R, c); }
        else { lo = c; c = dd; fc = fd; dd = lo + gr * (hi - lo); fd = sg * sray_f(R, dd); }
        if (!(c > lo && dd < hi && c < dd)) break;
      }
      /* the rounding of the field in doubles at the dip */
      double A;
      {
        mpfr_t p[3], v;
        mpfr_inits2(STAB_PREC, p[0], p[1], p[2], v, (mpfr_ptr)0);
        sray_point(R, tb, p);
        sray_at_point(R, p, v, &A);
        mpfr_clears(p[0], p[1], p[2], v, (mpfr_ptr)0);
      }
      double thr = 8 * STAB_EPS * A;
      if (fabs(best) <= thr) {  /* a touch within rounding: find its window */
        double w[2];
        for (int side = 0; side < 2; side++) {
          double u = tb, v = side ? x[i + 1] : x[i - 1];  /* in, out */
          if (sg * sray_f(R, v) <= thr) { w[side] = v; continue; }
          for (int it = 0; it < 200; it++) {
            double mid = 0.5 * (u + v);
            if (mid == u || mid == v) break;
            if (sg * sray_f(R, mid) <= thr) u = mid; else v = mid;
          }
          w[side] = v;
        }
        SR_ADD(tb, 0);
        if (nr <= maxout) { out[nr - 1].lo = w[0]; out[nr - 1].hi = w[1]; }
      } else if (best < 0) {  /* two crossings around the dip */
        SR_ADD(sray_bisect(R, x[i - 1], tb, f[i], -sg * fabs(best)), -(int)sg);
        SR_ADD(sray_bisect(R, tb, x[i + 1], -sg * fabs(best), f[i + 1]), (int)sg);
      }
    }
  }
#undef SR_ADD
  free(x);
  /* sort (dips are inserted out of order) */
  for (int i = 1; i < nr; i++) {
    sroot k = out[i];
    int j = i - 1;
    while (j >= 0 && out[j].t > k.t) { out[j + 1] = out[j]; j--; }
    out[j + 1] = k;
  }
  for (int i = 0; i < nr; i++) sray_slope(R, out[i].t, &out[i].slope, &out[i].cond);
  return nr;
}

/* Breakpoints of a density tree along the ray: where each leaf's filter
 * begins and ends (and a sharp leaf's plane). */
static inline int stree_breaks(const stree *t, const double o[3],
                               const double d[3], double *out) {
  int n = 0;
  for (int i = 0; i < t->n; i++) {
    const snode *x = &t->nodes[i];
    if (x->op != SR_LEAF) continue;
    double len = sqrt(x->n[0] * x->n[0] + x->n[1] * x->n[1] + x->n[2] * x->n[2]);
    double nd = (x->n[0] * d[0] + x->n[1] * d[1] + x->n[2] * d[2]) / len;
    double no = (x->n[0] * o[0] + x->n[1] * o[1] + x->n[2] * o[2] - x->d) / len;
    if (nd == 0) continue;
    out[n++] = (-x->r - no) / nd;
    out[n++] = (x->r - no) / nd;
    if (x->r > 0) out[n++] = -no / nd;
  }
  return n;
}

/* Where the ray enters and leaves each selected key and its closest point. */
static inline int soft_breaks(const ssoft *S, const double o[3],
                              const double d[3], double *out) {
  int n = 0;
  double len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  for (int j = 0; j < S->nact; j++) {
    const skey *K = &S->keys[S->act[j]];
    double q[3] = {K->c[0] - o[0], K->c[1] - o[1], K->c[2] - o[2]};
    double qd = q[0] * d[0] + q[1] * d[1] + q[2] * d[2];
    double q2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
    double tc = qd / len2, perp2 = fmax(0, q2 - qd * qd / len2);
    double half = sqrt(fmax(0, K->R * K->R - perp2) / len2);
    out[n++] = tc - half;
    out[n++] = tc;
    out[n++] = tc + half;
  }
  return n;
}

/* ---- scenes from qcs text ------------------------------------------- */

static Interp *stab_I;
static char stab_error[1100];

/* base: a local of main, where the C stack begins. */
static inline void stab_init(const char *prefix, char *base) {
  check_prefix = prefix;
  stab_I = bind_interp_new();
  interp_set_stack(stab_I, base, 4u << 20);
}

/* Compile qcs text into a scene; NULL and stab_error on an error. The
 * text must outlive the scene (it is copied and never freed). */
static inline Scene *stab_compile(const char *text) {
  Src *src = calloc(1, sizeof *src);
  size_t n = strlen(text) + 1;
  char *copy = malloc(n);
  memcpy(copy, text, n);
  src->name = "<stab>";
  src->text = copy;
  ErrFrame f;
  Scene *volatile s = NULL;
  int nforcing = stab_I->nforcing;
  stab_error[0] = 0;
  if (ERR_TRY(f)) {
    Expr *e = parse_expression(stab_I, src);
    Value *v = eval(stab_I, e, NULL);
    s = compile_scene(stab_I, v, pos_none);
    err_pop(&f);
  } else {
    err_pop(&f);
    ErrInfo *e = err_info();
    snprintf(stab_error, sizeof stab_error, "%d:%d: %s", e->pos.line,
             e->pos.col, e->msg);
    while (stab_I->nforcing > nforcing) {
      stab_I->nforcing--;
      *stab_I->forcing[stab_I->nforcing].v = stab_I->forcing[stab_I->nforcing].saved;
    }
    stab_I->ntrace = 0;
  }
  return s;
}

/* Compile with stderr captured into warn (the warnings it printed). */
static inline Scene *stab_compile_warn(const char *text, char *warn,
                                       size_t nwarn) {
  fflush(stderr);
  int saved = dup(2);
  FILE *tmp = tmpfile();
  dup2(fileno(tmp), 2);
  Scene *s = stab_compile(text);
  fflush(stderr);
  dup2(saved, 2);
  close(saved);
  rewind(tmp);
  size_t k = fread(warn, 1, nwarn - 1, tmp);
  warn[k] = 0;
  fclose(tmp);
  if (k) fprintf(stderr, "%s", warn);  /* still show them in the log */
  return s;
}

/* The crossings of the scene's root along the ray, t >= t0: span ends
 * that are surfaces (id >= 0). */
static inline int stab_scene_roots(const Scene *s, RayCtx *c, const double o[3],
                                   const double d[3], double t0, double t1,
                                   double *out, int maxout) {
  ray_reset(c);
  csg_span *sp;
  int n = ray_spans(s, s->root, o, d, t0, t1, c, &sp), cnt = 0;
  if (n < 0) return -1;
  for (int i = 0; i < n && cnt < maxout - 1; i++) {
    if (sp[i].id0 >= 0) out[cnt++] = sp[i].t0;
    if (sp[i].id1 >= 0 && isfinite(sp[i].t1)) out[cnt++] = sp[i].t1;
  }
  return cnt;
}

/* ---- comparing and summarising ---------------------------------------- */

typedef struct {
  const char *name;
  long rays, expected, found, missed, extra, nonfinite, overwork, touches;
  double max_err;        /* max |dt| |d| over matched crossings */
  double max_ratio;      /* max error / allowed */
  long max_work;         /* the most work one ray took (see case) */
  long work_cap;
  char first[300];       /* the first failure, for the log */
} scase;

static inline void sc_note(scase *c, const char *fmt, ...) {
  if (c->first[0]) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(c->first, sizeof c->first, fmt, ap);
  va_end(ap);
}

/* Compare the crossings got[0..ng) (ascending ray parameters) with the
 * reference ref (touches in ref are optional: the code may report none, or
 * a pair closer than 2 allow around it). tol: the root tolerance in scene
 * units. Returns 1 if the ray agrees. */
static inline int sc_compare(scase *c, const double *got, int ng,
                             sroot *ref, int nr, double tol, double len) {
  int ok = 1;
  c->rays++;
  for (int i = 0; i < ng; i++)
    if (!isfinite(got[i])) {
      c->nonfinite++;
      sc_note(c, "ray %ld: non-finite root %g", c->rays, got[i]);
      return 0;
    }
  int j = 0;
  for (int i = 0; i < nr; i++) {
    ref[i].allow = tol + 8 * STAB_EPS * ref[i].cond / fmax(ref[i].slope, 1e-300);
    if (ref[i].kind == 0) {  /* touch: a pair inside its window, or none */
      double lo = ref[i].lo - ref[i].allow / len, hi = ref[i].hi + ref[i].allow / len;
      if (j + 1 < ng && got[j] >= lo && got[j + 1] <= hi) j += 2;
      c->touches++;
      continue;
    }
    c->expected++;
    /* crossings reported well before this one are extra */
    while (j < ng && (ref[i].t - got[j]) * len > ref[i].allow) {
      c->extra++;
      ok = 0;
      sc_note(c, "ray %ld: extra crossing at t = %.17g (next reference %.17g)",
              c->rays, got[j], ref[i].t);
      j++;
    }
    double err = j < ng ? fabs(got[j] - ref[i].t) * len : INFINITY;
    if (err > ref[i].allow) {
      ok = 0;
      c->missed++;
      sc_note(c, "ray %ld: crossing %d at t = %.17g (slope %.3g): got %.17g, "
              "error %.3g > allowed %.3g", c->rays, i, ref[i].t, ref[i].slope,
              j < ng ? got[j] : NAN, err, ref[i].allow);
      continue;
    }
    c->found++;
    if (err > c->max_err) c->max_err = err;
    if (err / ref[i].allow > c->max_ratio) c->max_ratio = err / ref[i].allow;
    j++;
  }
  if (j < ng) {
    c->extra += ng - j;
    ok = 0;
    sc_note(c, "ray %ld: %d extra crossing(s), first at t = %.17g", c->rays,
            ng - j, got[j]);
  }
  return ok;
}

static inline void sc_work(scase *c, long work) {
  if (work > c->max_work) c->max_work = work;
  if (work > c->work_cap) {
    c->overwork++;
    sc_note(c, "ray %ld: work %ld > cap %ld", c->rays, work, c->work_cap);
  }
}

/* The checks and the summary line of one case. */
static inline void sc_report(scase *c, const char *ref, const char *tol) {
  char name[300];
  snprintf(name, sizeof name, "%s: %ld/%ld crossings found, none extra",
           c->name, c->found, c->expected);
  CHECK(name, c->missed == 0 && c->extra == 0 && c->found == c->expected);
  snprintf(name, sizeof name, "%s: no NaN or infinity", c->name);
  CHECK(name, c->nonfinite == 0);
  if (c->work_cap > 0) {
    snprintf(name, sizeof name, "%s: work per ray <= %ld", c->name, c->work_cap);
    CHECK(name, c->overwork == 0);
  }
  if (c->first[0]) printf("#   first problem: %s\n", c->first);
  printf("# summary | %s | %s | %s | %ld | %ld/%ld | %.2e | %.2f | %ld (cap %ld) | %s |\n",
         c->name, ref, tol, c->rays, c->found, c->expected, c->max_err,
         c->max_ratio, c->max_work, c->work_cap,
         c->missed || c->extra || c->nonfinite || c->overwork ? "FAIL" : "pass");
}

static inline double vlen(const double d[3]) {
  return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

#endif
