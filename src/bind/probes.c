/* probes.c: the geometry core as functions of the language. See probes.h.
 *
 * Each probe compiles what it is given (scene.c) and calls the kernels
 * the renderer calls. The compiled scene is freed before the probe
 * returns, also when an error unwinds (the ScopedScene handler below). */
#include "bind/probes.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/bounds.h"
#include "core/conv.h"
#include "core/density.h"
#include "lang/builtins.h"
#include "lang/eval.h"
#include "core/lg.h"
#include "lang/print.h"
#include "scene/ray.h"
#include "bind/compile.h"
#include "core/soft.h"

static void get_point(Interp *I, Value *v, Pos pos, const char *what,
                      double p[3]) {
  force_vec3(I, v, pos, what, p);
  if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
    qcs_error(pos, "%s must be finite, not (%g, %g, %g)", what, p[0], p[1],
              p[2]);
}

static double get_radius(Interp *I, Value *v, Pos pos) {
  double r = force_num(I, v, pos, "the radius");
  if (!isfinite(r) || r < 0)
    qcs_error(pos, "the radius must be finite and >= 0, not %g", r);
  return r;
}

/* Density r p tree: Figure 4. */
static Value *pr_density(Interp *I, Value **args, Pos pos) {
  double r = get_radius(I, args[0], pos), p[3];
  get_point(I, args[1], pos, "the point", p);
  dt_tape *t = compile_density_tape(I, args[2], r, pos);
  double rho = dt_density(t, p);
  dt_tape_free(t);
  return val_num(rho);
}

/* TrueDensity r p tree: the true convolution that Density approximates
   (Lobb's Figure 5): the fraction of the ball of radius r about p inside
   the sharp polyhedron, to about 1e-7. */
#define TRUE_TOL 1e-6
static Value *pr_true_density(Interp *I, Value **args, Pos pos) {
  double r = get_radius(I, args[0], pos), p[3];
  get_point(I, args[1], pos, "the point", p);
  dt_tape *t = compile_density_tape(I, args[2], r, pos);
  csg_tape *c = conv_sharp_of(t);
  dt_tape_free(t);
  if (!c) qcs_error(pos, "out of memory");
  double v;
  if (r == 0) {
    v = csg_inside(c, p) ? 1 : 0;
  } else {
    v = conv_fraction(c, p, r, TRUE_TOL, NULL);
  }
  csg_tape_free(c);
  return val_num(v);
}

/* Is v (forced) a SoftObject? */
static int is_soft(Interp *I, Value *v) {
  v = force(I, v);
  return v->kind == V_CON && v->u.con.con &&
         !strcmp(v->u.con.con->name, "SoftObject");
}

/* The gradient of Field p soft: eq. (1) differentiated, summed. */
static Value *soft_gradient(Interp *I, Value *obj, const double p[3],
                            Pos pos) {
  Scene *s = compile_scene(I, obj, pos);
  double g[3] = {0, 0, 0};
  for (int i = 0; i < s->n; i++)
    if (s->nodes[i].kind == SC_SOFT) {
      double gi[3];
      soft_field_grad(s->nodes[i].soft, p, gi);
      for (int k = 0; k < 3; k++) g[k] += gi[k];
    }
  scene_free(s);
  return val_tuple3(g[0], g[1], g[2]);
}

/* Gradient r p tree: Section 2.4; for a soft object (r unused) the
   gradient of its field. */
static Value *pr_gradient(Interp *I, Value **args, Pos pos) {
  double r = get_radius(I, args[0], pos), p[3], g[3];
  get_point(I, args[1], pos, "the point", p);
  if (is_soft(I, args[2])) return soft_gradient(I, args[2], p, pos);
  dt_tape *t = compile_density_tape(I, args[2], r, pos);
  dt_density_grad(t, p, g);
  dt_tape_free(t);
  return val_tuple3(g[0], g[1], g[2]);
}

/* PointInObject p obj: Figure 4, for every kind of object. */
static Value *pr_inside(Interp *I, Value **args, Pos pos) {
  double p[3];
  get_point(I, args[0], pos, "the point", p);
  Scene *s = compile_scene(I, args[1], pos);
  int in = scene_inside(s, s->root, p);
  scene_free(s);
  return val_bool(I, in);
}

