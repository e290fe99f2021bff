/* mesh_check.c: exact self-intersection check (see mesh_check.h). */
#include "render/mesh_check.h"

#include <float.h>
#include <gmp.h>
#include <limits.h>
#include <pthread.h>
#include <stdatomic.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/mesh.h"

/* no fused multiply-adds: the bounds are for rounded products (gcc's
   -std=c11 already keeps them apart) */
#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

/* ---- exact predicates ---------------------------------------------------- */

/* Shewchuk's A bounds (epsilon = 2^-53, round to nearest): the computed
   determinant is within bound * permanent of the true one, when nothing
   underflows or overflows. */
#define EPS 0x1p-53
static const double o3d_bound = (7.0 + 56.0 * EPS) * EPS;
static const double o2d_bound = (3.0 + 16.0 * EPS) * EPS;
/* the same bound in long double (epsilon 2^-LDBL_MANT_DIG) */
#define EPSL (LDBL_EPSILON / 2)
static const long double o3d_bound_l = (7.0L + 56.0L * EPSL) * EPSL;

/* The filter is trusted when every difference is 0 or within 2^-300 ..
   2^300: its products of three are then normal numbers, so the bound's
   proof (no underflow) holds. */
static int tame(double d) {
  double a = fabs(d);
  return (a == 0) | ((a >= 0x1p-300) & (a <= 0x1p300));
}

/* The least binary exponent of the last mantissa bit over n doubles. */
static int least_exp(const double *x, int n) {
  int e0 = INT_MAX;
  for (int i = 0; i < n; i++)
    if (x[i] != 0) {
      int ex;
      frexp(x[i], &ex);
      if (ex - 53 < e0) e0 = ex - 53;
    }
  return e0 == INT_MAX ? 0 : e0;
}

/* z = x / 2^e0 exactly (an integer: e0 is at most x's last bit). */
static void to_mpz(mpz_t z, double x, int e0) {
  if (x == 0) {
    mpz_set_ui(z, 0);
    return;
  }
  int ex;
  double f = frexp(x, &ex);
  mpz_set_d(z, ldexp(f, 53)); /* |f| 2^53 < 2^53: an exact integer */
  mpz_mul_2exp(z, z, (mp_bitcnt_t)(ex - 53 - e0));
}

/* The exact evaluations' integers, kept per thread (their limbs are
   reused; a thread's are freed by mesh_check_release). */
static _Thread_local mpz_t pool[15];
static _Thread_local int pool_ready;

static mpz_t *pool_get(void) {
  if (!pool_ready) {
    for (int i = 0; i < 15; i++) mpz_init2(pool[i], 256);
    pool_ready = 1;
  }
  return pool;
}

void mesh_check_release(void) {
  if (!pool_ready) return;
  for (int i = 0; i < 15; i++) mpz_clear(pool[i]);
  pool_ready = 0;
}

static int orient3d_exact(const double a[3], const double b[3],
                          const double c[3], const double d[3]) {
  double x[12];
  for (int i = 0; i < 3; i++)
    x[i] = a[i], x[3 + i] = b[i], x[6 + i] = c[i], x[9 + i] = d[i];
  int e0 = least_exp(x, 12);
  mpz_t *z = pool_get(), *u = z + 12, *v = z + 13, *det = z + 14;
  for (int i = 0; i < 12; i++) to_mpz(z[i], x[i], e0);
  mpz_set_ui(*det, 0);
  for (int i = 0; i < 9; i++) mpz_sub(z[i], z[i], z[9 + i % 3]);
  /* z[0..2] = a - d, z[3..5] = b - d, z[6..8] = c - d; the first row's
     cofactors */
  static const int r[3][2] = {{1, 2}, {2, 0}, {0, 1}};
  for (int k = 0; k < 3; k++) {
    mpz_mul(*u, z[3 + r[k][0]], z[6 + r[k][1]]);
    mpz_mul(*v, z[3 + r[k][1]], z[6 + r[k][0]]);
    mpz_sub(*u, *u, *v);
    mpz_addmul(*det, z[k], *u);
  }
  return mpz_sgn(*det);
}

static int same2(const double *p, const double *q, int i, int j) {
  return p[i] == q[i] && p[j] == q[j];
}

static int two_places(const double *a, const double *b, const double *c,
                      const double *d) {
  for (int k = 0; k < 3; k++) {
    int i = (k + 1) % 3, j = (k + 2) % 3;
    /* a's place, and the first point elsewhere */
    const double *p[3] = {b, c, d}, *o = NULL;
    int ok = 1;
    for (int q = 0; q < 3 && ok; q++) {
      if (same2(p[q], a, i, j)) continue;
      if (!o) o = p[q];
      else if (!same2(p[q], o, i, j)) ok = 0;
    }
    if (ok) return 1;
  }
  return 0;
}

/* safe: every coordinate is known to be a multiple of 2^-300 and below
   2^299 in magnitude (safe_coords), so every difference is tame. */
static int orient3d(const double a[3], const double b[3], const double c[3],
                    const double d[3], long *exact, int safe) {
  double adx = a[0] - d[0], bdx = b[0] - d[0], cdx = c[0] - d[0];
  double ady = a[1] - d[1], bdy = b[1] - d[1], cdy = c[1] - d[1];
  double adz = a[2] - d[2], bdz = b[2] - d[2], cdz = c[2] - d[2];
  if (safe || (tame(adx) & tame(bdx) & tame(cdx) & tame(ady) & tame(bdy) &
               tame(cdy) & tame(adz) & tame(bdz) & tame(cdz))) {
    double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
    double cdxady = cdx * ady, adxcdy = adx * cdy;
    double adxbdy = adx * bdy, bdxady = bdx * ady;
    double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) +
                 cdz * (adxbdy - bdxady);
    double perm = (fabs(bdxcdy) + fabs(cdxbdy)) * fabs(adz) +
                  (fabs(cdxady) + fabs(adxcdy)) * fabs(bdz) +
                  (fabs(adxbdy) + fabs(bdxady)) * fabs(cdz);
    double bound = o3d_bound * perm;
    if (det > bound) return 1;
    if (-det > bound) return -1;
    /* every product zero (none underflows): the determinant is */
    if (perm == 0) return 0;
    /* the same in long double, with its own epsilon: the differences of
       doubles near each other are exact, and the bound shrinks 2^11
       times where LDBL_MANT_DIG is 64 */
    long double Adx = (long double)a[0] - d[0], Bdx = (long double)b[0] - d[0],
                Cdx = (long double)c[0] - d[0], Ady = (long double)a[1] - d[1],
                Bdy = (long double)b[1] - d[1], Cdy = (long double)c[1] - d[1],
                Adz = (long double)a[2] - d[2], Bdz = (long double)b[2] - d[2],
                Cdz = (long double)c[2] - d[2];
    long double P1 = Bdx * Cdy, P2 = Cdx * Bdy, P3 = Cdx * Ady, P4 = Adx * Cdy,
                P5 = Adx * Bdy, P6 = Bdx * Ady;
    long double D = Adz * (P1 - P2) + Bdz * (P3 - P4) + Cdz * (P5 - P6);
    long double Q = (fabsl(P1) + fabsl(P2)) * fabsl(Adz) +
                    (fabsl(P3) + fabsl(P4)) * fabsl(Bdz) +
                    (fabsl(P5) + fabsl(P6)) * fabsl(Cdz);
    long double B = o3d_bound_l * Q;
    if (D > B) return 1;
    if (-D > B) return -1;
  }
  /* four points whose projections along an axis take two places at most
     (marching vertices on the grid's lines: a rounded edge along an
     axis) lie in a plane along that axis */
  if (two_places(a, b, c, d)) return 0;
  if (exact) ++*exact;
  return orient3d_exact(a, b, c, d);
}

