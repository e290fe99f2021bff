/* density.c: building and evaluating density tapes (paper Section 2). */
#include "core/density.h"
#include "core/tape.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

struct dt_builder {
  dt_instr *code;
  int ncode, capcode;
  dt_leaf *leaves;
  int nleaves, capleaves;
  int depth;      /* operands currently on the (symbolic) stack */
  int err;        /* first error seen; later calls are ignored */
};

dt_builder *dt_builder_new(void) {
  return calloc(1, sizeof(dt_builder));
}

void dt_builder_free(dt_builder *b) {
  if (!b) return;
  free(b->code);
  free(b->leaves);
  free(b);
}

void dt_tape_free(dt_tape *t) {
  if (!t) return;
  free(t->code);
  free(t->leaves);
  if (t->prog) {
    free(t->prog->pcode);
    free(t->prog->groups);
    free(t->prog->gleaf);
    free(t->prog->gsnip);
    free(t->prog->gcode);
    free(t->prog);
  }
  free(t);
}

const char *dt_strerror(int err) {
  switch (err) {
  case DT_OK: return "no error";
  case DT_EPLANE: return "plane normal must be finite and non-zero";
  case DT_ERADIUS: return "radius must be finite and >= 0";
  case DT_EOP: return "density operation needs two operands";
  case DT_EUNBALANCED: return "density tape must hold exactly one tree";
  case DT_ENOMEM: return "out of memory";
  }
  return "unknown density error";
}

static int push_instr(dt_builder *b, dt_instr in) {
  if (b->ncode == b->capcode) {
    int cap = b->capcode ? 2 * b->capcode : 16;
    dt_instr *p = realloc(b->code, (size_t)cap * sizeof *p);
    if (!p) return b->err = DT_ENOMEM;
    b->code = p;
    b->capcode = cap;
  }
  b->code[b->ncode++] = in;
  return DT_OK;
}

int dt_builder_leaf(dt_builder *b, const double n[3], double d, double r) {
  if (b->err) return b->err;
  double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!isfinite(len) || len == 0 || !isfinite(d)) return DT_EPLANE;
  if (!isfinite(r) || r < 0) return DT_ERADIUS;
  if (b->nleaves == b->capleaves) {
    int cap = b->capleaves ? 2 * b->capleaves : 16;
    dt_leaf *p = realloc(b->leaves, (size_t)cap * sizeof *p);
    if (!p) return b->err = DT_ENOMEM;
    b->leaves = p;
    b->capleaves = cap;
  }
  dt_leaf *lf = &b->leaves[b->nleaves];
  for (int i = 0; i < 3; i++) lf->n[i] = n[i] / len;
  lf->d = d / len;
  lf->r = r;
  lf->inv_r = r > 0 ? 1 / r : 0;
  dt_instr in = {DT_LEAF, b->nleaves, 0};
  if (push_instr(b, in)) return b->err;
  b->nleaves++;
  b->depth++;
  return DT_OK;
}

int dt_builder_op(dt_builder *b, dt_op op) {
  if (b->err) return b->err;
  if (op != DT_SUM && op != DT_PRODUCT && op != DT_DIFF && op != DT_UNION)
    return DT_EOP;
  if (b->depth < 2) return DT_EOP;
  dt_instr in = {(int)op, 0, 0};
  if (push_instr(b, in)) return b->err;
  b->depth--;
  return DT_OK;
}

/* Operands of a density tape, for tape_reorder. */
static int operand(int op) { return op == DT_LEAF || op == DT_CONST; }

/* Sethi-Ullman reordering (tape.h), which finds op as the first member. */
_Static_assert(offsetof(dt_instr, op) == 0, "tape_reorder reads op first");
static int reorder(const dt_instr *in, int n, dt_instr *out, int *depth) {
  return tape_reorder(in, out, sizeof *in, n, operand, DT_DIFF, DT_RDIFF,
                      depth) == TAPE_OK ? DT_OK : DT_ENOMEM;
}

