/* render.c: the ray tracer. See render.h. */
#include "render/render.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "core/bounds.h"
#include "render/camera.h"
#include "core/bvh.h"
#include "core/vec.h"
#include "scene/ray.h"

#define TILE 16
/* Tiles are traced in blocks of CULL_BLOCK x CULL_BLOCK pixels, each
   culled and pruned to its own rays (TileCull). */
#define CULL_BLOCK 8
/* The largest n of n x n samples per pixel (render_scene checks). */
#define GRID_MAX 16

/* ---- boxes ---- */

typedef struct Box {
  double lo[3], hi[3];
} Box;

static Box box_empty(void) {
  return (Box){{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
}
static Box box_all(void) {
  return (Box){{-INFINITY, -INFINITY, -INFINITY}, {INFINITY, INFINITY, INFINITY}};
}
static int box_is_empty(const Box *b) {
  return b->lo[0] > b->hi[0] || b->lo[1] > b->hi[1] || b->lo[2] > b->hi[2];
}
static int box_bounded(const Box *b) {
  for (int i = 0; i < 3; i++)
    if (!isfinite(b->lo[i]) || !isfinite(b->hi[i])) return box_is_empty(b);
  return 1;
}
static Box box_union(Box a, Box b) {
  for (int i = 0; i < 3; i++) {
    a.lo[i] = fmin(a.lo[i], b.lo[i]);
    a.hi[i] = fmax(a.hi[i], b.hi[i]);
  }
  return a;
}
static Box box_inter(Box a, Box b) {
  for (int i = 0; i < 3; i++) {
    a.lo[i] = fmax(a.lo[i], b.lo[i]);
    a.hi[i] = fmin(a.hi[i], b.hi[i]);
  }
  return a;
}

/* A convex set n.x <= d over a list of planes, or a box: a set holding
   the node's (only its box is asked for). An intersection that would
   hold more than CONVEX_MAX_PLANES planes keeps that many of them
   (shape_thin): convex_box costs the fourth power of the plane count,
   and a scene can intersect a million halfspaces. Fewer planes hold
   more, so the box stays conservative; they are chosen so that the set
   stays bounded (a prism of 72 sides and its two caps, 74 planes, had no
   box when the two halves' boxes, each unbounded, were intersected). */
#define CONVEX_MAX_PLANES 64
typedef struct Shape {
  int convex;
  int n, cap;
  double (*pl)[4];
  Box box;
} Shape;

static void shape_free(Shape *s) { free(s->pl); }

static int shape_add(Shape *s, const double n[3], double d) {
  if (s->n == s->cap) {
    int cap = s->cap ? 2 * s->cap : 8;
    double(*pl)[4] = realloc(s->pl, sizeof *pl * (size_t)cap);
    if (!pl) return -1;
    s->pl = pl;
    s->cap = cap;
  }
  s->pl[s->n][0] = n[0];
  s->pl[s->n][1] = n[1];
  s->pl[s->n][2] = n[2];
  s->pl[s->n][3] = d;
  s->n++;
  return 0;
}


/* The box of the convex set {x : n_j . x <= d_j} (unit normals). It is
   bounded iff its recession cone {u : n_j . u <= 0} is {0}; the cone's
   extreme rays lie along cross products of pairs of normals, and a set
   whose normals span less than 3 dimensions is unbounded. If bounded, the
   box is that of the vertices (triples of planes), widened a little. */
static Box convex_box(const Shape *s) {
  int n = s->n;
  if (n < 4) return box_all(); /* fewer than 4 halfspaces never enclose */
  int rank3 = 0;
  for (int j = 0; j < n; j++)
    for (int k = j + 1; k < n; k++) {
      double u[3];
      vec3_cross(s->pl[j], s->pl[k], u);
      double len = sqrt(vec3_dot(u, u));
      if (len < 1e-12) continue;
      for (int sgn = -1; sgn <= 1; sgn += 2) {
        int ray = 1;
        for (int i = 0; i < n && ray; i++)
          if (sgn * vec3_dot(s->pl[i], u) / len > 1e-12) ray = 0;
        if (ray) return box_all();
      }
      for (int i = 0; i < n && !rank3; i++)
        if (fabs(vec3_dot(s->pl[i], u)) / len > 1e-9) rank3 = 1;
    }
  if (!rank3) return box_all();
  Box b = box_empty();
  double scale = 1;
  for (int i = 0; i < n; i++) scale = fmax(scale, fabs(s->pl[i][3]));
  for (int a = 0; a < n; a++)
    for (int c = a + 1; c < n; c++)
      for (int e = c + 1; e < n; e++) {
        const double *p = s->pl[a], *q = s->pl[c], *r = s->pl[e];
        double qr[3], rp[3], pq[3];
        vec3_cross(q, r, qr);
        vec3_cross(r, p, rp);
        vec3_cross(p, q, pq);
        double det = vec3_dot(p, qr);
        if (fabs(det) < 1e-12) continue;
        double v[3];
        for (int i = 0; i < 3; i++)
          v[i] = (p[3] * qr[i] + q[3] * rp[i] + r[3] * pq[i]) / det;
        int inside = 1;
        for (int i = 0; i < n && inside; i++)
          if (vec3_dot(s->pl[i], v) > s->pl[i][3] + 1e-9 * scale) inside = 0;
        if (!inside) continue;
        for (int i = 0; i < 3; i++) {
          b.lo[i] = fmin(b.lo[i], v[i]);
          b.hi[i] = fmax(b.hi[i], v[i]);
        }
      }
  if (box_is_empty(&b)) return b;
  for (int i = 0; i < 3; i++) {
    double pad = 1e-9 * (scale + fabs(b.lo[i]) + fabs(b.hi[i]));
    b.lo[i] -= pad;
    b.hi[i] += pad;
  }
  return b;
}

static Box shape_box(Shape *s) { return s->convex ? convex_box(s) : s->box; }

/* Keeps CONVEX_MAX_PLANES of s's planes (s->n larger): first, for each
   of the 26 directions to a cube's faces, edges and corners from its
   centre, the plane whose normal is nearest it (so that a bounded set
   stays bounded: every direction is then cut off by some plane, unless
   the set is unbounded, or nearly, along it), then the others evenly
   spread over the list. */
static void shape_thin(Shape *s) {
  int n = s->n, k = 0;
  unsigned char *keep = calloc((size_t)n, 1);
  if (!keep) { /* the first planes alone: still a superset */
    s->n = CONVEX_MAX_PLANES;
    return;
  }
  for (int dx = -1; dx <= 1; dx++)
    for (int dy = -1; dy <= 1; dy++)
      for (int dz = -1; dz <= 1; dz++) {
        if (!dx && !dy && !dz) continue;
        double u[3] = {dx, dy, dz}, best = -HUGE_VAL;
        int bi = -1;
        for (int i = 0; i < n; i++) {
          double c = vec3_dot(s->pl[i], u);
          if (c > best) best = c, bi = i;
        }
        if (bi >= 0 && !keep[bi]) keep[bi] = 1, k++;
      }
  /* then every (rest / room)th of the rest: room of them exactly */
  int room = CONVEX_MAX_PLANES - k, rest = n - k, seen = 0;
  for (int i = 0; i < n && k < CONVEX_MAX_PLANES; i++) {
    if (keep[i]) continue;
    if ((long)seen++ * room % rest < room) keep[i] = 1, k++;
  }
  int m = 0;
  for (int i = 0; i < n && m < CONVEX_MAX_PLANES; i++)
    if (keep[i]) memmove(s->pl[m++], s->pl[i], sizeof s->pl[i]);
  s->n = m;
  free(keep);
}

/* Combine two shapes by a set operation ('u', 'i', 'd' for a - b). */
static void shape_combine(Shape *a, Shape *b, int op) {
  if (op == 'i' && a->convex && b->convex) {
    for (int i = 0; i < b->n; i++)
      if (shape_add(a, b->pl[i], b->pl[i][3]) < 0) break; /* a superset */
    shape_free(b);
    if (a->n > CONVEX_MAX_PLANES) shape_thin(a);
    return;
  }
  Box ba = shape_box(a), bb = shape_box(b);
  shape_free(a);
  shape_free(b);
  memset(a, 0, sizeof *a);
  a->box = op == 'u' ? box_union(ba, bb) : op == 'i' ? box_inter(ba, bb) : ba;
}

static void shape_plane(Shape *s, const double n[3], double d) {
  memset(s, 0, sizeof *s);
  s->convex = 1;
  shape_add(s, n, d);
}

static void shape_box_only(Shape *s, Box b) {
  memset(s, 0, sizeof *s);
  s->box = b;
}

/* The box of a sharp CSG tape (an outer bound). */
static Box csg_box(const csg_tape *t) {
  Shape stack[CSG_STACK_MAX + 2];
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const csg_instr *in = &t->code[i];
    switch (in->op) {
    case CSG_PLANE:
      shape_plane(&stack[sp++], t->planes[in->arg].n, t->planes[in->arg].d);
      break;
    case CSG_EMPTY: shape_box_only(&stack[sp++], box_empty()); break;
    case CSG_ALL: shape_box_only(&stack[sp++], box_all()); break;
    default: {
      Shape y = stack[--sp];
      Shape *x = &stack[sp - 1];
      if (in->op == CSG_RDIFF) { /* y - x */
        Shape tmp = *x;
        *x = y;
        shape_combine(x, &tmp, 'd');
      } else {
        shape_combine(x, &y, in->op == CSG_UNION ? 'u' : in->op == CSG_INTER ? 'i' : 'd');
      }
    }
    }
  }
  if (sp != 1) return box_all();
  Box b = shape_box(&stack[0]);
  shape_free(&stack[0]);
  return b;
}

/* The shape of a leaf node (not a set operation). */
static void leaf_shape(const ScNode *n, Shape *out) {
  switch (n->kind) {
  case SC_HALFSPACE:
    shape_plane(out, n->n, n->d);
    return;
  case SC_ROUNDED:
    shape_box_only(out, csg_box(n->outer));
    return;
  case SC_SOFT: {
    Box b;
    if (!soft_bounds(n->soft, b.lo, b.hi)) b = box_empty();
    shape_box_only(out, b);
    return;
  }
  case SC_ALL: shape_box_only(out, box_all()); return;
  default: shape_box_only(out, box_empty()); return; /* SC_EMPTY */
  }
}

static int is_op(ScKind k) { return k == SC_UNION || k == SC_INTER || k == SC_DIFF; }

/* Grow a stack *p of *cap elements of size sz (a local array at first:
   local) so that it holds at least need; 0, or -1 without memory. */
static int grow_stack(void **p, int *cap, int need, size_t sz, void *local) {
  if (need <= *cap) return 0;
  int cap2 = *cap * 2 > need ? *cap * 2 : need;
  void *q = *p == local ? malloc(sz * (size_t)cap2) : realloc(*p, sz * (size_t)cap2);
  if (!q) return -1;
  if (*p == local) memcpy(q, local, sz * (size_t)*cap);
  *p = q;
  *cap = cap2;
  return 0;
}

/* The shape of node: its subtree's leaves combined children first, a then
   b, on explicit stacks (the C stack stays flat however deep the tree).
   0, or -1 when memory runs out (*out is then unbounded). */
static int node_shape(const Scene *s, int node, Shape *out) {
  if (!is_op(s->nodes[node].kind)) {
    leaf_shape(&s->nodes[node], out);
    return 0;
  }
  enum { LOCAL = 32 };
  struct Frame { int node, stage; } lf[LOCAL], *fr = lf;
  Shape ls[LOCAL], *sh = ls;
  int capf = LOCAL, caps = LOCAL, nf = 0, ns = 0, r = 0;
  fr[nf++] = (struct Frame){node, 0};
  while (nf) {
    struct Frame *f = &fr[nf - 1];
    const ScNode *n = &s->nodes[f->node];
    if (!is_op(n->kind)) {
      if (grow_stack((void **)&sh, &caps, ns + 1, sizeof *sh, ls)) goto oom;
      leaf_shape(n, &sh[ns++]);
      nf--;
    } else if (f->stage < 2) {
      int child = f->stage++ ? n->b : n->a;
      if (grow_stack((void **)&fr, &capf, nf + 1, sizeof *fr, lf)) goto oom;
      fr[nf++] = (struct Frame){child, 0};
    } else {
      Shape b = sh[--ns];
      shape_combine(&sh[ns - 1], &b, n->kind == SC_UNION ? 'u' : n->kind == SC_INTER ? 'i' : 'd');
      nf--;
    }
  }
  *out = sh[0];
  goto done;
oom:
  for (int i = 0; i < ns; i++) shape_free(&sh[i]);
  shape_box_only(out, box_all());
  r = -1;
done:
  if (fr != lf) free(fr);
  if (sh != ls) free(sh);
  return r;
}

int render_node_box(const Scene *s, int node, double lo[3], double hi[3]) {
  Shape sh;
  node_shape(s, node, &sh); /* without memory: unbounded, still true */
  Box b = shape_box(&sh);
  shape_free(&sh);
  memcpy(lo, b.lo, sizeof b.lo);
  memcpy(hi, b.hi, sizeof b.hi);
  return box_bounded(&b);
}

/* ---- primitives and the BVH ---- */

typedef struct Prim {
  int node;
  Box box;
  int bounded;
  double colour[3];
} Prim;

typedef struct Tracer {
  const Scene *s;
  const RenderSettings *rs;
  Prim *prims;
  int nprims, capprims;
  int *bounded, nbounded;     /* prim indices in BVH order */
  int *unbounded, nunbounded;
  bvh bvh;                    /* over the bounded prims (core/bvh.h) */
  Camera cam;
  double coord_scale;       /* the largest |coordinate| of the eye and bounds */
  double lights[RENDER_MAX_LIGHTS][3];
  double intensity[RENDER_MAX_LIGHTS];
  int nlights;
  double eps;                 /* shadow-ray offset */
  Image *im;
  int tiles_x, tiles_y, ntiles;
  atomic_int next_tile;
  atomic_int done_tiles;
  atomic_int *cancel;
  pthread_mutex_t lock;
  double start, last_progress;
  int progressed;             /* the progress callback was called */
  int grid;                   /* n of the n x n samples */
  atomic_int oom;             /* a worker ran out of memory: all stop */
  int tiled;                  /* per-tile culling and pruning (TileCull) */
  /* Per primitive, a rounded one's log-concave envelope (dt_envelope):
     env_n[i] leaves at env_leaf[env_start[i] ..], 0 for none; NULL when
     QCS_ENVELOPE=0 or no primitive has one.  A shadow ray leaving the
     surface of its own primitive is first tried against it
     (dt_envelope_clear): a proof that it never re-enters spares the
     search. */
  int *env_n, *env_start, *env_leaf;
  double tile_pad;            /* how far a searched point may stray from
                                 a box it was bounded by (scene units) */
  Box *rbox;                  /* per scene node: a rounded node's outer
                                 bound's box (others unused) */
  int *prim_r, *prim_r0;      /* the rounded nodes of prim i's subtree:
                                 prim_r[prim_r0[i] .. prim_r0[i + 1]) */
} Tracer;

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int add_prim(Tracer *T, int node, const double *colour) {
  if (T->nprims == T->capprims) {
    int cap = T->capprims ? 2 * T->capprims : 16;
    Prim *p = realloc(T->prims, sizeof *p * (size_t)cap);
    if (!p) return -1;
    T->prims = p;
    T->capprims = cap;
  }
  Prim *p = &T->prims[T->nprims++];
  memset(p, 0, sizeof *p);
  p->node = node;
  const ScNode *n = &T->s->nodes[node];
  if (n->has_colour) colour = n->colour;
  if (colour) {
    memcpy(p->colour, colour, sizeof p->colour);
  } else {
    /* An unbounded halfspace is the floor of the conventions. */
    const double *c = n->kind == SC_HALFSPACE ? T->rs->floor_colour
                                              : T->rs->object_colour;
    memcpy(p->colour, c, sizeof p->colour);
  }
  Shape sh;
  if (node_shape(T->s, node, &sh)) return -1;
  p->box = shape_box(&sh);
  shape_free(&sh);
  p->bounded = box_bounded(&p->box);
  return 0;
}

/* The top-level union, flattened into primitives, a before b; colours
   are inherited. An explicit stack: a scene may be a union a million deep.
   0, or -1 when memory runs out. */
static int add_part(void *ctx, int part, const double *colour) {
  return add_prim((Tracer *)ctx, part, colour) ? -1 : 0;
}

static int collect_prims(Tracer *T, int root) {
  return scene_union_parts(T->s, root, add_part, T) ? -1 : 0;
}

/* The BVH over the bounded prims: median split on the widest spread of
   box centres, leaves of 2, ties in prim order (BVH_SORT); bounded is then
   put in leaf order. */
static int build_bvh(Tracer *T) {
  int n = T->nbounded, err = BVH_ENOMEM;
  bvh_item *it = malloc(sizeof *it * (size_t)n);
  int *order = malloc(sizeof *order * (size_t)n);
  if (it && order) {
    for (int i = 0; i < n; i++) {
      const Box *pb = &T->prims[T->bounded[i]].box;
      for (int k = 0; k < 3; k++) {
        it[i].lo[k] = pb->lo[k];
        it[i].hi[k] = pb->hi[k];
        it[i].c[k] = 0.5 * (pb->lo[k] + pb->hi[k]);
      }
    }
    err = bvh_build(&T->bvh, it, n, 2, BVH_SORT);
  }
  if (!err) {
    for (int i = 0; i < n; i++) order[i] = T->bounded[T->bvh.idx[i]];
    memcpy(T->bounded, order, sizeof *order * (size_t)n);
  }
  free(it);
  free(order);
  return err;
}

/* A ray's slab test set up once: o, inv = 1/d, and which components of d
   are 0 or NaN. */
typedef struct RaySlab {
  const double *o;
  double inv[3];
  unsigned char flat[3], any_flat;
} RaySlab;

static void ray_slab(RaySlab *r, const double o[3], const double d[3]) {
  r->o = o;
  int any = 0;   /* from registers: reading flat[] back as one word right
                    after its byte stores stalls store forwarding */
  for (int k = 0; k < 3; k++) {
    int f = !(fabs(d[k]) > 0);
    r->inv[k] = 1 / d[k];
    r->flat[k] = (unsigned char)f;
    any |= f;
  }
  r->any_flat = (unsigned char)any;
}

/* Slab test: the part of [t0, t1] inside the box, its start in *enter.
   The near face is lo's when 1/d > 0 and hi's when it is < 0 (rounding
   is monotonic, so the products keep that order, ties aside); on an axis
   the ray does not move along a product may be NaN (the origin on a face
   plane): the origin decides. */
static inline int slab_core(const double lo[3], const double hi[3],
                            const RaySlab *r, double t0, double t1,
                            double *enter, int flat) {
  for (int k = 0; k < 3; k++) {
    double a = (lo[k] - r->o[k]) * r->inv[k];
    double c = (hi[k] - r->o[k]) * r->inv[k];
    if (flat && r->flat[k] && (isnan(a) || isnan(c))) {
      if (r->o[k] < lo[k] || r->o[k] > hi[k]) return 0;
      continue;
    }
    if (r->inv[k] < 0) { /* a >= c: (hi - o) >= (lo - o), times 1/d < 0 */
      double tmp = a;
      a = c;
      c = tmp;
    }
    if (a > t0) t0 = a;
    if (c < t1) t1 = c;
    if (t0 > t1) return 0;
  }
  *enter = t0;
  return 1;
}

/* slab_core made twice by the compiler: without the NaN rule for the
   usual ray, with it for one with a zero component. */
static inline int slab_hit(const double lo[3], const double hi[3],
                           const RaySlab *r, double t0, double t1,
                           double *enter) {
  return r->any_flat ? slab_core(lo, hi, r, t0, t1, enter, 1)
                     : slab_core(lo, hi, r, t0, t1, enter, 0);
}

/* ---- tiles: the frustum, culled primitives and pruned tapes ---- */

/* The rays of a tile: from the eye along fwd + u right + v up for (u, v)
   in a rectangle, so inside the cone of its four corner directions c
   (c . fwd = 1). m are the cone's side planes through the eye, unit
   normals pointing in. */
typedef struct Frustum {
  double eye[3], fwd[3];
  double c[4][3], m[4][3];
} Frustum;

static void tile_frustum(const Camera *cam, double px0, double px1,
                         double py0, double py1, Frustum *f) {
  double h = cam->tan_half;
  double u0 = (2 * px0 / cam->width - 1) * h * cam->aspect;
  double u1 = (2 * px1 / cam->width - 1) * h * cam->aspect;
  double v0 = (1 - 2 * py1 / cam->height) * h; /* v falls as y grows */
  double v1 = (1 - 2 * py0 / cam->height) * h;
  /* widened past the rounding of camera_ray's directions */
  double wu = 1e-9 * (h * cam->aspect + fabs(u0) + fabs(u1));
  double wv = 1e-9 * (h + fabs(v0) + fabs(v1));
  u0 -= wu, u1 += wu, v0 -= wv, v1 += wv;
  double uv[4][2] = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
  memcpy(f->eye, cam->eye, sizeof f->eye);
  memcpy(f->fwd, cam->fwd, sizeof f->fwd);
  for (int k = 0; k < 4; k++)
    for (int i = 0; i < 3; i++)
      f->c[k][i] = cam->fwd[i] + uv[k][0] * cam->right[i] + uv[k][1] * cam->upv[i];
  double mid[3];
  for (int i = 0; i < 3; i++)
    mid[i] = cam->fwd[i] + 0.5 * (u0 + u1) * cam->right[i] +
             0.5 * (v0 + v1) * cam->upv[i];
  for (int k = 0; k < 4; k++) {
    double *m = f->m[k];
    vec3_cross(f->c[k], f->c[(k + 1) % 4], m);
    double len = sqrt(vec3_dot(m, m));
    double sg = vec3_dot(m, mid) < 0 ? -1 : 1;
    for (int i = 0; i < 3; i++) m[i] = len > 0 ? sg * m[i] / len : 0;
  }
}

/* The largest of n . (x - eye) over the box [lo, hi]. */
static double box_max_dot(const double n[3], const double eye[3],
                          const double lo[3], const double hi[3]) {
  double s = 0;
  for (int i = 0; i < 3; i++) {
    if (n[i] == 0) continue;
    double a = n[i] * (lo[i] - eye[i]), b = n[i] * (hi[i] - eye[i]);
    s += a > b ? a : b;
  }
  return s;
}

/* 0 if no point of the box, grown by pad, lies in the frustum in front
   of the eye (proved by a side plane or the eye's plane), else 1. */
static int frustum_meets_box(const void *ctx, const double lo[3],
                             const double hi[3], double pad) {
  const Frustum *f = ctx;
  if (box_max_dot(f->fwd, f->eye, lo, hi) < -pad) return 0;
  for (int k = 0; k < 4; k++)
    if (box_max_dot(f->m[k], f->eye, lo, hi) < -pad) return 0;
  return 1;
}

/* The segments from a box of points P (shadow rays' origins) to a point
   L (a light) fill the hull of P and L. */
typedef struct Hull {
  double lo[3], hi[3], L[3];
  double grow;               /* the segments may stray this far from it */
} Hull;

/* The range of (x_i - L_i) / w for x_i - L_i in [a, b], w in [w0, w1],
   0 < w0 <= w1. */
static void ratio_range(double a, double b, double w0, double w1,
                        double *lo, double *hi) {
  double q[4] = {a / w0, a / w1, b / w0, b / w1};
  *lo = *hi = q[0];
  for (int k = 1; k < 4; k++) {
    if (q[k] < *lo) *lo = q[k];
    if (q[k] > *hi) *hi = q[k];
  }
  double e = 1e-12 * (fabs(*lo) + fabs(*hi)) + 1e-300;
  *lo -= e;
  *hi += e;
}

/* 0 if the box grown by pad misses the hull (proved by the hull's box, or
   seen from L along an axis on one side of which all of P lies: beyond
   P, behind L, or outside P's rectangle in the central projection from
   L), else 1. */
static int hull_meets_box(const void *ctx, const double blo[3],
                          const double bhi[3], double pad) {
  const Hull *H = ctx;
  double lo[3], hi[3];
  pad += H->grow;
  for (int i = 0; i < 3; i++) {
    lo[i] = blo[i] - pad;
    hi[i] = bhi[i] + pad;
    double hl = H->lo[i] < H->L[i] ? H->lo[i] : H->L[i];
    double hh = H->hi[i] > H->L[i] ? H->hi[i] : H->L[i];
    if (hi[i] < hl || lo[i] > hh) return 0;
  }
  int k = -1;
  double gap = 0, sg = 1;
  for (int i = 0; i < 3; i++) {
    double a = H->lo[i] - H->L[i], b = H->L[i] - H->hi[i];
    if (a > gap) gap = a, k = i, sg = 1;
    if (b > gap) gap = b, k = i, sg = -1;
  }
  if (k < 0) return 1;
  /* w = sg (x_k - L_k): P's in [gap, pmax], the box's in [bl, bh] */
  double pmax = sg > 0 ? H->hi[k] - H->L[k] : H->L[k] - H->lo[k];
  double bl = sg > 0 ? lo[k] - H->L[k] : H->L[k] - hi[k];
  double bh = sg > 0 ? hi[k] - H->L[k] : H->L[k] - lo[k];
  double e = 1e-12 * (fabs(pmax) + fabs(bl) + fabs(bh));
  if (bh < -e || bl > pmax + e) return 0;
  if (bl <= e) return 1; /* the box reaches L's side: no projection */
  for (int i = 0; i < 3; i++) {
    if (i == k) continue;
    double pl, ph, ql, qh;
    ratio_range(H->lo[i] - H->L[i], H->hi[i] - H->L[i], gap, pmax, &pl, &ph);
    ratio_range(lo[i] - H->L[i], hi[i] - H->L[i], bl, bh, &ql, &qh);
    if (qh < pl || ql > ph) return 0;
  }
  return 1;
}

/* What one worker knows of its current tile (tile_begin): which BVH
   nodes and slots (T->bounded order) the tile's primary rays can meet,
   and, per rounded scene node, its tape pruned to the part of the
   frustum inside its outer bound's box (NULL: the whole tape); or, for
   the tile's shadow rays towards one light (shadow_begin), the nodes and
   slots the hull of their origins and the light meets. A culled box is
   one slab_hit refuses for every ray of the tile, and a pruned tape is
   one whose views over any searched interval are the whole tape's
   (density.h, dt_prune_class): the tile's pictures are the untiled
   tracer's, bit for bit (test_render checks). */
typedef struct TileSet {
  int node;
  size_t code, leaves, pcode, live; /* its view's offsets into the arenas */
} TileSet;

typedef struct TileCull {
  unsigned char *node_live, *slot_live;
  int nlive, one;            /* live slots; the slot when nlive == 1 */
  const dt_tape **tape;      /* per scene node, or NULL (no pruning) */
  unsigned *stamp;           /* per scene node: the tile it was pruned for */
  unsigned tile;             /* this tile's stamp (1, 2, ...) */
  TileSet *set;              /* the pruned nodes, and their views: */
  dt_tape *views;
  dt_prune_prog *progs;      /* the views' prune programs, if any */
  size_t nset, capset, capviews, capprogs;
  dt_instr *pcode;           /* arena of the programs' code */
  size_t npcode, cappcode;
  dt_instr *code;            /* arenas of the views' code and leaves */
  size_t ncode, capcode;
  dt_leaf *leaves;
  size_t nleaves, capleaves;
  int *live;                 /* arena of the grouped views' live lists */
  size_t nlv, caplv;
  signed char *cls;
  size_t capcls;
  int *stack;                /* the BVH walk's */
  long leaves_in, leaves_out; /* leaves before and after pruning */
} TileCull;

static void tile_cull_free(TileCull *tc) {
  free(tc->node_live);
  free(tc->slot_live);
  free(tc->tape);
  free(tc->stamp);
  free(tc->set);
  free(tc->views);
  free(tc->progs);
  free(tc->pcode);
  free(tc->code);
  free(tc->leaves);
  free(tc->live);
  free(tc->cls);
  free(tc->stack);
  memset(tc, 0, sizeof *tc);
}

/* prune: with the tape table (primary rays), else culling alone. */
static int tile_cull_init(const Tracer *T, TileCull *tc, int prune) {
  memset(tc, 0, sizeof *tc);
  size_t nn = (size_t)T->bvh.nnodes + 1, ns = (size_t)T->nbounded + 1;
  size_t sn = (size_t)T->s->n + 1;
  tc->node_live = malloc(nn);
  tc->slot_live = malloc(ns);
  tc->stack = malloc(sizeof *tc->stack * BVH_STACK);
  int bad = !tc->node_live || !tc->slot_live || !tc->stack;
  if (prune && !bad) {
    tc->tape = calloc(sn, sizeof *tc->tape);
    tc->stamp = calloc(sn, sizeof *tc->stamp);
    bad = !tc->tape || !tc->stamp;
  }
  if (bad) {
    tile_cull_free(tc);
    return -1;
  }
  return 0;
}

/* Room for n more elements of size sz in *p (capacity *cap, used). */
static int reserve(void **p, size_t *cap, size_t used, size_t n, size_t sz) {
  if (used + n <= *cap) return 0;
  size_t c = *cap * 2 > used + n ? *cap * 2 : used + n;
  void *q = realloc(*p, c * sz);
  if (!q) return -1;
  *p = q;
  *cap = c;
  return 0;
}

/* The region a tile's rays can search a rounded node in: the node's
   outer bound's box and the hull of a few points (the frustum's part of
   the box's depth range, or a shadow hull), each grown by pad. */
typedef struct Region {
  double P[9][3];
  int np;
  double pad;
} Region;

/* The region of a frustum over the box [lo, hi]: the frustum cut to the
   box's depth range along fwd, the hull of eight points. 0, or -1 if
   the box lies behind the eye. */
static int frustum_region(const Frustum *f, const double lo[3],
                          const double hi[3], Region *r) {
  double nf[3] = {-f->fwd[0], -f->fwd[1], -f->fwd[2]};
  double zh = box_max_dot(f->fwd, f->eye, lo, hi);
  double zl = -box_max_dot(nf, f->eye, lo, hi);
  if (!(zh >= 0)) return -1;
  if (zl < 0) zl = 0;
  r->np = 8;
  for (int k = 0; k < 4; k++)
    for (int i = 0; i < 3; i++) {
      r->P[k][i] = f->eye[i] + zl * f->c[k][i];
      r->P[k + 4][i] = f->eye[i] + zh * f->c[k][i];
    }
  return 0;
}

/* The leaves of a rounded node's tape t over the part of the region in
   its outer bound's box b (both grown by pad): 0 or 1 where a leaf's
   filter misses that part on its outer or inner side, -1 where it may be
   touched. A plane's range over the part is within its range over the
   box and over the hull of the region's points (the range over their
   vertices). Returns the live count, or -1 if the box is unbounded or
   the region empty (no pruning). */
static int classify_leaves(const dt_tape *t, const Frustum *f,
                           const Hull *H, const Box *b, double pad,
                           signed char *cls) {
  double lo[3], hi[3];
  for (int i = 0; i < 3; i++) {
    lo[i] = b->lo[i] - pad;
    hi[i] = b->hi[i] + pad;
    if (!isfinite(lo[i]) || !isfinite(hi[i])) return -1;
  }
  Region r;
  if (f) {
    if (frustum_region(f, lo, hi, &r)) return -1;
  } else {
    r.np = 9;
    for (int k = 0; k < 8; k++)
      for (int i = 0; i < 3; i++) r.P[k][i] = (k >> i) & 1 ? H->hi[i] : H->lo[i];
    memcpy(r.P[8], H->L, sizeof r.P[8]);
    pad += H->grow;
    for (int i = 0; i < 3; i++) {
      lo[i] -= H->grow;
      hi[i] += H->grow;
    }
  }
  int live = 0;
  for (int j = 0; j < t->nleaves; j++) {
    const dt_leaf *lf = &t->leaves[j];
    double pl = INFINITY, ph = -INFINITY;
    for (int k = 0; k < r.np; k++) {
      double sd = dt_leaf_dist(lf, r.P[k]);
      if (sd < pl) pl = sd;
      if (sd > ph) ph = sd;
    }
    double bl, bh;
    vec3_plane_range(lf->n, lf->d, lo, hi, &bl, &bh);
    /* the hull's range widened like the box's and by pad; the tighter */
    double w = 1e-12 * (fabs(pl) + fabs(ph) + 1) + pad;
    pl -= w;
    ph += w;
    double l = pl > bl ? pl : bl, h = ph < bh ? ph : bh;
    if (l > lf->r) cls[j] = 0;
    else if (h < -lf->r) cls[j] = 1;
    else cls[j] = -1, live++;
  }
  return live;
}

/* Prune rounded node id for the tile, once; its view is added to the
   arenas (tile_begin points tape[id] at it once all are made). */
static int tile_prune_node(const Tracer *T, TileCull *tc, const Frustum *f,
                           const Hull *H, int id) {
  if (tc->stamp[id] == tc->tile) return 0;
  tc->stamp[id] = tc->tile;
  const dt_tape *t = T->s->nodes[id].tape;
  size_t nl = (size_t)t->nleaves, nc = (size_t)t->ncode;
  if (reserve((void **)&tc->cls, &tc->capcls, 0, nl, 1)) return -1;
  int live = classify_leaves(t, f, H, &T->rbox[id], T->tile_pad, tc->cls);
  tc->leaves_in += t->nleaves;
  if (live < 0 || live == t->nleaves) {
    tc->leaves_out += t->nleaves;
    return 0;
  }
  size_t k = tc->nset, np = t->prog ? (size_t)t->prog->npcode : 0;
  if (reserve((void **)&tc->set, &tc->capset, k, 1, sizeof *tc->set) ||
      reserve((void **)&tc->views, &tc->capviews, k, 1, sizeof *tc->views) ||
      reserve((void **)&tc->progs, &tc->capprogs, k, 1, sizeof *tc->progs) ||
      reserve((void **)&tc->code, &tc->capcode, tc->ncode, nc, sizeof *tc->code) ||
      reserve((void **)&tc->pcode, &tc->cappcode, tc->npcode, np,
              sizeof *tc->pcode) ||
      reserve((void **)&tc->leaves, &tc->capleaves, tc->nleaves, nl,
              sizeof *tc->leaves) ||
      reserve((void **)&tc->live, &tc->caplv, tc->nlv, nl,
              sizeof *tc->live))
    return -1;
  dt_tape *v = &tc->views[k];
  dt_prune_prog *pg = &tc->progs[k];
  dt_prune_class(t, tc->cls, tc->code + tc->ncode, tc->leaves + tc->nleaves,
                 tc->pcode + tc->npcode, pg, tc->live + tc->nlv, v);
  tc->set[k] = (TileSet){id, tc->ncode, tc->nleaves, tc->npcode, tc->nlv};
  tc->ncode += (size_t)v->ncode;
  if (v->prog) {
    tc->npcode += (size_t)pg->npcode;
    tc->nlv += (size_t)v->nlive;
    tc->leaves_out += live;
  } else {
    tc->nleaves += (size_t)v->nleaves;
    tc->leaves_out += v->nleaves;
  }
  tc->nset++;
  return 0;
}

/* The rounded nodes of prim pi, pruned for the tile. */
static int tile_prune_prim(const Tracer *T, TileCull *tc, const Frustum *f,
                           const Hull *H, int pi) {
  if (!T->prim_r || (!f && !H)) return 0;
  for (int k = T->prim_r0[pi]; k < T->prim_r0[pi + 1]; k++)
    if (tile_prune_node(T, tc, f, H, T->prim_r[k])) return -1;
  return 0;
}

typedef int (*BoxTest)(const void *ctx, const double lo[3], const double hi[3],
                       double pad);

/* The BVH top down, dead subtrees skipped: node_live, slot_live, nlive
   and one by meets; with f, the live prims' rounded nodes pruned to f
   (tc's tapes set once all are made). 0, or -1 without memory. */
static int cull_bvh(const Tracer *T, TileCull *tc, BoxTest meets,
                    const void *ctx, const Frustum *f, const Hull *H) {
  double pad = T->tile_pad;
  tc->nlive = 0;
  tc->one = -1;
  if (tc->tape) {
    for (size_t k = 0; k < tc->nset; k++) tc->tape[tc->set[k].node] = NULL;
    tc->nset = tc->ncode = tc->nleaves = tc->npcode = tc->nlv = 0;
    if (++tc->tile == 0) { /* the stamps wrapped */
      memset(tc->stamp, 0, sizeof *tc->stamp * (size_t)(T->s->n + 1));
      tc->tile = 1;
    }
  } else {
    f = NULL;
    H = NULL;
  }
  if (T->bvh.nnodes) {
    int sp = 0;
    tc->stack[sp++] = 0;
    while (sp) {
      int ni = tc->stack[--sp];
      const bvh_node *b = &T->bvh.nodes[ni];
      tc->node_live[ni] = (unsigned char)meets(ctx, b->lo, b->hi, pad);
      if (!tc->node_live[ni]) continue;
      if (!b->count) {
        tc->stack[sp++] = b->first;
        tc->stack[sp++] = b->first + 1;
        continue;
      }
      for (int i = b->first; i < b->first + b->count; i++) {
        const Box *pb = &T->prims[T->bounded[i]].box;
        tc->slot_live[i] = (unsigned char)meets(ctx, pb->lo, pb->hi, pad);
        if (!tc->slot_live[i]) continue;
        tc->nlive++;
        tc->one = i;
        if (tile_prune_prim(T, tc, f, H, T->bounded[i])) goto oom;
      }
    }
  }
  for (int i = 0; i < T->nunbounded; i++)
    if (tile_prune_prim(T, tc, f, H, T->unbounded[i])) goto oom;
  for (size_t k = 0; k < tc->nset; k++) {
    dt_tape *v = &tc->views[k];
    v->code = tc->code + tc->set[k].code;
    if (v->prog) { /* its leaves are the whole tape's */
      v->prog = &tc->progs[k];
      v->prog->pcode = tc->pcode + tc->set[k].pcode;
      v->live = tc->live + tc->set[k].live;
    } else {
      v->leaves = tc->leaves + tc->set[k].leaves;
    }
    tc->tape[tc->set[k].node] = v;
  }
  return 0;
oom:
  tc->nset = 0;
  return -1;
}

/* tc for the primary rays of the pixel coordinates [px0, px1] x [py0,
   py1] (the extreme samples): culled to their frustum, tapes pruned. */
static int cull_bvh_frustum(const Tracer *T, TileCull *tc, double px0,
                            double px1, double py0, double py1) {
  Frustum f;
  tile_frustum(&T->cam, px0, px1, py0, py1, &f);
  return cull_bvh(T, tc, frustum_meets_box, &f, &f, NULL);
}

/* ---- hits ---- */

typedef struct Hit {
  double t;
  int prim;
  int id, flip;   /* the surface: scene node and orientation */
  int has_grad;   /* a rounded primitive's hit: grad is its density */
  double grad[3]; /* gradient there, from the root search */
} Hit;

/* A halfspace primitive's crossing in (t0, t1) (prim_hit's case, inlined
   into trace for the unbounded ones: the floor is tried by every ray). */
static inline int halfspace_hit(const ScNode *n, int node, int pi,
                                const double o[3], const double d[3],
                                double t0, double t1, Hit *h) {
  double nd = vec3_dot(n->n, d);
  if (nd == 0) return 0;
  double t = (n->d - vec3_dot(n->n, o)) / nd;
  if (!(t > t0 && t < t1)) return 0;
  h->t = t;
  h->id = node;
  h->flip = 0;
  h->has_grad = 0;
  h->prim = pi;
  return 1;
}

/* The first surface crossing of one primitive in (t0, t1); with any != 0
   (a shadow ray) a rounded primitive may report any t in (t0, t1] when
   there is a crossing, and none when there is none; any == 2 says the
   ray starts on this primitive's surface. */
static inline __attribute__((always_inline)) int
prim_hit(const Tracer *T, int pi, const double o[3],
                    const double d[3], double t0, double t1, RayCtx *c,
                    Hit *h, int any) {
  const Scene *s = T->s;
  int node = T->prims[pi].node;
  const ScNode *n = &s->nodes[node];
  switch (n->kind) {
  case SC_HALFSPACE:
    return halfspace_hit(n, node, pi, o, d, t0, t1, h);
  case SC_ROUNDED: {
    /* any == 2: a shadow ray from this primitive's own surface */
    if (any == 2 && T->env_n && T->env_n[pi] &&
        dt_envelope_clear(n->tape, T->env_leaf + T->env_start[pi],
                          T->env_n[pi], o, d))
      return 0;
    lg_root roots[8];
    double tol = ray_dist_tol(c, o, d);
    long unsplit = c->stats.lg.overflows;
    const dt_tape *tape = c->tapes && c->tapes[node] ? c->tapes[node] : n->tape;
    lg_query q = {.tape = tape, .o = o, .d = d, .t0 = t0, .t1 = t1,
                  .tol = tol, .out = roots, .maxout = 8, .stats = &c->stats.lg,
                  .mode = any ? LG_ANY : LG_FIRST, .grad = any ? NULL : h->grad};
    int nr = lg_search_bounded(&q, n->outer, n->inner);
    if (c->stats.lg.overflows != unsplit && c->unresolved_node < 0)
      c->unresolved_node = node;
    if (nr < 0) c->failed = 1;
    int k = 0;
    while (k < nr && (roots[k].kind == LG_TOUCH || !(roots[k].t > t0))) k++;
    if (k >= nr) return 0;
    h->t = roots[k].t;
    h->id = node;
    h->flip = 0;
    h->has_grad = !any;   /* the search stopped at roots[k] */
    h->prim = pi;
    return 1;
  }
  case SC_SOFT: {
    double t;
    int nr = any ? soft_any(n->soft, o, d, t0, t1, &t, c->soft, &c->stats.soft)
                 : soft_roots(n->soft, o, d, t0, t1, &t, 1, c->soft, &c->stats.soft);
    if (nr < 0) c->failed = 1;
    if (nr < 1) return 0;
    h->t = t;
    h->id = node;
    h->flip = 0;
    h->has_grad = 0;
    break;
  }
  default: {
    csg_span *sp;
    h->has_grad = 0;
    ray_reset(c);
    int ns = ray_spans(s, node, o, d, t0, t1, c, &sp);
    int found = 0;
    for (int i = 0; i < ns && !found; i++) {
      if (sp[i].id0 >= 0 && sp[i].t0 > t0 && sp[i].t0 < t1) {
        h->t = sp[i].t0;
        h->id = sp[i].id0;
        h->flip = sp[i].flip0;
        found = 1;
      } else if (sp[i].id1 >= 0 && sp[i].t1 > t0 && sp[i].t1 < t1) {
        h->t = sp[i].t1;
        h->id = sp[i].id1;
        h->flip = sp[i].flip1;
        found = 1;
      }
    }
    if (!found) return 0;
  }
  }
  h->prim = pi;
  return 1;
}

/* The nearest hit in (t0, t1); with any != 0, the first one found.
   With tc (a ray of tc's tile): only the BVH nodes and slots tc found
   live are visited, and rounded nodes are searched on tc's tapes (the
   same answer: TileCull). */
static inline __attribute__((always_inline)) int
trace(const Tracer *T, const double o[3], const double d[3],
                 double t0, double t1, RayCtx *c, Hit *best, int any,
                 const TileCull *tc, int self) {
  /* Hits go to *cur, one of *best and tmp (a primitive may write there
     and then miss), and the other becomes cur: at most one copy a ray,
     none when the nearest hit is the first. Copying each hit as found
     read the fields back whole right after their stores, which stalls
     store forwarding (a 48-byte rep movs on most primary rays). */
  Hit tmp, *cur = best, *won = NULL;
  c->tapes = tc ? tc->tape : NULL;
#define TRACE_WON                            \
  do {                                       \
    won = cur;                               \
    cur = cur == best ? &tmp : best;         \
    t1 = won->t;                             \
  } while (0)
  for (int i = 0; i < T->nunbounded; i++) {
    int pi = T->unbounded[i], node = T->prims[pi].node;
    const ScNode *n = &T->s->nodes[node];
    if (n->kind == SC_HALFSPACE
            ? halfspace_hit(n, node, pi, o, d, t0, t1, cur)
            : prim_hit(T, pi, o, d, t0, t1, c, cur,
                       any && pi == self ? 2 : any)) {
      TRACE_WON;
      if (any) goto out;
    }
  }
  if (!T->bvh.nnodes || (tc && tc->nlive == 0)) goto out;
  RaySlab rs;
  ray_slab(&rs, o, d);
  if (tc && tc->nlive == 1) { /* its ancestors' boxes hold its box */
    int pi = T->bounded[tc->one];
    const Box *pb = &T->prims[pi].box;
    double e2;
    if (slab_hit(pb->lo, pb->hi, &rs, t0, t1, &e2) &&
        prim_hit(T, pi, o, d, t0, t1, c, cur, any && pi == self ? 2 : any))
      TRACE_WON;
    goto out;
  }
  int stack[BVH_STACK], sp = 0;   /* enough for any tree (core/bvh.h) */
  stack[sp++] = 0;
  while (sp) {
    int ni = stack[--sp];
    if (tc && !tc->node_live[ni]) continue;
    const bvh_node *b = &T->bvh.nodes[ni];
    double enter;
    if (!slab_hit(b->lo, b->hi, &rs, t0, t1, &enter)) continue;
    if (b->count) {
      for (int i = b->first; i < b->first + b->count; i++) {
        if (tc && !tc->slot_live[i]) continue;
        int pi = T->bounded[i];
        const Box *pb = &T->prims[pi].box;
        double e2;
        if (!slab_hit(pb->lo, pb->hi, &rs, t0, t1, &e2)) continue;
        if (prim_hit(T, pi, o, d, t0, t1, c, cur, any && pi == self ? 2 : any)) {
          TRACE_WON;
          if (any) goto out;
        }
      }
      continue;
    }
    /* Visit the nearer child first. */
    const bvh_node *l = &T->bvh.nodes[b->first], *r = l + 1;
    double el = INFINITY, er = INFINITY;
    int hl = slab_hit(l->lo, l->hi, &rs, t0, t1, &el);
    int hr = slab_hit(r->lo, r->hi, &rs, t0, t1, &er);
    if (hl && hr) {
      if (el < er) {
        stack[sp++] = b->first + 1;
        stack[sp++] = b->first;
      } else {
        stack[sp++] = b->first;
        stack[sp++] = b->first + 1;
      }
    } else if (hl) {
      stack[sp++] = b->first;
    } else if (hr) {
      stack[sp++] = b->first + 1;
    }
  }
out:
#undef TRACE_WON
  c->tapes = NULL;
  if (won == &tmp) { /* by fields: a struct copy here is a rep movs */
    best->t = tmp.t;
    best->prim = tmp.prim;
    best->id = tmp.id;
    best->flip = tmp.flip;
    best->has_grad = tmp.has_grad;
    if (tmp.has_grad) memcpy(best->grad, tmp.grad, sizeof tmp.grad);
  }
  return won != NULL;
}

static long ray_work(const RayCtx *c) {
  return c->stats.lg.segments + c->stats.lg.rf_steps + c->stats.soft.intervals;
}

/* The lights' part of a camera sample's shading, between its shadow rays
   and its colour (shade_geom, shade_colour). */
typedef struct Lit {
  const double *col;             /* the primitive's colour; NULL: missed */
  double n[3];                   /* the normal, facing the ray */
  double L[RENDER_MAX_LIGHTS][3];/* towards light l, unit length */
  double ndl[RENDER_MAX_LIGHTS]; /* n . L */
  unsigned char lit[RENDER_MAX_LIGHTS]; /* light l reaches the point */
} Lit;

/* One camera sample of a tile, between its two passes. */
typedef struct Sample {
  Hit h;
  double d[3];
  long work;                  /* the primary ray's (ray_work), then its
                                 shadow rays' added */
  int found;
  double z, nrm[3];           /* its AOVs (shade_geom) */
} Sample;

typedef struct Worker {
  char pad0[128];             /* no cache line shared with the worker
                                 before it (its per-ray counters) */
  Tracer *T;
  RayCtx *c;
  long primary, shadow, max_work;
  long hits;                  /* primary rays that met a surface */
  long rounded_hits, rounded_hit_evals;
  TileCull tc;                /* the current tile's primary rays' */
  TileCull sh[RENDER_MAX_LIGHTS]; /* its shadow rays', per light */
  Sample *samples;            /* CULL_BLOCK^2 x grid^2 */
  Lit *lits;                  /* their shade_geom, as many */
  char pad1[128];
} Worker;

/* The primary ray of one camera sample: its hit, if any (counted). */
static inline __attribute__((always_inline)) int
primary_hit(Worker *W, const double o[3], const double d[3], Hit *h,
            const TileCull *tc) {
  const Tracer *T = W->T;
  RayCtx *c = W->c;
  long evals0 = c->stats.lg.evals;
  W->primary++;
  if (!trace(T, o, d, 0, INFINITY, c, h, 0, tc, -1)) return 0;
  W->hits++;
  if (T->s->nodes[h->id].kind == SC_ROUNDED) {
    W->rounded_hits++;
    W->rounded_hit_evals += c->stats.lg.evals - evals0;
  }
  return 1;
}

/* A camera sample's geometry from its primary hit h (found, else the
   background): for the AOVs the hit's distance and normal, and in *lt
   what shade_colour needs, its shadow rays traced; sh[l]: the culling of
   shadow rays towards light l, or NULL. */
static inline void shade_geom(Worker *W, const double o[3], const double d[3],
                              int found, const Hit *hp, Lit *lt, double *z,
                              double nrm[3], const TileCull *const *sh) {
  const Tracer *T = W->T;
  RayCtx *c = W->c;
  const RenderSettings *rs = T->rs;
  if (!found) {
    lt->col = NULL;
    *z = INFINITY;
    nrm[0] = nrm[1] = nrm[2] = 0;
    return;
  }
  double p[3], n[3];
  for (int i = 0; i < 3; i++) p[i] = o[i] + hp->t * d[i];
  if (hp->has_grad) { /* outward is down the density gradient */
    double g[3] = {-hp->grad[0], -hp->grad[1], -hp->grad[2]};
    ray_normal_grad(g, hp->flip, n);
  } else {
    ray_normal(T->s, hp->id, hp->flip, p, n);
  }
  if (vec3_dot(n, d) > 0)
    for (int i = 0; i < 3; i++) n[i] = -n[i];
  *z = hp->t; /* d is unit length: t is the distance */
  memcpy(nrm, n, sizeof n);
  memcpy(lt->n, n, sizeof n);
  lt->col = T->prims[hp->prim].colour;
  double pp = sqrt(vec3_dot(p, p));   /* fmax(1, pp) without a libm call */
  double scale = isnan(pp) || 1.0 > pp ? 1.0 : pp;
  double eps = T->eps * scale;
  for (int l = 0; l < T->nlights; l++) {
    double *L = lt->L[l];
    lt->lit[l] = 0;
    for (int i = 0; i < 3; i++) L[i] = T->lights[l][i] - p[i];
    double dist = sqrt(vec3_dot(L, L));
    if (!(dist > 0)) continue;
    for (int i = 0; i < 3; i++) L[i] /= dist;
    double ndl = vec3_dot(n, L);
    if (ndl <= 0) continue;
    if (rs->shadows) {
      double so[3];
      for (int i = 0; i < 3; i++) so[i] = p[i] + eps * n[i];
      Hit shh;
      W->shadow++;
      if (trace(T, so, L, 0, dist, c, &shh, 1, sh ? sh[l] : NULL, hp->prim))
        continue;
    }
    lt->ndl[l] = ndl;
    lt->lit[l] = 1;
  }
}

/* The sample's radiance from shade_geom's *lt (d: its ray). Apart from
   the tracing, so that a block's samples' colours are one loop of
   independent arithmetic (its square roots and divisions overlap). */
static inline void shade_colour(const Tracer *T, const double d[3],
                                const Lit *lt, double rgb[3]) {
  const RenderSettings *rs = T->rs;
  if (!lt->col) {
    memcpy(rgb, rs->background, 3 * sizeof(double));
    return;
  }
  const double *col = lt->col, *n = lt->n;
  for (int i = 0; i < 3; i++) rgb[i] = rs->ambient * col[i];
  for (int l = 0; l < T->nlights; l++) {
    if (!lt->lit[l]) continue;
    const double *L = lt->L[l];
    double ndl = lt->ndl[l];
    double H[3] = {L[0] - d[0], L[1] - d[1], L[2] - d[2]};
    double hl = sqrt(vec3_dot(H, H));
    double spec = 0;
    if (hl > 0) {
      double ndh = vec3_dot(n, H) / hl;
      if (ndh > 0) { /* 0.3 ndh^32 by five squarings */
        double p2 = ndh * ndh, p4 = p2 * p2, p8 = p4 * p4, p16 = p8 * p8;
        spec = 0.3 * p16 * p16;
      }
    }
    double I = T->intensity[l];
    for (int i = 0; i < 3; i++) rgb[i] += I * (col[i] * ndl + spec);
  }
}

/* A camera sample's radiance from its primary hit h, and its AOVs
   (shade_geom, then shade_colour). */
static inline void shade_hit(Worker *W, const double o[3], const double d[3],
                             int found, const Hit *hp, double rgb[3],
                             double *z, double nrm[3],
                             const TileCull *const *sh) {
  Lit lt;
  shade_geom(W, o, d, found, hp, &lt, z, nrm, sh);
  shade_colour(W->T, d, &lt, rgb);
}

static void progress(Tracer *T) {
  if (!T->rs->progress) return;
  double t = now();
  int done = atomic_load(&T->done_tiles);
  if (t - T->start < 0.5) return; /* start is set before the threads */
  pthread_mutex_lock(&T->lock);   /* last_progress is shared */
  if (t - T->last_progress >= 0.1) {
    T->last_progress = t;
    double frac = (double)done / T->ntiles;
    double left = frac > 0 ? (t - T->start) * (1 - frac) / frac : 0;
    T->rs->progress(T->rs->progress_ud, frac, left);
    T->progressed = 1;
  }
  pthread_mutex_unlock(&T->lock);
}

/* A pixel's values from its g x g samples' radiance, central AOVs and
   hits (render_tile's two forms). */
static inline void put_pixel(const Tracer *T, int g, int x, int y,
                             const double sum[3], int hits, double zmin,
                             const double nrm0[3], long cost) {
  Image *im = T->im;
  const RenderSettings *rs = T->rs;
  size_t k = img_index(im, x - im->x0, y - im->y0);
  /* one sample: dividing by 1 is exact, so it is skipped */
  for (int i = 0; i < 3; i++)
    im->rgba[4 * k + (size_t)i] = (float)(g == 1 ? sum[i] : sum[i] / (g * g));
  im->rgba[4 * k + 3] = rs->alpha ? (float)hits / (float)(g * g) : 1;
  if (im->z) im->z[k] = (float)zmin;
  if (im->n)
    for (int i = 0; i < 3; i++) im->n[3 * k + (size_t)i] = (float)nrm0[i];
  if (im->cost) im->cost[k] = (float)cost;
}

/* The offset (s + 0.5) / g of sample s of g across a pixel; 0.5 for one
   sample (the same value: dividing by 1 is exact) without a division. */
static inline double sample_off(int s, int g) {
  return g == 1 ? 0.5 : (s + 0.5) / g;
}

/* One sample of a pixel into its sums: the ray's work (for the largest),
   its colour (unless it missed and the picture has alpha), whether it hit,
   and the depth and normal AOVs from the central sample. The tiled and
   the untiled paths both use it, so they fill pixels alike. */
/* *p as one scalar load. rgb and nrm are stored a component at a time
   by shade_hit just before add_sample reads them; read as one 16-byte
   vector (what the compiler makes of the sums) they stall store
   forwarding, about 12 cycles a sample. The empty asm keeps each value
   its own register, so its load stays a scalar one. */
static inline double scalar_load(const double *p) {
  double v = *p;
#if defined(__x86_64__) || defined(__i386__)
  __asm__("" : "+x"(v));
#elif defined(__aarch64__)
  __asm__("" : "+w"(v));
#endif
  return v;
}

static inline void add_sample(Worker *W, long work, const double rgb[3],
                              double z, const double nrm[3], int central,
                              double sum[3], int *hits, double *zmin,
                              double nrm0[3]) {
  if (work > W->max_work) W->max_work = work;
  if (z < INFINITY) (*hits)++;
  if (z < INFINITY || !W->T->rs->alpha)
    for (int i = 0; i < 3; i++) sum[i] += scalar_load(&rgb[i]);
  if (central) {
    *zmin = z;
    for (int i = 0; i < 3; i++) nrm0[i] = scalar_load(&nrm[i]);
  }
}

/* A block's pixels [x0, x1) x [y0, y1) in two passes: every primary ray
   (culled and pruned to the block's frustum), then the shading, whose
   shadow rays are culled to the hull of their origins and each light.
   Rays do not depend on each other, so the pixels are those of the one
   pass form, bit for bit. */
static inline __attribute__((always_inline)) void
tile_culled(Worker *W, int x0, int x1, int y0, int y1, int g) {
  Tracer *T = W->T;
  const RenderSettings *rs = T->rs;
  const TileCull *tc = NULL;
  if (cull_bvh_frustum(T, &W->tc, x0 + 0.5 / g, x1 - 1 + (g - 0.5) / g,
                       y0 + 0.5 / g, y1 - 1 + (g - 0.5) / g) == 0)
    tc = &W->tc;
  Hull H;
  for (int i = 0; i < 3; i++) H.lo[i] = INFINITY, H.hi[i] = -INFINITY;
  double pmax = 1;
  /* camera_ray's factors of the block's sample columns and rows, once */
  double us[CULL_BLOCK * GRID_MAX], vs[CULL_BLOCK * GRID_MAX];
  for (int x = x0; x < x1; x++)
    for (int sx = 0; sx < g; sx++)
      us[(x - x0) * g + sx] = camera_u(&T->cam, x + sample_off(sx, g));
  for (int y = y0; y < y1; y++)
    for (int sy = 0; sy < g; sy++)
      vs[(y - y0) * g + sy] = camera_v(&T->cam, y + sample_off(sy, g));
  Sample *sp = W->samples;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++)
      for (int sy = 0; sy < g; sy++)
        for (int sx = 0; sx < g; sx++, sp++) {
          camera_dir(&T->cam, us[(x - x0) * g + sx], vs[(y - y0) * g + sy],
                     sp->d);
          long w0 = ray_work(W->c);
          sp->found = primary_hit(W, T->cam.eye, sp->d, &sp->h, tc);
          sp->work = ray_work(W->c) - w0;
        }
  /* the hit points' hull, after the tracing: its loop waits on no hit */
  size_t nsm = (size_t)(x1 - x0) * (size_t)(y1 - y0) * (size_t)g * (size_t)g;
  for (size_t k = 0; k < nsm; k++) {
    const Sample *s = &W->samples[k];
    if (!s->found) continue;
    for (int i = 0; i < 3; i++) {
      double p = T->cam.eye[i] + s->h.t * s->d[i];
      if (p < H.lo[i]) H.lo[i] = p;
      if (p > H.hi[i]) H.hi[i] = p;
      if (fabs(p) > pmax) pmax = fabs(p);
    }
  }
  /* a shadow ray runs from its hit point moved by eps along the normal
     (shade_hit) to the light moved alike: within eps of the segment from
     the hit point to the light */
  const TileCull *sh[RENDER_MAX_LIGHTS] = {NULL};
  if (rs->shadows && H.lo[0] <= H.hi[0]) {
    H.grow = 2 * T->eps * pmax * sqrt(3.0);
    for (int l = 0; l < T->nlights; l++) {
      memcpy(H.L, T->lights[l], sizeof H.L);
      if (cull_bvh(T, &W->sh[l], hull_meets_box, &H, NULL, &H) == 0)
        sh[l] = &W->sh[l];
    }
  }
  /* the shadow rays of every sample, then the colours: one loop of
     independent arithmetic, no tracing between */
  size_t ns = (size_t)(x1 - x0) * (size_t)(y1 - y0) * (size_t)g * (size_t)g;
  for (size_t k = 0; k < ns; k++) {
    sp = &W->samples[k];
    long w0 = ray_work(W->c);
    shade_geom(W, T->cam.eye, sp->d, sp->found, &sp->h, &W->lits[k], &sp->z,
               sp->nrm, sh);
    sp->work += ray_work(W->c) - w0;
  }
  sp = W->samples;
  const Lit *lt = W->lits;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++) {
      double sum[3] = {0, 0, 0}, zmin = INFINITY, nrm0[3] = {0, 0, 0};
      long cost = 0;
      int hits = 0;
      for (int sy = 0; sy < g; sy++)
        for (int sx = 0; sx < g; sx++, sp++, lt++) {
          double rgb[3];
          shade_colour(T, sp->d, lt, rgb);
          cost += sp->work;
          add_sample(W, sp->work, rgb, sp->z, sp->nrm,
                     sx == g / 2 && sy == g / 2, sum, &hits, &zmin, nrm0);
        }
      put_pixel(T, g, x, y, sum, hits, zmin, nrm0, cost);
    }
}