int mesh_orient3d(const double a[3], const double b[3], const double c[3],
                  const double d[3], long *exact) {
  return orient3d(a, b, c, d, exact, 0);
}

/* Every coordinate zero or a multiple of 2^-300 (its last mantissa bit
   at 2^-300 or above), and under 2^299: a nonzero difference of two is
   then between 2^-300 and 2^300. */
static int safe_coords(const double *v, size_t n) {
  for (size_t i = 0; i < n; i++) {
    if (v[i] == 0) continue;
    int ex;
    frexp(v[i], &ex);
    if (ex - 53 < -300 || ex > 299) return 0;
  }
  return 1;
}

static int orient2d_exact(const double a[3], const double b[3],
                          const double c[3], int i, int j, long *exact) {
  if (exact) ++*exact;
  double x[6] = {a[i], a[j], b[i], b[j], c[i], c[j]};
  int e0 = least_exp(x, 6);
  mpz_t *z = pool_get(), *u = z + 12, *v = z + 13;
  for (int k = 0; k < 6; k++) to_mpz(z[k], x[k], e0);
  for (int k = 0; k < 4; k++) mpz_sub(z[k], z[k], z[4 + k % 2]);
  mpz_mul(*u, z[0], z[3]);
  mpz_mul(*v, z[1], z[2]);
  int s = mpz_cmp(*u, *v);
  return s > 0 ? 1 : s < 0 ? -1 : 0;
}

/* The filter inline (the pair tests call it most), GMP behind it. */
static inline int orient2d(const double a[3], const double b[3],
                           const double c[3], int i, int j, long *exact) {
  double acx = a[i] - c[i], bcx = b[i] - c[i];
  double acy = a[j] - c[j], bcy = b[j] - c[j];
  if (tame(acx) && tame(bcx) && tame(acy) && tame(bcy)) {
    double l = acx * bcy, r = acy * bcx, det = l - r;
    double bound = o2d_bound * (fabs(l) + fabs(r));
    if (det > bound) return 1;
    if (-det > bound) return -1;
    if (l == 0 && r == 0) return 0;
  }
  return orient2d_exact(a, b, c, i, j, exact);
}

int mesh_orient2d(const double a[3], const double b[3], const double c[3],
                  int i, int j, long *exact) {
  return orient2d(a, b, c, i, j, exact);
}

/* ---- the pair test ------------------------------------------------------- */

typedef struct {
  long *ex;      /* counts the exact evaluations */
  int i, j;      /* the projection's axes (2-D tests) */
  int safe;      /* safe_coords holds for the mesh */
} Ctx;

static int o3(Ctx *c, const double *a, const double *b, const double *p,
              const double *d) {
  return orient3d(a, b, p, d, c->ex, c->safe);
}

static int o2(Ctx *c, const double *a, const double *b, const double *p) {
  return orient2d(a, b, p, c->i, c->j, c->ex);
}

/* The axis k along which triangle abc projects to a triangle of nonzero
   area (the axes i, j of the projection set in c, the sign of its area
   in *s), or -1 if a, b, c are collinear. The axis of the largest
   normal component is tried first. */
static int tri_axis(Ctx *c, const double *a, const double *b, const double *p,
                    int *s) {
  double u[3], v[3], n[3];
  for (int k = 0; k < 3; k++) u[k] = b[k] - a[k], v[k] = p[k] - a[k];
  n[0] = fabs(u[1] * v[2] - u[2] * v[1]);
  n[1] = fabs(u[2] * v[0] - u[0] * v[2]);
  n[2] = fabs(u[0] * v[1] - u[1] * v[0]);
  int order[3] = {0, 1, 2};
  for (int x = 0; x < 3; x++)
    for (int y = x + 1; y < 3; y++)
      if (n[order[y]] > n[order[x]]) {
        int t = order[x];
        order[x] = order[y];
        order[y] = t;
      }
  for (int q = 0; q < 3; q++) {
    int k = order[q];
    c->i = (k + 1) % 3;
    c->j = (k + 2) % 3;
    *s = o2(c, a, b, p);
    if (*s) return k;
  }
  return -1;
}

static void set_axis(Ctx *c, int k) {
  c->i = (k + 1) % 3;
  c->j = (k + 2) % 3;
}

/* Closed segments pq and rs of one plane (the projection in c) meet. */
static int seg_seg2(Ctx *c, const double *p, const double *q, const double *r,
                    const double *s) {
  int d1 = o2(c, p, q, r), d2 = o2(c, p, q, s);
  if (d1 * d2 > 0) return 0;
  int d3 = o2(c, r, s, p), d4 = o2(c, r, s, q);
  if (d3 * d4 > 0) return 0;
  if ((d1 == 0 && d2 == 0) || (d3 == 0 && d4 == 0)) {
    /* collinear: they meet where their boxes do */
    for (int a = 0; a < 2; a++) {
      int k = a ? c->j : c->i;
      if (fmax(p[k], q[k]) < fmin(r[k], s[k]) || fmax(r[k], s[k]) < fmin(p[k], q[k]))
        return 0;
    }
  }
  return 1;
}

