/* csg.c: sharp CSG tapes, point classification and Roth span lists. */
#include "core/csg.h"
#include "core/tape.h"
#include "core/vec.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

struct csg_builder {
  csg_instr *code;
  int ncode, capcode;
  csg_plane *planes;
  int nplanes, capplanes;
  int *start;       /* per operand on the symbolic stack: first instr */
  int nstack, capstack;
  int err;
};

csg_builder *csg_builder_new(void) {
  return calloc(1, sizeof(csg_builder));
}

void csg_builder_free(csg_builder *b) {
  if (!b) return;
  free(b->code);
  free(b->planes);
  free(b->start);
  free(b);
}

void csg_tape_free(csg_tape *t) {
  if (!t) return;
  free(t->code);
  free(t->planes);
  free(t->rcode);
  free(t->gstart);
  free(t->gplane);
  free(t->gpl);
  free(t->dir);
  free(t);
}

const char *csg_strerror(int err) {
  switch (err) {
  case CSG_OK: return "no error";
  case CSG_EPLANE: return "plane normal must be finite and non-zero";
  case CSG_EOP: return "set operation needs two operands";
  case CSG_EUNBALANCED: return "csg tape must hold exactly one object";
  case CSG_ENOMEM: return "out of memory";
  }
  return "unknown csg error";
}

static int grow(void **p, int *cap, int need, size_t elem) {
  if (need <= *cap) return 0;
  int c = *cap ? *cap : 16;
  while (c < need) c *= 2;
  void *q = realloc(*p, (size_t)c * elem);
  if (!q) return -1;
  *p = q;
  *cap = c;
  return 0;
}

static int push_operand(csg_builder *b, csg_instr in) {
  if (grow((void **)&b->code, &b->capcode, b->ncode + 1, sizeof *b->code) ||
      grow((void **)&b->start, &b->capstack, b->nstack + 1, sizeof(int)))
    return b->err = CSG_ENOMEM;
  b->start[b->nstack++] = b->ncode;
  b->code[b->ncode++] = in;
  return CSG_OK;
}

int csg_builder_plane(csg_builder *b, const double n[3], double d) {
  if (b->err) return b->err;
  double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!isfinite(len) || len == 0 || !isfinite(d)) return CSG_EPLANE;
  if (grow((void **)&b->planes, &b->capplanes, b->nplanes + 1,
           sizeof *b->planes))
    return b->err = CSG_ENOMEM;
  csg_plane *p = &b->planes[b->nplanes];
  for (int i = 0; i < 3; i++) p->n[i] = n[i] / len;
  p->d = d / len;
  csg_instr in = {CSG_PLANE, b->nplanes++};
  return push_operand(b, in);
}

int csg_builder_const(csg_builder *b, csg_op c) {
  if (b->err) return b->err;
  if (c != CSG_EMPTY && c != CSG_ALL) return CSG_EOP;
  csg_instr in = {(int)c, 0};
  return push_operand(b, in);
}

/* The constant an operand folded to, or -1. */
static int operand_const(const csg_builder *b, int k) {
  int s = b->start[k];
  int end = k + 1 < b->nstack ? b->start[k + 1] : b->ncode;
  if (end - s != 1) return -1;
  int op = b->code[s].op;
  return op == CSG_EMPTY || op == CSG_ALL ? op : -1;
}

/* Replace the top two operands by one: keep_x/keep_y keeps that operand's
 * code alone, else the constant c. */
static void fold_to(csg_builder *b, int keep, int c) {
  int sx = b->start[b->nstack - 2], sy = b->start[b->nstack - 1];
  if (keep == 0) {                /* keep x: drop y's code */
    b->ncode = sy;
  } else if (keep == 1) {         /* keep y: move it over x */
    memmove(&b->code[sx], &b->code[sy],
            (size_t)(b->ncode - sy) * sizeof *b->code);
    b->ncode = sx + (b->ncode - sy);
  } else {
    b->ncode = sx;
    b->code[b->ncode].op = c;
    b->code[b->ncode++].arg = 0;
  }
  b->nstack--;
}

