/* lg.c: LG bounds and the root search of Figure 9 (see lg.h for the
 * derivations). */
#include "core/lg.h"

#include <float.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Upper bounds get this relative headroom against rounding. */
#define LG_SAFE (1 + 1e-12)

/* x*y for non-negative bounds where 0 * inf means 0 (a factor that is
 * identically zero contributes nothing). */
static inline double mulnn(double x, double y) {
  /* x * y is NaN only for 0 * inf (the operands are >= +0 and not NaN),
     so this is the product with that case made 0, without a branch on
     each operand; bit for bit the same as testing them. Otherwise it is
     +0 or above (never -0), so r > 0 ? r : 0 keeps it to the bit and
     turns a NaN into 0: one maxsd instead of a compare and a move. */
  double r = x * y;
  return r > 0 ? r : 0;
}

/* iv_mul (interval.h), to the last bit: when both intervals are ordered
   and start at +0 or above, rounding is monotonic, so the least corner
   product is a0 b0 and the greatest a1 b1 (no -0 can tie with +0 there);
   otherwise the four corners. */
static inline void mul_range(double a0, double a1, double b0, double b1,
                             double *lo, double *hi) {
  if (!signbit(a0) && !signbit(b0) && a0 <= a1 && b0 <= b1) {
    *lo = a0 * b0;
    *hi = a1 * b1;
    return;
  }
  iv_mul(a0, a1, b0, b1, lo, hi);
}

/* max and min of two numbers that are never NaN (fmax and fmin are calls
 * into libm). */
static double max2(double x, double y) { return x > y ? x : y; }
static double min2(double x, double y) { return x < y ? x : y; }

static double maxabs(double lo, double hi) {
  return fabs(lo) > fabs(hi) ? fabs(lo) : fabs(hi);
}

/* eq. (2) and its alpha-derivatives over the segment for one leaf. */
static void leaf_bounds(const dt_leaf *lf, double base, double nd, double a,
                        double b, double *lo, double *hi, double *L,
                        double *G, double *split) {
  double sa = nd == 0 ? base : base + a * nd;
  double sb = nd == 0 ? base : base + b * nd;
  double smin = sa < sb ? sa : sb, smax = sa < sb ? sb : sa;
  if (lf->r == 0) {
    if (smin > 0 || smax < 0) {
      *lo = *hi = smin > 0 ? 0 : 1;
      *L = *G = 0;
    } else {
      *lo = 0;
      *hi = 1;
      *L = *G = INFINITY;
      if (nd != 0) *split = -base / nd;
    }
    return;
  }
  double amin = smin * lf->inv_r, amax = smax * lf->inv_r;
  if (amin >= 1 || amax <= -1) {
    *lo = *hi = amin >= 1 ? 0 : 1;
    *L = *G = 0;
    return;
  }
  if (amin < -1) amin = -1;
  if (amax > 1) amax = 1;
  *lo = dt_halfspace_a(amax);
  *hi = dt_halfspace_a(amin);
  double near = amin <= 0 && amax >= 0 ? 0 : min2(fabs(amin), fabs(amax));
  double far = max2(fabs(amin), fabs(amax));
  double k = fabs(nd) * lf->inv_r;
  *L = 0.75 * (1 - near * near) * k;
  *G = 1.5 * far * k * k;
}

/* Section 3.4.1: LG values of a tape over [a, b], the leaves' distances
 * from rl (dt_ray_leaf) or, without it, from o and d. */
static void eval_bounds(const dt_tape *t, const dt_ray_leaf *ray,
                        const double o[3], const double d[3], double a,
                        double b, lg_bounds *out) {
  double lo[DT_STACK_MAX], hi[DT_STACK_MAX], L[DT_STACK_MAX], G[DT_STACK_MAX];
  int sp = 0;
  out->split = NAN;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF) {
      const dt_leaf *lf = &t->leaves[in->arg];
      double base, nd;
      if (ray) {
        base = ray[in->arg].base;
        nd = ray[in->arg].nd;
      } else {
        nd = vec3_dot(lf->n, d);
        base = dt_leaf_dist(lf, o);
      }
      leaf_bounds(lf, base, nd, a, b, &lo[sp], &hi[sp], &L[sp], &G[sp],
                  &out->split);
      sp++;
      continue;
    }
    if (in->op == DT_CONST) {
      lo[sp] = hi[sp] = in->c;
      L[sp] = G[sp] = 0;
      sp++;
      continue;
    }
    sp--;
    int x = sp - 1, y = sp;
    double xl = lo[x], xh = hi[x], yl = lo[y], yh = hi[y];
    /* dt_range_op and the L, G rules per op, the same operations in the
       same order as the general forms (interval.h, mul_range) */
    switch (in->op) {
    case DT_SUM:
      lo[x] = xl + yl;
      hi[x] = xh + yh;
      L[x] = L[x] + L[y];
      G[x] = G[x] + G[y];
      break;
    case DT_DIFF:
      lo[x] = xl - yh;
      hi[x] = xh - yl;
      L[x] = L[x] + L[y];
      G[x] = G[x] + G[y];
      break;
    case DT_RDIFF:
      lo[x] = yl - xh;
      hi[x] = yh - xl;
      L[x] = L[x] + L[y];
      G[x] = G[x] + G[y];
      break;
    default: {
      /* Product x*y, or Union 1 - (1-x)(1-y) = 1 - X*Y with X = 1-x:
       * (XY)' = X'Y + XY', (XY)'' = X''Y + 2X'Y' + XY''. */
      double mx, my;
      if (in->op == DT_PRODUCT) {
        mul_range(xl, xh, yl, yh, &lo[x], &hi[x]);
        mx = maxabs(xl, xh);
        my = maxabs(yl, yh);
      } else {
        double l, h;
        mul_range(1 - xh, 1 - xl, 1 - yh, 1 - yl, &l, &h);
        lo[x] = 1 - h;
        hi[x] = 1 - l;
        mx = maxabs(1 - xh, 1 - xl);
        my = maxabs(1 - yh, 1 - yl);
      }
      double Lx = L[x], Ly = L[y];
      L[x] = mulnn(Lx, my) + mulnn(mx, Ly);
      G[x] = mulnn(G[x], my) + 2 * mulnn(Lx, Ly) + mulnn(mx, G[y]);
    }
    }
  }
  out->lo = lo[0];
  out->hi = hi[0];
  out->L = L[0] * LG_SAFE;
  out->G = G[0] * LG_SAFE;
}

