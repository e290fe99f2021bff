/* bounds.c: Figure 8 and Theorems 1-6, generalised to subtree ranges.
 *
 * The tape is walked twice.  Top-down (parents sit after their children
 * in postfix, so a descending loop sees every parent first) each node
 * receives one request (outer/inner/support at a threshold) and decides
 * what it becomes; bottom-up the decisions are emitted as postfix CSG.
 * A node that becomes a constant, or drops one operand, marks the
 * abandoned subtrees SKIP so they emit nothing.
 *
 * The generalised theorems (x below, y on top; [lo, hi] ranges):
 *   outer Sum      O(x, t/2) u O(y, t/2)                       (Thm 2)
 *   outer Diff     O(x, t + lo_y) - I(y, hi_x - t)             (Thm 3)
 *   outer Product  O(x, t/hi_y) n O(y, t/hi_x); the x side needs
 *                  lo_y >= 0, the y side lo_x >= 0, t >= 0     (Thm 1)
 *   outer Union    O(x, s) u O(y, s), s = 1 - sqrt(1 - t), t <= 1
 *                  (x, y <= s  =>  1 - (1-x)(1-y) <= 1 - (1-s)^2 = t)
 *   inner Sum      I(x, t - lo_y) u I(y, t - lo_x)             (Thm 4)
 *   inner Product  I(x, sqrt t) n I(y, sqrt t), t > 0          (Thm 5)
 *   inner Diff     I(x, t) - O(y, 0)                           (Thm 6)
 *   inner Union    I(x, t) u I(y, t); the x side needs hi_x <= 1 and
 *                  lo_y >= 0 (then x + y(1-x) >= x)
 * and at every node: outer = Empty if hi <= t, Everything if t < lo;
 * inner = Everything if lo >= t, Empty if hi < t. */
#include "core/bounds.h"
#include "core/tape.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

enum { K_SKIP, K_OUTER, K_INNER, K_SUPPORT };
enum { E_NONE, E_EMPTY, E_ALL, E_PLANE, E_OP };

typedef struct {
  int kind;        /* request */
  double t;
  int emit;        /* decision */
  int csgop;
  double offset;   /* plane offset for E_PLANE */
} node;

/* Thresholds rounded towards the safe side: an outer bound for a smaller
 * level, an inner bound for a larger one, is still valid. */
static double down(double x) { return x - fabs(x) * 4 * DBL_EPSILON; }
static double up(double x) { return x + fabs(x) * 4 * DBL_EPSILON; }

static void request(node *nd, int i, int kind, double t) {
  nd[i].kind = kind;
  nd[i].t = t;
}