/* g (T->grid) a constant in the common one sample a pixel: its loops
   and divisions by 1 go (the same values). */
static void render_tile_culled(Worker *W, int x0, int x1, int y0, int y1) {
  if (W->T->grid == 1) tile_culled(W, x0, x1, y0, y1, 1);
  else tile_culled(W, x0, x1, y0, y1, W->T->grid);
}

static void render_tile(Worker *W, int tile) {
  Tracer *T = W->T;
  Image *im = T->im;
  /* tiles cover the crop (im); pixel coordinates are the full picture's */
  int tx = tile % T->tiles_x, ty = tile / T->tiles_x;
  int x0 = im->x0 + tx * TILE, y0 = im->y0 + ty * TILE;
  int xe = im->x0 + im->width, ye = im->y0 + im->height;
  int x1 = x0 + TILE < xe ? x0 + TILE : xe;
  int y1 = y0 + TILE < ye ? y0 + TILE : ye;
  if (T->tiled) { /* culled and pruned per block of the tile */
    for (int by = y0; by < y1; by += CULL_BLOCK)
      for (int bx = x0; bx < x1; bx += CULL_BLOCK)
        render_tile_culled(W, bx, bx + CULL_BLOCK < x1 ? bx + CULL_BLOCK : x1,
                           by, by + CULL_BLOCK < y1 ? by + CULL_BLOCK : y1);
    return;
  }
  int g = T->grid;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++) {
      double sum[3] = {0, 0, 0}, zmin = INFINITY, nrm0[3] = {0, 0, 0};
      long work0 = ray_work(W->c);
      int hits = 0;
      for (int sy = 0; sy < g; sy++)
        for (int sx = 0; sx < g; sx++) {
          double d[3], rgb[3], z, nrm[3];
          camera_ray(&T->cam, x + sample_off(sx, g), y + sample_off(sy, g), d);
          long w0 = ray_work(W->c);
          Hit h = {0};   /* grad is read only when the search set it */
          int found = primary_hit(W, T->cam.eye, d, &h, NULL);
          shade_hit(W, T->cam.eye, d, found, &h, rgb, &z, nrm, NULL);
          add_sample(W, ray_work(W->c) - w0, rgb, z, nrm,
                     sx == g / 2 && sy == g / 2, sum, &hits, &zmin, nrm0);
        }
      put_pixel(T, g, x, y, sum, hits, zmin, nrm0, ray_work(W->c) - work0);
    }
}