/* Displacement r t: eq. (5). */
static Value *pr_displacement(Interp *I, Value **args, Pos pos) {
  double r = get_radius(I, args[0], pos);
  double t = force_num(I, args[1], pos, "the density level");
  if (!(t >= 0 && t <= 1))
    qcs_error(pos, "the density level of Displacement must be in [0, 1], "
              "not %g", t);
  return val_num(dt_displacement(r, t));
}

/* Field p soft: Wyvill and Trotman eq. (1), summed over the keys. */
static Value *pr_field(Interp *I, Value **args, Pos pos) {
  double p[3];
  get_point(I, args[0], pos, "the point", p);
  Scene *s = compile_scene(I, args[1], pos);
  double f = 0;
  int found = 0;
  for (int i = 0; i < s->n; i++)
    if (s->nodes[i].kind == SC_SOFT) {
      f += soft_field(s->nodes[i].soft, p);
      found = 1;
    }
  scene_free(s);
  if (!found)
    qcs_error(pos, "Field needs a soft object (SoftObject magic [keys])");
  return val_num(f);
}

/* A sharp CSG tape back into a scene-object value, for printing. */
static Value *csg_to_value(Interp *I, const csg_tape *t, Pos pos) {
  Value **stack = val_array(t->depth + 1);
  int sp = 0;
  Sym *s_half = sym_intern(I, "Halfspace", 9), *s_union = sym_intern(I, "Union", 5),
      *s_inter = sym_intern(I, "Intersection", 12),
      *s_diff = sym_intern(I, "SetDifference", 13),
      *s_empty = sym_intern(I, "Empty", 5),
      *s_all = sym_intern(I, "Everything", 10);
  for (int i = 0; i < t->ncode; i++) {
    const csg_instr *in = &t->code[i];
    Value **a;
    switch (in->op) {
    case CSG_PLANE: {
      const csg_plane *p = &t->planes[in->arg];
      Value **pl = val_array(2);
      pl[0] = val_tuple3(p->n[0], p->n[1], p->n[2]);
      pl[1] = val_num(p->d);
      a = val_array(1);
      a[0] = val_tuple(2, pl);
      stack[sp++] = val_con(s_half, 1, a);
      break;
    }
    case CSG_EMPTY: stack[sp++] = val_con(s_empty, 0, NULL); break;
    case CSG_ALL: stack[sp++] = val_con(s_all, 0, NULL); break;
    default: {
      a = val_array(2);
      Value *y = stack[--sp], *x = stack[--sp];
      Sym *c = in->op == CSG_UNION ? s_union : in->op == CSG_INTER ? s_inter : s_diff;
      a[0] = in->op == CSG_RDIFF ? y : x;
      a[1] = in->op == CSG_RDIFF ? x : y;
      stack[sp++] = val_con(c, 2, a);
    }
    }
  }
  if (sp != 1) qcs_error(pos, "internal error: malformed bound");
  return stack[0];
}

/* Cleanups for err_defer (error.h). */
static void free_csg_tape(void *b) { csg_tape_free(b); }
static void free_scene(void *s) { scene_free(s); }
static void free_ray_ctx(void *c) { ray_ctx_free(c); }

static Value *bounds_probe(Interp *I, Value **args, Pos pos, int outer) {
  double r = get_radius(I, args[0], pos);
  double t = force_num(I, args[1], pos, "the density threshold");
  if (!(t >= 0 && t <= 1))
    qcs_error(pos, "the threshold must be in [0, 1], not %g", t);
  dt_tape *tape = compile_density_tape(I, args[2], r, pos);
  int flags = 0;
  csg_tape *b = outer ? bnd_outer(tape, t, &flags) : bnd_inner(tape, t, &flags);
  dt_tape_free(tape);
  if (!b) qcs_error(pos, "out of memory");
  if ((flags & BND_RANGE) && compile_sum_overlaps(I, args[2], pos))
    compile_warn_once(I, pos, "a Sum in this density tree may exceed 1 where "
                    "its parts overlap (the paper's Figure 15b): the bounds "
                    "hold by interval arithmetic, but seams may bulge");
  if (flags & BND_FALLBACK)
    compile_warn_once(I, pos, "no theorem applies to part of this tree: a "
                    "looser, still safe bound was used there");
  ErrCleanup cu; /* the tape must not leak if an error unwinds */
  err_defer(&cu, free_csg_tape, b);
  Value *v = csg_to_value(I, b, pos);
  err_release(&cu);
  csg_tape_free(b);
  return v;
}