static void tape_range(dt_tape *t) {
  double lo[DT_STACK_MAX], hi[DT_STACK_MAX];
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF) { lo[sp] = 0; hi[sp] = 1; sp++; continue; }
    if (in->op == DT_CONST) { lo[sp] = hi[sp] = in->c; sp++; continue; }
    sp--;
    dt_range_op(in->op, lo[sp - 1], hi[sp - 1], lo[sp], hi[sp],
                &lo[sp - 1], &hi[sp - 1]);
  }
  t->lo = lo[0];
  t->hi = hi[0];
}

static int prune_program(dt_tape *t);

dt_tape *dt_builder_finish(dt_builder *b, int *err) {
  int e = b->err;
  if (!e && b->depth != 1) e = DT_EUNBALANCED;
  dt_tape *t = NULL;
  if (!e) {
    t = calloc(1, sizeof *t);
    dt_instr *code = malloc((size_t)b->ncode * sizeof *code);
    if (!t || !code) {
      free(code);
      e = DT_ENOMEM;
    } else if ((e = reorder(b->code, b->ncode, code, &t->depth)) != DT_OK) {
      free(code);
    } else {
      t->code = code;
      t->ncode = b->ncode;
      t->leaves = b->leaves;  /* ownership moves to the tape */
      t->nleaves = b->nleaves;
      b->leaves = NULL;
      for (int i = 0; i < t->nleaves; i++)
        if (t->leaves[i].r > t->rmax) t->rmax = t->leaves[i].r;
      if (t->depth > DT_STACK_MAX) e = DT_EOP; /* needs > 2^63 leaves */
      else {
        tape_range(t);
        e = prune_program(t);
      }
    }
    if (e) { dt_tape_free(t); t = NULL; }
  }
  if (err) *err = e;
  dt_builder_free(b);
  return t;
}

double dt_max(const dt_tape *t) {
  return t->hi;
}

/* dt_envelope: a stack of subtrees, each with its range (leaves in
 * [0, 1]), whether it has an envelope, and that envelope's leaves at
 * env[start .. start + n): a later subtree's leaves lie after an earlier
 * one's, so combining the top two moves the second's next to the first. */
int dt_envelope(const dt_tape *t, int *env) {
  struct { double lo, hi; int ok, start, n; } st[DT_STACK_MAX];
  int sp = 0, top = 0;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF || in->op == DT_CONST) {
      if (sp == DT_STACK_MAX) return 0;
      int leaf = in->op == DT_LEAF;
      st[sp].lo = leaf ? 0 : in->c;
      st[sp].hi = leaf ? 1 : in->c;
      st[sp].ok = leaf;
      st[sp].start = top;
      st[sp].n = leaf;
      if (leaf) env[top++] = in->arg;
      sp++;
      continue;
    }
    if (sp < 2) return 0;
    sp--;
    int xi = sp - 1, ok = 0, keep_x = 0, keep_y = 0;
    double lo, hi;
    double xl = st[xi].lo, xh = st[xi].hi, yl = st[sp].lo, yh = st[sp].hi;
    dt_range_op(in->op, xl, xh, yl, yh, &lo, &hi);
    switch (in->op) {
    case DT_PRODUCT:
      if (xl >= 0 && yl >= 0) {
        keep_x = st[xi].ok && (st[sp].ok || yh <= 1);
        keep_y = st[sp].ok && (st[xi].ok || xh <= 1);
        ok = keep_x || keep_y;
      }
      break;
    case DT_DIFF:   /* x - y <= x when y >= 0 */
      ok = keep_x = st[xi].ok && yl >= 0;
      break;
    case DT_RDIFF:  /* y - x <= y when x >= 0 */
      ok = keep_y = st[sp].ok && xl >= 0;
      break;
    default:        /* Sum, Union: no log-concave envelope */
      break;
    }
    int start = st[xi].start, n = 0;
    if (keep_x) n = st[xi].n;
    if (keep_y) {
      memmove(env + start + n, env + st[sp].start,
              sizeof *env * (size_t)st[sp].n);
      n += st[sp].n;
    }
    st[xi].lo = lo;
    st[xi].hi = hi;
    st[xi].ok = ok;
    st[xi].start = start;
    st[xi].n = ok ? n : 0;
    top = start + st[xi].n;
  }
  return sp == 1 && st[0].ok ? st[0].n : 0;
}