void lg_eval_bounds(const dt_tape *t, const double o[3], const double d[3],
                    double a, double b, lg_bounds *out) {
  eval_bounds(t, NULL, o, d, a, b, out);
}

/* x/y for bounds: 0/0 is 0 and x/0 is infinite. */
static double sdiv(double x, double y) {
  if (y > 0) return x / y;
  return x > 0 ? INFINITY : 0;
}

/* The least distance from an end to a turning point after the first root
 * (lg.h): f there, df its derivative moving inwards. */
static inline __attribute__((always_inline)) double reach(double f, double df, double L, double G) {
  double g = fabs(f), gp = f >= 0 ? df : -df;
  double s = 0;
  if (g > 0) {
    if (G == 0) s = gp < 0 ? g / -gp : INFINITY;
    else if (isinf(G)) s = 0;
    else {
      double disc = sqrt(gp * gp + 2 * G * g);
      s = gp >= 0 ? (gp + disc) / G : 2 * g / (disc - gp);
    }
  }
  double r = sdiv(g, L), q = sdiv(fabs(df), G);
  if (q > r) r = q;
  return s > r ? s : r;
}

/* eq. (6), sound form. */
double lg_multiroot_length(double f0, double df0, double f1, double df1,
                           double L, double G) {
  return reach(f0, df0, L, G) + reach(f1, -df1, L, G);
}

#define LG_LOCAL_LEAVES 64
#define LG_LEVEL_CODE 4096   /* instructions for the levels' views */
#define LG_MAX_LEVELS 32

/* depth is 8 bytes wide: a segment is copied off the stack as 16-byte
   loads and one 8-byte load of its tail, which a 4-byte store of depth
   alone cannot forward (a stall on every search's first pop and every
   split's) */
typedef struct {
  double a, b, fa, dfa, fb, dfb;
  int64_t depth;   /* the subdivision depth, and SEG_LG when the concave
                   path left the segment to the LG search */
} segment;

/* A segment (and its descendants) the concave path could not decide:
   searched by Figure 9 alone. */
#define SEG_LG ((int64_t)1 << 32)
#define SEG_DEPTH(sg) ((int)((sg).depth & 0xffffffff))

/* Everything one search needs, so helpers stay short. */
typedef struct {
  const double *o, *d;
  double tol;
  lg_root *out;
  int n, maxout;
  lg_stats *st;
  const lg_hook *hook;
  const dt_ray_leaf *rl;  /* the leaves along this ray */
  dt_instr *lvbuf;        /* nlv code buffers of ncode instructions, then */
  int nlv, ncode;         /* one scratch buffer for deeper segments */
  int first;          /* lg_mode: stop at the first crossing after first_after; 2:
                         any point of its bracket will do (polish) */
  double first_after;
  double *grad;       /* if not NULL: the gradient at that crossing */
} search;

static double feval(search *s, const dt_tape *t, double x, double *df) {
  if (s->st) s->st->evals++;
  return dt_density_rl_in(t, s->rl, x, df) - 0.5;
}

/* Returns 0 when out is full (the search stops). */
static inline __attribute__((always_inline)) int
emit(search *s, const dt_tape *view, double t, int kind) {
  if (s->n >= s->maxout) return 0;
  /* One graze seen from two adjacent tiny segments is one touch. */
  if (kind == LG_TOUCH && s->n > 0 && t - s->out[s->n - 1].t <= s->tol)
    return 1;
  s->out[s->n].t = t;
  s->out[s->n].kind = kind;
  s->n++;
  if (kind == LG_TOUCH && s->st) s->st->touches++;
  if (s->first && kind != LG_TOUCH && t > s->first_after) {
    if (s->grad) {   /* from the segment's pruned tape: few leaves */
      double p[3];
      for (int i = 0; i < 3; i++) p[i] = s->o[i] + t * s->d[i];
      dt_density_grad(view, p, s->grad);
    }
    return 0;
  }
  return s->n < s->maxout;
}


/* The inside predicate: the solid is where the density exceeds 0.5, so a
 * point where f = rho - 0.5 is exactly 0 is outside (as PointInObject
 * has it).  Crossings are the changes of this predicate; deciding them by
 * the sign of f alone would turn a stretch where the density is exactly
 * 0.5 (a ray in a face plane of a rounded cube) or a graze that the
 * rounding lifts to exactly 0.5 into a pair of crossings, or classify a
 * zero by its derivative. */
static int pos(double f) { return f > 0; }

/* The change of the inside predicate in a bracket [a, b] whose ends
 * differ (pos(fa) != pos(fb)): Newton steps from the better end, each
 * kept only if it lands inside the bracket and at least halves the step
 * before it, else a bisection (the safeguarded Newton of Numerical
 * Recipes' rtsafe, in place of the paper's regula falsi; both keep the
 * bracket, this one converges quadratically and uses the derivative every
 * evaluation computes anyway). Stops when a step is below
 * max(tol, 4 ulp).  An end where f is exactly 0 is on the surface: the
 * change is there when it is the outside end next to the bracket's inside
 * part, so exact zeros (a face plane at density 0.5) come back exactly. */
