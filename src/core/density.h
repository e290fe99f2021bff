/* density.h: density trees as flat tapes (Lobb, "Quasi-Convolutional
 * Smoothing of Polyhedra", Section 2).
 *
 * A density tree is built in postfix order with a dt_builder (leaves are
 * smoothed halfspaces, each with its own plane and radius; ops are Sum,
 * Product, Difference and the density Union a+b-ab) and finished into a
 * dt_tape: a flat array of instructions evaluated with a small fixed
 * stack, no pointer chasing and no allocation per evaluation.  Finishing
 * reorders the tape (Sethi-Ullman, tape.h) so any tree needs at most
 * DT_STACK_MAX stack slots.  The kernel of eq. (2) and the interval rules
 * of the ops (interval.h) are defined here once, static inline, for every
 * evaluator of the core.
 *
 * Memory: dt_builder_new returns a builder owned by the caller; it is
 * freed by dt_builder_finish (which always consumes it) or by
 * dt_builder_free.  dt_builder_finish returns a tape owned by the caller,
 * freed with dt_tape_free.  A tape is immutable after finishing, so any
 * number of threads may evaluate it at once.  A "view" (see dt_prune_ray)
 * borrows the leaves of its parent tape and the code buffer of its caller
 * and must never be passed to dt_tape_free. */
#ifndef QCS_DENSITY_H
#define QCS_DENSITY_H

#include <stddef.h>

#include "core/interval.h"
#include "core/vec.h"

#define DT_STACK_MAX 64

typedef enum {
  DT_LEAF,      /* push the smoothed halfspace leaves[arg] */
  DT_CONST,     /* push the constant c (only in pruned views) */
  DT_SUM,       /* x y -> x + y */
  DT_PRODUCT,   /* x y -> x * y */
  DT_DIFF,      /* x y -> x - y            (y on top of the stack) */
  DT_RDIFF,     /* x y -> y - x            (made by the reordering) */
  DT_UNION,     /* x y -> x + y - x*y      (stays in [0,1]) */
  DT_GROUP      /* only in a tape's prune program: groups[arg] */
} dt_op;

/* Error codes (0 is success). */
enum {
  DT_OK = 0,
  DT_EPLANE,      /* zero or non-finite normal, or non-finite offset */
  DT_ERADIUS,     /* negative or non-finite radius */
  DT_EOP,         /* unknown op, or fewer than two operands on the stack */
  DT_EUNBALANCED, /* finish with no tree or more than one tree */
  DT_ENOMEM
};

/* A smoothed halfspace: solid side n.x < d, |n| = 1, filter radius r
 * (r = 0: sharp step density).  inv_r is 1/r, or 0 when r = 0. */
typedef struct dt_leaf {
  double n[3], d, r, inv_r;
} dt_leaf;

typedef struct dt_instr {
  int op;       /* dt_op */
  int arg;      /* leaf index for DT_LEAF */
  double c;     /* value for DT_CONST */
} dt_instr;

typedef struct dt_tape {
  int ncode;
  dt_instr *code;
  int nleaves;
  dt_leaf *leaves;
  int depth;        /* stack slots needed, <= DT_STACK_MAX */
  double lo, hi;    /* range of the density, assuming leaves in [0,1] */
  double rmax;      /* largest leaf radius */
  /* The prune program, made by dt_builder_finish for the pruning
   * functions (NULL in views and when the tape has no group). */
  struct dt_prune_prog *prog;
  /* The leaves the code can reach, when a dt_prune_class view keeps its
   * parent's leaves: live[0 .. nlive) (NULL: all of them).  A ray's leaf
   * table (dt_ray_leaves) is filled for these only. */
  const int *live;
  int nlive;
} dt_tape;

/* The prune program: pcode is the tape's code with every maximal subtree
 * that only multiplies 2 to DT_GROUP_MAX leaves replaced by one DT_GROUP
 * instruction.  Such a subtree prunes to 0 if a leaf is 0 over the
 * segment, and otherwise to the code the live leaves leave, which is
 * stored for every set of live leaves (bit k: the group's k-th leaf, in
 * code order): the pruning classifies the leaves and copies that code
 * instead of folding instruction by instruction. */