/* Point p in the closed triangle abc of sign s in the projection. */
static int pt_tri2(Ctx *c, const double *p, const double *a, const double *b,
                   const double *q, int s) {
  return o2(c, a, b, p) * s >= 0 && o2(c, b, q, p) * s >= 0 &&
         o2(c, q, a, p) * s >= 0;
}

/* Closed segment pq and closed triangle abc (sign s) in one plane. */
static int seg_tri2(Ctx *c, const double *p, const double *q, const double *a,
                    const double *b, const double *t, int s) {
  return pt_tri2(c, p, a, b, t, s) || pt_tri2(c, q, a, b, t, s) ||
         seg_seg2(c, p, q, a, b) || seg_seg2(c, p, q, b, t) ||
         seg_seg2(c, p, q, t, a);
}

/* Closed triangles a and b (neither collinear) of one plane meet, in the
   projection set in c: no side of either has the other wholly strictly
   beyond it (the separating axis theorem in the plane). */
struct Tri;
static int tri_tri2(Ctx *c, const struct Tri *a, const struct Tri *b);

typedef struct Tri {
  const double *v[3]; /* its vertices */
  int id[3];          /* their indices */
  int k, s;           /* tri_axis; -1: collinear */
} Tri;

static int tri_tri2(Ctx *c, const Tri *a, const Tri *b) {
  for (int pass = 0; pass < 2; pass++) {
    const Tri *x = pass ? b : a, *y = pass ? a : b;
    /* x's orientation in the projection: inside is where o2 has its sign */
    int sx = o2(c, x->v[0], x->v[1], x->v[2]);
    for (int e = 0; e < 3; e++) {
      int out = 0;
      for (int q = 0; q < 3; q++)
        out += o2(c, x->v[e], x->v[(e + 1) % 3], y->v[q]) * sx < 0;
      if (out == 3) return 0;
    }
  }
  return 1;
}

/* Closed segment pq meets closed triangle t (not collinear); sp, sq: the
   signs of p and q against t's plane. */
static int seg_tri3(Ctx *c, const double *p, const double *q, const Tri *t,
                    int sp, int sq) {
  if (sp * sq > 0) return 0;
  const double *a = t->v[0], *b = t->v[1], *d = t->v[2];
  if (sp == 0 && sq == 0) {
    set_axis(c, t->k);
    return seg_tri2(c, p, q, a, b, d, t->s);
  }
  /* one end in the plane, the other off it: that end is all the segment
     has in the plane, so they meet when it is in the triangle (three
     orient2d in its projection instead of three orient3d) */
  if (sp == 0 || sq == 0) {
    set_axis(c, t->k);
    return pt_tri2(c, sp == 0 ? p : q, a, b, d, t->s);
  }
  /* the segment crosses the plane at one point: inside the closed
     triangle when the line passes no edge on the wrong side */
  int s1 = o3(c, p, q, a, b), s2 = o3(c, p, q, b, d);
  if (s1 * s2 < 0) return 0; /* already signs both ways: s3 cannot help */
  int s3 = o3(c, p, q, d, a);
  return !((s1 > 0 || s2 > 0 || s3 > 0) && (s1 < 0 || s2 < 0 || s3 < 0));
}

/* Vertex x = t->v[vi] of t (not collinear), y in t's plane: y - x in t's
   angle at x. */
static int into2(Ctx *c, const Tri *t, int vi, const double *y) {
  const double *x = t->v[vi], *p = t->v[(vi + 1) % 3], *q = t->v[(vi + 2) % 3];
  set_axis(c, t->k);
  return o2(c, x, p, y) * t->s >= 0 && o2(c, x, y, q) * t->s >= 0;
}

/* Vertex x = t->v[vi] of t (not collinear): the segment from x to y goes
   into t beyond x (y in t's plane, and y - x in t's angle at x). */
static int into(Ctx *c, const Tri *t, int vi, const double *y) {
  const double *x = t->v[vi], *p = t->v[(vi + 1) % 3], *q = t->v[(vi + 2) % 3];
  return o3(c, x, p, q, y) == 0 && into2(c, t, vi, y);
}

static int where(const Tri *t, int id) {
  for (int q = 0; q < 3; q++)
    if (t->id[q] == id) return q;
  return -1;
}

/* The two pieces [e0, m], [m, e1] of a collinear triangle (m the middle
   vertex), as vertex positions in t. */
static void pieces(const Tri *t, int pc[2][2]) {
  int d = 0;
  double spread = -1;
  for (int k = 0; k < 3; k++) {
    double lo = fmin(t->v[0][k], fmin(t->v[1][k], t->v[2][k]));
    double hi = fmax(t->v[0][k], fmax(t->v[1][k], t->v[2][k]));
    if (hi - lo > spread) spread = hi - lo, d = k;
  }
  int o[3] = {0, 1, 2};
  for (int x = 0; x < 3; x++)
    for (int y = x + 1; y < 3; y++)
      if (t->v[o[y]][d] < t->v[o[x]][d]) {
        int w = o[x];
        o[x] = o[y];
        o[y] = w;
      }
  pc[0][0] = o[0], pc[0][1] = o[1];
  pc[1][0] = o[1], pc[1][1] = o[2];
}

/* Piece [x, y] of collinear triangle a (positions in a) against triangle
   b (not collinear): they meet outside what a and b share. */
static int piece_tri(Ctx *c, const Tri *a, int px, int py, const Tri *b) {
  int x = a->id[px], y = a->id[py], z = a->id[3 - px - py];
  int bx = where(b, x), by = where(b, y);
  if (bx >= 0 && by >= 0) return 0; /* an edge of b */
  if (bx < 0 && by < 0) {
    const double *p = a->v[px], *q = a->v[py];
    return seg_tri3(c, p, q, b, o3(c, b->v[0], b->v[1], b->v[2], p),
                    o3(c, b->v[0], b->v[1], b->v[2], q));
  }
  if (by >= 0) { /* the shared end first */
    int t = px;
    px = py, py = t;
    bx = by;
  }
  /* [x, y] from a shared vertex: when the third vertex z is shared too
     and y lies between x and z, the piece is in what they share */
  if (where(b, z) >= 0) {
    const double *X = a->v[px], *Y = a->v[py], *Z = a->v[3 - px - py];
    int between = 1;
    for (int k = 0; k < 3; k++)
      if (!(fmin(X[k], Z[k]) <= Y[k] && Y[k] <= fmax(X[k], Z[k]))) between = 0;
    if (between) return 0;
  }
  return into(c, b, bx, a->v[py]);
}