static inline __attribute__((always_inline)) double
polish(search *s, const dt_tape *t, double a, double b, double fa, double fb,
       double dfa, double dfb) {
  /* The caller only asks whether there is a crossing after first_after
   * (a shadow ray): the bracket's far end stands for it. */
  if (s->first == 2 && a > s->first_after) return b;
  int pa = pos(fa);
  if (!pa && fa == 0) return a;    /* entering right after a zero at a */
  if (pa && fb == 0) return b;     /* leaving at a zero at b */
  /* 4 ulp of the bracket as it is now: the concave path polishes over a
     whole interval, whose far end may be 1e13 times the root's distance
     (a filter hull made long by planes all but parallel to the ray) */
  double rtol = max2(s->tol, 4 * DBL_EPSILON * max2(fabs(a), fabs(b)));
  double x, f, df;
  if (fabs(fa) < fabs(fb)) x = a, f = fa, df = dfa;
  else x = b, f = fb, df = dfb;
  double dx = b - a, dxold = dx;
  for (int it = 0; it < 200 && b - a > rtol; it++) {
    double nx = df != 0 && f != 0 ? x - f / df : NAN;
    if (nx > a && nx < b && fabs(2 * f) <= fabs(dxold * df)) {
      dxold = dx;
      dx = x - nx;
      x = nx;
    } else {
      dxold = dx;
      dx = 0.5 * (b - a);
      x = a + dx;
      if (!(x > a && x < b)) break;
    }
    if (s->st) s->st->rf_steps++;
    f = feval(s, t, x, &df);
    if (pos(f) == pa) a = x, fa = f;
    else b = x, fb = f;
    rtol = max2(s->tol, 4 * DBL_EPSILON * max2(fabs(a), fabs(b)));
    if (f == 0) {
      /* On the surface: a simple root is exact here, unless f stays 0
       * on a stretch (then the change is at its far end): look one tol
       * beyond. */
      double y = pa ? x - rtol : x + rtol, dfy;
      if (y > a && y < b) {
        if (s->st) s->st->rf_steps++;
        double fy = feval(s, t, y, &dfy);
        if (pos(fy) != pos(f)) return x;
        if (pa) b = y, fb = fy; else a = y, fa = fy;
      } else {
        return x;
      }
      df = 0;   /* bisect from here */
      continue;
    }
    if (fabs(dx) <= rtol) return x;
  }
  if (!pa && fa == 0) return a;
  if (pa && fb == 0) return b;
  return 0.5 * (a + b);
}

/* Lower bound of |f| on [a, a+h] from the quadratic envelope at a, f and
 * df (derivative moving inwards) given: concave, so the least value is at
 * an end of the interval. */
static double envelope_min(double f, double df, double G, double h) {
  double g = fabs(f), gp = f >= 0 ? df : -df;
  double e = g + gp * h - 0.5 * G * h * h;
  return e < g ? e : g;
}

/* The tolerance rule for a segment shorter than tol (lg.h). */
static int tiny_rule(search *s, const dt_tape *t, const segment *sg, double G,
                     int *nroots) {
  int pa = pos(sg->fa), pb = pos(sg->fb);
  if (pa != pb) {
    (*nroots)++;
    double x = polish(s, t, sg->a, sg->b, sg->fa, sg->fb, sg->dfa, sg->dfb);
    return emit(s, t, x, pa ? LG_EXIT : LG_ENTER);
  }
  if (isinf(G)) return 1;
  double m = 0.5 * (sg->a + sg->b);
  if ((sg->dfa < 0) != (sg->dfb < 0) && sg->dfa != sg->dfb) {
    double x = sg->a + (sg->b - sg->a) * sg->dfa / (sg->dfa - sg->dfb);
    if (x > sg->a && x < sg->b) m = x;
  }
  double dfm, fm = feval(s, t, m, &dfm);
  if (pos(fm) != pa) {
    int k1 = pa ? LG_EXIT : LG_ENTER;
    *nroots += 2;
    if (!emit(s, t, polish(s, t, sg->a, m, sg->fa, fm, sg->dfa, dfm), k1))
      return 0;
    return emit(s, t, polish(s, t, m, sg->b, fm, sg->fb, dfm, sg->dfb), -k1);
  }
  if (fm == 0 || sg->fa == 0 || sg->fb == 0) {
    (*nroots)++;
    return emit(s, t, fm == 0 ? m : sg->fa == 0 ? sg->a : sg->b, LG_TOUCH);
  }
  double h1 = m - sg->a, h2 = sg->b - m;
  double lb1 = fmax(envelope_min(sg->fa, sg->dfa, G, h1),
                    envelope_min(fm, -dfm, G, h1));
  double lb2 = fmax(envelope_min(fm, dfm, G, h2),
                    envelope_min(sg->fb, -sg->dfb, G, h2));
  if (lb1 > 0 && lb2 > 0) return 1;
  (*nroots)++;
  return emit(s, t, m, LG_TOUCH);
}

static void trace(search *s, const segment *sg, const lg_bounds *lb,
                  double lhs, int decision, int ncode, int nroots) {
  if (!s->hook || !s->hook->fn) return;
  lg_trace_event ev = {sg->a, sg->b, sg->fa, sg->fb, sg->dfa, sg->dfb,
                       lb->L, lb->G, lb->lo, lb->hi, lhs, decision,
                       SEG_DEPTH(*sg), ncode, nroots};
  s->hook->fn(s->hook->ctx, &ev);
}

/* The view of t over [a, b] (dt_prune_rl into buf), or t itself when
 * nothing would fold there (dt_prune_rl_same): the same code either way,
 * without the copy.  t's code then stays in use as the view's, which is
 * safe: t is the interval's view or a segment's ancestor's, kept until
 * every descendant is searched.  (For a segment's view only: an
 * interval's view of a tile's tape mostly folds, and the check would
 * cost more than it saves.) */
static void view_of(const dt_tape *t, const dt_ray_leaf *rl, double a,
                    double b, dt_instr *buf, dt_tape *view) {
#ifdef LG_CHECK_SAME
  dt_tape chk;
  dt_instr cbuf[4096];
  dt_prune_rl(t, rl, a, b, cbuf, &chk);
  if (dt_prune_rl_same(t, rl, a, b)) {
    if (chk.ncode != t->ncode ||
        memcmp(chk.code, t->code, sizeof *cbuf * (size_t)chk.ncode))
      __builtin_trap();
  }
#endif
  if (dt_prune_rl_same(t, rl, a, b)) {
    *view = *t;
    return;
  }
  dt_prune_rl(t, rl, a, b, buf, view);
}

/* A segment whose view is one leaf: the density there is that leaf's
 * smoothed halfspace of the distance along the ray, monotone, and eq.
 * (2)'s kernel is 0.5 exactly at alpha = 0, so the inside predicate
 * changes at most once, where the ray crosses the leaf's plane (for r = 0
 * too: the step is at the plane; a ray along the plane is left to the
 * search, which calls it flat or a miss). The ends' signs say whether it does;
 * the crossing is -base / nd, in [a, b], within an ulp or so of where the
 * computed density changes sign (polishing would stop within the
 * tolerance of it). Most of a rounded polyhedron's faces are flat this
 * way (Lobb, Section 2.3). The trace row keeps its LG bounds for the
 * table and the plots. Returns what emit does (1 if there is none). */
