/* test_mesh_exact.c: the sharp cells' exact, perturbed signs
 * (render/mesh_exact.h) against MPFR.
 *
 * The reference evaluates each point's side by its own formulas in MPFR
 * at 4000 bits (every product of the doubles involved is exact there)
 * with the perturbation made numeric: plane of rank r moved by
 * eps_r = 2^(-400 (r + 1)), far below any first-order term of these
 * inputs and far above any second-order one; a tie is then decided by the
 * value itself, not by a rule copied from the code under test. Inputs:
 * random planes and points, nearly degenerate ones (a fourth plane
 * through the meeting point of three, its offset rounded), and exactly
 * degenerate ones on small integers (three planes through one line, four
 * through one point, a plane through a segment's end), where the ties
 * are; the boxes (mx_*_box) must hold the exact point and mx_box_in agree
 * where it decides; mx_three_point and mx_edge_point give one position to
 * the bit for every triple that names one point. */
#include <gmp.h>
#include <mpfr.h>
#include <stdint.h>

#include "check.h"
#include "render/mesh_exact.h"

#define PREC 4000

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double urand(void) {
  rng ^= rng << 13;
  rng ^= rng >> 7;
  rng ^= rng << 17;
  return (double)(rng >> 11) * 0x1p-53;
}

/* a plane's n and d in MPFR (through points: n = (q1 - q0) x (q2 - q0),
   d = n . q0), with d - eps_rank when perturbed */
static void ref_plane(const MxPlane *p, mpfr_t n[3], mpfr_t d, int perturb) {
  mpfr_t t, u[3], w[3];
  mpfr_init2(t, PREC);
  for (int k = 0; k < 3; k++) {
    mpfr_inits2(PREC, u[k], w[k], (mpfr_ptr)0);
  }
  if (!p->pts[0]) {
    for (int k = 0; k < 3; k++) mpfr_set_d(n[k], p->n[k], MPFR_RNDN);
    mpfr_set_d(d, p->d, MPFR_RNDN);
  } else {
    for (int k = 0; k < 3; k++) {
      mpfr_set_d(u[k], p->pts[1][k], MPFR_RNDN);
      mpfr_sub_d(u[k], u[k], p->pts[0][k], MPFR_RNDN);
      mpfr_set_d(w[k], p->pts[2][k], MPFR_RNDN);
      mpfr_sub_d(w[k], w[k], p->pts[0][k], MPFR_RNDN);
    }
    static const int r[3][2] = {{1, 2}, {2, 0}, {0, 1}};
    for (int k = 0; k < 3; k++) {
      mpfr_mul(n[k], u[r[k][0]], w[r[k][1]], MPFR_RNDN);
      mpfr_mul(t, u[r[k][1]], w[r[k][0]], MPFR_RNDN);
      mpfr_sub(n[k], n[k], t, MPFR_RNDN);
    }
    mpfr_set_ui(d, 0, MPFR_RNDN);
    for (int k = 0; k < 3; k++) {
      mpfr_mul_d(t, n[k], p->pts[0][k], MPFR_RNDN);
      mpfr_add(d, d, t, MPFR_RNDN);
    }
  }
  if (perturb && p->rank >= 0) {
    mpfr_set_ui_2exp(t, 1, -400 * (p->rank + 1), MPFR_RNDN);
    mpfr_sub(d, d, t, MPFR_RNDN);
  }
  mpfr_clear(t);
  for (int k = 0; k < 3; k++) mpfr_clears(u[k], w[k], (mpfr_ptr)0);
}

/* the meeting point of three planes by Cramer's rule, x = X / det, X and
   det exact at PREC (no division) */