/* -(log rho)'(a) = 3 (1 + a) / ((1 - a) (2 + a)) inside the filter,
 * rising from 0 at a = -1 to infinity at a = 1 (rho log-concave). */
static double env_slope(double a) {
  if (a <= -1) return 0;
  if (a >= 1) return INFINITY;
  return 3 * (1 + a) / ((1 - a) * (2 + a));
}

int dt_envelope_clear(const dt_tape *t, const int *env, int n,
                      const double o[3], const double d[3]) {
  const double u = DBL_EPSILON;   /* twice the unit roundoff: generous */
  double e0 = 1, slope = 0, mag = 0;
  for (int k = 0; k < n; k++) {
    const dt_leaf *lf = &t->leaves[env[k]];
    double dist = dt_leaf_dist(lf, o), nd = vec3_dot(lf->n, d);
    /* |error| of each: 3 products and 2 sums (one more for -d) */
    double edist = 4 * u * (fabs(lf->n[0] * o[0]) + fabs(lf->n[1] * o[1]) +
                            fabs(lf->n[2] * o[2]) + fabs(lf->d)) + DBL_MIN;
    double end = 4 * u * (fabs(lf->n[0] * d[0]) + fabs(lf->n[1] * d[1]) +
                          fabs(lf->n[2] * d[2])) + DBL_MIN;
    if (!(isfinite(dist) && isfinite(nd))) return 0;
    if (lf->r <= 0) {                  /* a sharp step: 1, 0.5 or 0 */
      if (dist > edist && nd >= end) return 1;   /* 0 all along the ray */
      if (dist < -edist) continue;     /* 1 here: a tangent of slope 0 */
      return 0;
    }
    double a = dist * lf->inv_r, b = nd * lf->inv_r;
    double ea = edist * lf->inv_r * (1 + 2 * u) + 2 * u * fabs(a);
    double eb = end * lf->inv_r * (1 + 2 * u) + 2 * u * fabs(b);
    double alo = a - ea, ahi = a + ea, blo = b - eb;
    if (alo >= 1 && blo >= 0) return 1;  /* 0 here and from here on */
    if (ahi >= 1) return 0;              /* near 0: log E has no tangent */
    /* rho falls as a rises: its value at alo bounds E's factor above */
    e0 *= dt_halfspace_a(alo) * (1 + 8 * u);
    /* the factor's part of -(log E)' along the ray, c b with c in
       [env_slope(alo), env_slope(ahi)] and b in [blo, bhi]: its least */
    double clo = env_slope(alo) * (1 - 8 * u), chi = env_slope(ahi) * (1 + 8 * u);
    double term = blo >= 0 ? clo * blo : chi * blo;
    if (!isfinite(term)) return 0;
    slope += term;
    mag += fabs(term);
  }
  /* E(o) < 0.5 and -(log E)' >= 0 at s = 0, after the sum's rounding */
  return e0 * (1 + 2 * n * u) < 0.5 && slope - 2 * (n + 1) * u * mag >= 0;
}

/* Apply a binary op to stack values x (below) and y (top). */
static double apply(int op, double x, double y) {
  switch (op) {
  case DT_SUM: return x + y;
  case DT_PRODUCT: return x * y;
  case DT_DIFF: return x - y;
  case DT_RDIFF: return y - x;
  default: return x + y - x * y;
  }
}

/* Figure 4: Density. */
double dt_density(const dt_tape *t, const double p[3]) {
  double st[DT_STACK_MAX];
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF) {
      const dt_leaf *lf = &t->leaves[in->arg];
      st[sp++] = dt_halfspace(dt_leaf_dist(lf, p), lf->r);
    } else if (in->op == DT_CONST) {
      st[sp++] = in->c;
    } else {
      sp--;
      st[sp - 1] = apply(in->op, st[sp - 1], st[sp]);
    }
  }
  return st[0];
}

