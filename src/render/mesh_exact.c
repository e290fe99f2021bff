/* mesh_exact.c: exact, symbolically perturbed signs (see mesh_exact.h).
 *
 * Each answer is the sign of a polynomial in the inputs (doubles, exact
 * as rationals). The filter evaluates it in doubles carrying a bound of
 * the error (each operation's result is the exact one of its rounded
 * operands times 1 + delta, |delta| <= 2^-53, in round to nearest), and
 * trusts its sign when the value is farther from 0 than the bound; else
 * the polynomial is evaluated again in GMP rationals. A value exactly 0
 * is a tie, decided by the perturbation's first term that is not 0.
 *
 * Where the answers come from (s_p(x) = n_p . x - d_p, the perturbed
 * s_p + eps_p, inside when it is below 0):
 *  - a point: s_p(x); 0 is outside.
 *  - the crossing v of segment a - b with plane i:
 *      s_j(v) = (s_j(a) s_i(b) - s_i(a) s_j(b)) / (s_i(b) - s_i(a)),
 *    whose numerator perturbed is N + eps_i (s_j(a) - s_j(b))
 *    + eps_j (s_i(b) - s_i(a)); the denominator does not move.
 *  - the meeting point v of planes 0, 1, 2 (normals n_k, offsets d_k):
 *    with c_0 = n_1 x n_2, c_1 = n_2 x n_0, c_2 = n_0 x n_1 and
 *    D = n_0 . c_0, v = sum d_k c_k / D, so
 *      s_j(v) = (sum_k d_k (n_j . c_k) - d_j D) / D,
 *    whose numerator perturbed is N - sum_k eps_k (n_j . c_k) + eps_j D.
 * The coefficient of eps_j is never 0 (the denominator), so a tie is
 * always decided by the first-order terms, taken in the planes' ranks.
 */
#include "render/mesh_exact.h"

#include <gmp.h>
#include <math.h>
#include <stddef.h>

/* no fused multiply-adds: the bounds are for rounded products */
#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

/* ---- the filter ------------------------------------------------------------

   A value and a bound of its distance from the exact one. Inputs up to
   2^100 in magnitude (else the rational path): the polynomials have at
   most six factors a term, so an underflow's error (at most 2^-1075 an
   operation, outside the relative bound) grows to at most 2^-475 a term;
   the floor 2^-400 in ev_sign covers that and the bound's own rounding
   (each of its operations rounds by a relative 2^-53; the factor
   1 + 2^-30 covers them). */

#define U 0x1p-53
#define BIG 0x1p100

typedef struct {
  double v, e;
} ev;

static inline __attribute__((always_inline)) ev ev_of(double x) { return (ev){x, 0}; }

static inline __attribute__((always_inline)) ev ev_add(ev a, ev b) {
  double s = a.v + b.v;
  return (ev){s, a.e + b.e + U * fabs(s)};
}

static inline __attribute__((always_inline)) ev ev_sub(ev a, ev b) {
  double s = a.v - b.v;
  return (ev){s, a.e + b.e + U * fabs(s)};
}

static inline __attribute__((always_inline)) ev ev_mul(ev a, ev b) {
  double p = a.v * b.v;
  return (ev){p, fabs(a.v) * b.e + fabs(b.v) * a.e + a.e * b.e + U * fabs(p)};
}

/* The exact value's sign, or 2 when the filter cannot tell. */
static inline __attribute__((always_inline)) int ev_sign(ev a) {
  double m = a.e * (1 + 0x1p-30) + 0x1p-400;
  if (!(fabs(a.v) <= BIG * BIG * BIG * BIG) || !(m < INFINITY)) return 2;
  return a.v > m ? 1 : a.v < -m ? -1 : 2;
}

static inline __attribute__((always_inline)) int tame(const double *x, int n) {
  for (int i = 0; i < n; i++)
    if (!(fabs(x[i]) <= BIG)) return 0;
  return 1;
}

static inline __attribute__((always_inline)) int tame_plane(const MxPlane *p) {
  if (p->pts[0]) {
    for (int k = 0; k < 3; k++)
      if (!tame(p->pts[k], 3)) return 0;
    return 1;
  }
  return tame(p->n, 3) && tame(&p->d, 1);
}