/* OuterBounds r t tree: Figure 8. */
static Value *pr_outer(Interp *I, Value **args, Pos pos) {
  return bounds_probe(I, args, pos, 1);
}

/* InnerBounds r t tree: Appendix, Theorems 4-6. */
static Value *pr_inner(Interp *I, Value **args, Pos pos) {
  return bounds_probe(I, args, pos, 0);
}

/* The direction of a ray: finite and not zero. */
static void get_dir(Interp *I, Value *v, Pos pos, double d[3]) {
  get_point(I, v, pos, "the ray direction", d);
  if (d[0] == 0 && d[1] == 0 && d[2] == 0)
    qcs_error(pos, "the ray direction cannot be zero");
}

/* The default root tolerance, as a distance in scene units. */
#define PROBE_TOL 1e-10

/* Every crossing of node's boundary along o + t d, t >= 0, into a list. */
static Value *roots_list(Interp *I, const Scene *s, const double o[3],
                         const double d[3], RayCtx *c, Pos pos) {
  csg_span *sp;
  int n = ray_spans(s, s->root, o, d, 0, INFINITY, c, &sp);
  if (n < 0) qcs_error(pos, "out of memory tracing the ray");
  Value *list = I->v_nil;
  for (int i = n - 1; i >= 0; i--) {
    if (sp[i].id1 >= 0 && isfinite(sp[i].t1))
      list = val_cons(val_num(sp[i].t1), list);
    if (sp[i].id0 >= 0 && sp[i].t0 >= 0) list = val_cons(val_num(sp[i].t0), list);
  }
  return list;
}

static Value *ray_probe(Interp *I, Value **args, Pos pos, const lg_hook *hook,
                        const soft_hook *shook) {
  double o[3], d[3];
  get_point(I, args[1], pos, "the ray origin", o);
  get_dir(I, args[2], pos, d);
  Scene *s = compile_scene(I, args[0], pos);
  RayCtx *c = ray_ctx_new(s, PROBE_TOL);
  if (!c) {
    scene_free(s);
    qcs_error(pos, "out of memory");
  }
  c->hook = hook;
  c->soft_hook = shook;
  /* The scene and the context must not leak if an error unwinds. */
  ErrCleanup cu_scene, cu_ctx;
  err_defer(&cu_scene, free_scene, s);
  err_defer(&cu_ctx, free_ray_ctx, c);
  Value *v = roots_list(I, s, o, d, c, pos);
  if (c->unresolved_node >= 0)
    qcs_warning(compile_node_pos(s, c->unresolved_node),
                "the root search left %ld segment%s of this object "
                "undecided (the ray runs within rounding of its surface "
                "for a long stretch): crossings that only touch the ray "
                "there may be missing", c->stats.lg.overflows,
                c->stats.lg.overflows == 1 ? "" : "s");
  err_release(&cu_ctx);
  err_release(&cu_scene);
  ray_ctx_free(c);
  scene_free(s);
  return v;
}

/* Roots obj o d: every t >= 0 where o + t d crosses obj's surface. */
static Value *pr_roots(Interp *I, Value **args, Pos pos) {
  return ray_probe(I, args, pos, NULL, NULL);
}

/* ---- Trace: the root search as a table within 80 columns ---- */

/* What Trace collects while the ray is traced, printed afterwards so that
   the columns can be sized to what they hold. */
typedef struct TraceLog {
  lg_trace_event *lg;
  soft_trace_event *soft;
  size_t nlg, caplg, nsoft, capsoft;
  int oom;
} TraceLog;

static void trace_lg(void *ctx, const lg_trace_event *ev) {
  TraceLog *t = ctx;
  if (t->nlg == t->caplg) {
    size_t cap = t->caplg ? 2 * t->caplg : 64;
    lg_trace_event *n = realloc(t->lg, cap * sizeof *n);
    if (!n) { t->oom = 1; return; }
    t->lg = n;
    t->caplg = cap;
  }
  t->lg[t->nlg++] = *ev;
}

static void trace_soft(void *ctx, const soft_trace_event *ev) {
  TraceLog *t = ctx;
  if (t->nsoft == t->capsoft) {
    size_t cap = t->capsoft ? 2 * t->capsoft : 64;
    soft_trace_event *n = realloc(t->soft, cap * sizeof *n);
    if (!n) { t->oom = 1; return; }
    t->soft = n;
    t->capsoft = cap;
  }
  t->soft[t->nsoft++] = *ev;
}