int csg_builder_op(csg_builder *b, csg_op op) {
  if (b->err) return b->err;
  if (op != CSG_UNION && op != CSG_INTER && op != CSG_DIFF && op != CSG_RDIFF)
    return CSG_EOP;
  if (b->nstack < 2) return CSG_EOP;
  int cx = operand_const(b, b->nstack - 2), cy = operand_const(b, b->nstack - 1);
  if (op == CSG_RDIFF) {   /* y - x: fold as a difference with roles swapped */
    if (cy == CSG_EMPTY || cx == CSG_ALL) {
      fold_to(b, -1, CSG_EMPTY);
      return 0;
    }
    if (cx == CSG_EMPTY) { fold_to(b, 1, 0); return 0; }
  } else
  switch (op) {
  case CSG_UNION:
    if (cx == CSG_ALL || cy == CSG_ALL) { fold_to(b, -1, CSG_ALL); return 0; }
    if (cx == CSG_EMPTY) { fold_to(b, 1, 0); return 0; }
    if (cy == CSG_EMPTY) { fold_to(b, 0, 0); return 0; }
    break;
  case CSG_INTER:
    if (cx == CSG_EMPTY || cy == CSG_EMPTY) {
      fold_to(b, -1, CSG_EMPTY);
      return 0;
    }
    if (cx == CSG_ALL) { fold_to(b, 1, 0); return 0; }
    if (cy == CSG_ALL) { fold_to(b, 0, 0); return 0; }
    break;
  default:
    if (cx == CSG_EMPTY || cy == CSG_ALL) {
      fold_to(b, -1, CSG_EMPTY);
      return 0;
    }
    if (cy == CSG_EMPTY) { fold_to(b, 0, 0); return 0; }
    break;
  }
  if (grow((void **)&b->code, &b->capcode, b->ncode + 1, sizeof *b->code))
    return b->err = CSG_ENOMEM;
  csg_instr in = {(int)op, 0};
  b->code[b->ncode++] = in;
  b->nstack--;
  return CSG_OK;
}

/* Operands of a csg tape (planes and constants), for tape_reorder. */
static int operand(int op) { return op <= CSG_ALL; }

/* Sethi-Ullman reordering (tape.h), which finds op as the first member. */
_Static_assert(offsetof(csg_instr, op) == 0, "tape_reorder reads op first");
static int reorder(const csg_instr *in, int n, csg_instr *out, int *depth) {
  return tape_reorder(in, out, sizeof *in, n, operand, CSG_DIFF, CSG_RDIFF,
                      depth) == TAPE_OK ? CSG_OK : CSG_ENOMEM;
}

/* The index of n in dir[0 .. nd), bit for bit (same = 1), or equal
 * component by component (same = 0, zeros of either sign alike), or -1. */
static int find_dir(double (*dir)[3], int nd, const double n[3], int same) {
  for (int j = 0; j < nd; j++)
    if (same ? memcmp(dir[j], n, sizeof dir[j]) == 0
             : dir[j][0] == n[0] && dir[j][1] == n[1] && dir[j][2] == n[2])
      return j;
  return -1;
}

/* The place in csg_ray_dots' table of gpl plane p's dot products, the
 * directions dir[0 .. *nd) (appended to if need be, up to CSG_DIRS_MAX;
 * -1 past it).  A normal equal to a direction or its negation component
 * by component gives the same dot products but for the sign of a zero
 * (its nonzero products are the same and adding a zero to a nonzero sum
 * is exact; round to nearest is symmetric): a zero n.d is only tested
 * against 0, and a zero n.o only shows in n.o - p.d when p.d is 0, so
 * such a plane takes the direction's unless its offset is 0. */
static int dot_slot(double (*dir)[3], int *nd, const struct csg_gplane *p) {
  double m[3] = {-p->n[0], -p->n[1], -p->n[2]};
  int j = find_dir(dir, *nd, p->n, 1);
  if (j >= 0) return 4 * j;
  if (p->d != 0) {
    if ((j = find_dir(dir, *nd, p->n, 0)) >= 0) return 4 * j;
    if ((j = find_dir(dir, *nd, m, 0)) >= 0) return 4 * j + 2;
  }
  if (*nd == CSG_DIRS_MAX) return -1;
  memcpy(dir[*nd], p->n, sizeof dir[*nd]);
  return 4 * (*nd)++;
}