#define DT_GROUP_MAX 8
typedef struct dt_group {
  int n;       /* leaves, 2 .. DT_GROUP_MAX */
  int leaf0;   /* first of them in gleaf */
  int snip0;   /* the code for live set m is gcode[gsnip[snip0 + m] ..
                  gsnip[snip0 + m + 1]) */
} dt_group;

typedef struct dt_prune_prog {
  int npcode;
  dt_instr *pcode;
  int ngroups;
  dt_group *groups;
  int *gleaf;        /* the groups' leaf indices */
  int *gsnip;        /* per group and set of live leaves: code offsets */
  dt_instr *gcode;   /* the code of every group and set */
} dt_prune_prog;

typedef struct dt_builder dt_builder;

dt_builder *dt_builder_new(void);
/* Append a smoothed halfspace: raw plane (n, d) with solid side n.x < d,
 * normalised here; radius r >= 0. */
int dt_builder_leaf(dt_builder *b, const double n[3], double d, double r);
int dt_builder_op(dt_builder *b, dt_op op);
/* Consumes b.  On failure returns NULL and sets *err (if err != NULL). */
dt_tape *dt_builder_finish(dt_builder *b, int *err);
void dt_builder_free(dt_builder *b);
void dt_tape_free(dt_tape *t);
const char *dt_strerror(int err);

/* eq. (2), the smoothed-halfspace kernel, defined once here for every
 * evaluator (density.c, lg.c, the study): in alpha = s/r, the density
 * (1-alpha)^2 (2+alpha)/4 = 1/2 - 3/4 alpha + 1/4 alpha^3 inside the
 * filter (|alpha| < 1), 1 for alpha <= -1 and 0 for alpha >= 1, and its
 * derivative d rho/d alpha = 3/4 (alpha^2 - 1) (0 outside; Section 2.4)
 * into *dda.  static inline: it is the innermost operation of every
 * evaluation, and a caller that ignores *dda pays nothing for it. */
static inline double dt_halfspace_da(double a, double *dda) {
  if (a >= 1) { *dda = 0; return 0; }
  if (a <= -1) { *dda = 0; return 1; }
  *dda = 0.75 * (a * a - 1);
  return (1 - a) * (1 - a) * (2 + a) * 0.25;
}

/* The kernel's value alone, in alpha. */
static inline double dt_halfspace_a(double a) {
  double dda;
  return dt_halfspace_da(a, &dda);
}

/* eq. (2): one smoothed halfspace's density at signed distance s from its
 * plane (positive outside), radius r (r = 0: 1, 0.5, 0 for s <,=,> 0). */
static inline double dt_halfspace(double s, double r) {
  if (r <= 0) return s < 0 ? 1.0 : (s > 0 ? 0.0 : 0.5);
  return dt_halfspace_a(s / r);
}

/* Signed distance of p from a leaf's plane, positive outside. */
static inline double dt_leaf_dist(const dt_leaf *lf, const double p[3]) {
  return vec3_dot(lf->n, p) - lf->d;
}

/* The range of a density op's result (dt_op, not DT_LEAF/DT_CONST) from
 * its operands' ranges, x below and y on top of the stack (interval.h). */
static inline void dt_range_op(int op, double xl, double xh, double yl,
                               double yh, double *lo, double *hi) {
  switch (op) {
  case DT_SUM: iv_add(xl, xh, yl, yh, lo, hi); break;
  case DT_DIFF: iv_sub(xl, xh, yl, yh, lo, hi); break;
  case DT_RDIFF: iv_sub(yl, yh, xl, xh, lo, hi); break;
  case DT_PRODUCT: iv_mul(xl, xh, yl, yh, lo, hi); break;
  default: iv_union(xl, xh, yl, yh, lo, hi); break;
  }
}

