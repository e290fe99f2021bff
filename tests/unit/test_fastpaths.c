/* test_fastpaths.c: the rounded tracer's fast paths against independent
 * references (they are otherwise covered only through images and the
 * all-roots stability suite):
 *
 *  1. lg_first_bounded (first crossing after the ray's start; shadow mode;
 *     the gradient for the normal) against lg_roots_bounded (the search
 *     must be the same up to its stop, so the roots up to the first
 *     crossing must be identical, bit for bit) and against a long double
 *     reference (the cap-volume fraction of ref_density.h, first sign
 *     change of density - 0.5 bracketed by dense sampling plus every
 *     filter breakpoint, then bisected); normals against the analytic
 *     gradient of that reference, derived here from the cap formula.
 *  2. dt_prune_rl / dt_density_rl against dt_prune_ray / dt_density_ray
 *     (promised identical to the last bit), the pruned view against the
 *     full tape (folding 1+x-x to 1 and leaves at their filter edge to
 *     constants is not exact: a stated bound) and against the reference.
 *  3. csg_ray_spans (convex groups, the one-convex fast path) against
 *     spans made by long double clipping: every plane crossing sorted,
 *     each elementary interval classified at its midpoint by the tree.
 *  3b. csg_ray_spans_dots (dot products shared by a tape's and a linked
 *     tape's planes of equal or opposite normals, csg_tape_share_dirs)
 *     against csg_ray_spans, bit for bit, on normals with zeros of either
 *     sign, offsets of 0 and rays whose dot products are zeros.
 *  4. render_scene's Z and N planes on figure12's objects against
 *     ray_spans along the same pixel rays (the camera re-derived in long
 *     double) and against PointInObject sign checks.
 * Random data come from fixed seeds.  FASTPATHS_VERBOSE=1 prints every
 * problem (not only the first) and, for a crossing that disagrees with
 * the reference, the tree, the ray, every root and the bounds' spans. */
#include <float.h>

#include "core/bounds.h"
#include "core/csg.h"
#include "core/density.h"
#include "render/image.h"
#include "core/lg.h"
#include "ref_density.h"
#include "render/render.h"
#include "../stability/stab.h"

#define EPS DBL_EPSILON
#define NTREES_FIRST 300   /* x 14 rays */

static double lrand(rng_t *g, double lo, double hi) {  /* log-uniform */
  return pow(10, rng_range(g, lo, hi));
}

static void rand_unit(rng_t *g, double u[3]) {
  double l;
  do {
    for (int i = 0; i < 3; i++) u[i] = rng_range(g, -1, 1);
    l = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  } while (l < 0.2 || l > 1);
  for (int i = 0; i < 3; i++) u[i] /= l;
}

/* ==== random rounded density trees =================================== */

/* A radius: sharp (5%), tiny 1e-7..1e-3, usual 0.01..0.3, large 0.5..2. */
static double rand_radius(rng_t *g) {
  double u = rng_unit(g);
  if (u < 0.05) return 0;
  if (u < 0.25) return lrand(g, -7, -3);
  if (u < 0.8) return lrand(g, -2, -0.5);
  return rng_range(g, 0.5, 2);
}

/* A box (axis-aligned or turned) around c as the product of its six
 * halfspaces, each with its own radius; raw normals of random length. */
static int rand_box(rtree *t, rng_t *g, const double c[3]) {
  double e[3][3];
  if (rng_unit(g) < 0.4) {
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) e[i][j] = i == j;
  } else {  /* Gram-Schmidt of random vectors */
    for (int i = 0; i < 3; i++) {
      double l;
      do {
        rand_unit(g, e[i]);
        for (int k = 0; k < i; k++) {
          double p = e[i][0] * e[k][0] + e[i][1] * e[k][1] + e[i][2] * e[k][2];
          for (int j = 0; j < 3; j++) e[i][j] -= p * e[k][j];
        }
        l = sqrt(e[i][0] * e[i][0] + e[i][1] * e[i][1] + e[i][2] * e[i][2]);
      } while (l < 0.3);
      for (int j = 0; j < 3; j++) e[i][j] /= l;
    }
  }
  int k = -1;
  for (int i = 0; i < 3; i++) {
    double h = rng_range(g, 0.15, 0.8), ec = 0;
    for (int j = 0; j < 3; j++) ec += e[i][j] * c[j];
    int lf[2];
    for (int s = 0; s < 2; s++) {
      double sc = rng_range(g, 0.5, 3), sg = s ? -1 : 1;
      lf[s] = rt_leaf(t, sg * sc * e[i][0], sg * sc * e[i][1],
                      sg * sc * e[i][2], sc * (sg * ec + h), rand_radius(g));
    }
    int ab = rt_op(t, R_PROD, lf[0], lf[1]);
    k = k < 0 ? ab : rt_op(t, R_PROD, k, ab);
  }
  return k;
}

/* One to three parts (boxes, or single halfspaces through a point near
 * the centre) combined by products, sums, differences and unions, all
 * shifted by sh. */
static int rand_tree(rtree *t, rng_t *g, const double sh[3]) {
  t->n = 0;
  int np = 1 + (int)(rng_u64(g) % 3), k = -1;
  for (int i = 0; i < np; i++) {
    double c[3];
    for (int j = 0; j < 3; j++) c[j] = sh[j] + rng_range(g, -0.6, 0.6);
    int b;
    if (rng_unit(g) < 0.75) {
      b = rand_box(t, g, c);
    } else {
      double u[3];
      rand_unit(g, u);
      b = rt_leaf(t, u[0], u[1], u[2], u[0] * c[0] + u[1] * c[1] + u[2] * c[2],
                  rand_radius(g));
    }
    if (k < 0) { k = b; continue; }
    static const int ops[] = {R_PROD, R_SUM, R_DIFF, R_UNION};
    k = rt_op(t, ops[rng_u64(g) % 4], k, b);
  }
  return k;
}

static int tree_leaves(const rtree *t, int i) {
  const rnode *x = &t->nodes[i];
  return x->op == R_LEAF ? 1 : tree_leaves(t, x->a) + tree_leaves(t, x->b);
}

/* ==== the long double reference with its gradient ===================== *
 * A leaf is the cap-volume fraction V = h^2 (3r - h)/(4 r^3), h = r - s
 * (ref_density.h); along s: dV/ds = -3 h (2r - h)/(4 r^3) and
 * d2V/ds2 = 3 s/(2 r^3) inside the filter.  Alongside the value and
 * gradient, bounds on the error a double evaluation at the same point
 * makes: a leaf's distance is off by ds = 8 eps (1 + |p|_1 + |d|/|n|)
 * (the normalised plane and the dot product rounded), so its value by
 * |V'| ds + eps and its gradient by |V''| ds + 4 eps |V'|; ops propagate
 * these to first order and add their own rounding. */
/* A sharp leaf's plane within this distance (plus ds) of the point counts
 * as near (set by the caller; the gradient of a step is not a normal). */
static double ref_sharp_w;

typedef struct {
  long double v, g[3];
  long double ev, eg;   /* error bounds of a double evaluation */
  long double mv, md;   /* magnitudes (|.| at every op) of value and
                           derivative along dir (when given) */
  long double dd;       /* derivative along dir */
  long double slopes;   /* sum over leaves of |dV/ds| */
  int near_sharp;       /* a sharp leaf's plane within ds of p */
} rg;