static int plane_segment(search *s, const dt_tape *t, const segment *sg) {
  int pa = pos(sg->fa), nroots = pa != pos(sg->fb);
  double x = 0;
  if (nroots) {
    if (s->first == 2 && sg->a > s->first_after) x = sg->b;
    else if (!pa && sg->fa == 0) x = sg->a;   /* as polish has them */
    else if (pa && sg->fb == 0) x = sg->b;
    else {
      const dt_ray_leaf *r = &s->rl[t->code[0].arg];
      x = -r->base / r->nd;
      if (!(x >= sg->a)) x = sg->a;
      if (!(x <= sg->b)) x = sg->b;
    }
  }
  if (s->hook && s->hook->fn) {
    lg_bounds lb;
    eval_bounds(t, s->rl, s->o, s->d, sg->a, sg->b, &lb);
    trace(s, sg, &lb,
          lg_multiroot_length(sg->fa, sg->dfa, sg->fb, sg->dfb, lb.L, lb.G),
          LG_SEG_PLANE, t->ncode, nroots);
  }
  return nroots ? emit(s, t, x, pa ? LG_EXIT : LG_ENTER) : 1;
}

/* The concave path (beyond the paper). A smoothed halfspace is
 * log-concave in x (eq. (2)'s kernel integrates the log-concave
 * 3/4 (1 - a^2): Prekopa), and so is a product of them, so along a ray
 * g = log rho is concave wherever rho > 0: the solid (rho > 0.5) meets
 * a segment whose view is such a product in one interval or not at all.
 * Then the ends' signs say almost everything, with no LG bounds and no
 * splitting:
 *   - unlike signs: exactly one crossing, polished in [a, b];
 *   - both inside: none (rho's lower bounds above 0.5 at both ends,
 *     with their rounding, prove it);
 *   - both outside: none if the tangents of g at the ends of a bracket
 *     of g's peak keep g below log 0.5 (concave: g lies under every
 *     tangent), else the bracket shrinks by the sign of g' at the
 *     tangents' meeting point, or a point found inside splits the
 *     segment into one crossing on each side.
 * Every bound at a point takes the rounding of the leaves' distances
 * along the ray (from o and d), of alpha, the kernel, its log-slope
 * -3 (1 + a) / ((1 - a)(2 + a)) (increasing in a) and the sums, so an
 * answer of none is a proof; what the bounds cannot settle (a graze
 * within rounding of 0.5, a factor that may be 0, too many leaves, no
 * progress) goes to Figure 9 (SEG_LG), which decides it as before. */

#define LC_MAX 64      /* leaves of a view the concave path takes */
#define LC_ITERS 32    /* bracket steps before it gives the segment up */

/* Whether a view is a product of smoothed halfspaces of positive radius
 * (and positive constants). */
static int product_view(const dt_tape *t) {
  /* from the root down: a Difference or Sum at the root shows at once */
  for (int i = t->ncode - 1; i >= 0; i--) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF) {
      if (!(t->leaves[in->arg].r > 0)) return 0;
    } else if (in->op == DT_CONST) {
      if (!(in->c > 0)) return 0;
    } else if (in->op != DT_PRODUCT) {
      return 0;
    }
  }
  return 1;
}

/* One leaf of the view along the ray: base = n.o - d and nd = n.d as the
 * ray's table has them, k = 1/r; alpha = (base + x nd) k is known within
 * e0 + |x| e1 + 2u |alpha| (the rounding of base and nd from o and d, of
 * the sum and the product); b = nd k, alpha's rate, within eb. */
typedef struct {
  double base, nd, k, e0, e1, b, eb;
} lc_leaf;

/* The view's leaves and the product c of its constants; 0 if more than
 * LC_MAX leaves or a distance is not finite. */
static int lc_leaves(const search *s, const dt_tape *t, lc_leaf *lv, int *n,
                     double *c) {
  const double u = DBL_EPSILON;   /* twice the unit roundoff: generous */
  const double *o = s->o, *d = s->d;
  int m = 0;
  double cc = 1;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_CONST) cc *= in->c;
    if (in->op != DT_LEAF) continue;
    if (m == LC_MAX) return 0;
    const dt_leaf *lf = &t->leaves[in->arg];
    lc_leaf *l = &lv[m++];
    l->base = s->rl[in->arg].base;
    l->nd = s->rl[in->arg].nd;
    l->k = lf->inv_r;
    if (!(isfinite(l->base) && isfinite(l->nd) && isfinite(l->k))) return 0;
    /* n.o - d: 3 products and 2 sums (one more for -d); n.d likewise; then
       base + x nd (2u of each part) and the product by k */
    double eb = 4 * u * (fabs(lf->n[0] * o[0]) + fabs(lf->n[1] * o[1]) +
                         fabs(lf->n[2] * o[2]) + fabs(lf->d));
    double en = 4 * u * (fabs(lf->n[0] * d[0]) + fabs(lf->n[1] * d[1]) +
                         fabs(lf->n[2] * d[2]));
    l->e0 = (eb + 2 * u * fabs(l->base)) * l->k * (1 + 2 * u) + DBL_MIN;
    l->e1 = (en + 2 * u * fabs(l->nd)) * l->k * (1 + 2 * u);
    l->b = l->nd * l->k;
    l->eb = en * l->k * (1 + 2 * u) + 2 * u * fabs(l->b) + DBL_MIN;
  }
  *n = m;
  *c = cc;
  return m > 0 && cc > 0 && isfinite(cc);
}

/* At o + x d: an upper bound gup of g = log rho, an interval [slo, shi]
 * holding g' (per unit of the ray parameter) and a lower bound flo of rho.
 * Per leaf, with alpha known within ea and q = 1 - alpha >= 4 ea: the
 * kernel f falls as alpha rises and c = -(log f)' in alpha,
 * 3 (1 + a) / ((1 - a)(2 + a)), rises with c' = 3 (a^2 + 2a + 3) / D^2
 * <= 18 / (1 - a)^2 <= 32 / q^2 over alpha's interval; so log f there is
 * at most log f(alpha) + ea c(alpha) and c is within ea 32 / q^2 of
 * c(alpha). Returns 0 when a factor may be 0 or near it (no tangent). */