static void free_trace_log(void *p) {
  TraceLog *t = p;
  free(t->lg);
  free(t->soft);
}

/* x to the digits of a table cell, 0 when |x| <= tol. */
static void cell_tol(char *buf, double x, int digits, double tol) {
  if (isfinite(x) && fabs(x) <= tol) x = 0;
  if (isinf(x)) strcpy(buf, x > 0 ? "inf" : "-inf");
  else format_real_digits(buf, x, digits);
}

/* x to the digits of the table, a value within rounding of 0 beside the
   scale of its column (8 ulps of it) shown as 0. */
#define CELL 32
static void cell(char *buf, double x, int digits, double scale) {
  cell_tol(buf, x, digits, 8 * DBL_EPSILON * scale);
}

/* A table: rows of n cells, column headers, widths from the cells; cells
   right-aligned except the last (text). */
static void print_table(FILE *out, int n, const char *const *head,
                        char (*cells)[CELL], size_t rows) {
  int w[16] = {0};
  for (int j = 0; j < n; j++) w[j] = (int)strlen(head[j]);
  for (size_t i = 0; i < rows; i++)
    for (int j = 0; j < n; j++) {
      int l = (int)strlen(cells[i * (size_t)n + (size_t)j]);
      if (l > w[j]) w[j] = l;
    }
  for (size_t i = 0; i <= rows; i++) {
    for (int j = 0; j < n; j++) {
      const char *c = i == 0 ? head[j] : cells[(i - 1) * (size_t)n + (size_t)j];
      if (j == n - 1) fprintf(out, " %s", c);
      else fprintf(out, "%*s%s", j ? 1 : 0, "", c),
           fprintf(out, "%*s", w[j] - (int)strlen(c), "");
    }
    fputc('\n', out);
  }
}

/* The numbers of a Trace: the digits setting, else 4 significant. */
static int trace_digits(const Interp *I) { return I->digits ? I->digits : 4; }

static const char *const lg_decisions[] = {
    [LG_SEG_EXCLUDED] = "miss",  [LG_SEG_FLAT] = "flat",
    [LG_SEG_NO_ROOT] = "none",   [LG_SEG_ROOT] = "root",
    [LG_SEG_SPLIT] = "split",    [LG_SEG_TINY] = "tiny",
    [LG_SEG_PLANE] = "plane",    [LG_SEG_CONCAVE] = "concave",
};

static void print_lg_trace(FILE *out, const TraceLog *t, int digits) {
  fprintf(out,
          "Rounded objects: the search of Figure 9, one segment a line, "
          "depth first.\n"
          " d: depth of splitting  t0, t1: the segment of o + t d\n"
          " f0, f1: density - 0.5 at its ends  L >= |rho'|, G >= |rho''| "
          "on it (3.4.1)\n"
          " A+B: eq. (6); A+B > t1 - t0 proves at most one root  "
          "ops: tape size there\n"
          " split: may hold 2 roots  root: 1 root, polished  none: no "
          "sign change\n"
          " miss: range misses 0.5  flat: L = 0  tiny: below the "
          "tolerance\n"
          " plane: one leaf live, its plane is the 0.5 level: a root "
          "by one division\n"
          " concave: a product, log-concave: one stretch inside or none, "
          "decided whole\n");
  static const char *const head[] = {"d", "t0", "t1", "f0", "f1", "L",
                                     "G", "A+B", "ops", "decision"};
  char (*cells)[CELL] = calloc(t->nlg * 10 + 1, CELL);
  if (!cells) return;
  for (size_t i = 0; i < t->nlg; i++) {
    const lg_trace_event *e = &t->lg[i];
    char (*c)[CELL] = cells + i * 10;
    double ts = fmax(fabs(e->t0), fabs(e->t1));
    snprintf(c[0], CELL, "%d", e->depth);
    cell(c[1], e->t0, digits, ts);
    cell(c[2], e->t1, digits, ts);
    cell(c[3], e->f0, digits, 1);
    cell(c[4], e->f1, digits, 1);
    cell(c[5], e->L, digits, 0);
    cell(c[6], e->G, digits, 0);
    cell(c[7], e->lhs, digits, 0);
    snprintf(c[8], CELL, "%d", e->ncode);
    snprintf(c[9], CELL, "%s%s",
             e->decision >= 0 && e->decision <= LG_SEG_CONCAVE
                 ? lg_decisions[e->decision] : "?",
             e->nroots && e->decision == LG_SEG_TINY ? " -> root" : "");
  }
  print_table(out, 10, head, cells, t->nlg);
  free(cells);
}