static inline __attribute__((always_inline)) ev ev_dot(const ev a[3], const ev b[3]) {
  return ev_add(ev_add(ev_mul(a[0], b[0]), ev_mul(a[1], b[1])), ev_mul(a[2], b[2]));
}

static inline __attribute__((always_inline)) void ev_cross(const ev a[3], const ev b[3], ev c[3]) {
  c[0] = ev_sub(ev_mul(a[1], b[2]), ev_mul(a[2], b[1]));
  c[1] = ev_sub(ev_mul(a[2], b[0]), ev_mul(a[0], b[2]));
  c[2] = ev_sub(ev_mul(a[0], b[1]), ev_mul(a[1], b[0]));
}

static inline __attribute__((always_inline)) void ev_plane(const MxPlane *p, ev n[3], ev *d) {
  if (!p->pts[0] || p->l1 < 0) { /* (a prepared plane through points) */
    for (int k = 0; k < 3; k++) n[k] = (ev){p->n[k], p->pts[0] ? p->ne[k] : 0};
    *d = (ev){p->d, p->pts[0] ? p->de : 0};
    return;
  }
  ev q0[3], u[3], w[3];
  for (int k = 0; k < 3; k++) {
    q0[k] = ev_of(p->pts[0][k]);
    u[k] = ev_sub(ev_of(p->pts[1][k]), q0[k]);
    w[k] = ev_sub(ev_of(p->pts[2][k]), q0[k]);
  }
  ev_cross(u, w, n);
  *d = ev_dot(n, q0);
}

/* s_p(x) */
static inline __attribute__((always_inline)) ev ev_s(const MxPlane *p, const double x[3]) {
  ev n[3], d, xe[3];
  ev_plane(p, n, &d);
  for (int k = 0; k < 3; k++) xe[k] = ev_of(x[k]);
  return ev_sub(ev_dot(n, xe), d);
}

/* a / b, or an error bound of infinity when b may be 0 */
static inline __attribute__((always_inline)) ev ev_div(ev a, ev b) {
  double q = a.v / b.v, m = fabs(b.v) - b.e * (1 + 0x1p-30);
  if (!(m > 0)) return (ev){q, INFINITY};
  return (ev){q, (a.e + fabs(q) * b.e) / m * (1 + 0x1p-30) + U * fabs(q)};
}

/* ---- boxes ----------------------------------------------------------------- */

void mx_plane_prep(MxPlane *p) {
  if (p->pts[0]) {
    ev n[3], d;
    p->l1 = 0;
    ev_plane(p, n, &d);
    for (int k = 0; k < 3; k++) {
      p->n[k] = n[k].v;
      p->ne[k] = n[k].e;
    }
    p->d = d.v;
    p->de = d.e;
    p->l1 = -1; /* prepared: ev_plane takes n, d and their bounds */
    return;
  }
  p->l1 = fabs(p->n[0]) + fabs(p->n[1]) + fabs(p->n[2]);
  p->dl = 0x1p-50 * fabs(p->d) + 0x1p-400;
  if (!tame_plane(p)) p->l1 = INFINITY; /* never decides */
}

static int box_done(const ev x[3], MxBox *b) {
  double rm = 0, xm = 0;
  for (int k = 0; k < 3; k++) {
    b->x[k] = x[k].v;
    b->r[k] = x[k].e * (1 + 0x1p-30);
    if (!(b->r[k] < BIG) || !(fabs(x[k].v) <= BIG)) return -1;
    if (b->r[k] > rm) rm = b->r[k];
    if (fabs(x[k].v) > xm) xm = fabs(x[k].v);
  }
  b->q = (rm + 0x1p-50 * xm) * (1 + 0x1p-30);
  return 0;
}