static int lc_at(const lc_leaf *lv, int n, double c, double x, double *gup,
                 double *slo, double *shi, double *flo) {
  const double u = DBL_EPSILON;
  double p = c, gx = 0, S = 0, E = 0, mag = 0, ax = fabs(x);
  for (int i = 0; i < n; i++) {
    const lc_leaf *l = &lv[i];
    double a = (l->base + x * l->nd) * l->k;
    double ea = l->e0 + ax * l->e1 + 2 * u * fabs(a);
    if (a <= -1 - ea) continue;   /* 1 here, slope 0 */
    double q = 1 - a;
    if (!(ea <= 0.25 * q)) return 0;
    double a2 = 2 + a, inv = 1 / (q * a2), iq = a2 * inv;
    double cc = a <= -1 ? 0 : 3 * (1 + a) * inv;
    double f = a <= -1 ? 1 : q * q * a2 * 0.25;
    double dc = ea * 32 * iq * iq * (1 + 8 * u) + 8 * u * cc;
    p *= f;
    gx += ea * (cc + dc);
    double term = -cc * l->b;
    S += term;
    E += dc * fabs(l->b) + (cc + dc) * l->eb;
    mag += fabs(term);
  }
  /* a subnormal product has lost its relative precision */
  if (!(p >= DBL_MIN && isfinite(S) && isfinite(E))) return 0;
  double er = 8 * (n + 2) * u;   /* the kernels' and the product's rounding */
  double g = log(p * (1 + er)) + gx * (1 + 4 * u);
  *gup = g + 4 * u * fabs(g) + DBL_MIN;
  E = E * (1 + 4 * u) + 2 * (n + 1) * u * mag;
  *slo = S - E;
  *shi = S + E;
  *flo = p * (1 - er) * (1 - gx * (1 + 4 * u));
  return isfinite(*gup);
}

/* Cut [*l, *r] at the points where a leaf's alpha is about 1/2, keeping
 * the side where it is lower: where the alpha computed there is at least
 * 1/4 after its rounding, and rises away from the cut (the sign of its
 * rate nd k proven), the kernel is below f(1/4) = 0.3164 beyond it, and
 * rho, the constants' product c times kernels of at most 1, below 0.5
 * when c f(1/4) < 0.5 (c is 1 in a rounded polyhedron; a pruned Sum of
 * halfspaces that are 1 there can leave 2 or more), so the cut parts hold
 * no crossing. Returns 0 when nothing is left. */
static int lc_clip(const lc_leaf *lv, int n, double c, double *l, double *r) {
  const double u = DBL_EPSILON;
  double lo = *l, hi = *r;
  if (!(c * 0.3165 < 0.5)) return 1;
  for (int i = 0; i < n; i++) {
    const lc_leaf *f = &lv[i];
    if (!(fabs(f->b) > f->eb)) continue;   /* alpha's direction not proven */
    double x = (0.5 / f->k - f->base) / f->nd;   /* alpha = 1/2 about here */
    if (!(x > lo && x < hi)) continue;
    double a = (f->base + x * f->nd) * f->k;
    double ea = f->e0 + fabs(x) * f->e1 + 2 * u * fabs(a);
    if (!(a - ea >= 0.25)) continue;   /* not shown: keep it */
    if (f->nd > 0) hi = x;   /* alpha rises with x: nothing beyond x */
    else lo = x;
  }
  *l = lo;
  *r = hi;
  return lo < hi;
}

/* A concave segment's trace row (its LG bounds for the table). */
static void concave_trace(search *s, const dt_tape *t, const segment *sg,
                          int nroots) {
  if (!s->hook || !s->hook->fn) return;
  lg_bounds lb;
  eval_bounds(t, s->rl, s->o, s->d, sg->a, sg->b, &lb);
  trace(s, sg, &lb,
        lg_multiroot_length(sg->fa, sg->dfa, sg->fb, sg->dfb, lb.L, lb.G),
        LG_SEG_CONCAVE, t->ncode, nroots);
}

/* Both ends outside and m inside: one crossing on each side of m. */
static int concave_two(search *s, const dt_tape *t, const segment *sg,
                       double m, double fm, double dfm) {
  concave_trace(s, t, sg, 2);
  if (!emit(s, t, polish(s, t, sg->a, m, sg->fa, fm, sg->dfa, dfm), LG_ENTER))
    return 0;
  return emit(s, t, polish(s, t, m, sg->b, fm, sg->fb, dfm, sg->dfb), LG_EXIT);
}

/* The concave path over segment sg of the product view t: 1 decided
 * (its crossings emitted), 0 when emit says stop, 2 not decided. */