/* Request-making for a binary op node i with children x, y. */
static void decide_op(const dt_tape *tp, int i, int x, int y, const double *lo,
                      const double *hi, node *nd, int *flags) {
  int op = tp->code[i].op;
  double t = nd[i].t;
  if (op == DT_RDIFF) {     /* y - x: swap roles, keep the emission order */
    int tmp = x;
    x = y;
    y = tmp;
    op = DT_DIFF;
  }
  int diffop = tp->code[i].op == DT_RDIFF ? CSG_RDIFF : CSG_DIFF;
  nd[i].emit = E_OP;
  if (nd[i].kind == K_SUPPORT) {
    request(nd, x, K_SUPPORT, 0);
    request(nd, y, K_SUPPORT, 0);
    nd[i].csgop = op == DT_PRODUCT ? CSG_INTER : CSG_UNION;
    return;
  }
  if (nd[i].kind == K_OUTER) {
    switch (op) {
    case DT_SUM:                                      /* Theorem 2 */
      request(nd, x, K_OUTER, down(t / 2));
      request(nd, y, K_OUTER, down(t / 2));
      nd[i].csgop = CSG_UNION;
      return;
    case DT_DIFF:                                     /* Theorem 3 */
      request(nd, x, K_OUTER, down(t + lo[y]));
      request(nd, y, K_INNER, up(hi[x] - t));
      nd[i].csgop = diffop;
      return;
    case DT_PRODUCT: {                                /* Theorem 1 */
      int okx = lo[y] >= 0 && t >= 0, oky = lo[x] >= 0 && t >= 0;
      if (okx) request(nd, x, K_OUTER, down(t / hi[y]));
      if (oky) request(nd, y, K_OUTER, down(t / hi[x]));
      if (okx && oky) { nd[i].csgop = CSG_INTER; return; }
      *flags |= BND_FALLBACK;
      if (okx || oky) {                  /* keep the one valid side */
        request(nd, okx ? y : x, K_SKIP, 0);
        nd[i].emit = E_NONE;
        return;
      }
      break;
    }
    default:                                          /* Union */
      if (t <= 1) {
        double s = down(t / (1 + sqrt(1 - t)));
        request(nd, x, K_OUTER, s);
        request(nd, y, K_OUTER, s);
        nd[i].csgop = CSG_UNION;
        return;
      }
      *flags |= BND_FALLBACK;
      break;
    }
    /* No theorem applies: the filter supports (rho = 0 outside). */
    if (t >= 0) {
      request(nd, x, K_SUPPORT, 0);
      request(nd, y, K_SUPPORT, 0);
      nd[i].csgop = op == DT_PRODUCT ? CSG_INTER : CSG_UNION;
      return;
    }
    nd[i].emit = E_ALL;
    request(nd, x, K_SKIP, 0);
    request(nd, y, K_SKIP, 0);
    return;
  }
  /* K_INNER */
  switch (op) {
  case DT_SUM:                                        /* Theorem 4 */
    request(nd, x, K_INNER, up(t - lo[y]));
    request(nd, y, K_INNER, up(t - lo[x]));
    nd[i].csgop = CSG_UNION;
    return;
  case DT_DIFF:                                       /* Theorem 6 */
    request(nd, x, K_INNER, t);
    request(nd, y, K_OUTER, 0);
    nd[i].csgop = diffop;
    return;
  case DT_PRODUCT:                                    /* Theorem 5 */
    if (t > 0) {
      request(nd, x, K_INNER, up(sqrt(t)));
      request(nd, y, K_INNER, up(sqrt(t)));
      nd[i].csgop = CSG_INTER;
      return;
    }
    break;
  default: {                                          /* Union */
    int okx = hi[x] <= 1 && lo[y] >= 0, oky = hi[y] <= 1 && lo[x] >= 0;
    if (okx) request(nd, x, K_INNER, t);
    if (oky) request(nd, y, K_INNER, t);
    if (okx && oky) { nd[i].csgop = CSG_UNION; return; }
    if (okx || oky) {
      *flags |= BND_FALLBACK;
      request(nd, okx ? y : x, K_SKIP, 0);
      nd[i].emit = E_NONE;
      return;
    }
    break;
  }
  }
  *flags |= BND_FALLBACK;            /* an empty inner bound is always safe */
  nd[i].emit = E_EMPTY;
  request(nd, x, K_SKIP, 0);
  request(nd, y, K_SKIP, 0);
}

static void decide_leaf(const dt_leaf *lf, node *nd) {
  double t = nd->t, x;
  if (nd->kind == K_SUPPORT) x = lf->r;
  else x = dt_displacement(lf->r, t);
  /* A few ulps of the offset and radius, outwards for outer bounds and
   * supports, inwards for inner ones (also keeps an r = 0 plane, where
   * the density is 0.5 on the plane itself, on the safe side). */
  double eps = 4 * DBL_EPSILON * (fabs(lf->d) + lf->r) + DBL_MIN;
  nd->emit = E_PLANE;
  nd->offset = lf->d + x + (nd->kind == K_INNER ? -eps : eps);
}