/* Section 2.4: gradient by the usual differentiation rules. */
double dt_density_grad(const dt_tape *t, const double p[3], double grad[3]) {
  /* z[k]: the gradient of stack entry k is zero (a leaf outside its
   * filter, a constant, or ops on such), so the three components need no
   * arithmetic: at a point on a surface most leaves are constant. */
  double v[DT_STACK_MAX], g[DT_STACK_MAX][3];
  unsigned char z[DT_STACK_MAX];
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF) {
      const dt_leaf *lf = &t->leaves[in->arg];
      double s = dt_leaf_dist(lf, p), dda = 0;
      if (lf->r > 0) v[sp] = dt_halfspace_da(s * lf->inv_r, &dda);
      else v[sp] = dt_halfspace(s, 0);
      z[sp] = dda == 0;
      if (!z[sp])
        for (int j = 0; j < 3; j++) g[sp][j] = dda * lf->inv_r * lf->n[j];
      sp++;
    } else if (in->op == DT_CONST) {
      v[sp] = in->c;
      z[sp] = 1;
      sp++;
    } else {
      /* apply_d with the op decided once for the three components */
      sp--;
      double x = v[sp - 1], y = v[sp], *gx = g[sp - 1];
      const double *gy = g[sp];
      int zx = z[sp - 1], zy = z[sp];
      if (zx && zy) {
        v[sp - 1] = apply(in->op, x, y);
        continue;
      }
      if (zx) gx[0] = gx[1] = gx[2] = 0;
      const double zero[3] = {0, 0, 0};
      if (zy) gy = zero;
      z[sp - 1] = 0;
      switch (in->op) {
      case DT_SUM:
        for (int j = 0; j < 3; j++) gx[j] = gx[j] + gy[j];
        v[sp - 1] = x + y;
        break;
      case DT_PRODUCT:
        for (int j = 0; j < 3; j++) gx[j] = gx[j] * y + x * gy[j];
        v[sp - 1] = x * y;
        break;
      case DT_DIFF:
        for (int j = 0; j < 3; j++) gx[j] = gx[j] - gy[j];
        v[sp - 1] = x - y;
        break;
      case DT_RDIFF:
        for (int j = 0; j < 3; j++) gx[j] = gy[j] - gx[j];
        v[sp - 1] = y - x;
        break;
      default:
        for (int j = 0; j < 3; j++) gx[j] = gx[j] * (1 - y) + gy[j] * (1 - x);
        v[sp - 1] = x + y - x * y;
        break;
      }
    }
  }
  if (z[0]) grad[0] = grad[1] = grad[2] = 0;
  else memcpy(grad, g[0], sizeof g[0]);
  return v[0];
}

/* Section 2.4 along a ray: rho(o + s d) and d rho/ds by the chain rule,
 * d alpha/ds = (n.d)/r, so any length of d is handled exactly. The leaves'
 * distances are tabulated (dt_ray_leaves) and dt_density_rl, the search's
 * own evaluator, does the rest. */
double dt_density_ray(const dt_tape *t, const double o[3], const double d[3],
                      double s, double *drho_ds) {
  dt_ray_leaf local[64], *rl = local;
  if (t->nleaves > 64) {
    rl = malloc(sizeof *rl * (size_t)t->nleaves);
    if (!rl) return NAN;
  }
  dt_ray_leaves(t, o, d, rl);
  double v = dt_density_rl(t, rl, s, drho_ds);
  if (rl != local) free(rl);
  return v;
}

void dt_ray_leaves(const dt_tape *t, const double o[3], const double d[3],
                   dt_ray_leaf *rl) {
  if (t->live) {
    for (int k = 0; k < t->nlive; k++) {
      int i = t->live[k];
      const dt_leaf *lf = &t->leaves[i];
      rl[i].base = dt_leaf_dist(lf, o);
      rl[i].nd = vec3_dot(lf->n, d);
    }
    return;
  }
  for (int i = 0; i < t->nleaves; i++) {
    const dt_leaf *lf = &t->leaves[i];
    rl[i].base = dt_leaf_dist(lf, o);
    rl[i].nd = vec3_dot(lf->n, d);
  }
}

/* dt_density_ray with the leaves' distances from the ray's table: the same
 * operations in the same order, so the same result to the last bit
 * (dt_density_rl_in, density.h). */
double dt_density_rl(const dt_tape *t, const dt_ray_leaf *rl, double s,
                     double *drho_ds) {
  double dd, v = dt_density_rl_in(t, rl, s, &dd);
  if (drho_ds) *drho_ds = dd;
  return v;
}

