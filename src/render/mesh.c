/* mesh.c: octree classification and marching tetrahedra (see mesh.h). */
#include "render/mesh.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/bounds.h"
#include "core/interval.h"
#include "core/vec.h"
#include "render/image.h"
#include "render/render.h"
#include "scene/ray.h"

#define MAX_DEPTH 19       /* grid coordinates fit 20 bits */

/* ---- a hash map from 64-bit keys to ints ------------------------------ */

typedef struct {
  uint64_t *k;             /* key + 1; 0 is free */
  int *v;
  size_t cap, n;
} hmap;

static size_t hslot(const hmap *h, uint64_t key) {
  uint64_t x = key * 0x9E3779B97F4A7C15ull;
  x ^= x >> 29;
  size_t i = (size_t)x & (h->cap - 1);
  while (h->k[i] && h->k[i] != key + 1) i = (i + 1) & (h->cap - 1);
  return i;
}

static int hgrow(hmap *h) {
  size_t ncap = h->cap ? h->cap * 2 : 1024;
  hmap g = {calloc(ncap, sizeof *g.k), malloc(ncap * sizeof *g.v), ncap, 0};
  if (!g.k || !g.v) {
    free(g.k);
    free(g.v);
    return -1;
  }
  for (size_t i = 0; i < h->cap; i++)
    if (h->k[i]) {
      size_t j = hslot(&g, h->k[i] - 1);
      g.k[j] = h->k[i];
      g.v[j] = h->v[i];
    }
  g.n = h->n;
  free(h->k);
  free(h->v);
  *h = g;
  return 0;
}

/* The value of key, or -1 if absent. */
static int hget(const hmap *h, uint64_t key) {
  if (!h->cap) return -1;
  size_t i = hslot(h, key);
  return h->k[i] ? h->v[i] : -1;
}

static int hput(hmap *h, uint64_t key, int v) {
  if (2 * (h->n + 1) > h->cap && hgrow(h) < 0) return -1;
  size_t i = hslot(h, key);
  if (!h->k[i]) h->n++;
  h->k[i] = key + 1;
  h->v[i] = v;
  return 0;
}

static void hfree(hmap *h) {
  free(h->k);
  free(h->v);
}

/* ---- proofs over a box -------------------------------------------------- */

enum { T_OUT = 0, T_IN = 1, T_MIX = 2 };

/* The range of n.x - d over the box. */
static void plane_range(const double n[3], double d, const double lo[3],
                        const double hi[3], double *rl, double *rh) {
  double c = -d, r = 0;
  for (int i = 0; i < 3; i++) {
    double m = 0.5 * (lo[i] + hi[i]), e = 0.5 * (hi[i] - lo[i]);
    c += n[i] * m;
    r += fabs(n[i]) * e;
  }
  r += 1e-12 * (fabs(c) + r + 1); /* rounding */
  *rl = c - r;
  *rh = c + r;
}

static int tri_op(int op, int a, int b) {
  switch (op) {
  case 0: /* union */
    if (a == T_IN || b == T_IN) return T_IN;
    return a == T_OUT && b == T_OUT ? T_OUT : T_MIX;
  case 1: /* intersection */
    if (a == T_OUT || b == T_OUT) return T_OUT;
    return a == T_IN && b == T_IN ? T_IN : T_MIX;
  default: /* a - b */
    if (a == T_OUT || b == T_IN) return T_OUT;
    return a == T_IN && b == T_OUT ? T_IN : T_MIX;
  }
}

/* A sharp CSG tape over the box. */
static int csg_box(const csg_tape *t, const double lo[3], const double hi[3]) {
  unsigned char st[CSG_STACK_MAX];
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const csg_instr *in = &t->code[i];
    if (in->op == CSG_PLANE) {
      const csg_plane *p = &t->planes[in->arg];
      double rl, rh;
      plane_range(p->n, p->d, lo, hi, &rl, &rh);
      st[sp++] = rh < 0 ? T_IN : (rl > 0 ? T_OUT : T_MIX);
    } else if (in->op == CSG_EMPTY) {
      st[sp++] = T_OUT;
    } else if (in->op == CSG_ALL) {
      st[sp++] = T_IN;
    } else {
      sp--;
      int x = st[sp - 1], y = st[sp];
      switch (in->op) {
      case CSG_UNION: st[sp - 1] = (unsigned char)tri_op(0, x, y); break;
      case CSG_INTER: st[sp - 1] = (unsigned char)tri_op(1, x, y); break;
      case CSG_DIFF: st[sp - 1] = (unsigned char)tri_op(2, x, y); break;
      default: st[sp - 1] = (unsigned char)tri_op(2, y, x); break;
      }
    }
  }
  return sp == 1 ? st[0] : T_MIX;
}

