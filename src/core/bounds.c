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
 * inner = Everything if lo >= t, Empty if hi < t.
 *
 * Chamfers (beyond the paper): the outer bound of a product of smoothed
 * halfspaces is the sharp polyhedron, which the rounding pulls in at every
 * edge and corner.  The kernel rho(a) = (1-a)^2 (2+a)/4 is the integral of
 * 3/4 (1 - a^2), a log-concave density, so rho is log-concave (Prekopa);
 * with a_i = dist_i / r_i affine in x, a product of k factors that reaches
 * t has, by Jensen on log rho, mean(a_i) <= a*_k with rho(a*_k) = t^(1/k),
 * whatever the other factors in [0,1] do.  So the halfspace
 * sum_i (n_i.x - d_i) / r_i <= k a*_k holds every point where the product
 * reaches t: a chamfer plane per edge (two faces) and corner (three), cut
 * into the outer bound of every product of leaves (chamfer_* below;
 * bnd_outer_chamfered).  For k = 1 it is the face itself. */
#include "core/bounds.h"
#include "core/tape.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

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

/* a*_k for threshold t: the largest a with rho(a) >= t^(1/k), rounded up
 * (a looser, still valid plane): bisection on [-1, 1], where rho falls
 * from 1 to 0, to a width of 1e-12 (rho' >= 3/4 (a^2 - 1) is bounded, so
 * the rounding of rho in double moves the answer by far less). */
static double chamfer_level(double t, int k) {
  double u = pow(t, 1.0 / k) * (1 - 8 * DBL_EPSILON); /* lower target: safe */
  double a = -1, b = 1;                    /* rho(a) >= u > rho(b) */
  while (b - a > 1e-12) {
    double m = 0.5 * (a + b);
    if (dt_halfspace_a(m) >= u) a = m;
    else b = m;
  }
  return b + 1e-12;
}

#define CHAMFER_LEAVES 16  /* a product of more leaves gets no chamfers */
#define CHAMFER_MAX 48     /* planes per product at most */

typedef struct { double n[3], d; } chamfer_plane;

/* Appends to pl (room for CHAMFER_MAX) the chamfer plane of leaves
 * set[0 .. k) at threshold t, if it is worth one: normals not nearly
 * opposite pairwise, and (k = 3) not nearly coplanar. */
static int chamfer_add(const dt_tape *tp, const int *set, int k, double t,
                       chamfer_plane *pl, int np) {
  if (np >= CHAMFER_MAX) return np;
  const dt_leaf *lf[3];
  for (int a = 0; a < k; a++) lf[a] = &tp->leaves[set[a]];
  for (int a = 0; a < k; a++)
    for (int b = a + 1; b < k; b++)
      if (vec3_dot(lf[a]->n, lf[b]->n) < -0.9) return np;
  if (k == 3) {
    double c[3];
    vec3_cross(lf[0]->n, lf[1]->n, c);
    if (fabs(vec3_dot(c, lf[2]->n)) < 0.1) return np;
  }
  /* sum_i (n_i.x - d_i) / r_i <= k a*: N.x <= D with N = sum n_i / r_i,
   * D = k a* + sum d_i / r_i, then normalised; moved out by a margin far
   * above the rounding of these few sums. */
  double N[3] = {0, 0, 0}, D = k * chamfer_level(t, k), mag = fabs(D);
  for (int a = 0; a < k; a++) {
    for (int j = 0; j < 3; j++) N[j] += lf[a]->n[j] / lf[a]->r;
    D += lf[a]->d / lf[a]->r;
    mag += (fabs(lf[a]->d) + 1) / lf[a]->r;
  }
  double len = sqrt(vec3_dot(N, N));
  if (!(len > 0) || !isfinite(len) || !isfinite(D)) return np;
  for (int j = 0; j < 3; j++) pl[np].n[j] = N[j] / len;
  pl[np].d = (D + 64 * DBL_EPSILON * mag) / len;
  return np + 1;
}

/* The leaves of the product subtree at i (ops all DT_PRODUCT down to
 * leaves with r > 0); -1 if it has any other node or too many leaves. */
static int chamfer_leaves(const dt_tape *tp, const int *left, const int *right,
                          int i, int *out, int n) {
  const dt_instr *in = &tp->code[i];
  if (in->op == DT_LEAF) {
    if (!(tp->leaves[in->arg].r > 0) || n >= CHAMFER_LEAVES) return -1;
    out[n] = in->arg;
    return n + 1;
  }
  if (in->op != DT_PRODUCT) return -1;
  n = chamfer_leaves(tp, left, right, left[i], out, n);
  return n < 0 ? n : chamfer_leaves(tp, left, right, right[i], out, n);
}

/* The corners of the sharp polyhedron of leaves lv[0 .. m) (each plane
 * n.x <= d; every feasible intersection of three) into v; their count. */
#define CHAMFER_VERTS 256
static int chamfer_vertices(const dt_tape *tp, const int *lv, int m,
                            double (*v)[3]) {
  int nv = 0;
  for (int a = 0; a < m; a++)
    for (int b = a + 1; b < m; b++)
      for (int c = b + 1; c < m && nv < CHAMFER_VERTS; c++) {
        const dt_leaf *A = &tp->leaves[lv[a]], *B = &tp->leaves[lv[b]],
                      *C = &tp->leaves[lv[c]];
        double bc[3], ca[3], ab[3];
        vec3_cross(B->n, C->n, bc);
        vec3_cross(C->n, A->n, ca);
        vec3_cross(A->n, B->n, ab);
        double det = vec3_dot(A->n, bc);
        if (fabs(det) < 1e-9) continue;
        double x[3];
        for (int j = 0; j < 3; j++)
          x[j] = (A->d * bc[j] + B->d * ca[j] + C->d * ab[j]) / det;
        int ok = 1;
        for (int k = 0; k < m && ok; k++) {
          const dt_leaf *L = &tp->leaves[lv[k]];
          ok = vec3_dot(L->n, x) <= L->d + 1e-9 * (1 + fabs(L->d));
        }
        if (ok) memcpy(v[nv++], x, sizeof x);
      }
  return nv;
}