/* eq. (5): Displacement.  The paper's trigonometric root
 * alpha = 2 cos((acos(2 rho - 1) + 4 pi)/3) loses all relative accuracy
 * near rho = 0 and 1 (acos is infinitely steep at -1 and 1) and rounds the
 * sign away near 0.5, so we solve the cubic in better-conditioned
 * variables instead.  By the symmetry rho(-a) = 1 - rho(a) only
 * tau = min(level, 1 - level) (exact in binary) is needed:
 *   tau >= 1/4: a^3 - 3a + c = 0, c = 2 - 4 tau (exact), a in [0, 0.35],
 *               Newton from a = c/3 (the series a = c/3 + c^3/81 + ...);
 *   tau <  1/4: u = 1 - a solves u^2 (3 - u) = 4 tau, u in (0, 0.66],
 *               Newton from the series u = s (1 + s/6), s = sqrt(4 tau/3),
 *               which is already exact to rounding for tau < 1e-200. */
double dt_displacement(double r, double level) {
  if (!(level > 0)) return r;
  if (level >= 1) return -r;
  double tau = level <= 0.5 ? level : 1 - level;
  double a;
  if (tau >= 0.25) {
    double c = 2 - 4 * tau;
    a = c / 3;
    for (int i = 0; i < 6; i++) {
      double h = (a * a - 3) * a + c, dh = 3 * (a * a - 1);
      double na = a - h / dh;
      if (na == a) break;
      a = na;
    }
  } else {
    double s = sqrt(tau) * 1.1547005383792515; /* sqrt(4/3) */
    double u = s * (1 + s / 6);
    if (tau > 1e-200) {
      for (int i = 0; i < 8; i++) {
        double g = u * u * (3 - u) - 4 * tau, dg = 3 * u * (2 - u);
        double nu = u - g / dg;
        if (nu == u) break;
        u = nu;
      }
    }
    a = 1 - u;
  }
  return level <= 0.5 ? a * r : -a * r;
}

/* A leaf's value if it is constant over the ray segment, else -1. */
static inline double leaf_const(const dt_leaf *lf, double base, double nd,
                         double s0, double s1) {
  double a = nd == 0 ? base : base + s0 * nd;
  double b = nd == 0 ? base : base + s1 * nd;
  double lo = a < b ? a : b, hi = a < b ? b : a;
  if (lf->r > 0) {
    if (lo >= lf->r) return 0;
    if (hi <= -lf->r) return 1;
  } else {
    if (lo > 0) return 0;
    if (hi < 0) return 1;
  }
  return -1;
}

/* The fold stack of the pruning: per operand, a constant (isc, c) or live
 * code starting at buf[start]. */
typedef struct {
  double cst[DT_STACK_MAX];
  int start[DT_STACK_MAX];
  unsigned char isc[DT_STACK_MAX];
  int sp, n;
} fold_state;

/* Push a leaf or constant that is the constant c (isc) or live. */
static inline void fold_leaf(fold_state *f, const dt_instr *in, int isc,
                             double c, dt_instr *buf) {
  int sp = f->sp++;
  f->start[sp] = f->n;
  if (isc) {
    f->isc[sp] = 1;
    f->cst[sp] = c;
  } else {
    f->isc[sp] = 0;
    buf[f->n++] = *in;
  }
}

/* Combine the top two operands by the binary op in. */
static inline void fold_op(fold_state *f, const dt_instr *in, dt_instr *buf) {
  int sp = --f->sp, op = in->op;
  int xc = f->isc[sp - 1], yc = f->isc[sp];
  if (xc && yc) {
    f->cst[sp - 1] = apply(op, f->cst[sp - 1], f->cst[sp]);
    return;
  }
  if (!xc && !yc) {
    buf[f->n++] = *in;
    return;
  }
  /* Exactly one constant c; the live operand's code is buf[start..n). */
  double c = xc ? f->cst[sp - 1] : f->cst[sp];
  int st = xc ? f->start[sp] : f->start[sp - 1];
  int keep = 0, fold = 0;
  double fv = 0;
  switch (op) {
  case DT_SUM: keep = c == 0; break;
  case DT_PRODUCT:
    if (c == 0) { fold = 1; fv = 0; } else keep = c == 1;
    break;
  case DT_UNION:
    if (c == 1) { fold = 1; fv = 1; } else keep = c == 0;
    break;
  case DT_DIFF: keep = yc && c == 0; break;   /* x - 0 */
  case DT_RDIFF: keep = xc && c == 0; break;  /* y - 0 */
  }
  f->start[sp - 1] = st;
  if (fold) {
    f->n = st;
    f->isc[sp - 1] = 1;
    f->cst[sp - 1] = fv;
  } else if (keep) {
    f->isc[sp - 1] = 0;
  } else {
    /* Emit the constant after the live code: the operands are now in
     * swapped order, so differences flip. */
    dt_instr ci = {DT_CONST, 0, c};
    buf[f->n++] = ci;
    dt_instr oi = *in;
    if (xc) {
      if (op == DT_DIFF) oi.op = DT_RDIFF;
      else if (op == DT_RDIFF) oi.op = DT_DIFF;
    }
    buf[f->n++] = oi;
    f->isc[sp - 1] = 0;
  }
}