int mx_edge_box(const double a[3], const double b[3], double sa, double ea,
                double sb, double eb, MxBox *out) {
  /* a + t (b - a), t = sa / (sa - sb), each operation's rounding added
     (2^-52 for 2^-53 to cover the bound's own) */
  double den = sa - sb, eden = ea + eb + 0x1p-52 * fabs(den);
  double md = fabs(den) - eden;
  if (!(md > 0)) return -1;
  double t = sa / den, et = (ea + fabs(t) * eden) / md + 0x1p-52 * fabs(t);
  double rm = 0, xm = 0;
  for (int k = 0; k < 3; k++) {
    double d = b[k] - a[k], td = t * d, x = a[k] + td;
    double r = fabs(d) * et + 0x1p-52 * (fabs(d * t) + fabs(td) + fabs(x));
    r *= 1 + 0x1p-30;
    out->x[k] = x;
    out->r[k] = r;
    if (!(r < BIG) || !(fabs(x) <= BIG)) return -1;
    if (r > rm) rm = r;
    if (fabs(x) > xm) xm = fabs(x);
  }
  out->q = (rm + 0x1p-50 * xm) * (1 + 0x1p-30);
  return 0;
}

int mx_three_box(const MxPlane *const p[3], MxBox *out) {
  for (int k = 0; k < 3; k++)
    if (!tame_plane(p[k])) return -1;
  ev n[3][3], d[3], c[3][3], x[3];
  for (int k = 0; k < 3; k++) ev_plane(p[k], n[k], &d[k]);
  ev_cross(n[1], n[2], c[0]);
  ev_cross(n[2], n[0], c[1]);
  ev_cross(n[0], n[1], c[2]);
  ev det = ev_dot(n[0], c[0]);
  for (int a = 0; a < 3; a++) {
    ev num = ev_add(ev_add(ev_mul(d[0], c[0][a]), ev_mul(d[1], c[1][a])),
                    ev_mul(d[2], c[2][a]));
    x[a] = ev_div(num, det);
  }
  return box_done(x, out);
}

/* ---- rationals ------------------------------------------------------------- */

typedef struct {
  mpq_t n[3], d;
} QPlane;

static void qp_init(QPlane *q) {
  for (int k = 0; k < 3; k++) mpq_init(q->n[k]);
  mpq_init(q->d);
}

static void qp_clear(QPlane *q) {
  for (int k = 0; k < 3; k++) mpq_clear(q->n[k]);
  mpq_clear(q->d);
}

/* r = a . b, with t scratch */
static void q_dot(mpq_t r, mpq_t *const a, mpq_t *const b, mpq_t t) {
  mpq_mul(r, a[0], b[0]);
  mpq_mul(t, a[1], b[1]);
  mpq_add(r, r, t);
  mpq_mul(t, a[2], b[2]);
  mpq_add(r, r, t);
}

/* c = a x b (c distinct from a and b), with t scratch */
static void q_cross(mpq_t *c, mpq_t *const a, mpq_t *const b, mpq_t t) {
  static const int r[3][2] = {{1, 2}, {2, 0}, {0, 1}};
  for (int k = 0; k < 3; k++) {
    mpq_mul(c[k], a[r[k][0]], b[r[k][1]]);
    mpq_mul(t, a[r[k][1]], b[r[k][0]]);
    mpq_sub(c[k], c[k], t);
  }
}

static void q_plane(QPlane *q, const MxPlane *p) {
  if (!p->pts[0]) {
    for (int k = 0; k < 3; k++) mpq_set_d(q->n[k], p->n[k]);
    mpq_set_d(q->d, p->d);
    return;
  }
  mpq_t q0[3], u[3], w[3], t;
  mpq_init(t);
  for (int k = 0; k < 3; k++) {
    mpq_inits(q0[k], u[k], w[k], NULL);
    mpq_set_d(q0[k], p->pts[0][k]);
    mpq_set_d(u[k], p->pts[1][k]);
    mpq_sub(u[k], u[k], q0[k]);
    mpq_set_d(w[k], p->pts[2][k]);
    mpq_sub(w[k], w[k], q0[k]);
  }
  q_cross(q->n, u, w, t);
  q_dot(q->d, q->n, q0, t);
  for (int k = 0; k < 3; k++) mpq_clears(q0[k], u[k], w[k], NULL);
  mpq_clear(t);
}

/* r = s_p(x) */
static void q_s(mpq_t r, const QPlane *p, const double x[3]) {
  mpq_t xq[3], t;
  mpq_init(t);
  for (int k = 0; k < 3; k++) {
    mpq_init(xq[k]);
    mpq_set_d(xq[k], x[k]);
  }
  q_dot(r, (mpq_t *)p->n, xq, t);
  mpq_sub(r, r, p->d);
  for (int k = 0; k < 3; k++) mpq_clear(xq[k]);
  mpq_clear(t);
}