/* t's direction table (csg.h): base's directions first (base may be
 * NULL), then those t's groups add.  Past CSG_DIRS_MAX: t keeps its
 * table as it was if base is given, else has none. */
static int dir_table(csg_tape *t, const csg_tape *base) {
  int np = t->gstart[t->ngroups], nb = base ? base->ndirs : 0;
  double (*dir)[3] = malloc((CSG_DIRS_MAX + 1) * sizeof *dir);
  int *u = malloc(((size_t)np + 1) * sizeof *u);
  if (!dir || !u) {
    free(dir);
    free(u);
    return CSG_ENOMEM;
  }
  if (nb > 0) memcpy(dir, base->dir, (size_t)nb * sizeof *dir);
  int nd = nb, k = 0;
  for (; k < np; k++)
    if ((u[k] = dot_slot(dir, &nd, &t->gpl[k])) < 0) break;
  if (k < np) {
    free(dir);
    free(u);
    return CSG_OK;   /* base given: t as it was; else no table */
  }
  for (k = 0; k < np; k++) t->gpl[k].u = u[k];
  free(u);
  free(t->dir);
  t->dir = dir;
  t->ndirs = nd;
  t->dirs_of = base;
  return CSG_OK;
}

int csg_tape_share_dirs(csg_tape *t, const csg_tape *base) {
  if (!t->dir || !base->dir) return CSG_OK;
  return dir_table(t, base);
}

void csg_ray_dots(const csg_tape *t, const double o[3], const double d[3],
                  double *dots) {
  const double (*dir)[3] = (const double (*)[3])t->dir;
  const double o0 = o[0], o1 = o[1], o2 = o[2];
  const double d0 = d[0], d1 = d[1], d2 = d[2];
  for (int u = 0, n = t->ndirs; u < n; u++) {
    const double *v = dir[u];   /* vec3_dot's sums, in its order */
    double a = v[0] * o0 + v[1] * o1 + v[2] * o2;
    double b = v[0] * d0 + v[1] * d1 + v[2] * d2;
    dots[4 * u] = a;
    dots[4 * u + 1] = b;
    dots[4 * u + 2] = -a;
    dots[4 * u + 3] = -b;
  }
}

/* The ray program of t (csg.h): maximal subtrees of intersected planes
 * (more than one plane) become CSG_CONVEX groups.  A subtree is the
 * contiguous stretch of postfix code that ends at its root, so a group's
 * planes are the CSG_PLANE instructions of that stretch. */
static int ray_program(csg_tape *t) {
  int n = t->ncode;
  int *gend = malloc(((size_t)n + 1) * sizeof(int));
  t->rcode = malloc(((size_t)n + 1) * sizeof *t->rcode);
  t->gstart = malloc(((size_t)n + 1) * sizeof(int));
  t->gplane = malloc(((size_t)n + 1) * sizeof(int));
  if (!gend || !t->rcode || !t->gstart || !t->gplane) {
    free(gend);
    return CSG_ENOMEM;
  }
  /* Per operand on the stack: where its code starts, whether it is pure
   * (planes and intersections only) and where it ends. */
  int sst[CSG_STACK_MAX + 1], spure[CSG_STACK_MAX + 1], send[CSG_STACK_MAX + 1];
  int sp = 0;
  for (int i = 0; i < n; i++) gend[i] = -1;
  for (int i = 0; i < n; i++) {
    int op = t->code[i].op;
    if (op <= CSG_ALL) {
      sst[sp] = send[sp] = i;
      spure[sp++] = op == CSG_PLANE;
      continue;
    }
    sp--;
    int x = sp - 1, y = sp;
    int p = op == CSG_INTER && spure[x] && spure[y];
    if (!p) {   /* pure operands of an impure op are maximal */
      if (spure[x]) gend[sst[x]] = send[x];
      if (spure[y]) gend[sst[y]] = send[y];
    }
    spure[x] = p;
    send[x] = i;
  }
  if (n > 0 && spure[0]) gend[sst[0]] = send[0];
  int nr = 0, ng = 0, np = 0;
  for (int i = 0; i < n;) {
    int e = gend[i];
    if (e > i) {
      t->gstart[ng] = np;
      for (int k = i; k <= e; k++)
        if (t->code[k].op == CSG_PLANE) t->gplane[np++] = t->code[k].arg;
      csg_instr in = {CSG_CONVEX, ng++};
      t->rcode[nr++] = in;
      i = e + 1;
    } else {
      t->rcode[nr++] = t->code[i++];
    }
  }
  t->gstart[ng] = np;
  t->nrcode = nr;
  t->ngroups = ng;
  free(gend);
  t->gpl = malloc(((size_t)np + 1) * sizeof *t->gpl);
  if (!t->gpl) return CSG_ENOMEM;
  for (int k = 0; k < np; k++) {
    const csg_plane *p = &t->planes[t->gplane[k]];
    memcpy(t->gpl[k].n, p->n, sizeof p->n);
    t->gpl[k].d = p->d;
    t->gpl[k].id = t->gplane[k];
  }
  return dir_table(t, NULL);
}