static long double gnorm(const long double g[3]) {
  return sqrtl(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
}

static rg ref_grad(const rtree *t, int i, const long double p[3],
                   const double dir[3], double cs) {
  const rnode *x = &t->nodes[i];
  rg o;
  memset(&o, 0, sizeof o);
  if (x->op == R_LEAF) {
    long double len = sqrtl((long double)x->n[0] * x->n[0] +
                            (long double)x->n[1] * x->n[1] +
                            (long double)x->n[2] * x->n[2]);
    long double un[3], p1 = 0, s = -(long double)x->d / len, nd = 0;
    for (int j = 0; j < 3; j++) {
      un[j] = x->n[j] / len;
      s += un[j] * p[j];
      p1 += fabsl(p[j]);
      nd += un[j] * (dir ? dir[j] : 0);
    }
    /* cs: the coordinates' size when the caller's evaluation forms the
       distance from another point (n.o - d + s n.d) */
    long double ds = 8 * EPS * (1 + fmaxl(p1, cs) + fabsl((long double)x->d / len));
    long double r = x->r, V, dV = 0, d2V = 0;
    if (r == 0) {
      V = s < 0 ? 1 : (s > 0 ? 0 : 0.5L);
      o.near_sharp = fabsl(s) <= ds + ref_sharp_w;
    } else {
      long double h = r - s;
      if (h <= 0) V = 0;
      else if (h >= 2 * r) V = 1;
      else {
        V = h * h * (3 * r - h) / (4 * r * r * r);
        dV = -3 * h * (2 * r - h) / (4 * r * r * r);
      }
      /* the second derivative where the double distance may lie */
      if (fabsl(s) < r + ds) d2V = 3 * fminl(fabsl(s), r) / (2 * r * r * r);
    }
    o.v = V;
    for (int j = 0; j < 3; j++) o.g[j] = dV * un[j];
    o.ev = fabsl(dV) * ds + EPS;
    o.eg = d2V * ds + 4 * EPS * fabsl(dV);
    o.mv = V;
    o.dd = dV * nd;
    o.md = fabsl(dV * nd);
    /* a leaf within rounding of its filter edge: a double evaluation may
       give it a slope of up to 4 eps |n.d|/r (|alpha| = 1 - O(eps)) */
    if (r > 0 && fabsl(fabsl(s) - r) <= ds) o.md += 4 * EPS * fabsl(nd) / r;
    o.slopes = fabsl(dV);
    return o;
  }
  rg a = ref_grad(t, x->a, p, dir, cs), b = ref_grad(t, x->b, p, dir, cs);
  long double ga = gnorm(a.g), gb = gnorm(b.g);
  o.slopes = a.slopes + b.slopes;
  o.near_sharp = a.near_sharp || b.near_sharp;
  switch (x->op) {
  case R_SUM:
  case R_DIFF: {
    long double sg = x->op == R_SUM ? 1 : -1;
    o.v = a.v + sg * b.v;
    for (int j = 0; j < 3; j++) o.g[j] = a.g[j] + sg * b.g[j];
    o.dd = a.dd + sg * b.dd;
    o.ev = a.ev + b.ev + EPS * fabsl(o.v);
    o.eg = a.eg + b.eg + EPS * (ga + gb);
    o.mv = a.mv + b.mv;
    o.md = a.md + b.md;
    break;
  }
  case R_PROD:
    o.v = a.v * b.v;
    for (int j = 0; j < 3; j++) o.g[j] = a.g[j] * b.v + a.v * b.g[j];
    o.dd = a.dd * b.v + a.v * b.dd;
    o.ev = a.ev * fabsl(b.v) + fabsl(a.v) * b.ev + EPS * fabsl(o.v);
    o.eg = a.eg * fabsl(b.v) + ga * b.ev + a.ev * gb + fabsl(a.v) * b.eg +
           2 * EPS * (ga * fabsl(b.v) + fabsl(a.v) * gb);
    o.mv = a.mv * b.mv;
    o.md = a.md * b.mv + a.mv * b.md;
    break;
  default: {  /* density union a + b - ab */
    long double ca = 1 - a.v, cb = 1 - b.v;
    o.v = a.v + b.v - a.v * b.v;
    for (int j = 0; j < 3; j++) o.g[j] = a.g[j] * cb + b.g[j] * ca;
    o.dd = a.dd * cb + b.dd * ca;
    o.ev = a.ev * fabsl(cb) + b.ev * fabsl(ca) +
           3 * EPS * (fabsl(a.v) + fabsl(b.v) + fabsl(a.v * b.v));
    o.eg = a.eg * fabsl(cb) + ga * b.ev + b.eg * fabsl(ca) + gb * a.ev +
           3 * EPS * (ga * fabsl(cb) + gb * fabsl(ca));
    o.mv = a.mv + b.mv + a.mv * b.mv;
    o.md = a.md * (1 + b.mv) + b.md * (1 + a.mv);
  }
  }
  return o;
}

static void ld_point(const double o[3], const double d[3], long double s,
                     long double p[3]) {
  for (int i = 0; i < 3; i++) p[i] = o[i] + s * d[i];
}

static long double ref_f(const rtree *t, int root, const double o[3],
                         const double d[3], long double s) {
  return ref_ld_ray(t, root, o, d, s) - 0.5L;
}

/* Bisect a change of the inside predicate f > 0 on [a, b]. */
static long double ref_bisect(const rtree *t, int root, const double o[3],
                              const double d[3], long double a, long double b) {
  int pa = ref_f(t, root, o, d, a) > 0;
  for (int i = 0; i < 200; i++) {
    long double m = 0.5L * (a + b);
    if (!(m > a && m < b)) break;
    if ((ref_f(t, root, o, d, m) > 0) == pa) a = m;
    else b = m;
  }
  return 0.5L * (a + b);
}

static int cmp_ld(const void *x, const void *y) {
  long double a = *(const long double *)x, b = *(const long double *)y;
  return (a > b) - (a < b);
}

/* Changes of the inside predicate in (a, b]: nsamp uniform samples plus
 * every leaf's filter ends and plane, each change bisected. */
static int ref_crossings(const rtree *t, int root, const double o[3],
                         const double d[3], double a, double b, int nsamp,
                         long double *out, int *kind, int maxout) {
  static long double x[4096];
  int n = 0;
  for (int i = 0; i <= nsamp; i++) x[n++] = a + ((long double)b - a) * i / nsamp;
  for (int i = 0; i < t->n; i++) {
    const rnode *q = &t->nodes[i];
    if (q->op != R_LEAF) continue;
    long double len = sqrtl((long double)q->n[0] * q->n[0] +
                            (long double)q->n[1] * q->n[1] +
                            (long double)q->n[2] * q->n[2]);
    long double base = -(long double)q->d, nd = 0;
    for (int j = 0; j < 3; j++) {
      base += (long double)q->n[j] * o[j];
      nd += (long double)q->n[j] * d[j];
    }
    if (nd == 0) continue;
    long double br[3] = {(-q->r * len - base) / nd, (q->r * len - base) / nd,
                         -base / nd};
    for (int j = 0; j < 3 && n < 4096; j++)
      if (br[j] > a && br[j] < b) x[n++] = br[j];
  }
  qsort(x, (size_t)n, sizeof *x, cmp_ld);
  int nr = 0, prev = ref_f(t, root, o, d, x[0]) > 0;
  for (int i = 1; i < n && nr < maxout; i++) {
    if (!(x[i] > x[i - 1])) continue;
    int cur = ref_f(t, root, o, d, x[i]) > 0;
    if (cur != prev) {
      kind[nr] = cur ? LG_ENTER : LG_EXIT;
      out[nr++] = ref_bisect(t, root, o, d, x[i - 1], x[i]);
    }
    prev = cur;
  }
  return nr;
}

/* ==== 1. lg_first_bounded ============================================= */

static const char *first_problem;
static char first_buf[400];
static void note(const char *fmt, ...) {
  va_list ap;
  if (getenv("FASTPATHS_VERBOSE")) {
    va_start(ap, fmt);
    printf("#   ");
    vprintf(fmt, ap);
    printf("\n");
    va_end(ap);
  }
  if (first_problem) return;
  va_start(ap, fmt);
  vsnprintf(first_buf, sizeof first_buf, fmt, ap);
  va_end(ap);
  first_problem = first_buf;
}

/* A trace hook that looks at nothing: with one, every segment's whole
   multiroot length is computed (the search skips its second reach only
   when nothing traces it). */
static void nop_hook(void *ctx, const lg_trace_event *ev) {
  (void)ctx;
  (void)ev;
}

static void test_first(void) {
  rng_t g = {20240611};
  long hook_bad = 0;
  long rays = 0, hits = 0, same_bad = 0, ref_bad = 0, shadow_bad = 0,
       shadow_hits = 0, normals = 0, normal_bad = 0,
       nonfinite = 0, excused_pairs = 0, ref_missed = 0, skipped_sharp = 0,
       exits = 0, started_inside = 0;
  double max_err = 0, max_ratio = 0, max_nerr = 0, max_nratio = 0;
  first_problem = NULL;
  for (int sc = 0; sc < NTREES_FIRST; sc++) {
    double sh[3] = {0, 0, 0}, u = rng_unit(&g);
    if (u >= 0.5) {
      double dirn[3], mag = u < 0.75 ? 1e3 : 1e5;
      rand_unit(&g, dirn);
      for (int i = 0; i < 3; i++) sh[i] = dirn[i] * mag;
    }
    rtree t;
    int root = rand_tree(&t, &g, sh);
    int nleaves = tree_leaves(&t, root);
    dt_tape *tp = rt_tape(&t, root);
    csg_tape *ob = bnd_outer(tp, 0.5, NULL), *ib = bnd_inner(tp, 0.5, NULL);
    for (int k = 0; k < 14; k++) {
      double du[3], d[3], o[3], q[3];
      rand_unit(&g, du);
      if (rng_unit(&g) < 0.15) {  /* along an axis: parallel to planes */
        int ax = (int)(rng_u64(&g) % 3);
        du[0] = du[1] = du[2] = 0;
        du[ax] = rng_unit(&g) < 0.5 ? -1 : 1;
      }
      double len = lrand(&g, -2, 2);
      for (int i = 0; i < 3; i++) {
        q[i] = sh[i] + rng_range(&g, -1.3, 1.3);
        o[i] = q[i] - 3 * du[i];
        d[i] = du[i] * len;
      }
      double T = 6 / len, t0 = 0, t1 = T;
      if (rng_unit(&g) < 0.4) t0 = rng_range(&g, 0, 0.7) * T;
      if (rng_unit(&g) < 0.3) t1 = t0 + rng_range(&g, 0.05, 1) * (T - t0);
      /* the renderer's tolerance: 1e-9 in space, never below what
         doubles resolve at the origin's coordinates */
      double scale = fmax(1, fmax(fabs(o[0]), fmax(fabs(o[1]), fabs(o[2]))));
      double tol_s = fmax(1e-9, 4e-16 * scale), tol = tol_s / len;
      lg_root all[256], fr[256], shr[256];
      double grad[3] = {NAN, NAN, NAN};
      int na = lg_roots_bounded(tp, ob, ib, o, d, t0, t1, tol, all, 256, NULL,
                                NULL);
      {   /* (0) the same roots, bit for bit, with every lhs computed */
        lg_hook hk = {nop_hook, NULL};
        lg_root allh[256];
        int nh = lg_roots_bounded(tp, ob, ib, o, d, t0, t1, tol, allh, 256,
                                  NULL, &hk);
        int ok = nh == na;
        for (int i = 0; ok && i < na; i++)
          ok = memcmp(&allh[i].t, &all[i].t, sizeof(double)) == 0 &&
               allh[i].kind == all[i].kind;
        hook_bad += !ok;
      }
      int nf = lg_first_bounded(tp, ob, ib, o, d, t0, t1, tol, fr, 256, NULL,
                                0, grad);
      int ns = lg_first_bounded(tp, ob, ib, o, d, t0, t1, tol, shr, 256, NULL,
                                1, NULL);
      rays++;
      /* the first crossing of the all-roots search after t0 */
      int ka = 0;
      while (ka < na && (all[ka].kind == LG_TOUCH || !(all[ka].t > t0))) ka++;
      int has = ka < na;
      /* (a) identical to the all-roots search up to its stop */
      int same = has ? nf == ka + 1 : nf == na;
      for (int i = 0; same && i < nf; i++)
        same = memcmp(&fr[i].t, &all[i].t, sizeof(double)) == 0 &&
               fr[i].kind == all[i].kind;
      if (!same) {
        same_bad++;
        note("first: tree %d ray %d: lg_first_bounded gave %d roots, "
             "all-roots first crossing is #%d of %d", sc, k, nf, ka, na);
      }
      /* (b) shadow mode: a crossing in (t0, t1] exactly when there is one,
         reported at or after it and not beyond t1 */
      int ks = 0;
      while (ks < ns && (shr[ks].kind == LG_TOUCH || !(shr[ks].t > t0))) ks++;
      int shit = ks < ns;
      shadow_hits += shit;
      if (shit != has || (shit && !(shr[ks].t >= all[ka].t && shr[ks].t <= t1))) {
        shadow_bad++;
        note("shadow: tree %d ray %d: hit %d (t %.17g), all-roots %d (t %.17g)",
             sc, k, shit, shit ? shr[ks].t : NAN, has, has ? all[ka].t : NAN);
      }
      /* (c) against the long double reference */
      long double rc[256];
      int rk[256];
      int nr = ref_crossings(&t, root, o, d, t0, t1, 1500, rc, rk, 256);
      int kr = 0;
      while (kr < nr && !(rc[kr] > t0)) kr++;
      double got = has ? fr[nf - 1].t : NAN;
      if (has) {
        hits++;
        exits += fr[nf - 1].kind == LG_EXIT;
        if (!isfinite(got)) nonfinite++;
      }
      started_inside += ref_f(&t, root, o, d, t0) > 0;
      /* the allowance at a reference crossing x (stab.h's rule):
         |dt| |d| <= tol + 8 eps A / |df/ds|, A = leaves + S sum |V'| */
#define ALLOW(x, out) do {                                                 \
        long double p_[3];                                                 \
        ld_point(o, d, (x), p_);                                           \
        rg r_ = ref_grad(&t, root, p_, du, 0);                                \
        double S_ = fmax(scale, fabs((double)p_[0]));                      \
        S_ = fmax(S_, fmax(fabs((double)p_[1]), fabs((double)p_[2])));     \
        double A_ = nleaves + S_ * (double)r_.slopes;                      \
        (out) = (tol_s + 8 * EPS * A_ / fmax(fabsl(r_.dd), 1e-300)) / len; \
      } while (0)
      int ok = 1;
      if (kr < nr) {
        double allow;
        ALLOW(rc[kr], allow);
        double err = has ? fabs(got - (double)rc[kr]) : INFINITY;
        if (err > allow) {
          ok = 0;
          /* The reference may have stepped over a pair of crossings
             closer than its sampling: a crossing the code found earlier
             is real if the reference changes sign across it. */
          if (has && got < rc[kr]) {
            long double w = 4 * (long double)allow;
            int s0 = ref_f(&t, root, o, d, got - w) > 0;
            int s1 = ref_f(&t, root, o, d, got + w) > 0;
            if (s0 != s1 && (s1 ? LG_ENTER : LG_EXIT) == fr[nf - 1].kind) {
              ok = 1;
              ref_missed++;
            }
          }
          /* A pair of crossings closer than tol may be merged into a
             touch (lg.h's guarantee is for crossings more than tol from
             their neighbours). */
          if (!ok && kr + 1 < nr && rc[kr + 1] - rc[kr] <= 2 * tol + allow &&
              (!has || got > rc[kr + 1] - allow)) {
            ok = 1;
            excused_pairs++;
          }
        } else {
          if (has && fr[nf - 1].kind != rk[kr]) ok = 0;
          double e = err * len;
          if (e > max_err) max_err = e;
          if (err / allow > max_ratio) max_ratio = err / allow;
        }
        if (!ok)
          note("ref: tree %d ray %d: first crossing %.17g (kind %d), "
               "reference %.17Lg (kind %d), allowed %.3g", sc, k, got,
               has ? fr[nf - 1].kind : 9, rc[kr], rk[kr], allow);
      } else if (has) {
        /* none in the reference: the code's must be real */
        double allow;
        ALLOW(got, allow);
        long double w = 4 * (long double)allow;
        if ((ref_f(&t, root, o, d, got - w) > 0) ==
            (ref_f(&t, root, o, d, got + w) > 0)) {
          ok = 0;
          note("ref: tree %d ray %d: crossing at %.17g, none in the "
               "reference", sc, k, got);
        } else {
          ref_missed++;
        }
      }
      ref_bad += !ok;
      if (!ok && getenv("FASTPATHS_VERBOSE")) {
        printf("#     o = (%.17g, %.17g, %.17g) d = (%.17g, %.17g, %.17g) "
               "t0 %.17g t1 %.17g tol %.3g\n", o[0], o[1], o[2], d[0], d[1],
               d[2], t0, t1, tol);
        for (int i = 0; i < t.n; i++) {
          const rnode *x = &t.nodes[i];
          if (x->op == R_LEAF)
            printf("#     node %d leaf n (%.17g, %.17g, %.17g) d %.17g r %.17g\n",
                   i, x->n[0], x->n[1], x->n[2], x->d, x->r);
          else
            printf("#     node %d op %d (%d, %d)\n", i, x->op, x->a, x->b);
        }
        for (int i = 0; i < na; i++)
          printf("#     all-roots %.17g kind %d\n", all[i].t, all[i].kind);
        lg_root un[256];
        int nu = lg_roots(tp, o, d, t0, t1, tol, un, 256, NULL);
        for (int i = 0; i < nu; i++)
          printf("#     lg_roots %.17g kind %d\n", un[i].t, un[i].kind);
        for (int i = 0; i < nr; i++)
          printf("#     reference %.17Lg kind %d\n", rc[i], rk[i]);
        csg_span os[64];
        int no = csg_ray_spans(ob, o, d, t0, t1, os, 64, NULL, 0);
        for (int i = 0; i < no; i++)
          printf("#     outer span %.17g %.17g\n", os[i].t0, os[i].t1);
        no = csg_ray_spans(ib, o, d, t0, t1, os, 64, NULL, 0);
        for (int i = 0; i < no; i++)
          printf("#     inner span %.17g %.17g\n", os[i].t0, os[i].t1);
      }
      /* (d) the normal: -grad from the search against the reference's
         gradient at the same double point, within the propagated error
         bound eg (times 4) of a double evaluation there */
      if (has) {
        double p[3];
        long double pl[3];
        for (int i = 0; i < 3; i++) pl[i] = p[i] = o[i] + got * d[i];
        ref_sharp_w = 2 * tol_s;   /* the hit is within tol of the crossing */
        rg r = ref_grad(&t, root, pl, NULL, 0);
        ref_sharp_w = 0;
        int fin = isfinite(grad[0]) && isfinite(grad[1]) && isfinite(grad[2]);
        double gl = sqrt(grad[0] * grad[0] + grad[1] * grad[1] + grad[2] * grad[2]);
        long double rl = gnorm(r.g);
        if (!fin) {
          nonfinite++;
          normal_bad++;
          note("normal: tree %d ray %d: gradient (%g, %g, %g)", sc, k, grad[0],
               grad[1], grad[2]);
        } else if (r.near_sharp) {
          /* a crossing at a sharp leaf's plane: the density steps there,
             and the gradient of the rest (maybe 0) is not a normal */
          skipped_sharp++;
        } else if (!(gl > 0) || !(rl > 0)) {
          normal_bad++;
          note("normal: tree %d ray %d: gradient (%g, %g, %g), reference "
               "|g| %Lg", sc, k, grad[0], grad[1], grad[2], rl);
        } else {
          normals++;
          long double e = 0;
          for (int i = 0; i < 3; i++) {
            long double c = -grad[i] / gl - (-r.g[i] / rl);
            e += c * c;
          }
          e = sqrtl(e);
          long double allow = 8 * r.eg / rl + 4 * EPS;
          if (e > max_nerr) max_nerr = (double)e;
          if (e / allow > max_nratio) max_nratio = (double)(e / allow);
          if (e > allow) {
            normal_bad++;
            note("normal: tree %d ray %d: |n - n_ref| = %.3Lg > %.3Lg", sc, k,
                 e, allow);
          }
        }
      }
    }
    csg_tape_free(ob);
    csg_tape_free(ib);
    dt_tape_free(tp);
  }
  CHECK("lg_roots_bounded: the roots without a trace hook (the second reach "
        "skipped where the first decides) are those with one, bit for bit",
        hook_bad == 0);
  CHECK("lg_first_bounded: the roots up to the first crossing after t0 are "
        "lg_roots_bounded's, bit for bit", same_bad == 0);
  CHECK("lg_first_bounded: first crossing within tol + 8 eps A/|f'| of the "
        "long double reference's first sign change", ref_bad == 0);
  CHECK("lg_first_bounded shadow mode: a crossing in (t0, t1] exactly when "
        "there is one, reported in [crossing, t1]", shadow_bad == 0);
  CHECK("lg_first_bounded: normal within 8 x the propagated rounding bound "
        "of the reference gradient's direction", normal_bad == 0);
  CHECK("lg_first_bounded: crossings and gradients finite", nonfinite == 0);
  CHECK("lg_first_bounded: the random rays are not trivial (hits, exits, "
        "shadow hits, normals checked)",
        hits > rays / 4 && exits > 20 && shadow_hits > rays / 4 &&
            normals > hits / 2);
  if (first_problem) printf("#   first problem: %s\n", first_problem);
  printf("# summary | lg_first_bounded | %ld rays (%ld starting inside), %ld "
         "hits (%ld exits), %ld shadow hits | max err %.3g (space), %.3g of "
         "allowed | %ld reference-missed pairs, %ld merged pairs | normals %ld "
         "(%ld at sharp planes skipped): max err %.3g, %.3g of allowed |\n",
         rays, started_inside, hits, exits, shadow_hits, max_err, max_ratio,
         ref_missed, excused_pairs, normals, skipped_sharp, max_nerr,
         max_nratio);
}