static void *worker_main(void *arg) {
  Worker *W = arg;
  Tracer *T = W->T;
  for (;;) {
    if (T->cancel && atomic_load_explicit(T->cancel, memory_order_relaxed)) break;
    if (atomic_load_explicit(&T->oom, memory_order_relaxed)) break;
    int tile = atomic_fetch_add(&T->next_tile, 1);
    if (tile >= T->ntiles) break;
    render_tile(W, tile);
    if (W->c->failed) { /* a query ran out of memory: the picture is wrong */
      atomic_store(&T->oom, 1);
      break;
    }
    atomic_fetch_add(&T->done_tiles, 1);
    progress(T);
  }
  return NULL;
}

/* Per-tile culling and pruning (TileCull), unless the environment says
   QCS_TILES=0: the pad, the rounded nodes' outer boxes and each
   primitive's rounded nodes. 0, or -1 without memory. */
static int tiles_setup(Tracer *T) {
  const char *e = getenv("QCS_TILES");
  T->tiled = !(e && !strcmp(e, "0"));
  if (!T->tiled) return 0;
  T->tile_pad = 2 * fmax(T->rs->tol, RAY_TOL_FLOOR * T->coord_scale) +
                1e-9 * T->coord_scale;
  const Scene *s = T->s;
  if (!(s->flags & SCENE_HAS_ROUNDED)) return 0;
  size_t total = 0;
  for (int i = 0; i < T->nprims; i++) {
    int node = T->prims[i].node;
    for (int k = s->nodes[node].first; k <= node; k++)
      total += s->nodes[k].kind == SC_ROUNDED;
  }
  /* shared subtrees could make the lists longer than the scene: then no
     pruning (the culling stays) */
  if (total > 4 * (size_t)s->n + 1024) return 0;
  T->rbox = malloc(sizeof *T->rbox * (size_t)s->n);
  T->prim_r = malloc(sizeof *T->prim_r * (total + 1));
  T->prim_r0 = malloc(sizeof *T->prim_r0 * (size_t)(T->nprims + 1));
  if (!T->rbox || !T->prim_r || !T->prim_r0) return -1;
  for (int k = 0; k < s->n; k++)
    if (s->nodes[k].kind == SC_ROUNDED) T->rbox[k] = csg_box(s->nodes[k].outer);
  int m = 0;
  for (int i = 0; i < T->nprims; i++) {
    T->prim_r0[i] = m;
    int node = T->prims[i].node;
    for (int k = s->nodes[node].first; k <= node; k++)
      if (s->nodes[k].kind == SC_ROUNDED) T->prim_r[m++] = k;
  }
  T->prim_r0[T->nprims] = m;
  return 0;
}