/* A density tape's range over the box, by the interval rules. */
static void dt_box(const dt_tape *t, const double lo[3], const double hi[3],
                   double *dl, double *dh) {
  double sl[DT_STACK_MAX], sh[DT_STACK_MAX];
  int sp = 0;
  for (int i = 0; i < t->ncode; i++) {
    const dt_instr *in = &t->code[i];
    if (in->op == DT_LEAF) {
      const dt_leaf *lf = &t->leaves[in->arg];
      double rl, rh;
      plane_range(lf->n, lf->d, lo, hi, &rl, &rh);
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
  double m = 1e-12 * (fabs(sl[0]) + fabs(sh[0]) + 1);
  *dl = sl[0] - m;
  *dh = sh[0] + m;
}

static int leaf_box(const ScNode *nd, const double lo[3], const double hi[3]) {
  switch (nd->kind) {
  case SC_HALFSPACE: {
    double rl, rh;
    plane_range(nd->n, nd->d, lo, hi, &rl, &rh);
    return rh < 0 ? T_IN : (rl > 0 ? T_OUT : T_MIX);
  }
  case SC_ROUNDED: {
    if (nd->outer && csg_box(nd->outer, lo, hi) == T_OUT) return T_OUT;
    if (nd->inner && csg_box(nd->inner, lo, hi) == T_IN) return T_IN;
    double dl, dh;
    dt_box(nd->tape, lo, hi, &dl, &dh);
    return dh < 0.5 ? T_OUT : (dl > 0.5 ? T_IN : T_MIX);
  }
  case SC_SOFT: {
    double fl, fh, mg = soft_magic(nd->soft);
    soft_field_box(nd->soft, lo, hi, &fl, &fh);
    return fh < mg ? T_OUT : (fl > mg ? T_IN : T_MIX);
  }
  case SC_EMPTY: return T_OUT;
  case SC_ALL: return T_IN;
  default: return T_MIX;
  }
}

/* The node over the box, children first (st has room for the subtree). */
static int scene_box(const Scene *s, int node, const double lo[3],
                     const double hi[3], unsigned char *st) {
  int f = s->nodes[node].first;
  for (int i = f; i <= node; i++) {
    const ScNode *nd = &s->nodes[i];
    int r;
    switch (nd->kind) {
    case SC_UNION: r = tri_op(0, st[nd->a - f], st[nd->b - f]); break;
    case SC_INTER: r = tri_op(1, st[nd->a - f], st[nd->b - f]); break;
    case SC_DIFF: r = tri_op(2, st[nd->a - f], st[nd->b - f]); break;
    default: r = leaf_box(nd, lo, hi); break;
    }
    st[i - f] = (unsigned char)r;
  }
  return st[node - f];
}

/* ---- the mesher's state --------------------------------------------------- */

typedef struct {
  const Scene *s;
  int node;
  double org[3], h;        /* grid point (i, j, k) is org + h (i, j, k) */
  double clo[3], chi[3];   /* the clip box: outside it is outside */
  int depth;
  unsigned char *st;       /* scene_box scratch */
  uint32_t *leaves;        /* 3 per finest cell: its lowest grid point */
  size_t nleaves, capleaves;
  size_t max_cells;
  hmap sign;               /* grid point -> inside */
  hmap vert;               /* grid edge -> mesh vertex */
  double *v;
  size_t nv, capv;
  int *t;
  size_t nt, capt;
  RayCtx *ray;
  MeshReport *rep;
  int err;                 /* MESH_E* */
} Mesher;

static void grid_point(const Mesher *m, uint32_t i, uint32_t j, uint32_t k,
                       double p[3]) {
  p[0] = m->org[0] + m->h * i;
  p[1] = m->org[1] + m->h * j;
  p[2] = m->org[2] + m->h * k;
}

static uint64_t vkey(uint32_t i, uint32_t j, uint32_t k) {
  return (uint64_t)i | (uint64_t)j << 20 | (uint64_t)k << 40;
}

static int in_clip(const Mesher *m, const double p[3]) {
  for (int i = 0; i < 3; i++)
    if (!(p[i] > m->clo[i] && p[i] < m->chi[i])) return 0;
  return 1;
}

/* Classify the cell of side 2^(depth - level) finest cells at (i, j, k). */
static int walk(Mesher *m, uint32_t i, uint32_t j, uint32_t k, int level) {
  uint32_t n = 1u << (m->depth - level);
  double lo[3], hi[3];
  grid_point(m, i, j, k, lo);
  grid_point(m, i + n, j + n, k + n, hi);
  m->rep->cells++;
  int clip_out = 0, clip_in = 1;
  for (int a = 0; a < 3; a++) {
    if (hi[a] <= m->clo[a] || lo[a] >= m->chi[a]) clip_out = 1;
    if (lo[a] <= m->clo[a] || hi[a] >= m->chi[a]) clip_in = 0;
  }
  int c = clip_out ? T_OUT : scene_box(m->s, m->node, lo, hi, m->st);
  if (c == T_IN && !clip_in) c = T_MIX;
  if (c == T_OUT) {
    m->rep->empty++;
    return 0;
  }
  if (c == T_IN) {
    m->rep->full++;
    return 0;
  }
  if (level == m->depth) {
    if (m->nleaves >= m->max_cells) {
      m->err = MESH_ELIMIT;
      return -1;
    }
    if (m->nleaves == m->capleaves) {
      size_t nc = m->capleaves ? 2 * m->capleaves : 4096;
      uint32_t *g = realloc(m->leaves, 3 * nc * sizeof *g);
      if (!g) {
        m->err = MESH_ENOMEM;
        return -1;
      }
      m->leaves = g;
      m->capleaves = nc;
    }
    m->leaves[3 * m->nleaves] = i;
    m->leaves[3 * m->nleaves + 1] = j;
    m->leaves[3 * m->nleaves + 2] = k;
    m->nleaves++;
    return 0;
  }
  uint32_t hn = n / 2;
  for (int q = 0; q < 8; q++)
    if (walk(m, i + (q & 1 ? hn : 0), j + (q & 2 ? hn : 0),
             k + (q & 4 ? hn : 0), level + 1) < 0)
      return -1;
  return 0;
}

/* The sign of grid point (i, j, k), cached: 1 inside, 0 outside, -1 on
   failure. */
static int corner(Mesher *m, uint32_t i, uint32_t j, uint32_t k) {
  uint64_t key = vkey(i, j, k);
  int v = hget(&m->sign, key);
  if (v >= 0) return v;
  double p[3];
  grid_point(m, i, j, k, p);
  v = in_clip(m, p) ? scene_inside(m->s, m->node, p) : 0;
  if (v < 0 || hput(&m->sign, key, v) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  return v;
}

/* Inside at o + t d (the clipped solid). */
static int inside_at(Mesher *m, const double o[3], const double d[3],
                     double t) {
  double p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
  return in_clip(m, p) ? scene_inside(m->s, m->node, p) : 0;
}

/* A crossing on the segment from a (inside = sa) to b: t in (0, 1). */
static double crossing(Mesher *m, const double a[3], const double b[3],
                       int sa) {
  double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  /* the clip box's slab along the edge */
  double t0 = 0, t1 = 1;
  for (int i = 0; i < 3; i++) {
    if (d[i] == 0) continue;
    double u = (m->clo[i] - a[i]) / d[i], w = (m->chi[i] - a[i]) / d[i];
    if (u > w) { double x = u; u = w; w = x; }
    if (u > t0) t0 = u;
    if (w < t1) t1 = w;
  }
  double best = NAN;
  if (t0 < t1) {
    csg_span *sp;
    ray_reset(m->ray);
    int n = ray_spans(m->s, m->node, a, d, 0, 1, m->ray, &sp);
    for (int q = 0; q < n && isnan(best); q++) {
      double e[2] = {sp[q].t0 > t0 ? sp[q].t0 : t0,
                     sp[q].t1 < t1 ? sp[q].t1 : t1};
      if (e[0] >= e[1]) continue;
      for (int r = 0; r < 2; r++)
        if (e[r] > 0 && e[r] < 1 && isnan(best)) best = e[r];
    }
  }
  if (isnan(best)) { /* bisection on the point classification */
    double lo = 0, hi = 1;
    for (int it = 0; it < 60 && (hi - lo) * m->h > m->rep->vtol * 0.5; it++) {
      double mid = 0.5 * (lo + hi);
      int s = inside_at(m, a, d, mid);
      if (s < 0) break;
      if (s == sa) lo = mid;
      else hi = mid;
    }
    best = 0.5 * (lo + hi);
    m->rep->bisected++;
  }
  const double edge = 1.0 / 1048576; /* keep off the grid points */
  if (best < edge) best = edge;
  if (best > 1 - edge) best = 1 - edge;
  return best;
}

/* The mesh vertex on the grid edge from corner ca to cb of the cell at
   base (masks: bit 0 x, 1 y, 2 z; one mask holds the other). */
static int edge_vertex(Mesher *m, const uint32_t base[3], int ca, int cb,
                       const int sg[8]) {
  int lo = ca & cb, dir = ca ^ cb, hi = lo | dir;
  uint32_t i = base[0] + (uint32_t)(lo & 1), j = base[1] + (uint32_t)(lo >> 1 & 1),
           k = base[2] + (uint32_t)(lo >> 2 & 1);
  uint64_t key = vkey(i, j, k) << 3 | (uint64_t)dir;
  int v = hget(&m->vert, key);
  if (v >= 0) return v;
  double a[3], b[3];
  grid_point(m, i, j, k, a);
  grid_point(m, base[0] + (uint32_t)(hi & 1), base[1] + (uint32_t)(hi >> 1 & 1),
             base[2] + (uint32_t)(hi >> 2 & 1), b);
  double t = crossing(m, a, b, sg[lo]);
  if (m->nv == m->capv) {
    size_t nc = m->capv ? 2 * m->capv : 4096;
    double *g = realloc(m->v, 3 * nc * sizeof *g);
    if (!g) {
      m->err = MESH_ENOMEM;
      return -1;
    }
    m->v = g;
    m->capv = nc;
  }
  double *p = m->v + 3 * m->nv;
  for (int q = 0; q < 3; q++) p[q] = a[q] + t * (b[q] - a[q]);
  v = (int)m->nv++;
  m->rep->crossings++;
  if (hput(&m->vert, key, v) < 0) {
    m->err = MESH_ENOMEM;
    return -1;
  }
  return v;
}

static int emit(Mesher *m, int a, int b, int c) {
  if (a < 0 || b < 0 || c < 0) return -1;
  if (m->nt == m->capt) {
    size_t nc = m->capt ? 2 * m->capt : 4096;
    int *g = realloc(m->t, 3 * nc * sizeof *g);
    if (!g) {
      m->err = MESH_ENOMEM;
      return -1;
    }
    m->t = g;
    m->capt = nc;
  }
  m->t[3 * m->nt] = a;
  m->t[3 * m->nt + 1] = b;
  m->t[3 * m->nt + 2] = c;
  m->nt++;
  return 0;
}

/* The Kuhn split: 6 tetrahedra around the diagonal 0 - 7, each ordered to
   positive orientation. */
static const int kuhn[6][4] = {
    {0, 1, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, /* even permutations */
    {0, 1, 7, 5}, {0, 4, 7, 6}, {0, 2, 7, 3}, /* odd, last two swapped */
};

static double dist3(const double *a, const double *b) {
  double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return sqrt(x * x + y * y + z * z);
}

static int parity4(const int p[4]) {
  int inv = 0;
  for (int i = 0; i < 4; i++)
    for (int j = i + 1; j < 4; j++) inv += p[i] > p[j];
  return inv & 1;
}

/* Triangles of one positively oriented tetrahedron (corner masks c). When
   count is set, only count them. */
static int tet(Mesher *m, const uint32_t base[3], const int c[4],
               const int sg[8], size_t *count) {
  static const int lone[4][4] = {
      {0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};
  int in[4], n = 0;
  for (int i = 0; i < 4; i++) n += in[i] = sg[c[i]];
  if (n == 0 || n == 4) return 0;
  if (n == 1 || n == 3) {
    if (count) return (void)(*count += 1), 0;
    int i = 0;
    while (in[i] != (n == 1)) i++;
    const int *p = lone[i];
    int e1 = edge_vertex(m, base, c[p[0]], c[p[1]], sg);
    int e2 = edge_vertex(m, base, c[p[0]], c[p[2]], sg);
    int e3 = edge_vertex(m, base, c[p[0]], c[p[3]], sg);
    return n == 1 ? emit(m, e1, e2, e3) : emit(m, e1, e3, e2);
  }
  if (count) return (void)(*count += 2), 0;
  int p[4], a = 0, b = 2;
  for (int i = 0; i < 4; i++) {
    if (in[i]) p[a++] = i;
    else p[b++] = i;
  }
  if (parity4(p)) {
    int x = p[2];
    p[2] = p[3];
    p[3] = x;
  }
  int q0 = edge_vertex(m, base, c[p[0]], c[p[2]], sg);
  int q1 = edge_vertex(m, base, c[p[0]], c[p[3]], sg);
  int q2 = edge_vertex(m, base, c[p[1]], c[p[3]], sg);
  int q3 = edge_vertex(m, base, c[p[1]], c[p[2]], sg);
  if (q0 < 0 || q1 < 0 || q2 < 0 || q3 < 0) return -1;
  if (dist3(m->v + 3 * q0, m->v + 3 * q2) <= dist3(m->v + 3 * q1, m->v + 3 * q3))
    return emit(m, q0, q1, q2) < 0 ? -1 : emit(m, q0, q2, q3);
  return emit(m, q1, q2, q3) < 0 ? -1 : emit(m, q1, q3, q0);
}

static int cell(Mesher *m, size_t leaf, size_t *count) {
  const uint32_t *b = m->leaves + 3 * leaf;
  int sg[8];
  for (int q = 0; q < 8; q++) {
    sg[q] = corner(m, b[0] + (uint32_t)(q & 1), b[1] + (uint32_t)(q >> 1 & 1),
                   b[2] + (uint32_t)(q >> 2 & 1));
    if (sg[q] < 0) return -1;
  }
  for (int t = 0; t < 6; t++)
    if (tet(m, b, kuhn[t], sg, count) < 0) return -1;
  return 0;
}

/* The covering radius of a triangle by its vertices: the circumradius if
   no angle is obtuse, else half the longest side. */
static double cover_radius(const double *a, const double *b, const double *c) {
  double la = dist3(b, c), lb = dist3(a, c), lc = dist3(a, b);
  double l = fmax(la, fmax(lb, lc));
  double s2 = la * la + lb * lb + lc * lc;
  if (2 * l * l >= s2) return 0.5 * l; /* obtuse or right */
  double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]}, x[3];
  vec3_cross(u, w, x);
  double area2 = sqrt(vec3_dot(x, x));
  if (!(area2 > 0)) return l; /* degenerate: the longest side bounds it */
  double r = la * lb * lc / (2 * area2);
  return r < l ? r : l;
}

/* The node of node's subtree that makes it unbounded. */
static int unbounded_leaf(const Scene *s, int node) {
  double lo[3], hi[3];
  for (;;) {
    const ScNode *nd = &s->nodes[node];
    if (nd->kind != SC_UNION && nd->kind != SC_INTER && nd->kind != SC_DIFF)
      return node;
    if (!render_node_box(s, nd->a, lo, hi)) node = nd->a;
    else if (nd->kind == SC_UNION && !render_node_box(s, nd->b, lo, hi))
      node = nd->b;
    else return node;
  }
}

int mesh_scene(const Scene *s, int node, const MeshSettings *ms, Mesh **out,
               MeshReport *rep, int *bad_node, char *err, size_t errlen) {
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  memset(rep, 0, sizeof *rep);
  *out = NULL;
  *bad_node = -1;
  double lo[3], hi[3];
  if (!render_node_box(s, node, lo, hi)) {
    if (!ms->has_bounds) {
      *bad_node = unbounded_leaf(s, node);
      snprintf(err, errlen, "the object is unbounded (it has no finite "
               "box): give Bounds lo hi to mesh the part inside a box");
      return MESH_EUNBOUNDED;
    }
    memcpy(lo, ms->lo, sizeof lo);
    memcpy(hi, ms->hi, sizeof hi);
  } else if (ms->has_bounds) {
    for (int i = 0; i < 3; i++) {
      lo[i] = fmax(lo[i], ms->lo[i]);
      hi[i] = fmin(hi[i], ms->hi[i]);
    }
  }
  double size = 0, scale = 1;
  for (int i = 0; i < 3; i++)
    if (!(hi[i] > lo[i])) {
      snprintf(err, errlen, "the object is empty: nothing to mesh");
      return MESH_EEMPTY;
    }
  for (int i = 0; i < 3; i++) {
    if (!isfinite(lo[i]) || !isfinite(hi[i])) {
      snprintf(err, errlen, "the box to mesh is not finite");
      return MESH_EUNBOUNDED;
    }
    if (hi[i] <= lo[i]) {
      snprintf(err, errlen, "the object is empty: nothing to mesh");
      return MESH_EEMPTY;
    }
    size = fmax(size, hi[i] - lo[i]);
    scale = fmax(scale, fmax(fabs(lo[i]), fabs(hi[i])));
  }
  double e = ms->tol;
  if (!(e > 0) || !isfinite(e) || e < 1e-12 * scale) {
    snprintf(err, errlen, "the tolerance must be finite and at least %g "
             "(what doubles resolve at this object's coordinates), not %g",
             1e-12 * scale, e);
    return MESH_ETOL;
  }
  double vtol = fmax(0.01 * e, 64 * RAY_TOL_FLOOR * scale);
  double ht = e - vtol, L = size + 2 * ht;
  int depth = 0;
  while (L / ldexp(1, depth) > ht) depth++;
  if (depth > MAX_DEPTH) {
    snprintf(err, errlen, "the tolerance %g is too fine for this object "
             "(size %g): the octree would need %d levels, at most %d",
             e, size, depth, MAX_DEPTH);
    return MESH_ETOL;
  }
  Mesher m;
  memset(&m, 0, sizeof m);
  m.s = s;
  m.node = node;
  m.depth = depth;
  m.h = L / ldexp(1, depth);
  m.rep = rep;
  m.max_cells = ms->max_cells ? ms->max_cells : (size_t)1 << 24;
  for (int i = 0; i < 3; i++) {
    double c = 0.5 * (lo[i] + hi[i]);
    m.org[i] = c - 0.5 * L;
    /* the clip box: the object's box, a little enlarged (never cutting
       a bounded object), or the user's box */
    m.clo[i] = ms->has_bounds && ms->lo[i] >= lo[i] ? lo[i] : lo[i] - 0.5 * ht;
    m.chi[i] = ms->has_bounds && ms->hi[i] <= hi[i] ? hi[i] : hi[i] + 0.5 * ht;
  }
  rep->depth = depth;
  rep->h = m.h;
  rep->vtol = vtol;
  int nsub = node - s->nodes[node].first + 1;
  m.st = malloc((size_t)nsub);
  m.ray = ray_ctx_new(s, vtol);
  int rc = MESH_OK;
  if (!m.st || !m.ray) {
    rc = MESH_ENOMEM;
    goto done;
  }
  if (walk(&m, 0, 0, 0, 0) < 0) {
    rc = m.err;
    if (rc == MESH_ELIMIT)
      snprintf(err, errlen, "the mesh needs more than %zu finest octree "
               "cells (limit max-cells): give a larger tolerance than %g",
               m.max_cells, e);
    goto done;
  }
  rep->leaves = (long)m.nleaves;
  /* count the triangles from the signs before any crossing is sought */
  size_t count = 0;
  for (size_t l = 0; l < m.nleaves; l++)
    if (cell(&m, l, &count) < 0) {
      rc = m.err;
      goto done;
    }
  if (ms->max_triangles && count > ms->max_triangles) {
    snprintf(err, errlen, "the mesh would have %zu triangles, over the "
             "limit of %zu (max-triangles): give a larger tolerance than %g",
             count, ms->max_triangles, e);
    rc = MESH_ELIMIT;
    goto done;
  }
  if (count == 0) {
    snprintf(err, errlen, "the object is empty: no inside point was found "
             "in its box at this tolerance (%g)", e);
    rc = MESH_EEMPTY;
    goto done;
  }
  if (count > (size_t)1 << 30) {
    snprintf(err, errlen, "the mesh would have %zu triangles", count);
    rc = MESH_ELIMIT;
    goto done;
  }
  for (size_t l = 0; l < m.nleaves; l++)
    if (cell(&m, l, NULL) < 0) {
      rc = m.err;
      goto done;
    }
  if (m.ray->failed) {
    rc = MESH_ENOMEM;
    goto done;
  }
  double cert = 0;
  for (size_t i = 0; i < m.nt; i++) {
    const int *t = m.t + 3 * i;
    double r = cover_radius(m.v + 3 * t[0], m.v + 3 * t[1], m.v + 3 * t[2]);
    if (r > cert) cert = r;
  }
  rep->certified = cert + vtol;
  Mesh *me = malloc(sizeof *me);
  if (!me) {
    rc = MESH_ENOMEM;
    goto done;
  }
  me->nv = m.nv;
  me->nt = m.nt;
  me->v = m.v;
  me->t = m.t;
  m.v = NULL;
  m.t = NULL;
  MeshCheck ck;
  int cr = mesh_check(me, &ck);
  if (cr != 0) {
    mesh_free(me);
    if (cr == -2) {
      rc = MESH_ENOMEM;
      goto done;
    }
    snprintf(err, errlen, "internal error: the mesh failed its closure check "
             "(%ld boundary, %ld non-manifold edges, %ld non-manifold "
             "vertices); nothing was written", ck.boundary_edges,
             ck.nonmanifold_edges, ck.nonmanifold_verts);
    rc = MESH_EINTERNAL;
    goto done;
  }
  rep->vertices = me->nv;
  rep->triangles = me->nt;
  *out = me;
done:
  if (rc == MESH_ENOMEM) snprintf(err, errlen, "out of memory while meshing");
  free(m.st);
  free(m.leaves);
  free(m.v);
  free(m.t);
  hfree(&m.sign);
  hfree(&m.vert);
  if (m.ray) ray_ctx_free(m.ray);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  rep->seconds = (double)(t1.tv_sec - t0.tv_sec) +
                 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  return rc;
}

void mesh_free(Mesh *m) {
  if (!m) return;
  free(m->v);
  free(m->t);
  free(m);
}

/* ---- edge counting ------------------------------------------------------ */

static int find(int *p, int x) {
  while (p[x] != x) x = p[x] = p[p[x]];
  return x;
}

int mesh_check(const Mesh *m, MeshCheck *c) {
  memset(c, 0, sizeof *c);
  hmap de = {0};           /* directed edge -> count */
  int *par = malloc((m->nt ? m->nt : 1) * sizeof *par);
  int *deg = calloc(m->nv ? m->nv : 1, sizeof *deg);
  int *nxt = NULL;
  long edges = 0, used = 0;
  int rc = 0;
  if (!par || !deg) goto nomem;
  for (size_t i = 0; i < m->nt; i++) {
    par[i] = (int)i;
    const int *t = m->t + 3 * i;
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) c->degenerate++;
    for (int e = 0; e < 3; e++) {
      uint64_t a = (uint64_t)t[e], b = (uint64_t)t[(e + 1) % 3];
      uint64_t k = a << 32 | b;
      int n = hget(&de, k);
      if (hput(&de, k, n < 0 ? 1 : n + 1) < 0) goto nomem;
      deg[t[e]]++;
    }
  }
  for (size_t i = 0; i < de.cap; i++) {
    if (!de.k[i]) continue;
    uint64_t k = de.k[i] - 1, r = (k & 0xffffffffu) << 32 | k >> 32;
    if (de.v[i] > 1) c->nonmanifold_edges++;
    if (hget(&de, r) != 1) c->boundary_edges++;
    edges++;
  }
  edges /= 2;
  /* components: triangles joined through shared edges */
  {
    hmap first = {0}; /* undirected edge -> a triangle */
    for (size_t i = 0; i < m->nt; i++) {
      const int *t = m->t + 3 * i;
      for (int e = 0; e < 3; e++) {
        uint64_t a = (uint64_t)t[e], b = (uint64_t)t[(e + 1) % 3];
        uint64_t k = a < b ? a << 32 | b : b << 32 | a;
        int o = hget(&first, k);
        if (o < 0) {
          if (hput(&first, k, (int)i) < 0) {
            hfree(&first);
            goto nomem;
          }
        } else {
          par[find(par, o)] = find(par, (int)i);
        }
      }
    }
    hfree(&first);
    for (size_t i = 0; i < m->nt; i++) c->components += find(par, (int)i) == (int)i;
  }
  /* vertex fans: around each vertex, the triangles' opposite edges must
     chain into one cycle (checked by following next-vertex links) */
  {
    size_t tot = 0;
    int *start = malloc((m->nv + 1) * sizeof *start);
    if (!start) goto nomem;
    for (size_t v = 0; v < m->nv; v++) {
      start[v] = (int)tot;
      tot += (size_t)deg[v];
      used += deg[v] > 0;
    }
    start[m->nv] = (int)tot;
    nxt = malloc(2 * (tot ? tot : 1) * sizeof *nxt);
    int *fill = calloc(m->nv ? m->nv : 1, sizeof *fill);
    if (!nxt || !fill) {
      free(start);
      free(fill);
      goto nomem;
    }
    for (size_t i = 0; i < m->nt; i++) {
      const int *t = m->t + 3 * i;
      for (int e = 0; e < 3; e++) {
        int v = t[e], slot = start[v] + fill[v]++;
        nxt[2 * slot] = t[(e + 1) % 3];
        nxt[2 * slot + 1] = t[(e + 2) % 3];
      }
    }
    for (size_t v = 0; v < m->nv; v++) {
      int n = deg[v];
      if (!n) continue;
      const int *f = nxt + 2 * start[v];
      /* follow b -> c links from the first wedge; one cycle of n wedges */
      int cur = f[1], steps = 1, ok = 1;
      while (cur != f[0] && ok) {
        int found = -1;
        for (int w = 0; w < n; w++)
          if (f[2 * w] == cur) {
            found = w;
            break;
          }
        if (found < 0 || steps > n) ok = 0;
        else {
          cur = f[2 * found + 1];
          steps++;
        }
      }
      if (!ok || steps != n) c->nonmanifold_verts++;
    }
    free(start);
    free(fill);
  }
  c->euler = used - edges + (long)m->nt;
  rc = c->boundary_edges || c->nonmanifold_edges || c->nonmanifold_verts ||
               c->degenerate
           ? -1
           : 0;
  goto out;
nomem:
  rc = -2;
out:
  hfree(&de);
  free(par);
  free(deg);
  free(nxt);
  return rc;
}

/* ---- writers ------------------------------------------------------------ */

static const char *ext_of(const char *path) {
  const char *d = strrchr(path, '.');
  return d ? d + 1 : "";
}

int mesh_is_mesh_path(const char *path) {
  const char *e = ext_of(path);
  return !strcmp(e, "stl") || !strcmp(e, "obj");
}

typedef struct {
  char *p;
  size_t n, cap;
  int bad;
} buf;

static void put(buf *b, const void *d, size_t n) {
  if (b->bad) return;
  if (b->n + n > b->cap) {
    size_t nc = b->cap ? b->cap : 65536;
    while (nc < b->n + n) nc *= 2;
    char *g = realloc(b->p, nc);
    if (!g) {
      b->bad = 1;
      return;
    }
    b->p = g;
    b->cap = nc;
  }
  memcpy(b->p + b->n, d, n);
  b->n += n;
}

static void put_f32(buf *b, double x) {
  float f = (float)x;
  unsigned char q[4];
  uint32_t u;
  memcpy(&u, &f, 4);
  for (int i = 0; i < 4; i++) q[i] = (unsigned char)(u >> (8 * i));
  put(b, q, 4);
}

static void tri_normal(const Mesh *m, size_t i, double n[3]) {
  const int *t = m->t + 3 * i;
  const double *a = m->v + 3 * t[0], *b = m->v + 3 * t[1], *c = m->v + 3 * t[2];
  double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  vec3_cross(u, w, n);
}

int mesh_write(const Mesh *m, const char *path, char *err, size_t errlen) {
  buf b = {0};
  if (!strcmp(ext_of(path), "stl")) {
    char head[80] = "binary STL written by qcs";
    put(&b, head, 80);
    unsigned char q[4];
    for (int i = 0; i < 4; i++) q[i] = (unsigned char)(m->nt >> (8 * i));
    put(&b, q, 4);
    for (size_t i = 0; i < m->nt; i++) {
      double n[3];
      tri_normal(m, i, n);
      double l = sqrt(vec3_dot(n, n));
      for (int k = 0; k < 3; k++) put_f32(&b, l > 0 ? n[k] / l : 0);
      for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++) put_f32(&b, m->v[3 * (size_t)m->t[3 * i + (size_t)k] + (size_t)j]);
      put(&b, "\0\0", 2);
    }
  } else if (!strcmp(ext_of(path), "obj")) {
    double *vn = calloc(3 * (m->nv ? m->nv : 1), sizeof *vn);
    if (!vn) b.bad = 1;
    for (size_t i = 0; vn && i < m->nt; i++) {
      double n[3];
      tri_normal(m, i, n); /* area-weighted */
      for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++) vn[3 * (size_t)m->t[3 * i + (size_t)k] + (size_t)j] += n[j];
    }
    char line[160];
    int len = snprintf(line, sizeof line, "# written by qcs: %zu vertices, "
                       "%zu triangles\n", m->nv, m->nt);
    put(&b, line, (size_t)len);
    for (size_t i = 0; vn && i < m->nv; i++) {
      len = snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", m->v[3 * i],
                     m->v[3 * i + 1], m->v[3 * i + 2]);
      put(&b, line, (size_t)len);
    }
    for (size_t i = 0; vn && i < m->nv; i++) {
      double *n = vn + 3 * i, l = sqrt(vec3_dot(n, n));
      if (!(l > 0)) l = 1;
      len = snprintf(line, sizeof line, "vn %.9g %.9g %.9g\n", n[0] / l,
                     n[1] / l, n[2] / l);
      put(&b, line, (size_t)len);
    }
    for (size_t i = 0; vn && i < m->nt; i++) {
      const int *t = m->t + 3 * i;
      len = snprintf(line, sizeof line, "f %d//%d %d//%d %d//%d\n", t[0] + 1,
                     t[0] + 1, t[1] + 1, t[1] + 1, t[2] + 1, t[2] + 1);
      put(&b, line, (size_t)len);
    }
    free(vn);
  } else {
    snprintf(err, errlen, "cannot write %s: a mesh is written as .stl or "
             ".obj", path);
    return -1;
  }
  if (b.bad) {
    free(b.p);
    snprintf(err, errlen, "cannot write %s: out of memory", path);
    return -1;
  }
  int rc = img_write_bytes(path, b.p, b.n, err, errlen);
  free(b.p);
  return rc;
}