/* Two collinear triangles: each the union of its two pieces. */
static int seg_seg3(Ctx *c, const Tri *a, const Tri *b) {
  int pa[2][2], pb[2][2];
  pieces(a, pa);
  pieces(b, pb);
  /* all four extremes on one line? */
  const double *x = a->v[pa[0][0]], *y = a->v[pa[1][1]];
  const double *r = b->v[pb[0][0]], *t = b->v[pb[1][1]];
  if (o3(c, x, y, r, t) != 0) return 0; /* skew lines */
  int k = -1;
  for (int q = 0; q < 3 && k < 0; q++) {
    set_axis(c, q);
    if (o2(c, x, y, r) || o2(c, x, y, t)) k = q;
  }
  if (k >= 0) { /* two lines of one plane, crossing at one point at most */
    set_axis(c, k);
    if (!seg_seg2(c, x, y, r, t)) return 0;
    /* they meet in one point: allowed when it is a shared vertex, the
       end of a piece of each */
    for (int i = 0; i < 3; i++)
      if (where(b, a->id[i]) >= 0) return 0;
    return 1;
  }
  /* one line: intervals along the axis of the largest spread */
  int d = 0;
  double spread = -1;
  for (int q = 0; q < 3; q++)
    if (fmax(fabs(y[q] - x[q]), fabs(t[q] - r[q])) > spread)
      spread = fmax(fabs(y[q] - x[q]), fabs(t[q] - r[q])), d = q;
  double lo = fmax(fmin(x[d], y[d]), fmin(r[d], t[d]));
  double hi = fmin(fmax(x[d], y[d]), fmax(r[d], t[d]));
  if (lo > hi) return 0;
  double slo = INFINITY, shi = -INFINITY;
  for (int i = 0; i < 3; i++)
    if (where(b, a->id[i]) >= 0) {
      slo = fmin(slo, a->v[i][d]);
      shi = fmax(shi, a->v[i][d]);
    }
  return !(slo <= lo && hi <= shi);
}

/* The common cases decided by the planes alone (most pairs are
   neighbours on a curved surface): the vertices of one triangle other
   than those it shares strictly on one side of the other's plane (a
   collinear triangle has every point on its "plane": never decided
   here). */
static int early_out(Ctx *c, const Tri *A, const Tri *B, int shared) {
  for (int pass = 0; pass < 2; pass++) {
    const Tri *a = pass ? B : A, *b = pass ? A : B;
    int pos = 0, neg = 0, n = 0;
    for (int q = 0; q < 3; q++) {
      if (where(a, b->id[q]) >= 0) continue;
      int s = o3(c, a->v[0], a->v[1], a->v[2], b->v[q]);
      pos += s > 0, neg += s < 0, n++;
      if (pos && neg) break;
      if (!s) break;
    }
    if (pos == n || neg == n) return 1;
    if (shared == 2) return 0; /* the other pass sees the same plane pair */
  }
  return 0;
}

/* The fast path's triangles (below): when pair is given them, its signs
   of vertices against a plane are taken on the plane made once. */
typedef struct CTri CTri;
static inline int plane_side(Ctx *c, const CTri *t, const double *d);

static int ctri_axis(Ctx *c, const CTri *t, int *s);

static int side(Ctx *c, const CTri *ct, const Tri *t, const double *x) {
  return ct ? plane_side(c, ct, x) : o3(c, t->v[0], t->v[1], t->v[2], x);
}

/* ca, cb: triangles i and j as CTri, or NULL; when given, early_out has
   been done (early_fast) and is not repeated. */
static int pair(Ctx *c, const Mesh *m, size_t i, size_t j, const CTri *ca,
                const CTri *cb) {
  Tri A, B;
  const int *ta = m->t + 3 * i, *tb = m->t + 3 * j;
  int shared = 0;
  for (int q = 0; q < 3; q++) {
    A.id[q] = ta[q];
    B.id[q] = tb[q];
    A.v[q] = m->v + 3 * (size_t)ta[q];
    B.v[q] = m->v + 3 * (size_t)tb[q];
  }
  for (int x = 0; x < 3; x++)
    for (int y = 0; y < 3; y++) {
      if (A.id[x] == B.id[y]) shared++;
      else if (A.v[x][0] == B.v[y][0] && A.v[x][1] == B.v[y][1] &&
               A.v[x][2] == B.v[y][2])
        return 1; /* two vertices at one place */
    }
  if (shared >= 3) return 1; /* the same three vertices twice */
  if (!ca && early_out(c, &A, &B, shared)) return 0;
  A.k = ca ? ctri_axis(c, ca, &A.s) : tri_axis(c, A.v[0], A.v[1], A.v[2], &A.s);
  B.k = cb ? ctri_axis(c, cb, &B.s) : tri_axis(c, B.v[0], B.v[1], B.v[2], &B.s);
  if (A.k < 0 || B.k < 0) {
    if (A.k < 0 && B.k < 0) return seg_seg3(c, &A, &B);
    const Tri *a = A.k < 0 ? &A : &B, *b = A.k < 0 ? &B : &A;
    int pc[2][2];
    pieces(a, pc);
    return piece_tri(c, a, pc[0][0], pc[0][1], b) ||
           piece_tri(c, a, pc[1][0], pc[1][1], b);
  }
  if (shared == 0) {
    int sa[3], sb[3], pa = 0, na = 0, pb = 0, nb = 0;
    for (int q = 0; q < 3; q++) {
      sb[q] = side(c, ca, &A, B.v[q]);
      pb += sb[q] > 0;
      nb += sb[q] < 0;
    }
    if (pb == 3 || nb == 3) return 0;
    for (int q = 0; q < 3; q++) {
      sa[q] = side(c, cb, &B, A.v[q]);
      pa += sa[q] > 0;
      na += sa[q] < 0;
    }
    if (pa == 3 || na == 3) return 0;
    if (!pb && !nb) { /* one plane */
      set_axis(c, A.k);
      return tri_tri2(c, &A, &B);
    }
    for (int e = 0; e < 3; e++)
      if (seg_tri3(c, A.v[e], A.v[(e + 1) % 3], &B, sa[e], sa[(e + 1) % 3]) ||
          seg_tri3(c, B.v[e], B.v[(e + 1) % 3], &A, sb[e], sb[(e + 1) % 3]))
        return 1;
    return 0;
  }
  if (shared == 1) {
    int ia = 0, ib = 0;
    for (int x = 0; x < 3; x++)
      for (int y = 0; y < 3; y++)
        if (A.id[x] == B.id[y]) ia = x, ib = y;
    /* the edges opposite the shared vertex against the other triangle */
    const double *a1 = A.v[(ia + 1) % 3], *a2 = A.v[(ia + 2) % 3];
    const double *b1 = B.v[(ib + 1) % 3], *b2 = B.v[(ib + 2) % 3];
    int s1 = side(c, ca, &A, b1), s2 = side(c, ca, &A, b2);
    if (s1 == 0 && s2 == 0)
      /* one plane: two angles at v, each under 180 degrees, overlap
         beyond v exactly when a side of one lies in the other */
      return into2(c, &B, ib, a1) || into2(c, &B, ib, a2) ||
             into2(c, &A, ia, b1) || into2(c, &A, ia, b2);
    int r1 = side(c, cb, &B, a1), r2 = side(c, cb, &B, a2);
    if (seg_tri3(c, a1, a2, &B, r1, r2) || seg_tri3(c, b1, b2, &A, s1, s2))
      return 1;
    /* the edges at the shared vertex going into the other triangle (only
       an edge in the other's plane can) */
    return (!r1 && into2(c, &B, ib, a1)) || (!r2 && into2(c, &B, ib, a2)) ||
           (!s1 && into2(c, &A, ia, b1)) || (!s2 && into2(c, &A, ia, b2));
  }
  /* one shared edge u w: improper only when the planes agree and the
     third vertices lie on one side of it (folded onto each other) */
  int a3 = 0, b3 = 0;
  for (int q = 0; q < 3; q++) {
    if (where(&B, A.id[q]) < 0) a3 = q;
    if (where(&A, B.id[q]) < 0) b3 = q;
  }
  const double *u = A.v[(a3 + 1) % 3], *w = A.v[(a3 + 2) % 3];
  if (o3(c, u, w, A.v[a3], B.v[b3]) != 0) return 0;
  set_axis(c, A.k);
  return o2(c, u, w, A.v[a3]) * o2(c, u, w, B.v[b3]) > 0;
}