/* A lone rounded halfspace: its outer and inner bounds are both its plane
 * (the 0.5 isosurface), so outer minus inner is empty up to rounding; the
 * crossing on it must still be found (it was lost, e.g. a rounded floor
 * y < 0 seen from (0.3, 2, 0.1) straight down had no crossing). */
static void test_shared_surface(void) {
  double n[3] = {0, 1, 0}, o[3] = {0.3, 2, 0.1}, d[3] = {0, -1, 0};
  dt_builder *b = dt_builder_new();
  dt_builder_leaf(b, n, 0, 0.1);
  int err;
  dt_tape *tp = dt_builder_finish(b, &err);
  csg_tape *ob = bnd_outer(tp, 0.5, NULL), *ib = bnd_inner(tp, 0.5, NULL);
  lg_root all[8], fr[8], shr[8];
  double grad[3];
  int na = lg_roots_bounded(tp, ob, ib, o, d, 0, 10, 1e-9, all, 8, NULL, NULL);
  int nf = lg_first_bounded(tp, ob, ib, o, d, 0, 10, 1e-9, fr, 8, NULL, 0, grad);
  int ns = lg_first_bounded(tp, ob, ib, o, d, 0, 10, 1e-9, shr, 8, NULL, 1, NULL);
  /* the plane y = 0 at t = 2; the gradient -3/(4r) (0, 1, 0) there */
  CHECK("rounded floor from above: lg_roots_bounded finds y = 0 at t = 2",
        na == 1 && all[0].kind == LG_ENTER && fabs(all[0].t - 2) <= 1e-9);
  CHECK("rounded floor from above: lg_first_bounded finds it, with the "
        "gradient (0, -7.5, 0)",
        nf == 1 && fabs(fr[0].t - 2) <= 1e-9 && fabs(grad[1] + 7.5) <= 1e-6 &&
            grad[0] == 0 && grad[2] == 0);
  CHECK("rounded floor from above: a shadow ray is blocked",
        ns == 1 && shr[0].kind == LG_ENTER && shr[0].t >= all[0].t && shr[0].t <= 10);
  csg_tape_free(ob);
  csg_tape_free(ib);
  dt_tape_free(tp);
}

