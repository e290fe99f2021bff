/* ref_density.h: test-only reference density trees, independent of
 * src/core/density.c.  A tree is an array of nodes with child indices (not a
 * tape); a leaf's density is the spherical-cap volume fraction
 * V = pi h^2 (3r - h)/3 over 4/3 pi r^3 with h = r - s, evaluated either
 * in MPFR (REF_PREC bits) or in long double.  Also a fixed-seed RNG and a
 * random rounded-scene generator shared by the unit tests. */
#ifndef QCS_REF_DENSITY_H
#define QCS_REF_DENSITY_H
#include <math.h>
#include <mpfr.h>
#include <stdint.h>

#include "core/density.h"

#define REF_PREC 320
enum { R_LEAF, R_SUM, R_PROD, R_DIFF, R_UNION };

typedef struct rnode {
  int op, a, b;            /* children for ops */
  double n[3], d, r;       /* raw plane (n not normalised) for leaves */
} rnode;

typedef struct rtree {
  rnode nodes[512];
  int n;
} rtree;

static inline int rt_leaf(rtree *t, double nx, double ny, double nz, double d,
                   double r) {
  rnode *x = &t->nodes[t->n];
  x->op = R_LEAF;
  x->n[0] = nx; x->n[1] = ny; x->n[2] = nz;
  x->d = d;
  x->r = r;
  return t->n++;
}

static inline int rt_op(rtree *t, int op, int a, int b) {
  rnode *x = &t->nodes[t->n];
  x->op = op;
  x->a = a;
  x->b = b;
  return t->n++;
}

/* Product of the six halfspaces of [lo, hi], each with its own radius. */
static inline int rt_box(rtree *t, const double lo[3], const double hi[3],
                  const double r[6]) {
  int k = -1;
  for (int i = 0; i < 3; i++) {
    double np[3] = {0, 0, 0};
    np[i] = 1;
    int a = rt_leaf(t, np[0], np[1], np[2], hi[i], r[2 * i]);
    np[i] = -1;
    int b = rt_leaf(t, np[0], np[1], np[2], -lo[i], r[2 * i + 1]);
    int ab = rt_op(t, R_PROD, a, b);
    k = k < 0 ? ab : rt_op(t, R_PROD, k, ab);
  }
  return k;
}

/* Emit node i in postfix order into a builder (recursion is fine here:
 * test trees are small). */
static inline void rt_emit(const rtree *t, int i, dt_builder *b) {
  const rnode *x = &t->nodes[i];
  if (x->op == R_LEAF) {
    dt_builder_leaf(b, x->n, x->d, x->r);
    return;
  }
  rt_emit(t, x->a, b);
  rt_emit(t, x->b, b);
  static const dt_op ops[] = {DT_LEAF, DT_SUM, DT_PRODUCT, DT_DIFF, DT_UNION};
  dt_builder_op(b, ops[x->op]);
}

static inline dt_tape *rt_tape(const rtree *t, int root) {
  dt_builder *b = dt_builder_new();
  rt_emit(t, root, b);
  int err;
  return dt_builder_finish(b, &err);
}

/* Cap-volume fraction in MPFR: s = signed distance (outside positive). */
static inline void ref_cap(mpfr_t out, const mpfr_t s, double r) {
  if (r == 0) {
    int c = mpfr_sgn(s);
    mpfr_set_d(out, c < 0 ? 1.0 : (c > 0 ? 0.0 : 0.5), MPFR_RNDN);
    return;
  }
  mpfr_t h, rr, v, vs, pi;
  mpfr_inits2(REF_PREC, h, rr, v, vs, pi, (mpfr_ptr)0);
  mpfr_set_d(rr, r, MPFR_RNDN);
  mpfr_sub(h, rr, s, MPFR_RNDN);                 /* h = r - s */
  if (mpfr_sgn(h) <= 0) mpfr_set_zero(out, 1);
  else if (mpfr_cmp_d(h, 2 * r) >= 0) mpfr_set_ui(out, 1, MPFR_RNDN);
  else {
    mpfr_const_pi(pi, MPFR_RNDN);
    mpfr_mul_ui(v, rr, 3, MPFR_RNDN);
    mpfr_sub(v, v, h, MPFR_RNDN);                /* 3r - h */
    mpfr_mul(v, v, h, MPFR_RNDN);
    mpfr_mul(v, v, h, MPFR_RNDN);
    mpfr_mul(v, v, pi, MPFR_RNDN);
    mpfr_div_ui(v, v, 3, MPFR_RNDN);             /* V = pi h^2 (3r-h)/3 */
    mpfr_pow_ui(vs, rr, 3, MPFR_RNDN);
    mpfr_mul(vs, vs, pi, MPFR_RNDN);
    mpfr_mul_ui(vs, vs, 4, MPFR_RNDN);
    mpfr_div_ui(vs, vs, 3, MPFR_RNDN);           /* 4/3 pi r^3 */
    mpfr_div(out, v, vs, MPFR_RNDN);
  }
  mpfr_clears(h, rr, v, vs, pi, (mpfr_ptr)0);
}

/* Signed distance of MPFR point p from raw plane (n,d), normalised in
 * MPFR. */
static inline void ref_dist(mpfr_t s, const rnode *x, mpfr_t p[3]) {
  mpfr_t len, tmp;
  mpfr_inits2(REF_PREC, len, tmp, (mpfr_ptr)0);
  mpfr_set_zero(len, 1);
  mpfr_set_zero(s, 1);
  for (int i = 0; i < 3; i++) {
    mpfr_set_d(tmp, x->n[i], MPFR_RNDN);
    mpfr_fma(len, tmp, tmp, len, MPFR_RNDN);
    mpfr_fma(s, tmp, p[i], s, MPFR_RNDN);
  }
  mpfr_sqrt(len, len, MPFR_RNDN);
  mpfr_sub_d(s, s, x->d, MPFR_RNDN);
  mpfr_div(s, s, len, MPFR_RNDN);
  mpfr_clears(len, tmp, (mpfr_ptr)0);
}