int mesh_tri_pair(const Mesh *m, size_t i, size_t j) {
  Ctx c = {NULL, 0, 1, 0};
  return pair(&c, m, i, j, NULL, NULL);
}

/* ---- the fast path: planes made once per triangle ------------------------ */

/* A triangle as a grid cell's scan keeps it: vertices, indices, its box and
   first cell, and its plane. orient3d(a, b, c, d) = det [a - d; b - d;
   c - d] = -(d - a) . n with n = (b - a) x (c - a): n is made once per
   triangle (and cell), and each sign against the plane is then three
   differences, three products and two sums.

   The filter's bound, proven here for this order of operations (the
   standard model: every operation's result is the exact one times
   1 + delta, |delta| <= eps = 2^-53, which holds when no result
   underflows, so only with safe coordinates: every nonzero difference
   between 2^-300 and 2^300, every product of three a normal number).
   With U = b - a, V = c - a, W = d - a exact and u, v, w their rounded
   differences, n_x = fl(fl(u_y v_z) - fl(u_z v_y)) (and cyclically), the
   computed s = fl(fl(fl(w_x n_x) + fl(w_y n_y)) + fl(w_z n_z)) is the sum
   of the six monomials of the exact E = W . (U x V), each times a factor
   within (1 + eps)^8 of 1 (a difference, a product, the minor's
   difference, the product by w, two sums: at most 8 roundings), so
   |s - E| <= g M with g = (1 + eps)^8 - 1 <= 8 eps + 29 eps^2 and M the
   sum of the monomials' magnitudes. The permanent computed the same way
   from magnitudes, p = fl(sum |w_i| fl(|fl(u_j v_k)| + |fl(u_k v_j)|)),
   takes at most 8 roundings per monomial too, all of the same sign, so
   p >= M (1 - eps)^8; the bound fl(B p) >= B p (1 - eps). s > fl(B p)
   then gives E >= s - g M > p (B (1 - eps) - g / (1 - eps)^8) >= 0 when
   B >= g / (1 - eps)^9, which B = (8 + 256 eps) eps is (g / (1 - eps)^9
   <= (8 eps + 29 eps^2)(1 + 10 eps) < (8 + 110 eps) eps). p = 0 means
   every monomial is exactly zero (none underflows), so E = 0. Where the
   bound cannot decide, the full orient3d (its own filter, long double,
   GMP) does, so the sign is always the exact one. */
static const double plane_bound = (8.0 + 256.0 * EPS) * EPS;

struct CTri {
  double v[3][3];
  double n[3], pn[3]; /* the plane's normal and its magnitudes (above) */
  int id[3];
  float box[6];
  uint16_t c0[3];     /* the first grid cell it reaches */
  /* two_places made once: along axis k the vertices' projections take
     one place (tp[k][0] = 3: any fourth point makes two at most), two
     (vertices tp[k][0], tp[k][1]: a fourth point at either place), or
     three (tp[k][0] = -1) */
  signed char tp[3][2];
};

static void ctri_make(CTri *t, const Mesh *m, size_t i) {
  for (int q = 0; q < 3; q++) {
    t->id[q] = m->t[3 * i + (size_t)q];
    memcpy(t->v[q], m->v + 3 * (size_t)t->id[q], sizeof t->v[q]);
  }
  double u[3], v[3];
  for (int a = 0; a < 3; a++) u[a] = t->v[1][a] - t->v[0][a], v[a] = t->v[2][a] - t->v[0][a];
  for (int a = 0; a < 3; a++) {
    int j = (a + 1) % 3, k = (a + 2) % 3;
    double l = u[j] * v[k], r = u[k] * v[j];
    t->n[a] = l - r;
    t->pn[a] = fabs(l) + fabs(r);
  }
  for (int k = 0; k < 3; k++) {
    int x = (k + 1) % 3, y = (k + 2) % 3;
    int e01 = same2(t->v[0], t->v[1], x, y), e02 = same2(t->v[0], t->v[2], x, y),
        e12 = same2(t->v[1], t->v[2], x, y);
    signed char *tp = t->tp[k];
    if (e01 && e02) tp[0] = 3, tp[1] = 0;
    else if (e01 || e02) tp[0] = 0, tp[1] = e01 ? 2 : 1;
    else if (e12) tp[0] = 0, tp[1] = 1;
    else tp[0] = -1, tp[1] = 0;
  }
}