static int ref_three(const MxPlane *const p[3], int perturb, mpfr_t x[3],
                     mpfr_t det) {
  mpfr_t a[3][4], t, m[3][3];
  mpfr_init2(t, PREC);
  for (int i = 0; i < 3; i++) {
    for (int k = 0; k < 4; k++) mpfr_init2(a[i][k], PREC);
    for (int k = 0; k < 3; k++) mpfr_init2(m[i][k], PREC);
    ref_plane(p[i], a[i], a[i][3], perturb);
  }
  /* det of rows a[i][0..2], then x_c with column c replaced by d */
  for (int c = -1; c < 3; c++) {
    for (int i = 0; i < 3; i++)
      for (int k = 0; k < 3; k++) mpfr_set(m[i][k], a[i][k == c ? 3 : k], MPFR_RNDN);
    mpfr_t v;
    mpfr_init2(v, PREC);
    mpfr_set_ui(v, 0, MPFR_RNDN);
    static const int perm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    for (int q = 0; q < 6; q++) {
      mpfr_mul(t, m[0][perm[q][0]], m[1][perm[q][1]], MPFR_RNDN);
      mpfr_mul(t, t, m[2][perm[q][2]], MPFR_RNDN);
      if (q < 3) mpfr_add(v, v, t, MPFR_RNDN);
      else mpfr_sub(v, v, t, MPFR_RNDN);
    }
    if (c < 0) mpfr_set(det, v, MPFR_RNDN);
    else mpfr_set(x[c], v, MPFR_RNDN);
    mpfr_clear(v);
  }
  int ok = mpfr_sgn(det) != 0;
  mpfr_clear(t);
  for (int i = 0; i < 3; i++) {
    for (int k = 0; k < 4; k++) mpfr_clear(a[i][k]);
    for (int k = 0; k < 3; k++) mpfr_clear(m[i][k]);
  }
  return ok;
}

/* the crossing of a - b with plane i, x = X / den, X = b s(a) - a s(b),
   den = s(a) - s(b), exact */
static void ref_edge(const double a[3], const double b[3], const MxPlane *i,
                     int perturb, mpfr_t x[3], mpfr_t den) {
  mpfr_t n[3], d, sa, sb, t, u;
  mpfr_inits2(PREC, d, sa, sb, t, u, (mpfr_ptr)0);
  for (int k = 0; k < 3; k++) mpfr_init2(n[k], PREC);
  ref_plane(i, n, d, perturb);
  mpfr_neg(sa, d, MPFR_RNDN);
  mpfr_neg(sb, d, MPFR_RNDN);
  for (int k = 0; k < 3; k++) {
    mpfr_mul_d(t, n[k], a[k], MPFR_RNDN);
    mpfr_add(sa, sa, t, MPFR_RNDN);
    mpfr_mul_d(t, n[k], b[k], MPFR_RNDN);
    mpfr_add(sb, sb, t, MPFR_RNDN);
  }
  mpfr_sub(den, sa, sb, MPFR_RNDN);
  for (int k = 0; k < 3; k++) {
    mpfr_mul_d(u, sa, b[k], MPFR_RNDN);
    mpfr_mul_d(t, sb, a[k], MPFR_RNDN);
    mpfr_sub(x[k], u, t, MPFR_RNDN);
  }
  mpfr_clears(d, sa, sb, t, u, (mpfr_ptr)0);
  for (int k = 0; k < 3; k++) mpfr_clear(n[k]);
}

/* the sign of plane j's n . x - d at x = X / den */
static int ref_side(const MxPlane *j, mpfr_t x[3], mpfr_t den, int perturb) {
  mpfr_t n[3], d, s, t;
  mpfr_inits2(PREC, d, s, t, (mpfr_ptr)0);
  for (int k = 0; k < 3; k++) mpfr_init2(n[k], PREC);
  ref_plane(j, n, d, perturb);
  mpfr_mul(s, d, den, MPFR_RNDN);
  mpfr_neg(s, s, MPFR_RNDN);
  for (int k = 0; k < 3; k++) {
    mpfr_mul(t, n[k], x[k], MPFR_RNDN);
    mpfr_add(s, s, t, MPFR_RNDN);
  }
  int r = mpfr_sgn(s) * mpfr_sgn(den);
  mpfr_clears(d, s, t, (mpfr_ptr)0);
  for (int k = 0; k < 3; k++) mpfr_clear(n[k]);
  return r;
}