/* ---- the predicates ---------------------------------------------------------- */

int mx_point_in(const MxPlane *p, const double x[3], int *tie) {
  *tie = 0;
  if (tame_plane(p) && tame(x, 3)) {
    int sg = ev_sign(ev_s(p, x));
    if (sg != 2) return sg < 0;
  }
  QPlane q;
  qp_init(&q);
  q_plane(&q, p);
  mpq_t s;
  mpq_init(s);
  q_s(s, &q, x);
  int r = mpq_sgn(s) < 0; /* 0: s + eps > 0, outside */
  *tie = mpq_sgn(s) == 0;
  mpq_clear(s);
  qp_clear(&q);
  return r;
}

int mx_edge_in(const double a[3], const double b[3], int a_in,
               const MxPlane *i, const MxPlane *j, int *tie) {
  *tie = 0;
  int sigma = a_in ? 1 : -1; /* the sign of s_i(b) - s_i(a) */
  if (tame_plane(i) && tame_plane(j) && tame(a, 3) && tame(b, 3)) {
    ev sai = ev_s(i, a), sbi = ev_s(i, b), saj = ev_s(j, a), sbj = ev_s(j, b);
    int sg = ev_sign(ev_sub(ev_mul(saj, sbi), ev_mul(sai, sbj)));
    if (sg == 1 || sg == -1) return sg * sigma < 0;
  }
  QPlane qi, qj;
  qp_init(&qi);
  qp_init(&qj);
  q_plane(&qi, i);
  q_plane(&qj, j);
  mpq_t sai, sbi, saj, sbj, n, t;
  mpq_inits(sai, sbi, saj, sbj, n, t, NULL);
  q_s(sai, &qi, a);
  q_s(sbi, &qi, b);
  q_s(saj, &qj, a);
  q_s(sbj, &qj, b);
  mpq_mul(n, saj, sbi);
  mpq_mul(t, sai, sbj);
  mpq_sub(n, n, t);
  int val = mpq_sgn(n) * sigma;
  if (val == 0) {
    *tie = 1;
    /* eps_i's coefficient s_j(a) - s_j(b) first if i ranks first, then
       eps_j's, s_i(b) - s_i(a), whose sign is sigma's */
    val = 1;
    if (i->rank < j->rank) {
      mpq_sub(t, saj, sbj);
      if (mpq_sgn(t)) val = mpq_sgn(t) * sigma;
    }
  }
  mpq_clears(sai, sbi, saj, sbj, n, t, NULL);
  qp_clear(&qi);
  qp_clear(&qj);
  return val < 0;
}