/* A log-concave envelope of the density (beyond the paper): a product E
 * of some of t's leaves with density <= E everywhere.  A smoothed
 * halfspace is log-concave in x (its kernel integrates the log-concave
 * 3/4 (1 - a^2): Prekopa), and so is a product of them; a Difference
 * x - y with y >= 0 is at most x, and a Product of non-negative factors
 * at most the product of their envelopes (a factor in [0, 1] without
 * one may be dropped).  A Sum or Union has none.  Writes the leaves'
 * indices to env (room for t->nleaves) and returns how many, or 0 when
 * the tree has no such envelope.  Rounded convex polyhedra have their
 * own density as envelope; figure13's cube with a notch has the cube's. */
int dt_envelope(const dt_tape *t, int *env);

/* Whether the ray o + s*d, s >= 0, provably stays where the envelope E
 * (dt_envelope's n leaves env of t) is below 0.5, and so never enters
 * the solid (density > 0.5): E(o) < 0.5 and E does not grow at s = 0
 * (then, log E being concave along the ray, it never grows), or some
 * factor is 0 at o and the ray moves away from its plane.  Every
 * quantity is bounded with its rounding (the leaves' distances, the
 * kernel, the sums), so a 1 is a proof; 0 means only "not shown" (a
 * ray grazing or entering, or precision too poor to tell).  Used for a
 * shadow ray leaving the surface it starts on (render.c). */
int dt_envelope_clear(const dt_tape *t, const int *env, int n,
                      const double o[3], const double d[3]);

/* Figure 4: the density at point p. */
double dt_density(const dt_tape *t, const double p[3]);

/* Section 2.4: the density and its analytic gradient at p. */
double dt_density_grad(const dt_tape *t, const double p[3], double grad[3]);

/* The density at o + s*d and its derivative d rho / d s (d any length). */
double dt_density_ray(const dt_tape *t, const double o[3], const double d[3],
                      double s, double *drho_ds);

/* eq. (5): Displacement.  The signed distance (positive outward, i.e. > 0
 * for level < 0.5) from a plane to the level-isosurface of its halfspace
 * smoothed with radius r.  level <= 0 gives r, level >= 1 gives -r. */
double dt_displacement(double r, double level);

/* The density's range [*dl, *dh] over the box [lo, hi]: each leaf's
   kernel over its plane's range (vec3_plane_range), combined by the
   interval rules (dt_range_op), widened by a relative 1e-12. */
void dt_range_box(const dt_tape *t, const double lo[3], const double hi[3],
                  double *dl, double *dh);
/* The same range, not widened, with leaf fix (an index into t->leaves, or
   -1 for none) taken as the value v over the whole box. */
void dt_range_box_fix(const dt_tape *t, const double lo[3], const double hi[3],
                      int fix, double v, double *dl, double *dh);

/* M: the largest density the tape can take (Section 3.4.1), assuming each
 * leaf lies in [0,1]; > 1 flags an ill-formed tree (paper Figure 15b). */
double dt_max(const dt_tape *t);

/* The specialisation of t to the ray segment o + s*d, s in [s0, s1]:
 * leaves whose filter support the segment does not touch become constants
 * and are folded away (0*x = 0, 1*x = x, ...).  Writes at most t->ncode
 * instructions to buf and fills *view (borrowing t's leaves and buf).
 * Returns the number of instructions in the view (>= 1). */
int dt_prune_ray(const dt_tape *t, const double o[3], const double d[3],
                 double s0, double s1, dt_instr *buf, dt_tape *view);

/* One ray o + s*d seen from each leaf: base = n.o - d (the signed distance
 * at s = 0) and nd = n.d, computed once per ray instead of at every
 * evaluation.  The _rl functions take t's table (t->nleaves entries,
 * indexed like t->leaves, so a view's table is its parent's) and give the
 * results of their o, d counterparts to the last bit.  For a tape with a
 * live list dt_ray_leaves fills only those entries, the only ones its
 * code and its views' code read. */
typedef struct dt_ray_leaf {
  double base, nd;
} dt_ray_leaf;

void dt_ray_leaves(const dt_tape *t, const double o[3], const double d[3],
                   dt_ray_leaf *rl);