/* ==== 2. dt_prune_rl / dt_density_rl =================================== */

static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

static int same_code(const dt_tape *a, const dt_tape *b) {
  if (a->ncode != b->ncode) return 0;
  for (int i = 0; i < a->ncode; i++)
    if (a->code[i].op != b->code[i].op ||
        (a->code[i].op == DT_LEAF && a->code[i].arg != b->code[i].arg) ||
        (a->code[i].op == DT_CONST && !same_bits(a->code[i].c, b->code[i].c)))
      return 0;
  return 1;
}

static void test_prune(void) {
  rng_t g = {77001};
  long segs = 0, pts = 0, rl_bad = 0, prune_bad = 0, range_bad = 0,
       full_bad = 0, ref_bad = 0, nested_bad = 0, exact = 0, nested_exact = 0,
       shrunk = 0, nested_pts = 0, nested_direct = 0;
  double max_v = 0, max_d = 0, max_ref = 0, max_nest = 0;
  first_problem = NULL;
  for (int sc = 0; sc < 120; sc++) {
    double sh[3] = {0, 0, 0}, u = rng_unit(&g);
    if (u >= 0.5) {
      double dirn[3], mag = u < 0.75 ? 1e3 : 1e5;
      rand_unit(&g, dirn);
      for (int i = 0; i < 3; i++) sh[i] = dirn[i] * mag;
    }
    rtree t;
    int root = rand_tree(&t, &g, sh);
    int nleaves = tree_leaves(&t, root);
    dt_tape *tp = rt_tape(&t, root);
    size_t nc = (size_t)tp->ncode;
    dt_instr *buf = malloc(4 * nc * sizeof *buf);
    dt_instr *b1 = buf, *b2 = buf + nc, *b3 = buf + 2 * nc, *b4 = buf + 3 * nc;
    dt_ray_leaf *rl = malloc((size_t)tp->nleaves * sizeof *rl);
    for (int k = 0; k < 12; k++) {
      double du[3], d[3], o[3];
      rand_unit(&g, du);
      if (rng_unit(&g) < 0.15) {
        int ax = (int)(rng_u64(&g) % 3);
        du[0] = du[1] = du[2] = 0;
        du[ax] = 1;
      }
      double len = lrand(&g, -2, 2);
      for (int i = 0; i < 3; i++) {
        o[i] = sh[i] + rng_range(&g, -1.3, 1.3) - 3 * du[i];
        d[i] = du[i] * len;
      }
      dt_ray_leaves(tp, o, d, rl);
      double T = 6 / len;
      double s0 = rng_range(&g, 0, T), s1 = s0 + T * lrand(&g, -6, 0);
      dt_tape v1, v2, v3, v4;
      dt_prune_rl(tp, rl, s0, s1, b1, &v1);
      dt_prune_ray(tp, o, d, s0, s1, b2, &v2);
      segs++;
      shrunk += v1.ncode < tp->ncode;
      /* promised: the _rl pruning is dt_prune_ray's, instruction for
         instruction; its range (the parent's) bounds the recomputed one */
      if (!same_code(&v1, &v2)) {
        prune_bad++;
        note("prune: tree %d ray %d: dt_prune_rl %d instructions, "
             "dt_prune_ray %d (or different code)", sc, k, v1.ncode, v2.ncode);
      }
      if (!(v1.lo <= v2.lo && v1.hi >= v2.hi)) range_bad++;
      /* a sub-segment pruned from the view (as the search does) */
      double c0 = rng_range(&g, s0, s1), c1 = rng_range(&g, c0, s1);
      dt_prune_rl(&v1, rl, c0, c1, b3, &v3);
      dt_prune_rl(tp, rl, c0, c1, b4, &v4);
      double oscale = fabs(o[0]) + fabs(o[1]) + fabs(o[2]);
      for (int j = 0; j < 10; j++) {
        double s = j == 0 ? s0 : j == 1 ? s1 : rng_range(&g, s0, s1);
        double dfull, dray, dview;
        double vfull = dt_density_rl(tp, rl, s, &dfull);
        double vray = dt_density_ray(tp, o, d, s, &dray);
        double vview = dt_density_rl(&v1, rl, s, &dview);
        pts++;
        /* dt_density_ray is now dt_ray_leaves + dt_density_rl: this guards
           that wrapper; the references below test the evaluator itself */
        if (!same_bits(vfull, vray) || !same_bits(dfull, dray)) {
          rl_bad++;
          note("density_rl: tree %d ray %d s %.17g: %.17g/%.17g vs "
               "%.17g/%.17g", sc, k, s, vfull, dfull, vray, dray);
        }
        /* pruned against full: folding is exact except 1 + x - x -> 1
           and leaves at their filter edge (value O(eps^2), slope up to
           4 eps |n.d|/r) -> constants; each fold's error is at most eps
           of the magnitude there, so the bound is ncode eps times the
           magnitude evaluation (|.| at every op) of value and slope */
        long double pl[3];
        ld_point(o, d, s, pl);
        double ss = fabs(s) * (fabs(d[0]) + fabs(d[1]) + fabs(d[2]));
        rg r = ref_grad(&t, root, pl, d, oscale + ss);
        long double bv = tp->ncode * EPS * r.mv, bd = tp->ncode * EPS * r.md;
        double p[3] = {o[0] + s * d[0], o[1] + s * d[1], o[2] + s * d[2]};
        double pv = dt_density(&v1, p), pf = dt_density(tp, p);
        exact += same_bits(vview, vfull) && same_bits(dview, dfull);
        if (fabs(vview - vfull) > bv || fabs(dview - dfull) > bd ||
            fabs(pv - pf) > bv) {
          full_bad++;
          note("pruned: tree %d ray %d s %.17g: view %.17g/%.17g full "
               "%.17g/%.17g (dt_density %.17g vs %.17g), bounds %.3Lg/%.3Lg",
               sc, k, s, vview, dview, vfull, dfull, pv, pf, bv, bd);
        }
        if (bv > 0 && fabs(vview - vfull) / bv > max_v) max_v = fabs(vview - vfull) / bv;
        if (bd > 0 && fabs(dview - dfull) / bd > max_d) max_d = fabs(dview - dfull) / bd;
        /* against the reference (stab.h's condition): 8 eps A */
        double S = fmax(1, fmax(oscale, fabs(p[0]) + fabs(p[1]) + fabs(p[2])));
        double A = nleaves + S * (double)r.slopes;
        double e = fabs(vview - (double)r.v);
        if (e / (8 * EPS * A) > max_ref) max_ref = e / (8 * EPS * A);
        if (e > 8 * EPS * A && !r.near_sharp) {
          ref_bad++;
          note("pruned vs reference: tree %d ray %d s %.17g: %.17g vs %.17Lg",
               sc, k, s, vview, r.v);
        }
        if (s >= c0 && s <= c1) {
          double dn, dd4;
          double vn = dt_density_rl(&v3, rl, s, &dn);
          double v4v = dt_density_rl(&v4, rl, s, &dd4);
          nested_pts++;
          nested_direct++;
          nested_exact += same_bits(vn, v4v) && same_bits(dn, dd4);
          if (fabs(vn - vfull) > bv || fabs(dn - dfull) > bd) {
            nested_bad++;
            note("nested view: tree %d ray %d s %.17g: %.17g vs %.17g", sc, k,
                 s, vn, vfull);
          }
          if (bv > 0 && fabs(vn - vfull) / bv > max_nest) max_nest = fabs(vn - vfull) / bv;
        }
      }
      /* points of the sub-segment, for the nested views */
      for (int j = 0; j < 4; j++) {
        double s = j == 0 ? c0 : j == 1 ? c1 : rng_range(&g, c0, c1), dn, df;
        double vn = dt_density_rl(&v3, rl, s, &dn);
        double vf = dt_density_rl(tp, rl, s, &df);
        long double pl[3];
        ld_point(o, d, s, pl);
        double ss = fabs(s) * (fabs(d[0]) + fabs(d[1]) + fabs(d[2]));
        rg r = ref_grad(&t, root, pl, d, oscale + ss);
        long double bv = tp->ncode * EPS * r.mv, bd = tp->ncode * EPS * r.md;
        nested_pts++;
        if (fabs(vn - vf) > bv || fabs(dn - df) > bd) {
          nested_bad++;
          note("nested view: tree %d ray %d s %.17g: %.17g/%.17g vs "
               "%.17g/%.17g", sc, k, s, vn, dn, vf, df);
        }
        if (bv > 0 && fabs(vn - vf) / bv > max_nest) max_nest = fabs(vn - vf) / bv;
      }
    }
    free(rl);
    free(buf);
    dt_tape_free(tp);
  }
  CHECK("dt_density_rl equals dt_density_ray to the last bit (value and "
        "slope)", rl_bad == 0);
  CHECK("dt_prune_rl makes dt_prune_ray's view, instruction for instruction",
        prune_bad == 0);
  CHECK("dt_prune_rl's kept range bounds the view's", range_bad == 0);
  CHECK("pruned view = full tape within ncode eps x magnitude (value, slope, "
        "dt_density at the point)", full_bad == 0);
  CHECK("a view pruned from a view = the full tape within the same bound",
        nested_bad == 0);
  CHECK("pruned view = long double reference within 8 eps A", ref_bad == 0);
  CHECK("pruning shortens most views", shrunk > segs / 2);
  if (first_problem) printf("#   first problem: %s\n", first_problem);
  printf("# summary | prune | %ld segments (%ld shortened), %ld points | "
         "bit-identical to the full tape at %ld; nested views at %ld points, "
         "bit-identical to direct views at %ld of %ld | max |view - full| / bound: value %.3g, slope "
         "%.3g, nested %.3g | max |view - ref| / (8 eps A) %.3g |\n",
         segs, shrunk, pts, exact, nested_pts, nested_exact, nested_direct,
         max_v, max_d,
         max_nest, max_ref);
}