/* Each rounded primitive's envelope (Tracer.env_n), unless the
   environment says QCS_ENVELOPE=0. 0, or -1 without memory. */
static int envelopes_setup(Tracer *T) {
  const char *e = getenv("QCS_ENVELOPE");
  if (e && !strcmp(e, "0")) return 0;
  const Scene *s = T->s;
  size_t total = 0;
  for (int i = 0; i < T->nprims; i++) {
    const ScNode *n = &s->nodes[T->prims[i].node];
    if (n->kind == SC_ROUNDED) total += (size_t)n->tape->nleaves;
  }
  if (!total) return 0;
  T->env_n = calloc((size_t)T->nprims, sizeof *T->env_n);
  T->env_start = calloc((size_t)T->nprims, sizeof *T->env_start);
  T->env_leaf = malloc(sizeof *T->env_leaf * total);
  if (!T->env_n || !T->env_start || !T->env_leaf) return -1;
  int m = 0;
  for (int i = 0; i < T->nprims; i++) {
    const ScNode *n = &s->nodes[T->prims[i].node];
    if (n->kind != SC_ROUNDED) continue;
    T->env_start[i] = m;
    T->env_n[i] = dt_envelope(n->tape, T->env_leaf + m);
    m += T->env_n[i];
  }
  return 0;
}