double dt_density_rl(const dt_tape *t, const dt_ray_leaf *rl, double s,
                     double *drho_ds);

/* dt_density_rl itself, static inline for the root search's inner loop
 * (lg.c), where the call and the stack set-up cost as much as a short
 * view's arithmetic.  drho_ds must not be NULL. */
static inline double dt_density_rl_in(const dt_tape *t, const dt_ray_leaf *rl,
                                      double s, double *drho_ds) {
  double v[DT_STACK_MAX], dv[DT_STACK_MAX];
  v[0] = dv[0] = 0;   /* (a tape has code: only for the compiler's sake) */
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF) {
      const dt_leaf *lf = &t->leaves[in->arg];
      double nd = rl[in->arg].nd;
      double dist = rl[in->arg].base + s * nd, dda = 0;
      if (lf->r > 0) v[sp] = dt_halfspace_da(dist * lf->inv_r, &dda);
      else v[sp] = dt_halfspace(dist, 0);
      dv[sp] = dda * nd * lf->inv_r;
      sp++;
    } else if (in->op == DT_CONST) {
      v[sp] = in->c;
      dv[sp] = 0;
      sp++;
    } else {
      sp--;
      double x = v[sp - 1], y = v[sp], dx = dv[sp - 1], dy = dv[sp];
      switch (in->op) {
      case DT_SUM: dv[sp - 1] = dx + dy; v[sp - 1] = x + y; break;
      case DT_PRODUCT: dv[sp - 1] = dx * y + x * dy; v[sp - 1] = x * y; break;
      case DT_DIFF: dv[sp - 1] = dx - dy; v[sp - 1] = x - y; break;
      case DT_RDIFF: dv[sp - 1] = dy - dx; v[sp - 1] = y - x; break;
      default:
        dv[sp - 1] = dx * (1 - y) + dy * (1 - x);
        v[sp - 1] = x + y - x * y;
        break;
      }
    }
  }
  *drho_ds = dv[0];
  return v[0];
}
/* As dt_prune_ray, but the view keeps t's density range lo, hi (it still
 * bounds the view's) instead of recomputing it; t may itself be a view. */
int dt_prune_rl(const dt_tape *t, const dt_ray_leaf *rl, double s0, double s1,
                dt_instr *buf, dt_tape *view);

/* 1 if no leaf that t's code may reach is constant over o + s d, s in
 * [s0, s1] (rl: the ray's table): then nothing folds, and dt_prune_rl
 * would give t's own code, so t itself may stand for its view there.
 * 0 if some leaf may be constant (prune). */
int dt_prune_rl_same(const dt_tape *t, const dt_ray_leaf *rl, double s0,
                     double s1);

/* The specialisation of t to a region where the leaves' classes are
 * known: cls[i] is 0 or 1 for a leaf constant there at that value, -1 for
 * a live one (render.c decides them over a tile's frustum).  Folds as
 * dt_prune_ray does, so pruning the result over a ray segment inside the
 * region gives the code pruning t itself would give there, to the last
 * bit.  Writes at most t->ncode instructions to buf (the view's code).
 * Without a prune program, the live leaves are copied in code order to
 * leaves (room for t->nleaves) and renumbered, so a ray's leaf table
 * (dt_ray_leaves) covers only them.  With one, the view keeps t's leaves
 * and gets a program *prog sharing t's group tables, whose code (at most
 * t->prog->npcode instructions, in pbuf) keeps each live group as one
 * DT_GROUP instruction whose c is the mask of the group's leaves that may
 * be live (the others are 1 there), so the pruning functions still copy a
 * group's code for its live set, and the indices of the leaves that may
 * be live go to live (room for t->nleaves) as view->live.  *view borrows
 * buf, leaves or t's, prog and live; it keeps t's range, depth and rmax.
 * Returns the code length. */
int dt_prune_class(const dt_tape *t, const signed char *cls, dt_instr *buf,
                   dt_leaf *leaves, dt_instr *pbuf, dt_prune_prog *prog,
                   int *live, dt_tape *view);

#endif