/* ==== 3. CSG spans: convex groups against long double clipping ========= */

enum { CN_PLANE, CN_EMPTY, CN_ALL, CN_UNION, CN_INTER, CN_DIFF };
typedef struct {
  int op, a, b, pid;
  double n[3], d;       /* raw plane n.x < d */
} cnode;
typedef struct {
  cnode nd[600];
  int n, nplanes;
  int pnode[600];       /* plane id -> node */
} ctree;

static int cn_add(ctree *t, int op, int a, int b) {
  cnode *x = &t->nd[t->n];
  memset(x, 0, sizeof *x);
  x->op = op;
  x->a = a;
  x->b = b;
  x->pid = -1;
  return t->n++;
}

static int cn_plane(ctree *t, rng_t *g, const double c[3], int axis) {
  int k = cn_add(t, CN_PLANE, -1, -1);
  cnode *x = &t->nd[k];
  double u[3];
  if (axis) {
    u[0] = u[1] = u[2] = 0;
    u[rng_u64(g) % 3] = rng_unit(g) < 0.5 ? -1 : 1;
  } else {
    rand_unit(g, u);
  }
  double sc = rng_range(g, 0.5, 3), off = rng_range(g, -0.2, 1);
  for (int i = 0; i < 3; i++) x->n[i] = sc * u[i];
  x->d = sc * (u[0] * c[0] + u[1] * c[1] + u[2] * c[2] + off);
  return k;
}

/* An intersection of 2 to 8 planes around c, in a random tree shape. */
static int cn_convex(ctree *t, rng_t *g, const double c[3], int axis) {
  int np = 2 + (int)(rng_u64(g) % 7), items[8];
  for (int i = 0; i < np; i++) items[i] = cn_plane(t, g, c, axis);
  while (np > 1) {
    int i = (int)(rng_u64(g) % (unsigned)(np - 1));
    items[i] = cn_add(t, CN_INTER, items[i], items[i + 1]);
    memmove(&items[i + 1], &items[i + 2], sizeof(int) * (size_t)(np - i - 2));
    np--;
  }
  return items[0];
}

static int cn_random(ctree *t, rng_t *g, const double sh[3], int depth,
                     int axis) {
  double u = rng_unit(g);
  if (depth == 0 || u < 0.25) {
    double c[3];
    for (int i = 0; i < 3; i++) c[i] = sh[i] + rng_range(g, -0.8, 0.8);
    double v = rng_unit(g);
    if (v < 0.7) return cn_convex(t, g, c, axis);
    if (v < 0.95) return cn_plane(t, g, c, axis);
    return cn_add(t, v < 0.975 ? CN_EMPTY : CN_ALL, -1, -1);
  }
  static const int ops[] = {CN_UNION, CN_INTER, CN_DIFF};
  int op = ops[rng_u64(g) % 3];
  int a = cn_random(t, g, sh, depth - 1, axis);
  int b = cn_random(t, g, sh, depth - 1, axis);
  return cn_add(t, op, a, b);
}

/* Postfix into a builder; planes get their ids in emission order. */
static void cn_emit(ctree *t, int i, csg_builder *b) {
  cnode *x = &t->nd[i];
  switch (x->op) {
  case CN_PLANE:
    x->pid = t->nplanes;
    t->pnode[t->nplanes++] = i;
    csg_builder_plane(b, x->n, x->d);
    return;
  case CN_EMPTY: csg_builder_const(b, CSG_EMPTY); return;
  case CN_ALL: csg_builder_const(b, CSG_ALL); return;
  }
  cn_emit(t, x->a, b);
  cn_emit(t, x->b, b);
  csg_builder_op(b, x->op == CN_UNION ? CSG_UNION
                    : x->op == CN_INTER ? CSG_INTER : CSG_DIFF);
}

static int cn_inside(const ctree *t, int i, const unsigned char *in) {
  const cnode *x = &t->nd[i];
  switch (x->op) {
  case CN_PLANE: return in[x->pid];
  case CN_EMPTY: return 0;
  case CN_ALL: return 1;
  case CN_UNION: return cn_inside(t, x->a, in) || cn_inside(t, x->b, in);
  case CN_INTER: return cn_inside(t, x->a, in) && cn_inside(t, x->b, in);
  default: return cn_inside(t, x->a, in) && !cn_inside(t, x->b, in);
  }
}