/* out = a op b for the ops R_SUM .. R_UNION (out may be a; tmp is
 * scratch), in MPFR. */
static inline void ref_op(mpfr_t out, int op, mpfr_t a, mpfr_t b, mpfr_t tmp) {
  switch (op) {
  case R_SUM: mpfr_add(out, a, b, MPFR_RNDN); break;
  case R_PROD: mpfr_mul(out, a, b, MPFR_RNDN); break;
  case R_DIFF: mpfr_sub(out, a, b, MPFR_RNDN); break;
  default:
    mpfr_mul(tmp, a, b, MPFR_RNDN);
    mpfr_add(out, a, b, MPFR_RNDN);
    mpfr_sub(out, out, tmp, MPFR_RNDN);
  }
}

static inline void ref_eval(mpfr_t out, const rtree *t, int i, mpfr_t p[3]) {
  const rnode *x = &t->nodes[i];
  if (x->op == R_LEAF) {
    mpfr_t s;
    mpfr_init2(s, REF_PREC);
    ref_dist(s, x, p);
    ref_cap(out, s, x->r);
    mpfr_clear(s);
    return;
  }
  mpfr_t a, b, ab;
  mpfr_inits2(REF_PREC, a, b, ab, (mpfr_ptr)0);
  ref_eval(a, t, x->a, p);
  ref_eval(b, t, x->b, p);
  ref_op(out, x->op, a, b, ab);
  mpfr_clears(a, b, ab, (mpfr_ptr)0);
}

/* The MPFR density at the double point q + s*dir (exact in MPFR). */
static inline double ref_density_ray(const rtree *t, int root, const double q[3],
                              const double dir[3], double s) {
  mpfr_t p[3], out, tmp;
  mpfr_inits2(REF_PREC, p[0], p[1], p[2], out, tmp, (mpfr_ptr)0);
  for (int i = 0; i < 3; i++) {
    mpfr_set_d(tmp, dir[i], MPFR_RNDN);
    mpfr_mul_d(tmp, tmp, s, MPFR_RNDN);
    mpfr_add_d(p[i], tmp, q[i], MPFR_RNDN);
  }
  ref_eval(out, t, root, p);
  double v = mpfr_get_d(out, MPFR_RNDN);
  mpfr_clears(p[0], p[1], p[2], out, tmp, (mpfr_ptr)0);
  return v;
}

static inline double ref_density(const rtree *t, int root, const double q[3]) {
  static const double zero[3] = {0, 0, 0};
  return ref_density_ray(t, root, q, zero, 0);
}

/* Long double reference (cap formula again, different precision). */
static inline long double ref_ld(const rtree *t, int i, const long double p[3]) {
  const rnode *x = &t->nodes[i];
  if (x->op == R_LEAF) {
    long double len = sqrtl((long double)x->n[0] * x->n[0] +
                            (long double)x->n[1] * x->n[1] +
                            (long double)x->n[2] * x->n[2]);
    long double s = (x->n[0] * p[0] + x->n[1] * p[1] + x->n[2] * p[2] -
                     x->d) / len;
    long double r = x->r;
    if (r == 0) return s < 0 ? 1.0L : (s > 0 ? 0.0L : 0.5L);
    long double h = r - s;
    if (h <= 0) return 0;
    if (h >= 2 * r) return 1;
    return h * h * (3 * r - h) / (4 * r * r * r);
  }
  long double a = ref_ld(t, x->a, p), b = ref_ld(t, x->b, p);
  switch (x->op) {
  case R_SUM: return a + b;
  case R_PROD: return a * b;
  case R_DIFF: return a - b;
  default: return a + b - a * b;
  }
}

static inline long double ref_ld_ray(const rtree *t, int root, const double o[3],
                              const double d[3], long double s) {
  long double p[3];
  for (int i = 0; i < 3; i++) p[i] = o[i] + s * d[i];
  return ref_ld(t, root, p);
}

/* splitmix64: a fixed-seed generator for reproducible random tests. */
typedef struct { uint64_t s; } rng_t;
static inline uint64_t rng_u64(rng_t *g) {
  uint64_t z = (g->s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
static inline double rng_unit(rng_t *g) {     /* [0,1) */
  return (double)(rng_u64(g) >> 11) * 0x1.0p-53;
}
static inline double rng_range(rng_t *g, double a, double b) {
  return a + (b - a) * rng_unit(g);
}

/* A random rounded scene: two or three boxes (random per-plane radii in
 * [0.01, 0.3]) combined by products, sums, differences and unions. */
static inline int rt_random_scene(rtree *t, rng_t *g) {
  t->n = 0;
  int nbox = 2 + (int)(rng_u64(g) % 2), k = -1;
  for (int i = 0; i < nbox; i++) {
    double lo[3], hi[3], r[6];
    for (int j = 0; j < 3; j++) {
      lo[j] = rng_range(g, -1, 0.5);
      hi[j] = lo[j] + rng_range(g, 0.3, 1.5);
    }
    for (int j = 0; j < 6; j++) r[j] = rng_range(g, 0.01, 0.3);
    int b = rt_box(t, lo, hi, r);
    if (k < 0) { k = b; continue; }
    static const int ops[] = {R_PROD, R_SUM, R_DIFF, R_UNION};
    k = rt_op(t, ops[rng_u64(g) % 4], k, b);
  }
  return k;
}
#endif