static const char *const soft_decisions[] = {
    [SOFT_IV_EMPTY] = "no key: 0",   [SOFT_IV_BOUND] = "range",
    [SOFT_IV_COEFF] = "coeff",       [SOFT_IV_QUICK] = "solve: bound",
    [SOFT_IV_LAGUERRE] = "solve: Laguerre",
    [SOFT_IV_CASCADE] = "solve: cascade",
};

static void print_soft_trace(FILE *out, const TraceLog *t, int digits) {
  fprintf(out,
          "Soft objects: Wyvill and Trotman's intervals between key bounds, "
          "in order.\n"
          " t0, t1: the interval  keys: keys acting on it  field in "
          "[lo, hi] there\n"
          " range: [lo, hi] stays on one side of magic  coeff: the sextic's "
          "constant\n"
          " term outweighs the rest  solve: eq. (4) solved (bound: by its "
          "range;\n"
          " Laguerre: verified by signs; cascade: by derivatives)  "
          "roots: crossings\n"
          " steps: Laguerre iterations (the sextic's 6 roots found, then "
          "each polished)\n"
          " + Newton/bisection steps (cascade, or a sextic monotone "
          "there)\n");
  static const char *const head[] = {"t0", "t1", "keys", "lo", "hi",
                                     "decision", "steps", "roots"};
  enum { NC = 8 };
  size_t rows = 0;
  for (size_t i = 0; i < t->nsoft; i++)
    rows += t->soft[i].nroots > 1 ? (size_t)t->soft[i].nroots : 1;
  char (*cells)[CELL] = calloc(rows * NC + 1, CELL);
  if (!cells) return;
  size_t r = 0;
  for (size_t i = 0; i < t->nsoft; i++) {
    const soft_trace_event *e = &t->soft[i];
    char (*c)[CELL] = cells + r * NC;
    double ts = fmax(fabs(e->t0), fabs(e->t1));
    cell(c[0], e->t0, digits, ts);
    cell(c[1], e->t1, digits, ts);
    snprintf(c[2], CELL, "%d", e->nkeys);
    if (e->decision == SOFT_IV_EMPTY) {
      strcpy(c[3], "0");
      strcpy(c[4], "0");
    } else {
      double fs = fmax(fabs(e->flo), fabs(e->fhi));
      /* soft.c widens the range by 1e-12 sum |w| against rounding */
      cell_tol(c[3], e->flo, digits, 1e-11 * fs);
      cell_tol(c[4], e->fhi, digits, 1e-11 * fs);
    }
    strcpy(c[5], e->decision >= 0 && e->decision <= SOFT_IV_CASCADE
                     ? soft_decisions[e->decision] : "?");
    if (e->decision < SOFT_IV_QUICK) strcpy(c[6], "-");
    else if (e->bsteps) snprintf(c[6], CELL, "%ld+%ld", e->lsteps, e->bsteps);
    else snprintf(c[6], CELL, "%ld", e->lsteps);
    if (e->nroots == 0) strcpy(c[7], "-");
    for (int k = 0; k < e->nroots; k++) {
      char (*ck)[CELL] = cells + (r + (size_t)k) * NC;
      cell(ck[7], e->roots[k], digits, 0);
    }
    r += e->nroots > 1 ? (size_t)e->nroots : 1;
  }
  print_table(out, NC, head, cells, rows);
  free(cells);
}

/* Trace obj o d: Roots, printing the root search of every rounded leaf
   (Figure 9) and soft object (Wyvill and Trotman) the ray meets. */
static Value *pr_trace(Interp *I, Value **args, Pos pos) {
  TraceLog log = {0};
  ErrCleanup cu;
  err_defer(&cu, free_trace_log, &log);
  lg_hook hook = {trace_lg, &log};
  soft_hook shook = {trace_soft, &log};
  Value *v = ray_probe(I, args, pos, &hook, &shook);
  int digits = trace_digits(I);
  printf("Trace: the root search along o + t d; the value is Roots' list\n"
         "(numbers to %d significant digits: :set digits N for more)\n",
         digits);
  if (log.oom) printf("(out of memory: the trace is incomplete)\n");
  if (log.nlg) print_lg_trace(stdout, &log, digits);
  if (log.nsoft) print_soft_trace(stdout, &log, digits);
  if (!log.nlg && !log.nsoft)
    printf("No rounded or soft object's bound is met: nothing to search "
           "(sharp faces are\nsolved directly).\n");
  fflush(stdout);
  err_release(&cu);
  free_trace_log(&log);
  return v;
}