/* Per-segment pruning (Section 3.4.1: a leaf contributes nothing to L and
 * G where the segment misses its filter).  Constants are kept lazily on
 * the fold stack and only emitted when combined with live code.  A
 * finished tape is pruned through its prune program (density.h), with the
 * same result. */
static inline __attribute__((always_inline)) int
prune(const dt_tape *t, const double o[3], const double d[3],
                 const dt_ray_leaf *rl, const signed char *cls, int groups,
                 double s0, double s1, dt_instr *buf, dt_tape *view) {
  fold_state f;
  f.sp = f.n = 0;
  const dt_prune_prog *pp = t->prog;
  const dt_instr *code = pp ? pp->pcode : t->code;
  int nc = pp ? pp->npcode : t->ncode;
  for (int i = 0; i < nc; i++) {
    const dt_instr *in = &code[i];
    int op = in->op;
    if (op == DT_CONST) {
      fold_leaf(&f, in, 1, in->c, buf);
    } else if (op == DT_LEAF || op == DT_GROUP) {
      const dt_group *g = op == DT_GROUP ? &pp->groups[in->arg] : NULL;
      int nl = g ? g->n : 1;
      unsigned live = 0;
      /* a group of a dt_prune_class program: only the leaves of its mask
         may be live (the others are 1) */
      unsigned mask = g && in->c > 0 ? (unsigned)in->c : ~0u;
      double c = 1;
      for (int k = 0; k < nl; k++) {
        if (!((mask >> k) & 1)) continue;
        int li = g ? pp->gleaf[g->leaf0 + k] : in->arg;
        const dt_leaf *lf = &t->leaves[li];
        double lc;
        if (cls) {
          lc = cls[li];
        } else {
          double base, nd;
          if (rl) {
            base = rl[li].base;
            nd = rl[li].nd;
          } else {
            nd = vec3_dot(lf->n, d);
            base = dt_leaf_dist(lf, o);
          }
          lc = leaf_const(lf, base, nd, s0, s1);
        }
        if (lc == 0) { c = 0; break; }   /* a product with a 0 is 0 */
        if (lc < 0) live |= 1u << k;
      }
      if (!g) {
        fold_leaf(&f, in, !live || c == 0, c, buf);
      } else if (c == 0 || !live) {
        fold_leaf(&f, in, 1, c, buf);
      } else if (groups) {   /* the group stays, masked to its live set */
        dt_instr gi = {DT_GROUP, in->arg, (double)live};
        fold_leaf(&f, &gi, 0, 0, buf);
      } else {
        int a = pp->gsnip[(unsigned)g->snip0 + live], b = pp->gsnip[(unsigned)g->snip0 + live + 1];
        f.start[f.sp] = f.n;
        f.isc[f.sp++] = 0;
        memcpy(buf + f.n, pp->gcode + a, (size_t)(b - a) * sizeof *buf);
        f.n += b - a;
      }
    } else {
      fold_op(&f, in, buf);
    }
  }
  int n = f.n;
  if (f.isc[0]) {
    dt_instr ci = {DT_CONST, 0, f.cst[0]};
    n = 0;
    buf[n++] = ci;
  }
  *view = *t;
  view->code = buf;
  view->ncode = n;
  view->prog = NULL;
  return n;
}