csg_tape *csg_builder_finish(csg_builder *b, int *err) {
  int e = b->err;
  if (!e && b->nstack != 1) e = CSG_EUNBALANCED;
  csg_tape *t = NULL;
  if (!e) {
    t = calloc(1, sizeof *t);
    csg_instr *code = malloc((size_t)b->ncode * sizeof *code);
    if (!t || !code) {
      free(code);
      e = CSG_ENOMEM;
    } else if ((e = reorder(b->code, b->ncode, code, &t->depth)) != CSG_OK) {
      free(code);
    } else {
      t->code = code;
      t->ncode = b->ncode;
      t->planes = b->planes;   /* ownership moves to the tape */
      t->nplanes = b->nplanes;
      b->planes = NULL;
      for (int i = 0; i < t->ncode; i++)
        if (t->code[i].op <= CSG_ALL) t->nleaves++;
      if (t->depth > CSG_STACK_MAX) e = CSG_EOP;
      else e = ray_program(t);
    }
    if (e) { csg_tape_free(t); t = NULL; }
  }
  if (err) *err = e;
  csg_builder_free(b);
  return t;
}

int csg_is_empty(const csg_tape *t) {
  return t->ncode == 1 && t->code[0].op == CSG_EMPTY;
}

int csg_is_all(const csg_tape *t) {
  return t->ncode == 1 && t->code[0].op == CSG_ALL;
}

/* Figure 4: PointInObject over a sharp CSG tape. */
int csg_inside(const csg_tape *t, const double p[3]) {
  unsigned char st[CSG_STACK_MAX];
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const csg_instr *in = &t->code[i];
    switch (in->op) {
    case CSG_PLANE: {
      const csg_plane *pl = &t->planes[in->arg];
      st[sp++] = vec3_dot(pl->n, p) < pl->d;
      break;
    }
    case CSG_EMPTY: st[sp++] = 0; break;
    case CSG_ALL: st[sp++] = 1; break;
    default: {
      int y = st[--sp], x = st[sp - 1];
      switch (in->op) {
      case CSG_UNION: x = x || y; break;
      case CSG_INTER: x = x && y; break;
      case CSG_DIFF: x = x && !y; break;
      default: x = y && !x; break;
      }
      st[sp - 1] = (unsigned char)x;
    }
    }
  }
  return st[0];
}

/* Roth's union: merge by start, coalescing overlapping or touching
 * spans. */
static inline __attribute__((always_inline)) int
spans_union(const csg_span *a, int na, const csg_span *b, int nb,
            csg_span *out) {
  int i = 0, j = 0, n = 0;
  while (i < na || j < nb) {
    const csg_span *s = (j >= nb || (i < na && a[i].t0 <= b[j].t0)) ? &a[i++]
                                                                    : &b[j++];
    if (n > 0 && s->t0 <= out[n - 1].t1) {
      if (s->t1 > out[n - 1].t1) {
        out[n - 1].t1 = s->t1;
        out[n - 1].id1 = s->id1;
        out[n - 1].flip1 = s->flip1;
      }
    } else {
      out[n++] = *s;
    }
  }
  return n;
}