int mx_three_in(const MxPlane *const p[3], const MxPlane *j, int *tie) {
  *tie = 0;
  int ok = tame_plane(j);
  for (int k = 0; k < 3; k++) ok = ok && tame_plane(p[k]);
  if (ok) {
    ev n[4][3], d[4], c[3][3];
    for (int k = 0; k < 3; k++) ev_plane(p[k], n[k], &d[k]);
    ev_plane(j, n[3], &d[3]);
    ev_cross(n[1], n[2], c[0]);
    ev_cross(n[2], n[0], c[1]);
    ev_cross(n[0], n[1], c[2]);
    ev det = ev_dot(n[0], c[0]);
    ev num = ev_mul(d[3], det);
    num.v = -num.v;
    for (int k = 0; k < 3; k++) num = ev_add(num, ev_mul(d[k], ev_dot(n[3], c[k])));
    int sd = ev_sign(det), sn = ev_sign(num);
    if ((sd == 1 || sd == -1) && (sn == 1 || sn == -1)) return sd * sn < 0;
  }
  QPlane q[4];
  for (int k = 0; k < 4; k++) {
    qp_init(&q[k]);
    q_plane(&q[k], k < 3 ? p[k] : j);
  }
  mpq_t c[3][3], a[3], det, num, t;
  mpq_inits(det, num, t, NULL);
  for (int k = 0; k < 3; k++) {
    mpq_inits(c[k][0], c[k][1], c[k][2], a[k], NULL);
  }
  q_cross(c[0], q[1].n, q[2].n, t);
  q_cross(c[1], q[2].n, q[0].n, t);
  q_cross(c[2], q[0].n, q[1].n, t);
  q_dot(det, q[0].n, c[0], t);
  mpq_mul(num, q[3].d, det);
  mpq_neg(num, num);
  for (int k = 0; k < 3; k++) {
    q_dot(a[k], q[3].n, c[k], t);
    mpq_mul(t, q[k].d, a[k]);
    mpq_add(num, num, t);
  }
  int sd = mpq_sgn(det), val = mpq_sgn(num) * sd;
  if (val == 0 && sd != 0) {
    *tie = 1;
    /* the perturbed planes in rank order: eps_k's coefficient
       -(n_j . c_k), eps_j's D */
    const MxPlane *pl[4] = {p[0], p[1], p[2], j};
    int ord[4] = {0, 1, 2, 3};
    for (int r = 0; r < 4; r++)
      for (int s = 0; s + 1 < 4 - r; s++)
        if (pl[ord[s]]->rank > pl[ord[s + 1]]->rank) {
          int x = ord[s];
          ord[s] = ord[s + 1];
          ord[s + 1] = x;
        }
    for (int r = 0; r < 4 && val == 0; r++) {
      int k = ord[r];
      if (pl[k]->rank < 0) continue;
      int cs = k == 3 ? sd : -mpq_sgn(a[k]);
      val = cs * sd;
    }
  }
  for (int k = 0; k < 3; k++) mpq_clears(c[k][0], c[k][1], c[k][2], a[k], NULL);
  mpq_clears(det, num, t, NULL);
  for (int k = 0; k < 4; k++) qp_clear(&q[k]);
  return val < 0;
}

/* ---- positions ---------------------------------------------------------------

   The exact point rounded (mpq_get_d: toward 0), so that every formula for
   one point gives the same doubles. */

void mx_edge_point(const double a[3], const double b[3], const MxPlane *i,
                   double x[3]) {
  QPlane q;
  qp_init(&q);
  q_plane(&q, i);
  mpq_t sa, sb, t, u, v;
  mpq_inits(sa, sb, t, u, v, NULL);
  q_s(sa, &q, a);
  q_s(sb, &q, b);
  mpq_sub(t, sa, sb);
  if (mpq_sgn(t)) mpq_div(t, sa, t);
  for (int k = 0; k < 3; k++) {
    mpq_set_d(u, a[k]);
    mpq_set_d(v, b[k]);
    mpq_sub(v, v, u);
    mpq_mul(v, v, t);
    mpq_add(u, u, v);
    x[k] = mpq_get_d(u);
  }
  mpq_clears(sa, sb, t, u, v, NULL);
  qp_clear(&q);
}

int mx_three_point(const MxPlane *const p[3], double x[3]) {
  QPlane q[3];
  for (int k = 0; k < 3; k++) {
    qp_init(&q[k]);
    q_plane(&q[k], p[k]);
  }
  mpq_t c[3][3], det, t, r;
  mpq_inits(det, t, r, NULL);
  for (int k = 0; k < 3; k++) mpq_inits(c[k][0], c[k][1], c[k][2], NULL);
  q_cross(c[0], q[1].n, q[2].n, t);
  q_cross(c[1], q[2].n, q[0].n, t);
  q_cross(c[2], q[0].n, q[1].n, t);
  q_dot(det, q[0].n, c[0], t);
  int ok = mpq_sgn(det) != 0;
  if (ok)
    for (int a = 0; a < 3; a++) {
      mpq_set_ui(r, 0, 1);
      for (int k = 0; k < 3; k++) {
        mpq_mul(t, q[k].d, c[k][a]);
        mpq_add(r, r, t);
      }
      mpq_div(r, r, det);
      x[a] = mpq_get_d(r);
    }
  for (int k = 0; k < 3; k++) mpq_clears(c[k][0], c[k][1], c[k][2], NULL);
  mpq_clears(det, t, r, NULL);
  for (int k = 0; k < 3; k++) qp_clear(&q[k]);
  return ok ? 0 : -1;
}