/* The prune program of a finished tape (density.h). */
static int prune_program(dt_tape *t) {
  int n = t->ncode;
  int *mem = malloc((size_t)n * 5 * sizeof(int) + 1);
  if (!mem) return DT_ENOMEM;
  int *start = mem, *nl = mem + n, *pure = mem + 2 * n, *parent = mem + 3 * n;
  int *groot = mem + 4 * n;   /* at a group's first instruction: its root */
  int stk[DT_STACK_MAX + 1], sp = 0;
  for (int i = 0; i < n; i++) {
    int op = t->code[i].op;
    parent[i] = groot[i] = -1;
    start[i] = i;
    if (op == DT_LEAF || op == DT_CONST) {
      nl[i] = op == DT_LEAF;
      pure[i] = op == DT_LEAF;
    } else {
      int y = stk[--sp], x = stk[--sp];
      parent[x] = parent[y] = i;
      start[i] = start[x];
      nl[i] = nl[x] + nl[y];
      pure[i] = op == DT_PRODUCT && pure[x] && pure[y];
    }
    stk[sp++] = i;
  }
#define CAND(i) (pure[i] && nl[i] >= 2 && nl[i] <= DT_GROUP_MAX)
  int ng = 0, nleaf = 0;
  size_t nsnip = 0, ncodes = 0;
  for (int i = 0; i < n; i++)
    if (CAND(i) && (parent[i] < 0 || !CAND(parent[i]))) {
      groot[start[i]] = i;
      ng++;
      nleaf += nl[i];
      nsnip += ((size_t)1 << nl[i]) + 1;
      ncodes += ((size_t)1 << nl[i]) * (size_t)(i - start[i] + 1);
    }
#undef CAND
  if (!ng) {
    free(mem);
    return DT_OK;
  }
  dt_prune_prog *pp = t->prog = calloc(1, sizeof *pp);
  if (!pp) {
    free(mem);
    return DT_ENOMEM;
  }
  pp->pcode = malloc((size_t)n * sizeof *pp->pcode);
  pp->groups = malloc((size_t)ng * sizeof *pp->groups);
  pp->gleaf = malloc((size_t)nleaf * sizeof *pp->gleaf);
  pp->gsnip = malloc(nsnip * sizeof *pp->gsnip);
  pp->gcode = malloc(ncodes * sizeof *pp->gcode);
  if (!pp->pcode || !pp->groups || !pp->gleaf || !pp->gsnip || !pp->gcode) {
    free(mem);
    return DT_ENOMEM;   /* the caller frees the tape and its parts */
  }
  int np = 0, g = 0, lf = 0, sn = 0, nc = 0;
  for (int i = 0; i < n;) {
    int e = groot[i];
    if (e < 0) {
      pp->pcode[np++] = t->code[i++];
      continue;
    }
    dt_group *gr = &pp->groups[g];
    gr->n = nl[e];
    gr->leaf0 = lf;
    gr->snip0 = sn;
    for (int k = i; k <= e; k++)
      if (t->code[k].op == DT_LEAF) pp->gleaf[lf++] = t->code[k].arg;
    /* The code each set of live leaves prunes to; the others are 1. */
    for (unsigned m = 0; m < 1u << gr->n; m++) {
      pp->gsnip[sn++] = nc;
      if (!m) continue;   /* all 1: the constant 1, no code */
      fold_state f;
      f.sp = f.n = 0;
      int k = 0;
      for (int j = i; j <= e; j++) {
        const dt_instr *in = &t->code[j];
        if (in->op == DT_LEAF) {
          fold_leaf(&f, in, !((m >> k) & 1), 1, pp->gcode + nc);
          k++;
        } else {
          fold_op(&f, in, pp->gcode + nc);
        }
      }
      nc += f.n;
    }
    pp->gsnip[sn++] = nc;
    pp->pcode[np++] = (dt_instr){DT_GROUP, g, 0};
    g++;
    i = e + 1;
  }
  pp->npcode = np;
  pp->ngroups = ng;
  free(mem);
  return DT_OK;
}

int dt_prune_ray(const dt_tape *t, const double o[3], const double d[3],
                 double s0, double s1, dt_instr *buf, dt_tape *view) {
  int n = prune(t, o, d, NULL, NULL, 0, s0, s1, buf, view);
  tape_range(view);
  return n;
}