static inline __attribute__((always_inline)) int
spans_inter(const csg_span *a, int na, const csg_span *b, int nb,
            csg_span *out) {
  int i = 0, j = 0, n = 0;
  while (i < na && j < nb) {
    const csg_span *lo = a[i].t0 >= b[j].t0 ? &a[i] : &b[j];
    const csg_span *hi = a[i].t1 <= b[j].t1 ? &a[i] : &b[j];
    if (lo->t0 < hi->t1) {
      csg_span s = {lo->t0, hi->t1, lo->id0, hi->id1, lo->flip0, hi->flip1};
      out[n++] = s;
    }
    if (a[i].t1 <= b[j].t1) i++;
    else j++;
  }
  return n;
}

/* a minus b: each span of a loses the parts covered by b; the cut ends
 * take b's surfaces with their normals flipped. */
static inline __attribute__((always_inline)) int
spans_diff(const csg_span *a, int na, const csg_span *b, int nb,
           csg_span *out) {
  int j = 0, n = 0;
  for (int i = 0; i < na; i++) {
    csg_span cur = a[i];
    while (j < nb && b[j].t1 <= cur.t0) j++;
    int k = j;
    while (k < nb && b[k].t0 < cur.t1) {
      if (b[k].t0 > cur.t0) {
        csg_span s = cur;
        s.t1 = b[k].t0;
        s.id1 = b[k].id0;
        s.flip1 = (unsigned char)!b[k].flip0;
        out[n++] = s;
      }
      if (b[k].t1 >= cur.t1) { cur.t0 = cur.t1; break; }
      cur.t0 = b[k].t1;
      cur.id0 = b[k].id1;
      cur.flip0 = (unsigned char)!b[k].flip1;
      k++;
    }
    if (cur.t0 < cur.t1) out[n++] = cur;
  }
  return n;
}

/* The public set operations: the inline forms above (which ray_spans
   uses in place). */
int csg_spans_union(const csg_span *a, int na, const csg_span *b, int nb,
                    csg_span *out) {
  return spans_union(a, na, b, nb, out);
}

int csg_spans_inter(const csg_span *a, int na, const csg_span *b, int nb,
                    csg_span *out) {
  return spans_inter(a, na, b, nb, out);
}

int csg_spans_diff(const csg_span *a, int na, const csg_span *b, int nb,
                   csg_span *out) {
  return spans_diff(a, na, b, nb, out);
}

/* The one span (or none) of a halfspace; parallel rays are classified by
 * their origin so no division by zero occurs.  Directions of any length
 * are fine: t* = -s0/k scales with 1/|d| exactly as the parameter does. */
static int plane_span(const csg_plane *p, int id, const double o[3],
                      const double d[3], double s0, double s1, csg_span *out) {
  double base = vec3_dot(p->n, o) - p->d;
  double k = vec3_dot(p->n, d);
  csg_span s = {s0, s1, -1, -1, 0, 0};
  if (k == 0) {
    if (!(base < 0)) return 0;
  } else {
    double ts = -base / k;
    if (k > 0) {          /* inside before the crossing */
      if (ts < s1) { s.t1 = ts; s.id1 = id; }
    } else {              /* inside after it */
      if (ts > s0) { s.t0 = ts; s.id0 = id; }
    }
  }
  if (!(s.t0 < s.t1)) return 0;
  *out = s;
  return 1;
}

/* One plane of convex_span (base = n.o - d, kd = n.d): its own span
 * [a, b] within [s0, s1], as plane_span has it, clipping [*t0, *t1].
 * 0 when the span is found empty (the rest cannot refill it). */
static inline int clip_plane(double base, double kd, int id, double s0,
                             double s1, double *t0, double *t1, int *id0,
                             int *id1) {
  double a = s0, b = s1;
  if (kd == 0) return base < 0;
  double ts = -base / kd;
  if (kd > 0) {
    if (ts < s1) b = ts;
    if (!(a < b)) return 0;
    if (b < *t1) {
      *t1 = b;
      *id1 = id;
      if (!(*t0 < *t1)) return 0;
    }
  } else {
    if (ts > s0) a = ts;
    if (!(a < b)) return 0;
    if (a > *t0) {
      *t0 = a;
      *id0 = id;
      if (!(*t0 < *t1)) return 0;
    }
  }
  return 1;
}