static csg_tape *bound(const dt_tape *tp, double level, int kind, int *flagp) {
  int n = tp->ncode, flags = 0;
  node *nd = calloc((size_t)n, sizeof *nd);
  double *lo = malloc((size_t)n * 2 * sizeof(double));
  int *left = malloc((size_t)n * 3 * sizeof(int) + (size_t)n);
  csg_builder *b = csg_builder_new();
  csg_tape *out = NULL;
  if (!nd || !lo || !left || !b) goto done;
  double *hi = lo + n;
  int *right = left + n, *stk = left + 2 * n;
  unsigned char *leaf = (unsigned char *)(left + 3 * n);
  /* Tree shape (tape.h) and exact ranges (leaves in [0,1]). */
  for (int i = 0; i < n; i++)
    leaf[i] = tp->code[i].op == DT_LEAF || tp->code[i].op == DT_CONST;
  tape_shape(leaf, n, left, right, stk);
  for (int i = 0; i < n; i++) {
    const dt_instr *in = &tp->code[i];
    if (in->op == DT_LEAF) { lo[i] = 0; hi[i] = 1; }
    else if (in->op == DT_CONST) { lo[i] = hi[i] = in->c; }
    else {
      int x = left[i], y = right[i];
      dt_range_op(in->op, lo[x], hi[x], lo[y], hi[y], &lo[i], &hi[i]);
    }
    if (hi[i] > 1) flags |= BND_RANGE;
  }
  /* Top-down decisions. */
  request(nd, n - 1, kind, level);
  for (int i = n - 1; i >= 0; i--) {
    double t = nd[i].t;
    switch (nd[i].kind) {
    case K_SKIP:
      nd[i].emit = E_NONE;
      if (left[i] >= 0) {
        request(nd, left[i], K_SKIP, 0);
        request(nd, right[i], K_SKIP, 0);
      }
      continue;
    case K_OUTER:
      if (hi[i] <= t || t < lo[i]) nd[i].emit = hi[i] <= t ? E_EMPTY : E_ALL;
      break;
    case K_INNER:
      if (lo[i] >= t || hi[i] < t) nd[i].emit = lo[i] >= t ? E_ALL : E_EMPTY;
      break;
    }
    if (nd[i].emit == E_EMPTY || nd[i].emit == E_ALL) {
      if (left[i] >= 0) {
        request(nd, left[i], K_SKIP, 0);
        request(nd, right[i], K_SKIP, 0);
      }
      continue;
    }
    if (tp->code[i].op == DT_LEAF)
      decide_leaf(&tp->leaves[tp->code[i].arg], &nd[i]);
    else if (tp->code[i].op == DT_CONST)  /* not reached: lo = hi */
      nd[i].emit = E_ALL;
    else
      decide_op(tp, i, left[i], right[i], lo, hi, nd, &flags);
  }
  /* Bottom-up emission. */
  for (int i = 0; i < n; i++) {
    int e = 0;
    switch (nd[i].emit) {
    case E_EMPTY: e = csg_builder_const(b, CSG_EMPTY); break;
    case E_ALL: e = csg_builder_const(b, CSG_ALL); break;
    case E_PLANE:
      e = csg_builder_plane(b, tp->leaves[tp->code[i].arg].n, nd[i].offset);
      break;
    case E_OP: e = csg_builder_op(b, (csg_op)nd[i].csgop); break;
    }
    if (e) goto done;
  }
  int err;
  out = csg_builder_finish(b, &err);
  b = NULL;
done:
  csg_builder_free(b);
  free(nd);
  free(lo);
  free(left);
  if (flagp) *flagp = flags;
  return out;
}

/* Figure 8: OuterBounds. */
csg_tape *bnd_outer(const dt_tape *t, double level, int *flags) {
  return bound(t, level, K_OUTER, flags);
}

/* InnerBounds (Appendix, Theorems 4-6). */
csg_tape *bnd_inner(const dt_tape *t, double level, int *flags) {
  return bound(t, level, K_INNER, flags);
}