static MxPlane plane(double nx, double ny, double nz, double d, long rank) {
  MxPlane p = {{NULL, NULL, NULL}, {nx, ny, nz}, d, rank, 0, 0, {0, 0, 0}, 0};
  mx_plane_prep(&p);
  return p;
}

static MxPlane random_plane(long rank) {
  double n[3] = {2 * urand() - 1, 2 * urand() - 1, 2 * urand() - 1};
  return plane(n[0], n[1], n[2], 2 * urand() - 1, rank);
}

/* X / den within the box? */
static int in_box(const MxBox *b, mpfr_t x[3], mpfr_t den) {
  mpfr_t q;
  mpfr_init2(q, PREC);
  int in = 1;
  for (int k = 0; k < 3 && in; k++) {
    mpfr_div(q, x[k], den, MPFR_RNDN);
    in = mpfr_cmp_d(q, b->x[k] - b->r[k] * (1 + 0x1p-40)) >= 0 &&
         mpfr_cmp_d(q, b->x[k] + b->r[k] * (1 + 0x1p-40)) <= 0;
  }
  mpfr_clear(q);
  return in;
}

/* one question about three planes and a fourth: the predicate, the
   tie flag, the box, all against the reference */
static void ask_three(const MxPlane *const p[3], const MxPlane *j, long *bad,
                      long *ties, long *boxbad, long *boxdecided) {
  mpfr_t x[3], y[3], dx, dy;
  mpfr_inits2(PREC, dx, dy, (mpfr_ptr)0);
  for (int k = 0; k < 3; k++) mpfr_inits2(PREC, x[k], y[k], (mpfr_ptr)0);
  if (ref_three(p, 1, x, dx) && ref_three(p, 0, y, dy)) {
    int tie, got = mx_three_in(p, j, &tie);
    int want = ref_side(j, x, dx, 1) < 0, zero = ref_side(j, y, dy, 0) == 0;
    *bad += got != want || tie != zero;
    *ties += zero;
    MxBox b;
    if (!j->pts[0] && mx_three_box(p, &b) == 0) {
      *boxbad += !in_box(&b, y, dy);
      int r = mx_box_in(&b, j);
      if (r >= 0) {
        (*boxdecided)++;
        *boxbad += zero || r != want;
      }
    }
  }
  for (int k = 0; k < 3; k++) mpfr_clears(x[k], y[k], (mpfr_ptr)0);
  mpfr_clears(dx, dy, (mpfr_ptr)0);
}

static void ask_edge(const double a[3], const double b[3], const MxPlane *i,
                     const MxPlane *j, long *bad, long *ties, long *boxbad) {
  int tie;
  int ain = mx_point_in(i, a, &tie), bin = mx_point_in(i, b, &tie);
  if (ain == bin) return;
  mpfr_t x[3], y[3], dx, dy;
  mpfr_inits2(PREC, dx, dy, (mpfr_ptr)0);
  for (int k = 0; k < 3; k++) mpfr_inits2(PREC, x[k], y[k], (mpfr_ptr)0);
  ref_edge(a, b, i, 1, x, dx);
  ref_edge(a, b, i, 0, y, dy);
  int got = mx_edge_in(a, b, ain, i, j, &tie);
  int want = ref_side(j, x, dx, 1) < 0, zero = ref_side(j, y, dy, 0) == 0;
  *bad += got != want || tie != zero;
  *ties += zero;
  MxBox bx;
  /* the ends' distances as the mesher rounds them, with its bound
     (2^-50 of the permanent) */
  double se[2], ee[2];
  for (int q = 0; q < 2; q++) {
    const double *e = q ? b : a;
    double p0 = i->n[0] * e[0], p1 = i->n[1] * e[1], p2 = i->n[2] * e[2];
    se[q] = p0 + p1 + p2 - i->d;
    ee[q] = 0x1p-50 * (fabs(p0) + fabs(p1) + fabs(p2) + fabs(i->d)) + 0x1p-400;
  }
  if (mx_edge_box(a, b, se[0], ee[0], se[1], ee[1], &bx) == 0) {
    *boxbad += !in_box(&bx, y, dy);
    int r = mx_box_in(&bx, j);
    *boxbad += r >= 0 && (zero || r != want);
  }
  for (int k = 0; k < 3; k++) mpfr_clears(x[k], y[k], (mpfr_ptr)0);
  mpfr_clears(dx, dy, (mpfr_ptr)0);
}