/* The span (or none) of the intersection of group g's planes: the planes'
 * spans clipped one after another, which is what csg_spans_inter makes of
 * them in any tree shape (the larger start and the smaller end win, the
 * earlier operand on ties), without the merges. */
static inline int convex_span(const csg_tape *t, const double *dots, int g,
                              const double o[3], const double d[3],
                              double s0, double s1, csg_span *out) {
  double t0 = s0, t1 = s1;
  int id0 = -1, id1 = -1;
  const struct csg_gplane *p = t->gpl + t->gstart[g];
  const struct csg_gplane *end = t->gpl + t->gstart[g + 1];
  if (dots) {   /* the same values (dot_slot) */
    for (; p < end; p++)
      if (!clip_plane(dots[p->u] - p->d, dots[p->u + 1], p->id, s0, s1,
                      &t0, &t1, &id0, &id1))
        return 0;
  } else {
    for (; p < end; p++)
      if (!clip_plane(vec3_dot(p->n, o) - p->d, vec3_dot(p->n, d), p->id,
                      s0, s1, &t0, &t1, &id0, &id1))
        return 0;
  }
  if (!(t0 < t1)) return 0;
  csg_span sp = {t0, t1, id0, id1, 0, 0};
  *out = sp;
  return 1;
}

static int ray_spans_loop(const csg_tape *t, const double *dots,
                          const double o[3], const double d[3], double s0,
                          double s1, csg_span *out, int maxout,
                          csg_span *scratch, int nscratch);

/* Roth's ray casting: one span per halfspace, combined bottom-up with the
 * span-list set operations; dots as csg_ray_spans_dots has them, or
 * NULL. The two common shapes of a bound here, the rest in
 * ray_spans_loop (out of line: its frame and scratch lists are not set
 * up for the common ones). */
static inline int ray_spans(const csg_tape *t, const double *dots,
                            const double o[3], const double d[3], double s0,
                            double s1, csg_span *out, int maxout,
                            csg_span *scratch, int nscratch) {
  /* One convex polyhedron (a typical bound): straight to out. */
  if (t->nrcode == 1 && t->rcode[0].op == CSG_CONVEX && maxout >= 1)
    return convex_span(t, dots, t->rcode[0].arg, o, d, s0, s1, out);
  /* Two convex polyhedra and one operation (a bound with a hole): the
     same spans and merge as the loop, without its scratch lists. */
  if (t->nrcode == 3 && t->rcode[0].op == CSG_CONVEX &&
      t->rcode[1].op == CSG_CONVEX) {
    csg_span x, y, m[2];
    int nx = convex_span(t, dots, t->rcode[0].arg, o, d, s0, s1, &x);
    int ny = convex_span(t, dots, t->rcode[1].arg, o, d, s0, s1, &y), n;
    switch (t->rcode[2].op) {
    case CSG_UNION: n = spans_union(&x, nx, &y, ny, m); break;
    case CSG_INTER: n = spans_inter(&x, nx, &y, ny, m); break;
    case CSG_DIFF: n = spans_diff(&x, nx, &y, ny, m); break;
    default: n = spans_diff(&y, ny, &x, nx, m); break;
    }
    if (n > maxout) return -1;
    for (int i = 0; i < n; i++) out[i] = m[i];   /* at most 2: no memcpy */
    return n;
  }
  return ray_spans_loop(t, dots, o, d, s0, s1, out, maxout, scratch, nscratch);
}