int dt_prune_rl(const dt_tape *t, const dt_ray_leaf *rl, double s0, double s1,
                dt_instr *buf, dt_tape *view) {
  return prune(t, NULL, NULL, rl, NULL, 0, s0, s1, buf, view);
}

int dt_prune_rl_same(const dt_tape *t, const dt_ray_leaf *rl, double s0,
                     double s1) {
  if (t->prog) {   /* the leaves it may reach: its live list, or all */
    int n = t->live ? t->nlive : t->nleaves;
    for (int k = 0; k < n; k++) {
      int i = t->live ? t->live[k] : k;
      if (leaf_const(&t->leaves[i], rl[i].base, rl[i].nd, s0, s1) >= 0)
        return 0;
    }
    return 1;
  }
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF &&
        leaf_const(&t->leaves[in->arg], rl[in->arg].base, rl[in->arg].nd, s0,
                   s1) >= 0)
      return 0;
  }
  return 1;
}

int dt_prune_class(const dt_tape *t, const signed char *cls, dt_instr *buf,
                   dt_leaf *leaves, dt_instr *pbuf, dt_prune_prog *prog,
                   int *live, dt_tape *view) {
  int n = prune(t, NULL, NULL, NULL, cls, 0, 0, 0, buf, view);
  view->live = NULL;
  view->nlive = 0;
  if (t->prog) {   /* the parent's groups are kept: so are its leaves */
    dt_tape pv;
    *prog = *t->prog;
    prog->pcode = pbuf;
    prog->npcode = prune(t, NULL, NULL, NULL, cls, 1, 0, 0, pbuf, &pv);
    view->prog = prog;
    /* the leaves of the live code; in t's order (a view of a view has
       only the live ones among its parent's) */
    int m = 0;
    if (t->live) {
      for (int i = 0; i < t->nlive; i++)
        if (cls[t->live[i]] < 0) live[m++] = t->live[i];
    } else {
      for (int i = 0; i < t->nleaves; i++)
        if (cls[i] < 0) live[m++] = i;
    }
    view->live = live;
    view->nlive = m;
    return n;
  }
  int nl = 0;
  for (int i = 0; i < n; i++)
    if (buf[i].op == DT_LEAF) {
      leaves[nl] = t->leaves[buf[i].arg];
      buf[i].arg = nl++;
    }
  view->leaves = leaves;
  view->nleaves = nl;
  return n;
}

void dt_range_box_fix(const dt_tape *t, const double lo[3], const double hi[3],
                      int fix, double v, double *dl, double *dh) {
  double sl[DT_STACK_MAX], sh[DT_STACK_MAX];
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF && in->arg == fix) {
      sl[sp] = sh[sp] = v;
      sp++;
    } else if (in->op == DT_LEAF) {
      const dt_leaf *lf = &t->leaves[in->arg];
      double rl, rh;
      vec3_plane_range(lf->n, lf->d, lo, hi, &rl, &rh);
      /* the kernel falls as s grows */
      sl[sp] = dt_halfspace(rh, lf->r);
      sh[sp] = dt_halfspace(rl, lf->r);
      if (lf->r <= 0) { /* a step: 0.5 on the plane itself */
        if (rh >= 0) sl[sp] = 0;
        if (rl <= 0) sh[sp] = 1;
      }
      sp++;
    } else if (in->op == DT_CONST) {
      sl[sp] = sh[sp] = in->c;
      sp++;
    } else {
      sp--;
      double l, h;
      dt_range_op(in->op, sl[sp - 1], sh[sp - 1], sl[sp], sh[sp], &l, &h);
      sl[sp - 1] = l;
      sh[sp - 1] = h;
    }
  }
  *dl = sl[0];
  *dh = sh[0];
}

void dt_range_box(const dt_tape *t, const double lo[3], const double hi[3],
                  double *dl, double *dh) {
  double l, h;
  dt_range_box_fix(t, lo, hi, -1, 0, &l, &h);
  double m = 1e-12 * (fabs(l) + fabs(h) + 1);
  *dl = l - m;
  *dh = h + m;
}