/* two_places(t's vertices, d), from t->tp. */
static int two_places_t(const CTri *t, const double *d) {
  for (int k = 0; k < 3; k++) {
    const signed char *tp = t->tp[k];
    if (tp[0] < 0) continue;
    if (tp[0] == 3) return 1;
    int i = (k + 1) % 3, j = (k + 2) % 3;
    if (same2(t->v[tp[0]], d, i, j) || same2(t->v[tp[1]], d, i, j)) return 1;
  }
  return 0;
}

/* Where the filter cannot decide: as orient3d ends, first the planes
   along an axis (exact zeros, which no filter decides: its long double
   stage would be wasted), then orient3d itself. */
static int plane_side_slow(Ctx *c, const CTri *t, const double *d) {
  if (two_places_t(t, d)) return 0;
  return orient3d(t->v[0], t->v[1], t->v[2], d, c->ex, 1);
}

/* The sign of orient3d(t's vertices, d): exact (safe coordinates only). */
static inline int plane_side(Ctx *c, const CTri *t, const double *d) {
  double wx = d[0] - t->v[0][0], wy = d[1] - t->v[0][1], wz = d[2] - t->v[0][2];
  double s = wx * t->n[0] + wy * t->n[1] + wz * t->n[2];
  double p = fabs(wx) * t->pn[0] + fabs(wy) * t->pn[1] + fabs(wz) * t->pn[2];
  double b = plane_bound * p;
  if (s > b) return -1;
  if (-s > b) return 1;
  if (p == 0) return 0;
  return plane_side_slow(c, t, d);
}

/* tri_axis from the plane made once: n[k] (k its largest magnitude, the
   first of equals, the axis tri_axis tries first) is computed exactly as
   orient2d(v1, v2, v0) on the axes k + 1, k + 2 computes its
   determinant (the differences from v0, the two products, their
   difference) and pn[k] as its permanent, so where |n[k]| exceeds
   orient2d's bound its sign is that orient2d's, the sign of the
   triangle's projection: tri_axis's answer without its tests. Else
   tri_axis. */
static int ctri_axis(Ctx *c, const CTri *t, int *s) {
  int k = 0;
  for (int a = 1; a < 3; a++)
    if (fabs(t->n[a]) > fabs(t->n[k])) k = a;
  if (fabs(t->n[k]) > o2d_bound * t->pn[k]) {
    set_axis(c, k);
    *s = t->n[k] > 0 ? 1 : -1;
    return k;
  }
  return tri_axis(c, t->v[0], t->v[1], t->v[2], s);
}

/* early_out on the planes made once: the same signs, so the same answer. */
static int early_fast(Ctx *c, const CTri *A, const CTri *B) {
  for (int pass = 0; pass < 2; pass++) {
    const CTri *a = pass ? B : A, *b = pass ? A : B;
    int pos = 0, neg = 0, n = 0, shared = 0;
    for (int q = 0; q < 3; q++) {
      const int id = b->id[q];
      if (id == a->id[0] || id == a->id[1] || id == a->id[2]) {
        shared++;
        continue;
      }
      int s = plane_side(c, a, b->v[q]);
      pos += s > 0, neg += s < 0, n++;
      if (!s || (pos && neg)) break;
    }
    if (n && (pos == n || neg == n)) return 1;
    if (shared == 2) return 0; /* the other pass sees the same plane pair */
  }
  return 0;
}

/* The pair test (pair) with the common cases first, on safe coordinates.
   A pair is decided here only as pair decides it:
   - by early_fast, which is early_out with the same exact signs. pair
     tests two distinct vertices at one place before early_out; that order
     does not matter: such a vertex of one triangle lies on the other's
     plane (or makes the other collinear, all of whose signs are 0), so
     neither pass of early_out can find every other vertex strictly on
     one side. The test is made next, as in pair.
   - coplanar pairs, both triangles of nonzero area in the projection
     along A's axis from ctri_axis (that projection is then one to one on
     their plane, so neither is collinear, and pair's
     2-D tests, whose answers are products of signs in one projection,
     answer the same in it as in pair's own): on one edge u w (early_fast
     found B's third vertex not strictly off A's plane, so on it), pair's
     last case, o2(u, w, a3) o2(u, w, b3) > 0; on one vertex, pair's
     angles at it; on nothing, pair's separating sides (tri_tri2).
   Everything else goes to pair. */
static int pair_fast(Ctx *c, const Mesh *m, const CTri *A, const CTri *B,
                     size_t i, size_t j) {
  if (early_fast(c, A, B)) return 0;
  int shared = 0, ia = 0, ib = 0;
  for (int x = 0; x < 3; x++)
    for (int y = 0; y < 3; y++) {
      if (A->id[x] == B->id[y]) shared++, ia = x, ib = y;
      else if (A->v[x][0] == B->v[y][0] && A->v[x][1] == B->v[y][1] &&
               A->v[x][2] == B->v[y][2])
        return 1; /* two vertices at one place */
    }
  if (shared >= 3) return 1;
  /* are B's other vertices on A's plane? */
  if (shared < 2)
    for (int q = 0; q < 3; q++)
      if (B->id[q] != A->id[ia] && plane_side(c, A, B->v[q]) != 0)
        return pair(c, m, i, j, A, B);
  Tri TA, TB;
  for (int q = 0; q < 3; q++) {
    TA.v[q] = A->v[q], TA.id[q] = A->id[q];
    TB.v[q] = B->v[q], TB.id[q] = B->id[q];
  }
  int k = ctri_axis(c, A, &TA.s);
  if (k < 0) return pair(c, m, i, j, A, B);
  TA.k = TB.k = k;
  set_axis(c, k);
  TB.s = o2(c, TB.v[0], TB.v[1], TB.v[2]);
  if (!TA.s || !TB.s) return pair(c, m, i, j, A, B);
  if (shared == 0) return tri_tri2(c, &TA, &TB);
  if (shared == 1) {
    const double *a1 = A->v[(ia + 1) % 3], *a2 = A->v[(ia + 2) % 3];
    const double *b1 = B->v[(ib + 1) % 3], *b2 = B->v[(ib + 2) % 3];
    return into2(c, &TB, ib, a1) || into2(c, &TB, ib, a2) ||
           into2(c, &TA, ia, b1) || into2(c, &TA, ia, b2);
  }
  int a3 = 0, b3 = 0;
  for (int q = 0; q < 3; q++) {
    if (where(&TB, A->id[q]) < 0) a3 = q;
    if (where(&TA, B->id[q]) < 0) b3 = q;
  }
  const double *u = A->v[(a3 + 1) % 3], *w = A->v[(a3 + 2) % 3];
  return o2(c, u, w, A->v[a3]) * o2(c, u, w, B->v[b3]) > 0;
}