void render_defaults(RenderSettings *rs) {
  memset(rs, 0, sizeof *rs);
  rs->width = 600;
  rs->height = 380;
  rs->spp = 1;
  rs->fov = 35;
  rs->up[1] = 1;
  rs->ambient = 0.15;
  rs->background[0] = 0.55;
  rs->background[1] = 0.65;
  rs->background[2] = 0.85;
  rs->object_colour[0] = 0.80;
  rs->object_colour[1] = 0.78;
  rs->object_colour[2] = 0.72;
  rs->floor_colour[0] = rs->floor_colour[1] = rs->floor_colour[2] = 0.5;
  rs->tol = 1e-9;
  rs->shadows = 1;
  rs->aovs = IMG_Z | IMG_N;
  rs->progress = NULL;
}

/* The camera (camera.h) framing the bounded primitives, the lights and
   the shadow offset scaled to them, and the coordinate scale. */
static int setup_camera(Tracer *T, char *err, size_t errlen) {
  const RenderSettings *rs = T->rs;
  Box all = box_empty();
  for (int i = 0; i < T->nprims; i++) {
    if (!T->prims[i].bounded) continue;
    const ScNode *nd = &T->s->nodes[T->prims[i].node];
    Box b = T->prims[i].box;
    /* a soft object is framed by where its surface can be (as
       camera_scene_box does), not by its keys' reach; with the camera
       given there is nothing to frame, and the keys' reach (known
       already) scales the shadow offset as it always did */
    if (nd->kind == SC_SOFT && !rs->camera_set &&
        !soft_surface_bounds(nd->soft, b.lo, b.hi))
      continue;
    all = box_union(all, b);
  }
  if (camera_setup(&T->cam, rs, !box_is_empty(&all), all.lo, all.hi, err, errlen))
    return -1;
  const double *eye = T->cam.eye, *c = T->cam.centre;
  double R = T->cam.radius;
  /* Rounded roots are placed to ray_dist_tol: max(tol, RAY_TOL_FLOOR |o|)
     along a ray from o: rays start at the eye or at a hit inside the bounds. */
  T->coord_scale = 1;
  for (int i = 0; i < 3; i++) {
    T->coord_scale = fmax(T->coord_scale, fabs(eye[i]));
    if (isfinite(T->cam.lo[i]) && isfinite(T->cam.hi[i]))
      T->coord_scale = fmax(T->coord_scale, fmax(fabs(T->cam.lo[i]), fabs(T->cam.hi[i])));
  }
  if (rs->nlights) {
    T->nlights = rs->nlights;
    memcpy(T->lights, rs->lights, sizeof T->lights);
    memcpy(T->intensity, rs->light_intensity, sizeof T->intensity);
  } else {
    T->nlights = 1;
    T->intensity[0] = 1;
    if (rs->camera_set) { /* the conventional light */
      T->lights[0][0] = -3;
      T->lights[0][1] = 8;
      T->lights[0][2] = 6;
    } else { /* the same direction, scaled to the scene */
      double l[3] = {-3, 8, 6};
      for (int i = 0; i < 3; i++) T->lights[0][i] = c[i] + l[i] * R;
    }
  }
  T->eps = 1e-7 * fmax(R, 1e-3);
  return 0;
}