static int ray_spans_loop(const csg_tape *t, const double *dots,
                          const double o[3], const double d[3], double s0,
                          double s1, csg_span *out, int maxout,
                          csg_span *scratch, int nscratch) {
  csg_span local[CSG_LOCAL_SPANS];
  int need = csg_scratch_spans(t);
  if (!scratch) {
    scratch = local;
    nscratch = CSG_LOCAL_SPANS;
  }
  if (nscratch < need) return -1;
  /* The operand lists sit back to back in scratch[0 .. nleaves]; merges go
   * through the second half and are copied back. */
  csg_span *tmp = scratch + t->nleaves + 1;
  int off[CSG_STACK_MAX], cnt[CSG_STACK_MAX], sp = 0, top = 0;
  for (int i = 0; i < t->nrcode; i++) {
    const csg_instr *in = &t->rcode[i];
    if (in->op <= CSG_ALL || in->op == CSG_CONVEX) {
      int c = 0;
      if (in->op == CSG_CONVEX)
        c = convex_span(t, dots, in->arg, o, d, s0, s1, &scratch[top]);
      else if (in->op == CSG_PLANE)
        c = plane_span(&t->planes[in->arg], in->arg, o, d, s0, s1,
                       &scratch[top]);
      else if (in->op == CSG_ALL && s0 < s1) {
        csg_span s = {s0, s1, -1, -1, 0, 0};
        scratch[top] = s;
        c = 1;
      }
      off[sp] = top;
      cnt[sp++] = c;
      top += c;
      continue;
    }
    sp--;
    csg_span *x = &scratch[off[sp - 1]], *y = &scratch[off[sp]];
    int nx = cnt[sp - 1], ny = cnt[sp], n;
    switch (in->op) {
    case CSG_UNION: n = spans_union(x, nx, y, ny, tmp); break;
    case CSG_INTER: n = spans_inter(x, nx, y, ny, tmp); break;
    case CSG_DIFF: n = spans_diff(x, nx, y, ny, tmp); break;
    default: n = spans_diff(y, ny, x, nx, tmp); break;
    }
    memcpy(x, tmp, (size_t)n * sizeof *tmp);
    cnt[sp - 1] = n;
    top = off[sp - 1] + n;
  }
  if (cnt[0] > maxout) return -1;
  memcpy(out, scratch, (size_t)cnt[0] * sizeof *out);
  return cnt[0];
}

int csg_ray_spans(const csg_tape *t, const double o[3], const double d[3],
                  double s0, double s1, csg_span *out, int maxout,
                  csg_span *scratch, int nscratch) {
  return ray_spans(t, NULL, o, d, s0, s1, out, maxout, scratch, nscratch);
}

int csg_ray_spans_dots(const csg_tape *t, const double *dots,
                       const double o[3], const double d[3], double s0,
                       double s1, csg_span *out, int maxout,
                       csg_span *scratch, int nscratch) {
  return ray_spans(t, dots, o, d, s0, s1, out, maxout, scratch, nscratch);
}

/* The three-valued set operations of csg_box_class. */
static int box_op(csg_op op, int a, int b) {
  switch (op) {
  case CSG_UNION:
    if (a == CSG_BOX_IN || b == CSG_BOX_IN) return CSG_BOX_IN;
    return a == CSG_BOX_OUT && b == CSG_BOX_OUT ? CSG_BOX_OUT : CSG_BOX_MIX;
  case CSG_INTER:
    if (a == CSG_BOX_OUT || b == CSG_BOX_OUT) return CSG_BOX_OUT;
    return a == CSG_BOX_IN && b == CSG_BOX_IN ? CSG_BOX_IN : CSG_BOX_MIX;
  case CSG_DIFF:
    if (a == CSG_BOX_OUT || b == CSG_BOX_IN) return CSG_BOX_OUT;
    return a == CSG_BOX_IN && b == CSG_BOX_OUT ? CSG_BOX_IN : CSG_BOX_MIX;
  default: /* the reversed difference, b - a */
    return box_op(CSG_DIFF, b, a);
  }
}