/* LG r tree o d (t0, t1): (M, L, G) over the segment (Section 3.4.1). */
static Value *pr_lg(Interp *I, Value **args, Pos pos) {
  double r = get_radius(I, args[0], pos), o[3], d[3];
  get_point(I, args[2], pos, "the ray origin", o);
  get_dir(I, args[3], pos, d);
  Value *seg = force(I, args[4]);
  if (seg->kind != V_TUPLE || seg->u.tup.n != 2)
    qcs_error(pos, "the segment is a pair (t0, t1)");
  double t0 = force_num(I, seg->u.tup.items[0], pos, "t0");
  double t1 = force_num(I, seg->u.tup.items[1], pos, "t1");
  if (!isfinite(t0) || !isfinite(t1) || t1 < t0)
    qcs_error(pos, "the segment (t0, t1) needs finite t0 <= t1");
  dt_tape *t = compile_density_tape(I, args[1], r, pos);
  lg_bounds b;
  lg_eval_bounds(t, o, d, t0, t1, &b);
  dt_tape_free(t);
  double M = fmax(fabs(b.lo), fabs(b.hi));
  return val_tuple3(M, b.L, b.G);
}

#define PROBES(X)                                                            \
  X("Density", 3, pr_density,                                                \
    "Density r p tree: the density of the tree smoothed with radius r at p"  \
    "; e.g. Density 0.1 (0.5, 0.5, 0.5) UnitCube")                           \
  X("TrueDensity", 3, pr_true_density,                                       \
    "TrueDensity r p tree: the true convolution Density stands in for: the "  \
    "fraction of the ball of radius r about p inside the sharp polyhedron; "  \
    "e.g. TrueDensity 0.1 (1, 1, 1) UnitCube")                                \
  X("Gradient", 3, pr_gradient,                                              \
    "Gradient r p tree: the density's (or soft field's) gradient at p"      \
    "; e.g. Gradient 0.1 (1, 0.5, 0.5) UnitCube")                            \
  X("PointInObject", 2, pr_inside,                                           \
    "PointInObject p obj: is p inside the object?"                           \
    "; e.g. PointInObject (0.5, 0.5, 0.5) (Rounded 0.1 UnitCube)")           \
  X("Displacement", 2, pr_displacement,                                      \
    "Displacement r t: distance from a plane to its t-isosurface, outward"   \
    "; e.g. Displacement 0.1 0.5")                                           \
  X("Field", 2, pr_field,                                                    \
    "Field p soft: the soft object's field at p"                             \
    "; e.g. Field (0, 0, 0) (SoftObject 0.5 [Key (0, 0, 0) 1 1])")           \
  X("OuterBounds", 3, pr_outer,                                              \
    "OuterBounds r t tree: a sharp object outside which density <= t"        \
    "; e.g. OuterBounds 0.1 0.01 UnitCube")                                  \
  X("InnerBounds", 3, pr_inner,                                              \
    "InnerBounds r t tree: a sharp object inside which density >= t"         \
    "; e.g. InnerBounds 0.1 0.99 UnitCube")                                  \
  X("Roots", 3, pr_roots,                                                    \
    "Roots obj o d: every t >= 0 where o + t d crosses obj's surface"        \
    "; e.g. Roots (Rounded 0.1 UnitCube) (-1, 0.5, 0.5) (1, 0, 0)")          \
  X("Trace", 3, pr_trace,                                                    \
    "Trace obj o d: Roots, printing the root search step by step"            \
    "; e.g. Trace (Rounded 0.1 UnitCube) (-1, 0.5, 0.5) (1, 0, 0)")          \
  X("LG", 5, pr_lg,                                                          \
    "LG r tree o d (t0, t1): (M, L, G) bounds over the ray segment"         \
    "; e.g. LG 0.1 UnitCube (-1, 0.5, 0.5) (1, 0, 0) (0, 3)")

static const Builtin probes[] = {
#define X(name, arity, fn, doc) {name, arity, fn, doc},
    PROBES(X)
#undef X
};

void probes_install(Interp *I) {
  for (size_t i = 0; i < sizeof probes / sizeof *probes; i++)
    builtin_define(I, &probes[i]);
}