static int concave_segment(search *s, const dt_tape *t, const segment *sg) {
  int pa = pos(sg->fa), pb = pos(sg->fb);
  if (pa != pb) {
    double x = polish(s, t, sg->a, sg->b, sg->fa, sg->fb, sg->dfa, sg->dfb);
    concave_trace(s, t, sg, 1);
    return emit(s, t, x, pa ? LG_EXIT : LG_ENTER);
  }
  if (!pa) {
    /* both outside: first a guess at g's peak, where g' = rho'/rho,
       taken as linear between the ends, is 0; a point found inside there
       needs no proof, and is one when the ray meets the solid */
    double Fa = sg->fa + 0.5, Fb = sg->fb + 0.5;
    if (Fa > 0 && Fb > 0) {
      double Sa = sg->dfa / Fa, Sb = sg->dfb / Fb;
      if (Sa > 0 && Sb < 0) {
        double m = sg->a + (sg->b - sg->a) * (Sa / (Sa - Sb));
        if (m > sg->a && m < sg->b) {
          double dfm, fm = feval(s, t, m, &dfm);
          if (pos(fm)) return concave_two(s, t, sg, m, fm, dfm);
        }
      }
    }
  }
  lc_leaf lv[LC_MAX];
  int n;
  double c;
  if (!lc_leaves(s, t, lv, &n, &c)) return 2;
  double Gl, Sl0, Sl1, Fl, Gr, Sr0, Sr1, Fr;
  double l = sg->a, r = sg->b;
  if (!pa && !lc_clip(lv, n, c, &l, &r)) {   /* rho < 0.5 all along */
    concave_trace(s, t, sg, 0);
    return 1;
  }
  int okl = lc_at(lv, n, c, l, &Gl, &Sl0, &Sl1, &Fl);
  int okr = lc_at(lv, n, c, r, &Gr, &Sr0, &Sr1, &Fr);
  if (s->st) s->st->evals += 2;
  if (pa) {   /* both inside: rho > 0.5 at both ends, so all along */
    if (!(okl && okr && Fl > 0.5 && Fr > 0.5)) return 2;
    concave_trace(s, t, sg, 0);
    return 1;
  }
  const double lh = -M_LN2;   /* log 0.5 */
  double minlen = max2(s->tol, 16 * DBL_EPSILON * max2(fabs(l), fabs(r)));
  for (int it = 0; it < LC_ITERS; it++) {
    /* g's least upper bound on [l, r] from the tangents at its ends */
    double w = r - l, B = INFINITY, x = 0.5 * w;
    double P = Sl1, Q = -Sr0;   /* g(t) <= Gl + P (t - l), Gr + Q (r - t) */
    if (okl && okr) {
      if (P <= 0) B = Gl;
      else if (Q <= 0) B = Gr;
      else {
        x = (Gr - Gl + Q * w) / (P + Q);
        if (x < 0) x = 0;
        if (x > w) x = w;
        B = Gl + P * x;
      }
    } else if (okl) {
      B = Gl + max2(P, 0) * w;
    } else if (okr) {
      B = Gr + max2(Q, 0) * w;
    }
    double mu = 1e-12 * (1 + fabs(Gl) + fabs(Gr) + (fabs(P) + fabs(Q)) * w);
    if (B < lh - mu) {
      concave_trace(s, t, sg, 0);
      return 1;
    }
    if (!(w > minlen)) return 2;
    if (x < w / 16) x = w / 16;
    if (x > w - w / 16) x = w - w / 16;
    double m = l + x, Gm, Sm0, Sm1, Fm;
    if (!(m > l && m < r)) return 2;
    int okm = lc_at(lv, n, c, m, &Gm, &Sm0, &Sm1, &Fm);
    if (s->st) s->st->evals++;
    if (!okm) return 2;
    if (!(Gm < lh - 1e-12 * (1 + fabs(Gm)))) {
      /* rho may exceed 0.5 at m: inside by the tape's own value (the
         predicate the crossings are polished on) gives one crossing on
         each side; else too close to tell */
      double dfm, fm = feval(s, t, m, &dfm);
      if (!pos(fm)) return 2;
      return concave_two(s, t, sg, m, fm, dfm);
    }
    /* rho < 0.5 at m: the peak is on the side g rises to */
    if (Sm0 > 0) {
      l = m, Gl = Gm, Sl0 = Sm0, Sl1 = Sm1, okl = 1;
    } else if (Sm1 < 0) {
      r = m, Gr = Gm, Sr0 = Sm0, Sr1 = Sm1, okr = 1;
    } else {   /* g' straddles 0 at m: the tangents at m both ways */
      double Bm = Gm + max2(max2(Sm1 * (r - m), -Sm0 * (m - l)), 0);
      double mum = 1e-12 * (1 + fabs(Gm) + (fabs(Sm0) + fabs(Sm1)) * w);
      if (!(Bm < lh - mum)) return 2;
      concave_trace(s, t, sg, 0);
      return 1;
    }
  }
  return 2;
}

/* Figure 9 over [a, b] of the (span-pruned) tape t.  Returns 0 when the
 * output is full.  A segment's tape is pruned from its parent's, not from
 * t: the search is depth first, so when a segment of depth k is popped
 * the views of levels below k are those of its ancestors (only the
 * ancestors' other descendants, all deeper, ran since).  Levels from nlv
 * on prune from the deepest stored one. */
static int search_interval(search *s, const dt_tape *t, double a, double b) {
  segment stack[LG_STACK];
  dt_tape lv[LG_MAX_LEVELS + 1];   /* lv[nlv]: deeper segments' views */
  int sp = 0;
  long budget = LG_MAX_SEGMENTS;
  segment first = {a, b, 0, 0, 0, 0, 0};
  first.fa = feval(s, t, a, &first.dfa);
  first.fb = feval(s, t, b, &first.dfb);
  stack[sp++] = first;
  while (sp) {
    segment sg = stack[--sp];
    if (s->st) s->st->segments++;
    const dt_tape *vp = t;   /* this segment's view; level 0 is t */
    if (SEG_DEPTH(sg) > 0) {
      int dep = SEG_DEPTH(sg);
      int from = dep - 1 < s->nlv - 1 ? dep - 1 : s->nlv - 1;
      int to = dep < s->nlv ? dep : s->nlv;
      view_of(from ? &lv[from] : t, s->rl, sg.a, sg.b,
              s->lvbuf + (size_t)to * (size_t)s->ncode, &lv[to]);
      vp = &lv[to];
    }
    int nc = vp->ncode;
    if (nc == 1 && vp->code[0].op == DT_LEAF && s->rl[vp->code[0].arg].nd != 0) {
      if (!plane_segment(s, vp, &sg)) return 0;
      continue;
    }
    if (nc > 1 && !(sg.depth & SEG_LG) && product_view(vp)) {
      int r = concave_segment(s, vp, &sg);
      if (r == 0) return 0;
      if (r == 1) continue;
      sg.depth |= SEG_LG;   /* not decided: Figure 9, here and below */
    }
    lg_bounds lb;
    eval_bounds(vp, s->rl, s->o, s->d, sg.a, sg.b, &lb);
    double margin = 1e-12 * (1 + fabs(lb.lo) + fabs(lb.hi));
    if (lb.lo > 0.5 + margin || lb.hi < 0.5 - margin) {
      trace(s, &sg, &lb, INFINITY, LG_SEG_EXCLUDED, nc, 0);
      continue;
    }
    if (lb.L == 0) {
      trace(s, &sg, &lb, INFINITY, LG_SEG_FLAT, nc, 0);
      continue;
    }
    double len = sg.b - sg.a, lim = len * LG_SAFE;
    /* lg_multiroot_length, its second reach skipped when the first alone
       exceeds lim and nothing traces lhs: reach of a finite f is never
       NaN and never negative, so the sum would exceed lim too (rounding
       is monotonic) */
    double lhs = reach(sg.fa, sg.dfa, lb.L, lb.G);
    int shorty = 1;
    if (!(lhs > lim && !s->hook && isfinite(sg.fb) && isfinite(sg.dfb))) {
      lhs += reach(sg.fb, -sg.dfb, lb.L, lb.G);
      shorty = lhs > lim;
    }
    double minlen = max2(s->tol, 16 * DBL_EPSILON * max2(fabs(sg.a), fabs(sg.b)));
    double m = 0.5 * (sg.a + sg.b);
    if (!isnan(lb.split) && lb.split > sg.a + 0.25 * minlen &&
        lb.split < sg.b - 0.25 * minlen)
      m = lb.split;
    int tiny = len <= minlen || !(m > sg.a && m < sg.b);
    if (!shorty && !tiny && (sp + 2 > LG_STACK || --budget < 0)) {
      tiny = 1;
      if (s->st) s->st->overflows++;
    }
    int nroots = 0, more = 1;
    if (shorty) {
      if (pos(sg.fa) != pos(sg.fb)) {
        nroots = 1;
        more = emit(s, vp, polish(s, vp, sg.a, sg.b, sg.fa, sg.fb, sg.dfa, sg.dfb),
                    pos(sg.fa) ? LG_EXIT : LG_ENTER);
      }
      trace(s, &sg, &lb, lhs, nroots ? LG_SEG_ROOT : LG_SEG_NO_ROOT, nc,
            nroots);
    } else if (tiny) {
      more = tiny_rule(s, vp, &sg, lb.G, &nroots);
      trace(s, &sg, &lb, lhs, LG_SEG_TINY, nc, nroots);
    } else {
      trace(s, &sg, &lb, lhs, LG_SEG_SPLIT, nc, 0);
      segment left = sg, right = sg;
      double fm, dfm;
      fm = feval(s, vp, m, &dfm);
      left.b = right.a = m;
      left.fb = right.fa = fm;
      left.dfb = right.dfa = dfm;
      left.depth = right.depth = sg.depth + 1;
      stack[sp++] = right;
      stack[sp++] = left;
    }
    if (!more) return 0;
  }
  return 1;
}