/* FNV-1a over bytes. */
static uint64_t fnv(uint64_t h, const void *p, size_t n) {
  const unsigned char *b = p;
  for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 1099511628211ULL;
  return h;
}

/* The camera matrices and the settings as attributes of im (render.h). */
static int image_meta(const Tracer *T, Image *im) {
  const RenderSettings *rs = T->rs;
  const Camera *c = &T->cam;
  /* worldToCamera: camera space looks down -z, x right, y up; rows are
     the images of the world axes (OpenEXR's row-vector convention) */
  float *m = im->world_to_camera;
  const double *ax[3] = {c->right, c->upv, c->fwd};
  for (int j = 0; j < 3; j++) {
    double sg = j == 2 ? -1 : 1;
    for (int i = 0; i < 3; i++) m[4 * i + j] = (float)(sg * ax[j][i]);
    m[12 + j] = (float)(-sg * (ax[j][0] * c->eye[0] + ax[j][1] * c->eye[1] +
                               ax[j][2] * c->eye[2]));
    m[4 * j + 3] = 0;
  }
  m[15] = 1;
  /* worldToNDC = worldToCamera x projection: after the division by w
     (the distance in front of the eye), x and y run over [-1, 1] across
     the whole picture (y up), and z = near / w with near = 1e-3 R */
  double sx = 1 / (c->tan_half * c->aspect), sy = 1 / c->tan_half;
  double P[4][4] = {{sx, 0, 0, 0}, {0, sy, 0, 0}, {0, 0, 0, -1},
                    {0, 0, 1e-3 * c->radius, 0}};
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      double v = 0;
      for (int k = 0; k < 4; k++) v += (double)m[4 * i + k] * P[k][j];
      im->world_to_ndc[4 * i + j] = (float)v;
    }
  im->has_camera = 1;
  char buf[512];
  int r = 0;
  snprintf(buf, sizeof buf, "%dx%d", rs->width, rs->height);
  r |= img_set_attr(im, "qcs.size", buf);
  snprintf(buf, sizeof buf, "%d", rs->spp);
  r |= img_set_attr(im, "qcs.samples", buf);
  snprintf(buf, sizeof buf, "eye %.17g %.17g %.17g forward %.17g %.17g %.17g "
           "up %.17g %.17g %.17g fov %.17g", c->eye[0], c->eye[1], c->eye[2],
           c->fwd[0], c->fwd[1], c->fwd[2], c->upv[0], c->upv[1], c->upv[2],
           rs->fov);
  r |= img_set_attr(im, "qcs.camera", buf);
  int n = 0;
  buf[0] = 0;
  for (int l = 0; l < T->nlights && n < (int)sizeof buf - 80; l++)
    n += snprintf(buf + n, sizeof buf - (size_t)n, "%s%.17g %.17g %.17g "
                  "intensity %.17g", l ? "; " : "", T->lights[l][0],
                  T->lights[l][1], T->lights[l][2], T->intensity[l]);
  r |= img_set_attr(im, "qcs.lights", buf);
  snprintf(buf, sizeof buf, "ambient %.17g background %.17g %.17g %.17g "
           "object %.17g %.17g %.17g floor %.17g %.17g %.17g shadows %s",
           rs->ambient, rs->background[0], rs->background[1],
           rs->background[2], rs->object_colour[0], rs->object_colour[1],
           rs->object_colour[2], rs->floor_colour[0], rs->floor_colour[1],
           rs->floor_colour[2], rs->shadows ? "on" : "off");
  r |= img_set_attr(im, "qcs.shading", buf);
  snprintf(buf, sizeof buf, "%.17g", rs->tol);
  r |= img_set_attr(im, "qcs.tolerance", buf);
  r |= img_set_attr(im, "qcs.alpha", rs->alpha ? "on" : "off");
  /* the scene: its nodes' kinds, links, planes and colours, and the
     primitives' boxes (which rounded and soft shapes determine) */
  uint64_t h = 1469598103934665603ULL;
  for (int i = 0; i < T->s->n; i++) {
    const ScNode *nd = &T->s->nodes[i];
    int ints[4] = {(int)nd->kind, nd->a, nd->b, nd->has_colour};
    h = fnv(h, ints, sizeof ints);
    h = fnv(h, nd->n, sizeof nd->n);
    h = fnv(h, &nd->d, sizeof nd->d);
    h = fnv(h, nd->colour, sizeof nd->colour);
  }
  for (int i = 0; i < T->nprims; i++) {
    h = fnv(h, T->prims[i].box.lo, sizeof T->prims[i].box.lo);
    h = fnv(h, T->prims[i].box.hi, sizeof T->prims[i].box.hi);
  }
  snprintf(buf, sizeof buf, "%d nodes, %d primitives, fingerprint %016llx",
           T->s->n, T->nprims, (unsigned long long)h);
  r |= img_set_attr(im, "qcs.scene", buf);
  return r ? -1 : 0;
}