int mesh_orient3d_plane(const double a[3], const double b[3],
                        const double c[3], const double d[3], long *exact) {
  double v[12];
  int t[3] = {0, 1, 2};
  memcpy(v, a, 3 * sizeof *v);
  memcpy(v + 3, b, 3 * sizeof *v);
  memcpy(v + 6, c, 3 * sizeof *v);
  memcpy(v + 9, d, 3 * sizeof *v);
  if (!safe_coords(v, 12)) return orient3d(a, b, c, d, exact, 0);
  Mesh m = {3, 1, v, t, NULL};
  Ctx ctx = {exact, 0, 1, 1};
  CTri ct;
  ctri_make(&ct, &m, 0);
  return plane_side(&ctx, &ct, d);
}

int mesh_tri_pair_fast(const Mesh *m, size_t i, size_t j) {
  Ctx c = {NULL, 0, 1, 0};
  if (!safe_coords(m->v, 3 * m->nv)) return pair(&c, m, i, j, NULL, NULL);
  c.safe = 1;
  CTri A, B;
  ctri_make(&A, m, i);
  ctri_make(&B, m, j);
  return pair_fast(&c, m, &A, &B, i, j);
}

/* ---- the broad phase: a uniform grid over the triangles' boxes ---------- */

/* Triangle i's box. */
static void tri_box(const Mesh *m, size_t i, double l[3], double h[3]) {
  const double *p = m->v + 3 * (size_t)m->t[3 * i], *q = m->v + 3 * (size_t)m->t[3 * i + 1],
               *r = m->v + 3 * (size_t)m->t[3 * i + 2];
  for (int a = 0; a < 3; a++) { /* finite (checked first): no NaN rules */
    double lo = p[a] < q[a] ? p[a] : q[a], hi = p[a] < q[a] ? q[a] : p[a];
    l[a] = r[a] < lo ? r[a] : lo;
    h[a] = r[a] > hi ? r[a] : hi;
  }
}

/* x as a float no greater (down) or no less (up) than x. */
static float down(double x) {
  if (x > FLT_MAX) return FLT_MAX;
  float f = (float)x;
  return (double)f > x ? nextafterf(f, -INFINITY) : f;
}

static float up(double x) {
  if (x < -FLT_MAX) return -FLT_MAX;
  float f = (float)x;
  return (double)f < x ? nextafterf(f, INFINITY) : f;
}

/* The grid's cells are taken in blocks by CHECK_THREADS threads. */
#define CHECK_THREADS 2
#define CHECK_BLOCK 256

typedef struct {
  const Mesh *m;
  const float *box;        /* per triangle: lo[3], hi[3] (outward) */
  uint16_t (*cb)[6];       /* per triangle: its cells' range */
  const size_t *cnt;       /* cell q's triangles: items[cnt[q - 1] ..
                              cnt[q]) (from 0 for q = 0) */
  const int *items;
  int g[3];
  size_t ncell;
  size_t maxrun;           /* the most triangles in a cell */
  atomic_size_t next;      /* the next block of cells */
  int safe;
} Scan;

typedef struct {
  Scan *sc;
  long pairs, exact, bad;
  size_t first;            /* the cell of the first intersecting pair */
  size_t tri[2];
  double at[3];
  int nomem;
} Part;

/* The pair i, j of cell q intersects: counted, the first kept. */
static void found(Part *pt, size_t q, size_t i, size_t j, const float *bi,
                  const float *bj) {
  if (pt->bad++) return;
  pt->first = q;
  pt->tri[0] = i, pt->tri[1] = j;
  for (int a = 0; a < 3; a++)
    pt->at[a] = 0.5 * ((double)fmaxf(bi[a], bj[a]) + (double)fminf(bi[3 + a], bj[3 + a]));
}

static void *scan(void *arg) {
  Part *pt = arg;
  Scan *sc = pt->sc;
  const float *box = sc->box;
  uint16_t (*cb)[6] = sc->cb;
  Ctx ctx = {&pt->exact, 0, 1, sc->safe};
  /* a cell's triangles copied together, planes made (safe meshes only) */
  CTri *ct = sc->safe ? malloc((sc->maxrun ? sc->maxrun : 1) * sizeof *ct) : NULL;
  if (sc->safe && !ct) {
    pt->nomem = 1;
    return NULL;
  }
  for (;;) {
    size_t q0 = atomic_fetch_add(&sc->next, CHECK_BLOCK);
    if (q0 >= sc->ncell) break;
    size_t q1 = q0 + CHECK_BLOCK < sc->ncell ? q0 + CHECK_BLOCK : sc->ncell;
    for (size_t q = q0; q < q1; q++) {
      uint16_t cx = (uint16_t)(q / ((size_t)sc->g[1] * (size_t)sc->g[2]));
      uint16_t cy = (uint16_t)(q / (size_t)sc->g[2] % (size_t)sc->g[1]);
      uint16_t cz = (uint16_t)(q % (size_t)sc->g[2]);
      size_t start = q ? sc->cnt[q - 1] : 0, end = sc->cnt[q];
      if (end - start < 2) continue;
      if (!ct) {
        for (size_t x = start; x < end; x++)
          for (size_t y = x + 1; y < end; y++) {
            size_t i = (size_t)sc->items[x], j = (size_t)sc->items[y];
            const float *bi = box + 6 * i, *bj = box + 6 * j;
            if (bi[0] > bj[3] || bj[0] > bi[3] || bi[1] > bj[4] || bj[1] > bi[4] ||
                bi[2] > bj[5] || bj[2] > bi[5])
              continue;
            /* tested in the first cell both reach */
            if ((cb[i][0] > cb[j][0] ? cb[i][0] : cb[j][0]) != cx ||
                (cb[i][1] > cb[j][1] ? cb[i][1] : cb[j][1]) != cy ||
                (cb[i][2] > cb[j][2] ? cb[i][2] : cb[j][2]) != cz)
              continue;
            pt->pairs++;
            if (pair(&ctx, sc->m, i, j, NULL, NULL)) found(pt, q, i, j, bi, bj);
          }
        continue;
      }
      size_t n = end - start;
      for (size_t x = 0; x < n; x++) {
        size_t i = (size_t)sc->items[start + x];
        ctri_make(&ct[x], sc->m, i);
        memcpy(ct[x].box, box + 6 * i, sizeof ct[x].box);
        memcpy(ct[x].c0, cb[i], sizeof ct[x].c0);
      }
      for (size_t x = 0; x < n; x++) {
        const CTri *A = &ct[x];
        for (size_t y = x + 1; y < n; y++) {
          const CTri *B = &ct[y];
          const float *bi = A->box, *bj = B->box;
          if (bi[0] > bj[3] || bj[0] > bi[3] || bi[1] > bj[4] || bj[1] > bi[4] ||
              bi[2] > bj[5] || bj[2] > bi[5])
            continue;
          /* tested in the first cell both reach */
          if ((A->c0[0] > B->c0[0] ? A->c0[0] : B->c0[0]) != cx ||
              (A->c0[1] > B->c0[1] ? A->c0[1] : B->c0[1]) != cy ||
              (A->c0[2] > B->c0[2] ? A->c0[2] : B->c0[2]) != cz)
            continue;
          pt->pairs++;
          size_t i = (size_t)sc->items[start + x], j = (size_t)sc->items[start + y];
          if (pair_fast(&ctx, sc->m, A, B, i, j)) found(pt, q, i, j, bi, bj);
        }
      }
    }
  }
  free(ct);
  mesh_check_release();
  return NULL;
}