int main(void) {
  check_prefix = "mesh_exact";
  char buf[300];

  /* a point on a plane is outside it (n . x - d + eps > 0) */
  {
    MxPlane p = plane(1, 0, 0, 0.5, 3);
    int tie;
    double on[3] = {0.5, 7, -2}, in[3] = {0.5 - 0x1p-53, 0, 0};
    CHECK("a point exactly on a plane is outside it, and a tie",
          mx_point_in(&p, on, &tie) == 0 && tie == 1);
    CHECK("a point an ulp inside is inside, not a tie",
          mx_point_in(&p, in, &tie) == 1 && tie == 0);
  }

  /* random triples and a fourth plane: general position */
  long bad = 0, ties = 0, boxbad = 0, decided = 0, n = 0;
  for (int it = 0; it < 3000; it++) {
    MxPlane a = random_plane(it % 5), b = random_plane(5 + it % 3),
            c = random_plane(9), j = random_plane(it % 11);
    if (j.rank == a.rank || j.rank == b.rank || j.rank == c.rank) j.rank = 20;
    const MxPlane *p[3] = {&a, &b, &c};
    ask_three(p, &j, &bad, &ties, &boxbad, &decided);
    n++;
  }
  snprintf(buf, sizeof buf, "3000 random triples and planes: every side as MPFR's "
           "(%ld wrong, %ld ties), every box holds its point and decides as MPFR "
           "(%ld decided, %ld wrong)", bad, ties, decided, boxbad);
  CHECK(buf, bad == 0 && boxbad == 0 && decided > 2500);

  /* nearly degenerate: j through the meeting point of a, b, c, its
     offset rounded (a tie by the reals, not by the doubles) */
  bad = ties = boxbad = decided = 0;
  for (int it = 0; it < 3000; it++) {
    MxPlane a = random_plane(1), b = random_plane(2), c = random_plane(3),
            j = random_plane(it % 2 ? 0 : 4);
    const MxPlane *p[3] = {&a, &b, &c};
    mpfr_t x[3], dx;
    mpfr_init2(dx, PREC);
    for (int k = 0; k < 3; k++) mpfr_init2(x[k], PREC);
    if (ref_three(p, 0, x, dx)) {
      for (int k = 0; k < 3; k++) mpfr_div(x[k], x[k], dx, MPFR_RNDN);
      double xd[3] = {mpfr_get_d(x[0], MPFR_RNDN), mpfr_get_d(x[1], MPFR_RNDN),
                      mpfr_get_d(x[2], MPFR_RNDN)};
      j.d = j.n[0] * xd[0] + j.n[1] * xd[1] + j.n[2] * xd[2];
      mx_plane_prep(&j);
      ask_three(p, &j, &bad, &ties, &boxbad, &decided);
    }
    for (int k = 0; k < 3; k++) mpfr_clear(x[k]);
    mpfr_clear(dx);
  }
  snprintf(buf, sizeof buf, "3000 nearly degenerate fourth planes (offset "
           "rounded through the point): every side as MPFR's (%ld wrong, %ld "
           "ties), boxes right where they decide (%ld decided, %ld wrong)",
           bad, ties, decided, boxbad);
  CHECK(buf, bad == 0 && boxbad == 0);

  /* exactly degenerate, on small integers: four planes through (1, 2, 3)
     and three through the line x = 1, z = 3, each rank order */
  bad = ties = boxbad = decided = 0;
  static const double four[][4] = {
      {1, 0, 0, 1}, {0, 1, 0, 2}, {0, 0, 1, 3}, {1, 1, 1, 6}, {1, -1, 0, -1},
      {2, 0, -1, -1}, {1, 0, 1, 4}, {-1, 0, 1, 2}, {3, 1, -2, -1}};
  int nf = (int)(sizeof four / sizeof *four);
  for (int r = 0; r < 24; r++)
    for (int i0 = 0; i0 < nf; i0++)
      for (int i1 = i0 + 1; i1 < nf; i1++)
        for (int i2 = i1 + 1; i2 < nf; i2++)
          for (int jj = 0; jj < nf; jj++) {
            if (jj == i0 || jj == i1 || jj == i2) continue;
            int idx[4] = {i0, i1, i2, jj};
            MxPlane q[4];
            for (int k = 0; k < 4; k++) {
              const double *f = four[idx[k]];
              /* ranks: the 24 orders of the four */
              static const int perm[24][4] = {
                  {0,1,2,3},{0,1,3,2},{0,2,1,3},{0,2,3,1},{0,3,1,2},{0,3,2,1},
                  {1,0,2,3},{1,0,3,2},{1,2,0,3},{1,2,3,0},{1,3,0,2},{1,3,2,0},
                  {2,0,1,3},{2,0,3,1},{2,1,0,3},{2,1,3,0},{2,3,0,1},{2,3,1,0},
                  {3,0,1,2},{3,0,2,1},{3,1,0,2},{3,1,2,0},{3,2,0,1},{3,2,1,0}};
              q[k] = plane(f[0], f[1], f[2], f[3], perm[r][k]);
            }
            const MxPlane *p[3] = {&q[0], &q[1], &q[2]};
            ask_three(p, &q[3], &bad, &ties, &boxbad, &decided);
          }
  snprintf(buf, sizeof buf, "planes through one point and one line (small "
           "integers), every order of ranks: every side as MPFR's with the "
           "perturbation numeric (%ld wrong, %ld ties seen), no box decides a "
           "tie (%ld wrong)", bad, ties, boxbad);
  CHECK(buf, bad == 0 && boxbad == 0 && ties > 1000);

  /* a tetrahedron's face as one of the three (through its corners, not
     perturbed), and planes through the point it meets two planes at */
  bad = ties = boxbad = decided = 0;
  {
    double c0[3] = {0, 0, 0}, c1[3] = {2, 0, 0}, c2[3] = {0, 2, 0};
    MxPlane face = {{c0, c1, c2}, {0, 0, 0}, 0, -1, INFINITY, 0, {0, 0, 0}, 0};
    MxPlane prepped = face;
    mx_plane_prep(&prepped);
    for (int i0 = 0; i0 < nf; i0++)
      for (int i1 = 0; i1 < nf; i1++)
        for (int jj = 0; jj < nf; jj++) {
          if (i0 == i1 || jj == i0 || jj == i1) continue;
          MxPlane a = plane(four[i0][0], four[i0][1], four[i0][2], four[i0][3] - 3 * four[i0][2], 1);
          MxPlane b = plane(four[i1][0], four[i1][1], four[i1][2], four[i1][3] - 3 * four[i1][2], 2);
          MxPlane j = plane(four[jj][0], four[jj][1], four[jj][2], four[jj][3] - 3 * four[jj][2], jj % 2 ? 0 : 3);
          const MxPlane *p[3] = {&face, &a, &b}, *pp[3] = {&prepped, &a, &b};
          ask_three(p, &j, &bad, &ties, &boxbad, &decided);
          ask_three(pp, &j, &bad, &ties, &boxbad, &decided);
        }
  }
  snprintf(buf, sizeof buf, "a tetrahedron face (through points, made or "
           "prepared) and planes through (1, 2, 0) on it: every side as MPFR's "
           "(%ld wrong, %ld ties seen; boxes %ld wrong)", bad, ties, boxbad);
  CHECK(buf, bad == 0 && boxbad == 0 && ties > 100);

  /* segments: random, nearly degenerate, and planes through the
     crossing exactly (the segment x from -1 to 3 at y = 2, z = 3 against
     the planes above) */
  bad = ties = boxbad = 0;
  for (int it = 0; it < 3000; it++) {
    double a[3] = {2 * urand() - 1, 2 * urand() - 1, 2 * urand() - 1};
    double b[3] = {2 * urand() - 1, 2 * urand() - 1, 2 * urand() - 1};
    MxPlane i = random_plane(1 + it % 3), j = random_plane(it % 2 ? 0 : 4);
    if (it % 3 == 0) { /* j through the crossing, rounded */
      mpfr_t x[3], dx;
      mpfr_init2(dx, PREC);
      for (int k = 0; k < 3; k++) mpfr_init2(x[k], PREC);
      int tie;
      if (mx_point_in(&i, a, &tie) != mx_point_in(&i, b, &tie)) {
        ref_edge(a, b, &i, 0, x, dx);
        for (int k = 0; k < 3; k++) mpfr_div(x[k], x[k], dx, MPFR_RNDN);
        j.d = j.n[0] * mpfr_get_d(x[0], MPFR_RNDN) + j.n[1] * mpfr_get_d(x[1], MPFR_RNDN) +
              j.n[2] * mpfr_get_d(x[2], MPFR_RNDN);
        mx_plane_prep(&j);
      }
      for (int k = 0; k < 3; k++) mpfr_clear(x[k]);
      mpfr_clear(dx);
    }
    ask_edge(a, b, &i, &j, &bad, &ties, &boxbad);
  }
  for (int r = 0; r < 2; r++)
    for (int i0 = 0; i0 < nf; i0++)
      for (int jj = 0; jj < nf; jj++) {
        if (i0 == jj) continue;
        double a[3] = {-1, 2, 3}, b[3] = {3, 2, 3};
        const double *f = four[i0], *g = four[jj];
        MxPlane i = plane(f[0], f[1], f[2], f[3], r), j = plane(g[0], g[1], g[2], g[3], 1 - r);
        ask_edge(a, b, &i, &j, &bad, &ties, &boxbad);
        ask_edge(b, a, &i, &j, &bad, &ties, &boxbad);
      }
  snprintf(buf, sizeof buf, "segments: random, nearly and exactly degenerate "
           "crossings: every side as MPFR's (%ld wrong, %ld ties seen; boxes "
           "%ld wrong)", bad, ties, boxbad);
  CHECK(buf, bad == 0 && boxbad == 0 && ties > 10);

  /* one point, one position: the triples through (1, 2, 3), and the
     segment's crossings there */
  {
    double x0[3];
    int diff = 0, made = 0;
    for (int i0 = 0; i0 < nf; i0++)
      for (int i1 = i0 + 1; i1 < nf; i1++)
        for (int i2 = i1 + 1; i2 < nf; i2++) {
          MxPlane a = plane(four[i0][0], four[i0][1], four[i0][2], four[i0][3], 0),
                  b = plane(four[i1][0], four[i1][1], four[i1][2], four[i1][3], 1),
                  c = plane(four[i2][0], four[i2][1], four[i2][2], four[i2][3], 2);
          const MxPlane *p[3] = {&a, &b, &c};
          double x[3];
          if (mx_three_point(p, x) < 0) continue;
          if (!made++) memcpy(x0, x, sizeof x);
          diff += memcmp(x, x0, sizeof x) != 0;
        }
    double a[3] = {1, 2, -5.5}, b[3] = {1, 2, 3.25};
    for (int i0 = 0; i0 < nf; i0++) {
      MxPlane p = plane(four[i0][0], four[i0][1], four[i0][2], four[i0][3], 0);
      int tie;
      if (mx_point_in(&p, a, &tie) == mx_point_in(&p, b, &tie)) continue;
      double x[3];
      mx_edge_point(a, b, &p, x);
      diff += memcmp(x, x0, sizeof x) != 0;
      made++;
    }
    snprintf(buf, sizeof buf, "the %d names of the point (1, 2, 3) give one "
             "position to the bit (%d differ)", made, diff);
    CHECK(buf, diff == 0 && made > 20 && x0[0] == 1 && x0[1] == 2 && x0[2] == 3);
  }
  mpfr_free_cache();
  CHECK_DONE();
}