Image *render_scene(const Scene *s, const RenderSettings *rs,
                    RenderReport *rep, atomic_int *cancel,
                    char *err, size_t errlen) {
  memset(rep, 0, sizeof *rep);
  if (img_check_size(rs->width, rs->height, err, errlen)) return NULL;
  int grid = (int)lround(sqrt((double)rs->spp));
  if (rs->spp < 1 || grid * grid != rs->spp || grid > GRID_MAX) {
    snprintf(err, errlen, "samples per pixel must be a square number from 1 "
             "to 256 (1, 4, 9, ...: an n x n stratified grid), not %d",
             rs->spp);
    return NULL;
  }
  if (!(rs->fov > 0 && rs->fov < 180)) {
    snprintf(err, errlen, "the field of view must be between 0 and 180 "
             "degrees, not %g", rs->fov);
    return NULL;
  }
  int cx0 = 0, cx1 = rs->width, cy0 = 0, cy1 = rs->height;
  if (rs->crop_x0 || rs->crop_x1 || rs->crop_y0 || rs->crop_y1) {
    if (rs->crop_x0 < 0 || rs->crop_x1 > rs->width ||
        rs->crop_x0 >= rs->crop_x1 || rs->crop_y0 < 0 ||
        rs->crop_y1 > rs->height || rs->crop_y0 >= rs->crop_y1) {
      snprintf(err, errlen, "the crop %d,%d,%d,%d (columns x0..x1, rows "
               "y0..y1, end excluded) is not a part of the %dx%d image",
               rs->crop_x0, rs->crop_x1, rs->crop_y0, rs->crop_y1,
               rs->width, rs->height);
      return NULL;
    }
    cx0 = rs->crop_x0, cx1 = rs->crop_x1, cy0 = rs->crop_y0, cy1 = rs->crop_y1;
  }
  Tracer T;
  memset(&T, 0, sizeof T);
  T.s = s;
  T.rs = rs;
  T.grid = grid;
  T.cancel = cancel;
  pthread_mutex_init(&T.lock, NULL);
  Image *im = NULL;
  Worker *workers = NULL;
  pthread_t *threads = NULL;
  int nthreads = rs->threads > 0 ? rs->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
  if (nthreads < 1) nthreads = 1;
  if (nthreads > 256) nthreads = 256;
  if (collect_prims(&T, s->root)) goto oom;
  T.bounded = malloc(sizeof(int) * (size_t)(T.nprims + 1));
  T.unbounded = malloc(sizeof(int) * (size_t)(T.nprims + 1));
  if (!T.bounded || !T.unbounded) goto oom;
  for (int i = 0; i < T.nprims; i++) {
    if (box_is_empty(&T.prims[i].box)) continue; /* nothing to see */
    if (T.prims[i].bounded) T.bounded[T.nbounded++] = i;
    else T.unbounded[T.nunbounded++] = i;
  }
  if (T.nbounded && build_bvh(&T)) goto oom;
  if (setup_camera(&T, err, errlen)) goto fail;
  if (tiles_setup(&T)) goto oom;
  if (envelopes_setup(&T)) goto oom;
  im = img_new(cx1 - cx0, cy1 - cy0, rs->aovs);
  if (!im) goto oom;
  im->x0 = cx0;
  im->y0 = cy0;
  im->full_width = rs->width;
  im->full_height = rs->height;
  if (image_meta(&T, im)) goto oom;
  T.im = im;
  T.tiles_x = (im->width + TILE - 1) / TILE;
  T.tiles_y = (im->height + TILE - 1) / TILE;
  T.ntiles = T.tiles_x * T.tiles_y;
  atomic_init(&T.next_tile, 0);
  atomic_init(&T.done_tiles, 0);
  atomic_init(&T.oom, 0);
  T.start = now();
  workers = calloc((size_t)nthreads, sizeof *workers);
  threads = calloc((size_t)nthreads, sizeof *threads);
  if (!workers || !threads) goto oom;
  for (int i = 0; i < nthreads; i++) {
    workers[i].T = &T;
    workers[i].c = ray_ctx_new(s, rs->tol);
    if (!workers[i].c) goto oom;
    if (T.tiled) {
      size_t ns = (size_t)CULL_BLOCK * CULL_BLOCK * (size_t)grid * (size_t)grid;
      workers[i].samples = malloc(sizeof *workers[i].samples * ns);
      workers[i].lits = malloc(sizeof *workers[i].lits * ns);
      if (!workers[i].samples || !workers[i].lits ||
          tile_cull_init(&T, &workers[i].tc, 1))
        goto oom;
      for (int l = 0; l < T.nlights; l++)
        if (tile_cull_init(&T, &workers[i].sh[l], 1)) goto oom;
    }
  }
  int started = 0;
  for (int i = 1; i < nthreads; i++)
    if (pthread_create(&threads[i], NULL, worker_main, &workers[i]) == 0)
      started = i;
    else
      break;
  worker_main(&workers[0]);
  for (int i = 1; i <= started; i++) pthread_join(threads[i], NULL);
  if (rs->progress && T.progressed) rs->progress(rs->progress_ud, 1, 0);
  rep->seconds = now() - T.start;
  rep->width = im->width;
  rep->height = im->height;
  rep->spp = rs->spp;
  rep->threads = started + 1;
  rep->tol = rs->tol;
  rep->unresolved = 0;
  rep->unresolved_node = -1;
  rep->coord_scale = T.coord_scale;
  rep->tol_in_force = fmax(rs->tol, RAY_TOL_FLOOR * T.coord_scale);
  rep->prims = T.nprims;
  rep->bounded_prims = T.nbounded;
  for (int i = 0; i < nthreads; i++) {
    Worker *W = &workers[i];
    rep->primary += W->primary;
    rep->hits += W->hits;
    rep->shadow += W->shadow;
    rep->evals += W->c->stats.lg.evals;
    rep->segments += W->c->stats.lg.segments;
    rep->steps += W->c->stats.lg.rf_steps;
    rep->soft_solves += W->c->stats.soft.poly.solves;
    if (W->max_work > rep->max_ray_work) rep->max_ray_work = W->max_work;
    rep->rounded_hits += W->rounded_hits;
    rep->rounded_hit_evals += W->rounded_hit_evals;
    rep->unresolved += W->c->stats.lg.overflows;
    if (rep->unresolved_node < 0) rep->unresolved_node = W->c->unresolved_node;
  }
  if (atomic_load(&T.oom)) goto oom;
  if (cancel && atomic_load(cancel) && atomic_load(&T.done_tiles) < T.ntiles) {
    rep->interrupted = 1;
    snprintf(err, errlen, "render interrupted");
    img_free(im);
    im = NULL;
  }
  goto done;
oom:
  snprintf(err, errlen, "out of memory for the render");
fail:
  img_free(im);
  im = NULL;
done:
  if (workers)
    for (int i = 0; i < nthreads; i++) {
      ray_ctx_free(workers[i].c);
      tile_cull_free(&workers[i].tc);
      for (int l = 0; l < RENDER_MAX_LIGHTS; l++) tile_cull_free(&workers[i].sh[l]);
      free(workers[i].samples);
      free(workers[i].lits);
    }
  free(workers);
  free(threads);
  free(T.prims);
  free(T.bounded);
  free(T.unbounded);
  free(T.rbox);
  free(T.prim_r);
  free(T.prim_r0);
  free(T.env_n);
  free(T.env_start);
  free(T.env_leaf);
  bvh_free(&T.bvh);
  pthread_mutex_destroy(&T.lock);
  return im;
}