/* The leaves along the ray (dt_ray_leaves) and the part of the ray where
 * some filter is touched, [*lo, *hi]: outside it every leaf is constant,
 * so the density is too. */
static void ray_leaves_hull(const dt_tape *t, const double o[3],
                            const double d[3], dt_ray_leaf *rl, double *lo,
                            double *hi) {
  double l = INFINITY, h = -INFINITY;
  for (int i = 0; i < t->nleaves; i++) {
    const dt_leaf *lf = &t->leaves[i];
    double base = dt_leaf_dist(lf, o);
    double nd = vec3_dot(lf->n, d);
    rl[i].base = base;
    rl[i].nd = nd;
    if (nd == 0) continue;
    double x = (-lf->r - base) / nd, y = (lf->r - base) / nd;
    if (x > y) { double tmp = x; x = y; y = tmp; }
    if (x < l) l = x;
    if (y > h) h = y;
  }
  *lo = l;
  *hi = h;
}

/* Search the sorted, disjoint intervals iv[0..n) (pairs of doubles). */
static int run(const lg_query *q, const double *iv, int n, int bounded_iv) {
  const dt_tape *t = q->tape;
  const double *o = q->o, *d = q->d;
  if (n <= 0 || q->maxout <= 0) return 0;
  dt_instr local[LG_LEVEL_CODE], *buf = local;
  dt_ray_leaf lrl[LG_LOCAL_LEAVES], *rl = lrl;
  int nc = t->ncode > 0 ? t->ncode : 1;
  /* Buffers: the interval's view, nlv levels (the first is the interval's
   * view itself), one scratch. */
  /* (without the integer division when the cap decides: a short tape) */
  int nlv = nc <= LG_LEVEL_CODE / (LG_MAX_LEVELS + 2) ? LG_MAX_LEVELS
                                                     : LG_LEVEL_CODE / nc - 2;
  if (nlv > LG_MAX_LEVELS) nlv = LG_MAX_LEVELS;
  if (nlv < 1) nlv = 1;
  size_t need = (size_t)(nlv + 2) * (size_t)nc;
  if (need > LG_LEVEL_CODE) {
    buf = malloc(need * sizeof *buf);
    if (!buf) return -1;
  }
  if (t->nleaves > LG_LOCAL_LEAVES) {
    rl = malloc((size_t)t->nleaves * sizeof *rl);
    if (!rl) {
      if (buf != local) free(buf);
      return -1;
    }
  }
  /* Intervals from the outer bound (bounded_iv) already lie where the
   * filters are, unless an end is infinite (an unbounded object): the
   * clip to the filters' hull, which costs two divisions per leaf, is
   * only needed for those and for intervals from the caller. */
  double hlo = -INFINITY, hhi = INFINITY;
  if (bounded_iv && isfinite(iv[0]) && isfinite(iv[2 * n - 1]))
    dt_ray_leaves(t, o, d, rl);
  else
    ray_leaves_hull(t, o, d, rl, &hlo, &hhi);
  search s = {o, d, q->tol > 0 ? q->tol : DBL_MIN, q->out, 0, q->maxout,
              q->stats, q->hook, rl, buf + nc, nlv, nc, (int)q->mode, q->t0,
              q->grad};
  for (int i = 0; i < n; i++) {
    double a = iv[2 * i], b = iv[2 * i + 1];
    if (hlo > a) a = hlo;
    if (hhi < b) b = hhi;
    if (!(a <= b)) continue;
    dt_tape view;   /* pruned always: a tile's view mostly folds here */
    dt_prune_rl(t, rl, a, b, buf, &view);
    if (!search_interval(&s, &view, a, b)) break;
  }
  if (buf != local) free(buf);
  if (rl != lrl) free(rl);
  return s.n;
}

/* Figure 9: Roots. */
int lg_roots(const dt_tape *t, const double o[3], const double d[3],
             double t0, double t1, double tol, lg_root *out, int maxout,
             lg_stats *stats) {
  double iv[2] = {t0, t1};
  lg_query q = {t, o, d, t0, t1, tol, out, maxout, stats, NULL, LG_ALL, NULL};
  return run(&q, iv, t0 <= t1, 0);
}

/* Search the given sorted spans, each widened by tol (plus a few ulps) and
   clipped to [q->t0, q->t1]; widened neighbours are merged. */