/* The chamfer planes of the product at i for threshold t into pl: only
 * those worth a ray's time, that cut the sharp polyhedron by at least
 * CHAMFER_GAIN of its extent across them (each plane costs every ray that
 * reaches the object a dot product and a division; a chamfer of a small
 * radius cuts a sliver: with every plane kept, figure12 (r = 0.07) lost
 * 7% more time to them than they saved).  None for a polyhedron without
 * corners. */
#define CHAMFER_GAIN 0.05
static int chamfer_planes(const dt_tape *tp, const int *left, const int *right,
                          int i, double t, chamfer_plane *pl) {
  int lv[CHAMFER_LEAVES], m = chamfer_leaves(tp, left, right, i, lv, 0), np = 0;
  if (m < 3 || !(t > 0 && t < 1)) return 0;
  double (*v)[3] = malloc(CHAMFER_VERTS * sizeof *v);
  if (!v) return 0;
  int nv = chamfer_vertices(tp, lv, m, v);
  if (nv < 4) { free(v); return 0; }
  chamfer_plane cand[CHAMFER_MAX];
  int nc = 0;
  for (int a = 0; a < m; a++)
    for (int b = a + 1; b < m; b++)
      nc = chamfer_add(tp, (int[]){lv[a], lv[b]}, 2, t, cand, nc);
  for (int a = 0; a < m; a++)
    for (int b = a + 1; b < m; b++)
      for (int c = b + 1; c < m; c++)
        nc = chamfer_add(tp, (int[]){lv[a], lv[b], lv[c]}, 3, t, cand, nc);
  for (int k = 0; k < nc; k++) {
    double hi = -INFINITY, lo = INFINITY;
    for (int j = 0; j < nv; j++) {
      double h = vec3_dot(cand[k].n, v[j]);
      hi = fmax(hi, h);
      lo = fmin(lo, h);
    }
    if (hi - cand[k].d >= CHAMFER_GAIN * (hi - lo)) pl[np++] = cand[k];
  }
  free(v);
  return np;
}

static csg_tape *bound(const dt_tape *tp, double level, int kind, int chamfer,
                       int *flagp) {
  int n = tp->ncode, flags = 0;
  node *nd = calloc((size_t)n, sizeof *nd);
  double *lo = malloc((size_t)n * 2 * sizeof(double));
  int *left = malloc((size_t)n * 4 * sizeof(int) + (size_t)n);
  chamfer_plane *cpl = malloc(CHAMFER_MAX * sizeof *cpl);
  csg_builder *b = csg_builder_new();
  csg_tape *out = NULL;
  if (!nd || !lo || !left || !cpl || !b) goto done;
  double *hi = lo + n;
  int *right = left + n, *stk = left + 2 * n, *parent = left + 3 * n;
  unsigned char *leaf = (unsigned char *)(left + 4 * n);
  /* Tree shape (tape.h) and exact ranges (leaves in [0,1]). */
  for (int i = 0; i < n; i++)
    leaf[i] = tp->code[i].op == DT_LEAF || tp->code[i].op == DT_CONST;
  tape_shape(leaf, n, left, right, stk);
  for (int i = 0; i < n; i++) parent[i] = -1;
  for (int i = 0; i < n; i++)
    if (left[i] >= 0) parent[left[i]] = parent[right[i]] = i;
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
    /* the chamfers of an outer-bounded product of leaves, once, at its
     * top (its parent is not such a product too) */
    if (chamfer && nd[i].kind == K_OUTER && nd[i].emit == E_OP &&
        tp->code[i].op == DT_PRODUCT && nd[i].csgop == CSG_INTER &&
        !(parent[i] >= 0 && tp->code[parent[i]].op == DT_PRODUCT &&
          nd[parent[i]].kind == K_OUTER && nd[parent[i]].emit == E_OP &&
          nd[parent[i]].csgop == CSG_INTER)) {
      int np = chamfer_planes(tp, left, right, i, nd[i].t, cpl);
      for (int k = 0; k < np && !e; k++) {
        e = csg_builder_plane(b, cpl[k].n, cpl[k].d);
        if (!e) e = csg_builder_op(b, CSG_INTER);
      }
      if (e) goto done;
    }
  }
  int err;
  out = csg_builder_finish(b, &err);
  b = NULL;
done:
  csg_builder_free(b);
  free(nd);
  free(lo);
  free(left);
  free(cpl);
  if (flagp) *flagp = flags;
  return out;
}

/* Figure 8: OuterBounds. */
csg_tape *bnd_outer(const dt_tape *t, double level, int *flags) {
  return bound(t, level, K_OUTER, 0, flags);
}

/* Figure 8 with the chamfers. */
csg_tape *bnd_outer_chamfered(const dt_tape *t, double level, int *flags) {
  return bound(t, level, K_OUTER, 1, flags);
}

/* InnerBounds (Appendix, Theorems 4-6). */
csg_tape *bnd_inner(const dt_tape *t, double level, int *flags) {
  return bound(t, level, K_INNER, 0, flags);
}