int csg_prune_box(const csg_tape *t, const double lo[3], const double hi[3],
                  csg_instr *buf, csg_tape *view) {
  /* per stack entry: a constant (CSG_BOX_IN or CSG_BOX_OUT), or -1 for
     code, buf[start ..) */
  int kind[CSG_STACK_MAX + 1], start[CSG_STACK_MAX + 1], sp = 0, n = 0;
  for (int i = 0; i < t->ncode; i++) {
    const csg_instr *in = &t->code[i];
    if (in->op == CSG_PLANE || in->op == CSG_EMPTY || in->op == CSG_ALL) {
      int c = in->op == CSG_EMPTY ? CSG_BOX_OUT : CSG_BOX_IN;
      if (in->op == CSG_PLANE) {
        const csg_plane *p = &t->planes[in->arg];
        double rl, rh;
        vec3_plane_range(p->n, p->d, lo, hi, &rl, &rh);
        c = rh < 0 ? CSG_BOX_IN : (rl > 0 ? CSG_BOX_OUT : CSG_BOX_MIX);
      }
      kind[sp] = c == CSG_BOX_MIX ? -1 : c;
      start[sp++] = n;
      if (c == CSG_BOX_MIX) buf[n++] = *in;
      continue;
    }
    sp--;
    int op = in->op, x = kind[sp - 1], y = kind[sp];
    if (op == CSG_RDIFF) { /* y - x: as a difference of the two swapped */
      int r;
      if (x >= 0 && y >= 0) r = box_op(CSG_DIFF, y, x);
      else if (x >= 0) r = x == CSG_BOX_IN ? CSG_BOX_OUT : -2; /* y, or y */
      else if (y >= 0) r = y == CSG_BOX_OUT ? CSG_BOX_OUT : -3; /* all - x */
      else r = -4;
      if (r >= 0) {
        n = start[sp - 1];
        kind[sp - 1] = r;
      } else if (r == -2) { /* y - Empty: y's code in x's place */
        kind[sp - 1] = -1;
        start[sp - 1] = start[sp];
      } else if (r == -3) { /* Everything - x */
        buf[n++] = (csg_instr){CSG_ALL, 0};
        buf[n++] = (csg_instr){CSG_RDIFF, 0};
      } else {
        buf[n++] = *in;
      }
      continue;
    }
    if (x >= 0 && y >= 0) {
      kind[sp - 1] = box_op((csg_op)op, x, y);
      continue;
    }
    if (x < 0 && y < 0) {
      buf[n++] = *in;
      continue;
    }
    /* one operand constant: the result is a constant, the other operand,
       or (Everything - the other) */
    int cst = x >= 0 ? x : y, other_first = x >= 0; /* the code is y's */
    int res; /* CSG_BOX_IN / OUT, or -1: the other, -2: its complement */
    switch (op) {
    case CSG_UNION: res = cst == CSG_BOX_IN ? CSG_BOX_IN : -1; break;
    case CSG_INTER: res = cst == CSG_BOX_OUT ? CSG_BOX_OUT : -1; break;
    default: /* x - y */
      if (x >= 0) res = x == CSG_BOX_OUT ? CSG_BOX_OUT : -2;
      else res = y == CSG_BOX_IN ? CSG_BOX_OUT : -1;
      break;
    }
    if (res >= 0) {
      n = start[sp - 1];
      kind[sp - 1] = res;
      continue;
    }
    kind[sp - 1] = -1;
    if (other_first) start[sp - 1] = start[sp];
    if (res == -2) { /* Everything - y, y's code on the stack */
      buf[n++] = (csg_instr){CSG_ALL, 0};
      buf[n++] = (csg_instr){CSG_RDIFF, 0};
    }
  }
  if (sp == 1 && kind[0] >= 0) {
    n = 0;
    buf[n++] = (csg_instr){kind[0] == CSG_BOX_IN ? CSG_ALL : CSG_EMPTY, 0};
  }
  *view = *t;
  view->code = buf;
  view->ncode = n;
  view->nrcode = 0;
  view->rcode = NULL;
  view->ngroups = 0;
  view->ndirs = 0;
  view->dir = NULL;
  view->dirs_of = NULL;
  return n;
}

int csg_box_class(const csg_tape *t, const double lo[3], const double hi[3]) {
  unsigned char st[CSG_STACK_MAX];
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const csg_instr *in = &t->code[i];
    if (in->op == CSG_PLANE) {
      const csg_plane *p = &t->planes[in->arg];
      double rl, rh;
      vec3_plane_range(p->n, p->d, lo, hi, &rl, &rh);
      st[sp++] = rh < 0 ? CSG_BOX_IN : (rl > 0 ? CSG_BOX_OUT : CSG_BOX_MIX);
    } else if (in->op == CSG_EMPTY) {
      st[sp++] = CSG_BOX_OUT;
    } else if (in->op == CSG_ALL) {
      st[sp++] = CSG_BOX_IN;
    } else {
      sp--;
      st[sp - 1] = (unsigned char)box_op((csg_op)in->op, st[sp - 1], st[sp]);
    }
  }
  return sp == 1 ? st[0] : CSG_BOX_MIX;
}