int mesh_self_check(const Mesh *m, MeshSelfCheck *c) {
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  memset(c, 0, sizeof *c);
  size_t nt = m->nt;
  for (size_t i = 0; i < 3 * nt; i++)
    if (m->t[i] < 0 || (size_t)m->t[i] >= m->nv) return -1;
  for (size_t i = 0; i < 3 * m->nv; i++)
    if (!isfinite(m->v[i])) return -1;
  if (nt < 2) return 0;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  double mean = 0;
  for (size_t i = 0; i < nt; i++) {
    double l[3], h[3], side = 0;
    tri_box(m, i, l, h);
    for (int a = 0; a < 3; a++) {
      lo[a] = fmin(lo[a], l[a]);
      hi[a] = fmax(hi[a], h[a]);
      side = fmax(side, h[a] - l[a]);
    }
    mean += side;
  }
  mean /= (double)nt;
  /* cells about twice a triangle's box, at most 2 nt of them */
  double cs = 2 * mean;
  int g[3];
  for (;;) {
    size_t n = 1;
    for (int a = 0; a < 3; a++) {
      double w = (hi[a] - lo[a]) / cs;
      g[a] = w < 1 ? 1 : w > 65535 ? 65535 : (int)ceil(w);
      n *= (size_t)g[a];
    }
    if (cs > 0 && n <= 2 * nt + 8) break;
    cs = cs > 0 ? cs * 1.26 : fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2])) + 1;
  }
  /* a triangle's cells: the monotone map x -> floor((x - lo) / cs) of its
     exact box, clamped, so two closed boxes that overlap share a cell;
     the box kept in floats rounded outward (the overlap test is then
     conservative: it only lets more pairs through to the exact test) */
  float *box = malloc(6 * nt * sizeof *box);
  uint16_t (*cb)[6] = malloc(nt * sizeof *cb);
  size_t ncell = (size_t)g[0] * (size_t)g[1] * (size_t)g[2];
  size_t *cnt = calloc(ncell + 1, sizeof *cnt);
  int *items = NULL, rc = 0;
  if (!box || !cb || !cnt) {
    rc = -2;
    goto out;
  }
  for (size_t i = 0; i < nt; i++) {
    double b[2][3];
    tri_box(m, i, b[0], b[1]);
    for (int a = 0; a < 3; a++)
      for (int e = 0; e < 2; e++) {
        /* b - lo >= 0: truncation is floor */
        double f = (b[e][a] - lo[a]) / cs;
        cb[i][3 * e + a] = (uint16_t)(f >= g[a] ? g[a] - 1 : (int)f);
        box[6 * i + 3 * (size_t)e + (size_t)a] = e ? up(b[e][a]) : down(b[e][a]);
      }
  }
  /* counting sort of the (cell, triangle) entries: cnt[q] counts cell q's
     entries, then is made the end of cell q's run as it is filled */
  for (int pass = 0; pass < 2; pass++) {
    for (size_t i = 0; i < nt; i++)
      for (int x = cb[i][0]; x <= cb[i][3]; x++)
        for (int y = cb[i][1]; y <= cb[i][4]; y++)
          for (int z = cb[i][2]; z <= cb[i][5]; z++) {
            size_t q = ((size_t)x * (size_t)g[1] + (size_t)y) * (size_t)g[2] + (size_t)z;
            if (pass) items[cnt[q]++] = (int)i;
            else cnt[q]++;
          }
    if (!pass) {
      size_t sum = 0;
      for (size_t q = 0; q <= ncell; q++) {
        size_t n = cnt[q];
        cnt[q] = sum;
        sum += n;
      }
      items = malloc((sum ? sum : 1) * sizeof *items);
      if (!items) {
        rc = -2;
        goto out;
      }
    }
  }
  size_t maxrun = 0;
  for (size_t q = 0; q < ncell; q++) {
    size_t n = cnt[q] - (q ? cnt[q - 1] : 0);
    if (n > maxrun) maxrun = n;
  }
  Scan sc = {m, box, cb, cnt, items, {g[0], g[1], g[2]}, ncell, maxrun, 0,
             safe_coords(m->v, 3 * m->nv)};
  int nth = nt < 20000 ? 1 : CHECK_THREADS;
  Part part[CHECK_THREADS];
  pthread_t th[CHECK_THREADS];
  memset(part, 0, sizeof part);
  for (int t = 0; t < nth; t++) {
    part[t].sc = &sc;
    part[t].first = SIZE_MAX;
  }
  int started = 1;
  for (int t = 1; t < nth; t++)
    if (pthread_create(&th[t], NULL, scan, &part[t]) == 0) started++;
    else break;
  scan(&part[0]);
  for (int t = 1; t < started; t++) pthread_join(th[t], NULL);
  size_t first = SIZE_MAX;
  for (int t = 0; t < started; t++)
    if (part[t].nomem) {
      rc = -2;
      goto out;
    }
  for (int t = 0; t < started; t++) {
    c->pairs += part[t].pairs;
    c->exact += part[t].exact;
    c->bad += part[t].bad;
    if (part[t].bad && part[t].first < first) {
      first = part[t].first;
      c->tri[0] = part[t].tri[0], c->tri[1] = part[t].tri[1];
      memcpy(c->at, part[t].at, sizeof c->at);
    }
  }
  rc = c->bad > 0;
out:
  mesh_check_release();
  free(box);
  free(cb);
  free(cnt);
  free(items);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  c->seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  return rc;
}