typedef struct { long double t0, t1; int id0, id1; } lspan;

/* The reference: each plane's crossing in long double (raw normals), the
 * sorted crossings cut [s0, s1] into elementary intervals, each is
 * classified at its midpoint (plane by plane: n.o - d + m n.d < 0, a
 * parallel plane by its origin) and the tree combines the answers. */
static int cn_ref_spans(const ctree *t, int root, const double o[3],
                        const double d[3], double s0, double s1,
                        long double *cross, lspan *out) {
  int np = t->nplanes;
  long double base[600], k[600], br[601];
  int bid[601], nb = 0;
  for (int p = 0; p < np; p++) {
    const cnode *x = &t->nd[t->pnode[p]];
    base[p] = -(long double)x->d;
    k[p] = 0;
    for (int i = 0; i < 3; i++) {
      base[p] += (long double)x->n[i] * o[i];
      k[p] += (long double)x->n[i] * d[i];
    }
    cross[p] = k[p] != 0 ? -base[p] / k[p] : NAN;
    if (k[p] != 0 && cross[p] > s0 && cross[p] < s1) {
      br[nb] = cross[p];
      bid[nb++] = p;
    }
  }
  for (int i = 1; i < nb; i++) {  /* insertion sort with the ids */
    long double v = br[i];
    int id = bid[i], j = i - 1;
    while (j >= 0 && br[j] > v) { br[j + 1] = br[j]; bid[j + 1] = bid[j]; j--; }
    br[j + 1] = v;
    bid[j + 1] = id;
  }
  int n = 0;
  unsigned char in[600];
  for (int e = 0; e <= nb; e++) {
    long double a = e ? br[e - 1] : s0, b = e < nb ? br[e] : s1, m;
    if (!(a < b)) continue;
    if (isinf(a) && isinf(b)) m = 0;
    else if (isinf(a)) m = b - 1 - fabsl(b);
    else if (isinf(b)) m = a + 1 + fabsl(a);
    else m = 0.5L * (a + b);
    for (int p = 0; p < np; p++) in[p] = k[p] == 0 ? base[p] < 0 : base[p] + m * k[p] < 0;
    if (!cn_inside(t, root, in)) continue;
    int id0 = e ? bid[e - 1] : -1, id1 = e < nb ? bid[e] : -1;
    if (n > 0 && out[n - 1].t1 == a) {
      out[n - 1].t1 = b;
      out[n - 1].id1 = id1;
    } else {
      out[n].t0 = a;
      out[n].t1 = b;
      out[n].id0 = id0;
      out[n].id1 = id1;
      n++;
    }
  }
  return n;
}

/* Spans shorter than w dropped, gaps shorter than w closed. */
static int squash(lspan *s, int n, long double w) {
  int m = 0;
  for (int i = 0; i < n; i++) {
    if (s[i].t1 - s[i].t0 <= w) continue;
    if (m > 0 && s[i].t0 - s[m - 1].t1 <= w) {
      s[m - 1].t1 = s[i].t1;
      s[m - 1].id1 = s[i].id1;
    } else {
      s[m++] = s[i];
    }
  }
  return m;
}

static void test_csg(void) {
  rng_t g = {31337};
  long two_convex = 0;   /* the two-convex fast path */
  long rays = 0, spans = 0, ends = 0, bad = 0, flip_bad = 0, one_convex = 0,
       parallel = 0, squashed = 0, id_ties = 0;
  double max_err = 0, max_ratio = 0;
  static ctree t;
  first_problem = NULL;
  for (int sc = 0; sc < 400; sc++) {
    double sh[3] = {0, 0, 0};
    if (sc % 4 == 3) {
      double u[3];
      rand_unit(&g, u);
      for (int i = 0; i < 3; i++) sh[i] = 1e4 * u[i];
    }
    int axis = sc % 5 == 0;
    t.n = t.nplanes = 0;
    int root = sc % 6 == 1 ? cn_convex(&t, &g, sh, axis)
                           : cn_random(&t, &g, sh, 1 + (int)(rng_u64(&g) % 4), axis);
    csg_builder *b = csg_builder_new();
    cn_emit(&t, root, b);
    int err;
    csg_tape *tp = csg_builder_finish(b, &err);
    if (!tp) { bad++; note("csg tape %d: %s", sc, csg_strerror(err)); continue; }
    one_convex += tp->nrcode == 1 && tp->rcode[0].op == CSG_CONVEX;
    two_convex += tp->nrcode == 3 && tp->rcode[0].op == CSG_CONVEX &&
                  tp->rcode[1].op == CSG_CONVEX;
    int nsc = csg_scratch_spans(tp);
    csg_span *scratch = malloc(sizeof *scratch * (size_t)nsc);
    csg_span out[700];
    long double cross[600];
    lspan ref[700], got[700];
    for (int k = 0; k < 25; k++) {
      double du[3], o[3], d[3];
      rand_unit(&g, du);
      if (axis || rng_unit(&g) < 0.1) {
        du[0] = du[1] = du[2] = 0;
        du[rng_u64(&g) % 3] = rng_unit(&g) < 0.5 ? -1 : 1;
      }
      double len = lrand(&g, -3, 3);
      for (int i = 0; i < 3; i++) {
        o[i] = sh[i] + rng_range(&g, -1.5, 1.5) - 3 * du[i];
        d[i] = du[i] * len;
      }
      double s0 = 0, s1 = 6 / len;
      double v = rng_unit(&g);
      if (v < 0.15) s0 = -INFINITY;
      else if (v < 0.4) s0 = rng_range(&g, 0, 4) / len;
      if (rng_unit(&g) < 0.2) s1 = INFINITY;
      if (!(s0 < s1)) s1 = s0 + 1 / len;
      int n = csg_ray_spans(tp, o, d, s0, s1, out, 700, scratch, nsc);
      int nr = cn_ref_spans(&t, root, o, d, s0, s1, cross, ref);
      rays++;
      /* the allowance of a crossing: the double evaluation of
         -(n.o - d)/(n.d) with n normalised, 16 eps of the terms over
         |n.d| */
      long double W = 0, al[600];
      for (int p = 0; p < t.nplanes; p++) {
        const cnode *x = &t.nd[t.pnode[p]];
        long double ln = sqrtl((long double)x->n[0] * x->n[0] +
                               (long double)x->n[1] * x->n[1] +
                               (long double)x->n[2] * x->n[2]);
        long double no = 0, ndd = 0, kd = 0;
        for (int i = 0; i < 3; i++) {
          no += fabsl(x->n[i] / ln * o[i]);
          ndd += fabsl(x->n[i] / ln * d[i]);
          kd += x->n[i] / ln * d[i];
        }
        if (kd == 0) { al[p] = 0; parallel++; continue; }
        al[p] = 16 * EPS * (no + fabsl(x->d / ln) + fabsl(cross[p]) * ndd) / fabsl(kd);
        if (cross[p] >= s0 && cross[p] <= s1 && al[p] > W) W = al[p];
      }
      if (n < 0) {
        bad++;
        note("csg tree %d ray %d: csg_ray_spans failed", sc, k);
        continue;
      }
      int ok = 1;
      for (int i = 0; i < n; i++) {
        got[i].t0 = out[i].t0;
        got[i].t1 = out[i].t1;
        got[i].id0 = out[i].id0;
        got[i].id1 = out[i].id1;
        if (!(out[i].t0 < out[i].t1) || (i && !(out[i].t0 > out[i - 1].t1))) ok = 0;
        /* the solid's outward normal at an end faces the ray at its
           start and away at its end (an independent check of flip) */
        for (int e = 0; e < 2; e++) {
          int id = e ? out[i].id1 : out[i].id0;
          if (id < 0) continue;
          const csg_plane *pl = &tp->planes[id];
          double sgn = (e ? out[i].flip1 : out[i].flip0) ? -1 : 1;
          double nd = sgn * (pl->n[0] * d[0] + pl->n[1] * d[1] + pl->n[2] * d[2]);
          if (e ? !(nd > 0) : !(nd < 0)) {
            flip_bad++;
            note("csg tree %d ray %d: span %d end %d: outward normal . d = %g",
                 sc, k, i, e, nd);
          }
        }
      }
      int ng = squash(got, n, W), nr2 = squash(ref, nr, W);
      squashed += (ng != n) + (nr2 != nr);
      if (ng != nr2) ok = 0;
      for (int i = 0; ok && i < ng; i++)
        for (int e = 0; e < 2; e++) {
          long double tg = e ? got[i].t1 : got[i].t0, tr = e ? ref[i].t1 : ref[i].t0;
          int idg = e ? got[i].id1 : got[i].id0, idr = e ? ref[i].id1 : ref[i].id0;
          ends++;
          if (isinf(tr) || isinf(tg)) {
            if (tg != tr || idg != -1) ok = 0;
            continue;
          }
          long double allow = idr >= 0 ? al[idr] : W, dt = fabsl(tg - tr);
          if (allow < W && idr >= 0) {
            /* another plane crossing within W: the id may be either */
            for (int p = 0; p < t.nplanes; p++)
              if (p != idr && fabsl(cross[p] - tr) <= W) allow = W;
          }
          if (dt > allow) { ok = 0; continue; }
          if (allow > 0 && dt / allow > max_ratio) max_ratio = (double)(dt / allow);
          if (dt * len > max_err) max_err = (double)(dt * len);
          if (idg != idr) {
            /* a tie: the code's plane (or the range end) crosses within
               the allowance of the reference's */
            int tie = idg >= 0 ? fabsl(cross[idg] - tr) <= W
                               : (fabsl(tg - s0) <= W || fabsl(tg - s1) <= W);
            if (!tie) ok = 0;
            else id_ties++;
          }
        }
      spans += ng;
      if (!ok) {
        bad++;
        note("csg tree %d ray %d: %d spans vs reference %d (after squashing "
             "below %.3Lg: %d vs %d)", sc, k, n, nr, W, ng, nr2);
      }
    }
    free(scratch);
    csg_tape_free(tp);
  }
  CHECK("csg_ray_spans = long double clipping (ends within 16 eps of their "
        "terms over |n.d|, plane ids, count)", bad == 0);
  CHECK("csg_ray_spans: flip makes the outward normal face the ray at span "
        "starts and away at span ends", flip_bad == 0);
  CHECK("csg: the random tapes include one-convex tapes, parallel planes and "
        "non-empty spans", one_convex > 30 && parallel > 100 && spans > rays / 3);
  if (getenv("QCS_TEST_VERBOSE"))
    printf("# csg: %ld tapes of two convex groups and one operation\n",
           two_convex);
  CHECK("csg: the random tapes include two convex groups under one operation "
        "(csg_ray_spans' second fast path)", two_convex > 10);
  if (first_problem) printf("#   first problem: %s\n", first_problem);
  printf("# summary | csg spans | %ld rays over 400 tapes (%ld one convex "
         "group) | %ld spans, %ld ends, %ld id ties, %ld lists squashed | max "
         "err %.3g (space), %.3g of allowed |\n", rays, one_convex, spans, ends,
         id_ties, squashed, max_err, max_ratio);
}