static inline __attribute__((always_inline)) int
spans_run(const lg_query *q, const csg_span *spans, int nspans,
          int bounded_iv) {
  const double tol = q->tol, t0 = q->t0, t1 = q->t1;
  double local[2 * 64], *iv = local;
  if (nspans > 64) {
    iv = malloc((size_t)nspans * 2 * sizeof *iv);
    if (!iv) return -1;
  }
  int n = 0;
  for (int i = 0; i < nspans; i++) {
    double pad0 = tol + 8 * DBL_EPSILON * fabs(spans[i].t0);
    double pad1 = tol + 8 * DBL_EPSILON * fabs(spans[i].t1);
    double a = max2(spans[i].t0 - pad0, t0), b = min2(spans[i].t1 + pad1, t1);
    if (!(a <= b)) continue;
    if (n > 0 && a <= iv[2 * n - 1]) {   /* merge widened neighbours */
      if (b > iv[2 * n - 1]) iv[2 * n - 1] = b;
      continue;
    }
    iv[2 * n] = a;
    iv[2 * n + 1] = b;
    n++;
  }
  int r = n > 0 ? run(q, iv, n, bounded_iv) : 0;
  if (iv != local) free(iv);
  return r;
}

int lg_roots_spans(const dt_tape *t, const double o[3], const double d[3],
                   double t0, double t1, const csg_span *spans, int nspans,
                   double tol, lg_root *out, int maxout, lg_stats *stats,
                   const lg_hook *hook) {
  lg_query q = {t, o, d, t0, t1, tol, out, maxout, stats, hook, LG_ALL, NULL};
  return spans_run(&q, spans, nspans, 0);
}

/* LG_ANY (a shadow ray) without a search, when the answer is plain: the
 * ray starts outside the outer bound (os[0] begins after t0, and
 * outside it rho <= 0.5: not inside) and meets the inner bound (is, m
 * spans moved in, clipped to [t0, t1]) at a point where the density is
 * above 0.5 (evaluated: inside the inner bound it is >= 0.5, so the
 * evaluation only rules out a density of exactly 0.5 there). The inside
 * predicate changes between the two, so the search would report a
 * crossing after t0; this reports one, at that point, in q->out and
 * returns 1. Else 0: search. Not with a trace hook, which wants every
 * segment. */
static int any_inside(const lg_query *q, const csg_span *os,
                      const csg_span *is, int m) {
  if (q->mode != LG_ANY || q->hook || m == 0 || q->maxout < 1) return 0;
  if (!(os[0].t0 > q->t0)) return 0;
  double tm = 0.5 * (is[0].t0 + is[0].t1);
  if (!(tm > q->t0 && tm <= q->t1)) return 0;
  double p[3];
  for (int i = 0; i < 3; i++) p[i] = q->o[i] + tm * q->d[i];
  if (q->stats) q->stats->evals++;
  if (!(dt_density(q->tape, p) > 0.5)) return 0;
  q->out[0].t = tm;
  q->out[0].kind = LG_ENTER;
  return 1;
}

/* Figure 7 (c): search where outer and not inner. */
int lg_search_bounded(const lg_query *q, const csg_tape *outer,
                      const csg_tape *inner) {
  const double *o = q->o, *d = q->d;
  const double t0 = q->t0, t1 = q->t1, tol = q->tol;
  int no = outer->nleaves + 1, ni = inner ? inner->nleaves + 1 : 0;
  int nsc = csg_scratch_spans(outer);
  if (inner && csg_scratch_spans(inner) > nsc) nsc = csg_scratch_spans(inner);
  size_t need = (size_t)(2 * no + 2 * ni + nsc);
  csg_span local[4 * 64 + 2 * 64 + 8], *mem = local;
  if (need > sizeof local / sizeof *local) {
    mem = malloc(need * sizeof *mem);
    if (!mem) return -1;
  }
  csg_span *os = mem, *is = os + no, *ds = is + ni, *sc = ds + no + ni;
  /* An inner bound linked to its outer bound (csg_tape_share_dirs): the
     dot products of their planes' common normals once. */
  double dbuf[4 * CSG_DIRS_MAX];
  const double *dots = NULL;
  if (inner && inner->dirs_of == outer) {
    csg_ray_dots(inner, o, d, dbuf);
    dots = dbuf;
  }
  int n = dots ? csg_ray_spans_dots(outer, dots, o, d, t0, t1, os, no, sc, nsc)
               : csg_ray_spans(outer, o, d, t0, t1, os, no, sc, nsc);
  int r = -1;
  if (n == 0) {   /* the ray misses the outer bound: no crossing */
    r = 0;
  } else if (n > 0) {
    int m = !inner ? 0
          : dots ? csg_ray_spans_dots(inner, dots, o, d, t0, t1, is, ni, sc, nsc)
                 : csg_ray_spans(inner, o, d, t0, t1, is, ni, sc, nsc);
    if (m >= 0) {
      /* A crossing on a surface the two bounds share (a lone halfspace,
       * whose 0.5 isosurface is its plane; a sharp leaf's plane) lies on
       * the inner bound's surface, and rounding may make outer minus inner
       * empty there (the bounds' few ulps of offset vanish in n.o at the
       * ray's coordinates): move the inner spans' surface ends in by the
       * padding spans_run widens by, so such a crossing is searched. */
      int w = 0;
      for (int i = 0; i < m; i++) {
        csg_span s = is[i];
        if (s.id0 >= 0) s.t0 += tol + 8 * DBL_EPSILON * fabs(s.t0);
        if (s.id1 >= 0) s.t1 -= tol + 8 * DBL_EPSILON * fabs(s.t1);
        if (s.t0 < s.t1) is[w++] = s;
      }
      m = w;
      if (any_inside(q, os, is, m)) {
        r = 1;
      } else {
        int k = csg_spans_diff(os, n, is, m, ds);
        r = spans_run(q, ds, k, 1);
      }
    }
  }
  if (mem != local) free(mem);
  return r;
}

int lg_roots_bounded(const dt_tape *t, const csg_tape *outer,
                     const csg_tape *inner, const double o[3],
                     const double d[3], double t0, double t1, double tol,
                     lg_root *out, int maxout, lg_stats *stats,
                     const lg_hook *hook) {
  lg_query q = {t, o, d, t0, t1, tol, out, maxout, stats, hook, LG_ALL, NULL};
  return lg_search_bounded(&q, outer, inner);
}

int lg_first_bounded(const dt_tape *t, const csg_tape *outer,
                     const csg_tape *inner, const double o[3],
                     const double d[3], double t0, double t1, double tol,
                     lg_root *out, int maxout, lg_stats *stats, int any,
                     double grad[3]) {
  lg_query q = {t, o, d, t0, t1, tol, out, maxout, stats, NULL,
                any ? LG_ANY : LG_FIRST, grad};
  return lg_search_bounded(&q, outer, inner);
}