/* ==== 4. the render path ============================================== */

static const char *fig12_defs =
    "r    = 0.07;\n"
    "box1 = Shift (0.25, 0.8, 0.25) (Scale (0.5, 0.5, 0.5) UnitCube);\n"
    "box2 = Shift (0.25, 0.8, 0.25) (Scale (0.5, 1.0, 0.5) UnitCube);\n"
    "box3 = Shift (0.25, 1.0, 0.25) (Scale (0.5, 0.5, 0.5) UnitCube);\n"
    "obj1 = SetDifference UnitCube box1;\n"
    "obj2 = SetDifference (Rounded r UnitCube) box1;\n"
    "obj3 = SetDifference UnitCube (Rounded r box2);\n"
    "obj4 = Rounded r (Difference UnitCube box1);\n"
    "obj5 = Union (Rounded r UnitCube) (Rounded r box3);\n"
    "obj6 = Rounded r (Sum UnitCube box3);\n"
    "floor = Halfspace ((0, 1, 0), 0);\n"
    "fastpaths_scene = foldr1 Union\n"
    "  [ Shift (0,    0, -1.75) obj1, Shift (1.75, 0, -1.75) obj2\n"
    "  , Shift (3.5,  0, -1.75) obj3, Shift (0,    0, 0) obj4\n"
    "  , Shift (1.75, 0, 0) obj5,     Shift (3.5,  0, 0) obj6\n"
    "  , floor ];\n";

/* The pinhole camera of render.h re-derived in long double (as
 * test_render.c's floor_radiance does): forward f, right f x up, up
 * right x f, the pixel centre (x + 1/2, y + 1/2) at
 * u = (2 px/w - 1) tan(fov/2) w/h, v = (1 - 2 py/h) tan(fov/2). */
static void pixel_ray(const double eye[3], const double at[3], double fov,
                      int w, int h, int x, int y, double d[3]) {
  long double f[3], r[3], u[3], up[3] = {0, 1, 0}, fl = 0;
  for (int i = 0; i < 3; i++) f[i] = (long double)at[i] - eye[i], fl += f[i] * f[i];
  fl = sqrtl(fl);
  for (int i = 0; i < 3; i++) f[i] /= fl;
  r[0] = f[1] * up[2] - f[2] * up[1];
  r[1] = f[2] * up[0] - f[0] * up[2];
  r[2] = f[0] * up[1] - f[1] * up[0];
  long double rl = sqrtl(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  for (int i = 0; i < 3; i++) r[i] /= rl;
  u[0] = r[1] * f[2] - r[2] * f[1];
  u[1] = r[2] * f[0] - r[0] * f[2];
  u[2] = r[0] * f[1] - r[1] * f[0];
  long double th = tanl(fov * 3.14159265358979323846264338327950288L / 360);
  long double pu = (2 * (x + 0.5L) / w - 1) * th * w / h;
  long double pv = (1 - 2 * (y + 0.5L) / h) * th;
  long double dd[3], dl = 0;
  for (int i = 0; i < 3; i++) dd[i] = f[i] + pu * r[i] + pv * u[i], dl += dd[i] * dd[i];
  dl = sqrtl(dl);
  for (int i = 0; i < 3; i++) d[i] = (double)(dd[i] / dl);
}

static void test_render(void) {
  if (interp_run_string(stab_I, "<fastpaths>", fig12_defs, MODE_SCRIPT) != RUN_OK) {
    CHECK("render: figure12's objects compile", 0);
    return;
  }
  Scene *s = stab_compile("fastpaths_scene");
  if (!s) {
    printf("FAIL fastpaths: render scene: %s\n", stab_error);
    check_failed_count++;
    return;
  }
  RenderSettings rs;
  render_defaults(&rs);
  rs.width = 72;
  rs.height = 46;
  rs.threads = 2;
  rs.progress = NULL;
  rs.camera_set = 1;
  double eye[3] = {2.25, 3.2, 5.0}, at[3] = {2.25, 0.5, -0.4};
  memcpy(rs.eye, eye, sizeof eye);
  memcpy(rs.at, at, sizeof at);
  rs.up[0] = 0; rs.up[1] = 1; rs.up[2] = 0;
  rs.fov = 35;
  rs.aovs = IMG_Z | IMG_N;
  RenderReport rep;
  char err[300];
  Image *im = render_scene(s, &rs, &rep, NULL, err, sizeof err);
  if (!im) {
    printf("FAIL fastpaths: render: %s\n", err);
    check_failed_count++;
    scene_free(s);
    return;
  }
  RayCtx *c = ray_ctx_new(s, rs.tol);
  long pixels = 0, hits = 0, rounded = 0, z_bad = 0, n_bad = 0, hit_bad = 0,
       pio_bad = 0, thin = 0;
  double max_zerr = 0, max_zratio = 0, max_nerr = 0;
  first_problem = NULL;
  for (int y = 0; y < rs.height; y++)
    for (int x = 0; x < rs.width; x++) {
      double d[3];
      pixel_ray(eye, at, rs.fov, rs.width, rs.height, x, y, d);
      size_t k = img_index(im, x, y);
      double Z = im->z[k];
      pixels++;
      ray_reset(c);
      csg_span *sp;
      int ns = ray_spans(s, s->root, eye, d, 0, INFINITY, c, &sp);
      double tr = INFINITY;
      int id = -1, flip = 0;
      for (int i = 0; i < ns && id < 0; i++) {
        if (sp[i].id0 >= 0 && sp[i].t0 > 0) {
          tr = sp[i].t0, id = sp[i].id0, flip = sp[i].flip0;
        } else if (sp[i].id1 >= 0 && sp[i].t1 > 0) {
          tr = sp[i].t1, id = sp[i].id1, flip = sp[i].flip1;
        }
      }
      if (isinf(Z) != (id < 0)) {
        hit_bad++;
        note("render pixel (%d, %d): Z %g, ray_spans first root %g", x, y, Z, tr);
        continue;
      }
      double Lw = isinf(Z) ? 60 : Z;
      if (id >= 0) {
        hits++;
        rounded += s->nodes[id].kind == SC_ROUNDED;
        double p[3], nr[3];
        for (int i = 0; i < 3; i++) p[i] = eye[i] + tr * d[i];
        ray_normal(s, id, flip, p, nr);
        if (nr[0] * d[0] + nr[1] * d[1] + nr[2] * d[2] > 0)
          for (int i = 0; i < 3; i++) nr[i] = -nr[i];
        double cosv = fabs(nr[0] * d[0] + nr[1] * d[1] + nr[2] * d[2]);
        /* Z: float storage (half an ulp, 2^-24 Z), both searches within
           tol of the crossing (2 tol), and the renderer's double camera
           ray differs from this one by ~1e-15 in direction, which moves
           the crossing along the ray by up to 1e-15 t / cos */
        double zallow = 0x1p-24 * tr + 2 * rs.tol + 1e-15 * tr / fmax(cosv, 1e-6);
        double ze = fabs(Z - tr);
        if (ze > max_zerr) max_zerr = ze;
        if (ze / zallow > max_zratio) max_zratio = ze / zallow;
        if (ze > zallow) {
          z_bad++;
          note("render pixel (%d, %d): Z %.9g, first root %.17g (allowed "
               "%.3g)", x, y, Z, tr, zallow);
        }
        /* N: float storage (2^-24 per component) plus the normal's turn
           over the hit points' distance (the crossing error above) at the
           rounded surfaces' curvature, at most 2/r = 29 for r = 0.07 */
        double nallow = 2 * 0x1p-24 + 29 * (2 * rs.tol + 1e-15 * tr / fmax(cosv, 1e-6));
        double ne = 0;
        for (int i = 0; i < 3; i++) ne = fmax(ne, fabs(im->n[3 * k + i] - nr[i]));
        if (ne > max_nerr) max_nerr = ne;
        if (!(ne <= nallow)) {
          n_bad++;
          note("render pixel (%d, %d): N (%.9g, %.9g, %.9g), ray_normal at "
               "the first root (%.9g, %.9g, %.9g)", x, y, im->n[3 * k],
               im->n[3 * k + 1], im->n[3 * k + 2], nr[0], nr[1], nr[2]);
        }
        /* PointInObject: outside just before Z, inside just after it
           (unless the first span is thinner than that) */
        double e = 4 * 0x1p-24 * Z + 1e-8;
        double pm[3], pp[3];
        for (int i = 0; i < 3; i++) {
          pm[i] = eye[i] + (Z - e) * d[i];
          pp[i] = eye[i] + (Z + e) * d[i];
        }
        int span_len_ok = 0;
        for (int i = 0; i < ns; i++)
          if (sp[i].t0 <= tr + e && sp[i].t1 >= tr + 2 * e) span_len_ok = 1;
        if (!span_len_ok) thin++;
        if (scene_inside(s, s->root, pm) || (span_len_ok && !scene_inside(s, s->root, pp))) {
          pio_bad++;
          note("render pixel (%d, %d): PointInObject at Z -/+ %.3g: %d, %d", x,
               y, e, scene_inside(s, s->root, pm), scene_inside(s, s->root, pp));
        }
        Lw = Z - e;
      }
      /* nothing inside before the hit (or along 60 units for a miss):
         256 samples of PointInObject */
      for (int j = 1; j <= 256; j++) {
        double tt = Lw * j / 257, q[3];
        for (int i = 0; i < 3; i++) q[i] = eye[i] + tt * d[i];
        if (scene_inside(s, s->root, q)) {
          pio_bad++;
          note("render pixel (%d, %d): inside at t = %.17g, before Z = %g", x,
               y, tt, Z);
          break;
        }
      }
    }
  CHECK("render: a pixel has a Z exactly when its ray has a crossing",
        hit_bad == 0);
  CHECK("render: Z = the first root of ray_spans within float rounding + "
        "2 tol", z_bad == 0);
  CHECK("render: N = ray_normal at that root, facing the eye, within float "
        "rounding", n_bad == 0);
  CHECK("render: PointInObject outside before Z and inside just after it",
        pio_bad == 0);
  CHECK("render: the image has rounded hits", rounded > pixels / 10);
  if (first_problem) printf("#   first problem: %s\n", first_problem);
  printf("# summary | render figure12 %dx%d | %ld pixels, %ld hits (%ld "
         "rounded, %ld thin first spans) | max |Z - root| %.3g (%.3g of "
         "allowed), max |N - normal| %.3g |\n", rs.width, rs.height, pixels,
         hits, rounded, thin, max_zerr, max_zratio, max_nerr);
  ray_ctx_free(c);
  img_free(im);
  scene_free(s);
}

/* ==== shared dot products (csg_ray_dots) ============================== */

/* A normal from a small pool: an axis or its negation, written with zeros
   of either sign, or one of a few fixed oblique directions. */
static void pool_normal(rng_t *g, double n[3]) {
  static const double ob[3][3] = {{0.6, 0.8, 0}, {1, 1, 1}, {-0.3, 0.2, 0.9}};
  int k = (int)(rng_u64(g) % 9);
  double sg = rng_unit(g) < 0.5 ? -1 : 1;
  if (k < 6) {
    for (int i = 0; i < 3; i++) n[i] = rng_unit(g) < 0.5 ? -0.0 : 0.0;
    n[k % 3] = sg;
  } else {
    for (int i = 0; i < 3; i++) n[i] = sg * ob[k - 6][i];
  }
}

/* A random tree over planes of pool normals: two or three convex groups
   (intersections of 3 to 6 planes, or of 9 to 30 as a chamfered bound
   has: convex_span takes those 8 planes at a time) joined by random
   operations. */
static csg_tape *pool_tape(rng_t *g) {
  csg_builder *b = csg_builder_new();
  int ng = 2 + (int)(rng_u64(g) % 2);
  for (int k = 0; k < ng; k++) {
    int np = 3 + (int)(rng_u64(g) % 4);
    if (rng_u64(g) % 4 == 0) np = 9 + (int)(rng_u64(g) % 22);
    for (int j = 0; j < np; j++) {
      double n[3];
      pool_normal(g, n);
      double d = rng_unit(g) < 0.4 ? 0 : (double)(int)rng_range(g, -3, 4) / 2;
      csg_builder_plane(b, n, d);
      if (j > 0) csg_builder_op(b, CSG_INTER);
    }
    if (k > 0) {
      static const csg_op ops[3] = {CSG_UNION, CSG_INTER, CSG_DIFF};
      csg_builder_op(b, ops[rng_u64(g) % 3]);
    }
  }
  int err;
  return csg_builder_finish(b, &err);
}

/* Spans equal bit for bit (t as stored: the sign of a zero counts). */
static int spans_same(const csg_span *a, const csg_span *b, int n) {
  for (int i = 0; i < n; i++)
    if (memcmp(&a[i].t0, &b[i].t0, sizeof a[i].t0) ||
        memcmp(&a[i].t1, &b[i].t1, sizeof a[i].t1) || a[i].id0 != b[i].id0 ||
        a[i].id1 != b[i].id1 || a[i].flip0 != b[i].flip0 ||
        a[i].flip1 != b[i].flip1)
      return 0;
  return 1;
}

static void test_csg_dots(void) {
  rng_t g = {4242};
  int bad = 0, linked = 0, shared = 0, zeros = 0, pairs = 0;
  long rays = 0;
  for (int sc = 0; sc < 200; sc++) {
    csg_tape *a = pool_tape(&g), *b = pool_tape(&g);
    if (!a || !b || csg_tape_share_dirs(b, a) != CSG_OK) {
      bad++;
      note("dots tapes %d: not built", sc);
      csg_tape_free(a);
      csg_tape_free(b);
      continue;
    }
    pairs++;
    linked += b->dirs_of == a;
    shared += b->ndirs < a->gstart[a->ngroups] + b->gstart[b->ngroups];
    double dots[4 * CSG_DIRS_MAX];
    for (int k = 0; k < 200 && b->dirs_of == a; k++) {
      double o[3], d[3];
      for (int i = 0; i < 3; i++) {
        double u = rng_unit(&g);
        o[i] = u < 0.2 ? 0.0 : u < 0.3 ? -0.0 : u < 0.5
             ? (double)(int)rng_range(&g, -3, 4) / 2 : rng_range(&g, -3, 3);
        u = rng_unit(&g);
        d[i] = u < 0.3 ? (u < 0.15 ? 0.0 : -0.0) : rng_range(&g, -1, 1);
      }
      if (d[0] == 0 && d[1] == 0 && d[2] == 0) d[rng_u64(&g) % 3] = 1;
      double s0 = rng_unit(&g) < 0.5 ? -INFINITY : rng_range(&g, -2, 0);
      double s1 = rng_unit(&g) < 0.5 ? INFINITY : rng_range(&g, 0, 4);
      csg_ray_dots(b, o, d, dots);
      for (int u = 0; u < b->ndirs; u++) zeros += dots[4 * u] == 0;
      for (int w = 0; w < 2; w++) {
        const csg_tape *t = w ? b : a;
        csg_span x[64], y[64];
        int nx = csg_ray_spans(t, o, d, s0, s1, x, 64, NULL, 0);
        int ny = csg_ray_spans_dots(t, dots, o, d, s0, s1, y, 64, NULL, 0);
        rays++;
        if (nx != ny || (nx > 0 && !spans_same(x, y, nx))) {
          if (!bad || getenv("FASTPATHS_VERBOSE"))
            note("dots tapes %d ray %d tape %d: %d spans, %d with shared "
                 "dots", sc, k, w, nx, ny);
          bad++;
        }
      }
    }
    csg_tape_free(a);
    csg_tape_free(b);
  }
  printf("# dots: %d tape pairs, %d linked, %d sharing, %ld span queries, "
         "%d zero dot products\n", pairs, linked, shared, rays, zeros);
  CHECK("csg_ray_spans_dots = csg_ray_spans bit for bit (shared and "
        "negated normals, zeros of either sign, offsets 0)", bad == 0);
  CHECK("dots: the pairs are linked and share directions, with zero dot "
        "products among the rays", linked == pairs && shared > pairs / 2 &&
        zeros > 1000);
}

int main(void) {
  char base;
  stab_init("fastpaths", &base);
  test_shared_surface();
  test_first();
  test_prune();
  test_csg();
  test_csg_dots();
  test_render();
  CHECK_DONE();
}
