/* mesh_cover.c: every part of the surface within e of the mesh, proven
   box by box (mesh_cover.h). */
#include "render/mesh_cover.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---- a hierarchy of boxes over the triangles, in their order ------------ */

#define LEAF_TRIS 4

/* The most boxes the proof spends on one given box of side a: a surface
   wholly missing from the mesh would otherwise be followed down to
   e / 1024. A surface crossing the box needs about 5 (a / e)^2 boxes
   (boxes of side e / 2 near it, and the levels above). */
#define BOX_BUDGET(a, e) (4096 + (long)fmin(1e9, 64 * ((a) / (e)) * ((a) / (e))))

typedef struct {
  double lo[3], hi[3];
} Bx;

typedef struct {
  Bx box;
  uint32_t a, b;           /* a leaf: its triangles tri[a .. b); else its
                              children node[a], node[b] */
  int leaf;
} Node;

typedef struct {
  const Mesh *me;
  uint32_t *tri;           /* the triangles in the order of their
                              centroids' Morton codes */
  uint64_t *key;           /* those codes */
  Node *node;              /* node[0] is the root */
  size_t nn;
} Bvh;

static void bx_empty(Bx *b) {
  for (int k = 0; k < 3; k++) {
    b->lo[k] = INFINITY;
    b->hi[k] = -INFINITY;
  }
}

static void bx_add(Bx *b, const double *p) {
  for (int k = 0; k < 3; k++) {
    if (p[k] < b->lo[k]) b->lo[k] = p[k];
    if (p[k] > b->hi[k]) b->hi[k] = p[k];
  }
}

/* x's low 21 bits spread to every third bit */
static uint64_t spread(uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

/* h->tri: the triangles sorted by their centroids' Morton codes (a radix
   sort, 8 bits a pass). */
static int morton_order(Bvh *h, const Mesh *me) {
  size_t n = me->nt;
  Bx all;
  bx_empty(&all);
  for (size_t i = 0; i < me->nv; i++) bx_add(&all, me->v + 3 * i);
  uint64_t *key = malloc(2 * (n ? n : 1) * sizeof *key);
  h->key = key;
  uint32_t *tmp = malloc((n ? n : 1) * sizeof *tmp);
  h->tri = malloc((n ? n : 1) * sizeof *h->tri);
  if (!key || !tmp || !h->tri) {
    free(tmp);
    return -1;
  }
  uint64_t *key2 = key + n;
  for (size_t t = 0; t < n; t++) {
    uint64_t k = 0;
    for (int a = 0; a < 3; a++) {
      double c = 0;
      for (int j = 0; j < 3; j++) c += me->v[3 * (size_t)(unsigned)me->t[3 * t + (size_t)j] + (size_t)a];
      double span = all.hi[a] - all.lo[a];
      double u = span > 0 ? (c / 3 - all.lo[a]) / span : 0;
      u = u < 0 ? 0 : u > 1 ? 1 : u;
      k |= spread((uint64_t)(u * 2097151.0)) << a;
    }
    key[t] = k;
    h->tri[t] = (uint32_t)t;
  }
  for (int sh = 0; sh < 64; sh += 8) {
    size_t cnt[257] = {0};
    for (size_t t = 0; t < n; t++) cnt[(key[t] >> sh & 0xff) + 1]++;
    for (int b = 0; b < 256; b++) cnt[b + 1] += cnt[b];
    for (size_t t = 0; t < n; t++) {
      size_t d = cnt[key[t] >> sh & 0xff]++;
      key2[d] = key[t];
      tmp[d] = h->tri[t];
    }
    memcpy(key, key2, n * sizeof *key);
    memcpy(h->tri, tmp, n * sizeof *tmp);
  }
  free(tmp);
  return 0;
}

/* The node over tri[lo .. hi), split where the highest bit in which the
   codes differ turns on (the middle where they are all equal); returns
   its index. Nodes are made in depth-first order, each after its
   children's room is taken, so node[0] is the root. */
static uint32_t bvh_node(Bvh *h, size_t lo, size_t hi, int bit) {
  uint32_t me = (uint32_t)h->nn++;
  Node *nd = &h->node[me];
  if (hi - lo <= LEAF_TRIS) {
    nd->leaf = 1;
    nd->a = (uint32_t)lo;
    nd->b = (uint32_t)hi;
    bx_empty(&nd->box);
    for (size_t t = lo; t < hi; t++)
      for (size_t k = 0; k < 3; k++)
        bx_add(&nd->box, h->me->v + 3 * (size_t)(unsigned)h->me->t[3 * (size_t)h->tri[t] + k]);
    return me;
  }
  size_t mid = lo + (hi - lo) / 2;
  while (bit >= 0 && !((h->key[lo] ^ h->key[hi - 1]) >> bit & 1)) bit--;
  if (bit >= 0) { /* the first code with the bit set */
    size_t l = lo, r = hi - 1;
    while (l < r) {
      size_t m = l + (r - l) / 2;
      if (h->key[m] >> bit & 1) r = m;
      else l = m + 1;
    }
    mid = l;
  }
  uint32_t a = bvh_node(h, lo, mid, bit - 1);
  uint32_t b = bvh_node(h, mid, hi, bit - 1);
  nd = &h->node[me];
  nd->leaf = 0;
  nd->a = a;
  nd->b = b;
  nd->box = h->node[a].box;
  bx_add(&nd->box, h->node[b].box.lo);
  bx_add(&nd->box, h->node[b].box.hi);
  return me;
}

static int bvh_build(Bvh *h, const Mesh *me) {
  memset(h, 0, sizeof *h);
  h->me = me;
  if (morton_order(h, me) < 0) {
    free(h->key);
    free(h->tri);
    return -1;
  }
  /* a split leaves each side at least one triangle: fewer than 2 nt nodes */
  if (!(h->node = malloc(2 * (me->nt ? me->nt : 1) * sizeof *h->node))) {
    free(h->key);
    free(h->tri);
    return -1;
  }
  bvh_node(h, 0, me->nt, 62);
  free(h->key);
  h->key = NULL;
  return 0;
}

static double bx_d2(const Bx *b, const double p[3]) {
  double s = 0;
  for (int k = 0; k < 3; k++) {
    double d = b->lo[k] - p[k], u = p[k] - b->hi[k];
    d = d > u ? d : u;
    if (d > 0) s += d * d;
  }
  return s;
}

static double d2(const double *a, const double *b) {
  double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return x * x + y * y + z * z;
}

static double dot(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The squared distance from p to a point of triangle abc: the closest one
   (Ericson, Real-Time Collision Detection 5.1.5) with its barycentric
   weights clamped to the triangle, so that whatever the rounding the
   point is a convex combination of the vertices and the distance is an
   upper bound of the true one up to that combination's rounding; a
   degenerate triangle whose weights are not finite gives its nearest
   vertex. */
static double tri_d2(const double p[3], const double *a, const double *b,
                     const double *c) {
  double ab[3], ac[3], ap[3], bp[3], cp[3], q[3];
  for (int k = 0; k < 3; k++) {
    ab[k] = b[k] - a[k];
    ac[k] = c[k] - a[k];
    ap[k] = p[k] - a[k];
    bp[k] = p[k] - b[k];
    cp[k] = p[k] - c[k];
  }
  double d1 = dot(ab, ap), dd2 = dot(ac, ap);
  if (d1 <= 0 && dd2 <= 0) return d2(p, a);
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return d2(p, b);
  double vc = d1 * d4 - d3 * dd2, v, w;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    v = d1 / (d1 - d3);
    w = 0;
  } else {
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return d2(p, c);
    double vb = d5 * dd2 - d1 * d6;
    if (vb <= 0 && dd2 >= 0 && d6 <= 0) {
      v = 0;
      w = dd2 / (dd2 - d6);
    } else {
      double va = d3 * d6 - d5 * d4;
      if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        v = 1 - w;
      } else {
        double den = 1 / (va + vb + vc);
        v = vb * den;
        w = vc * den;
      }
    }
  }
  if (!isfinite(v) || !isfinite(w))
    return fmin(d2(p, a), fmin(d2(p, b), d2(p, c)));
  v = fmin(fmax(v, 0), 1);
  w = fmin(fmax(w, 0), 1 - v);
  for (int k = 0; k < 3; k++) q[k] = a[k] + v * ab[k] + w * ac[k];
  return d2(p, q);
}

/* The distance from p to a triangle if one is nearer than cut (the
   first found, the nearer child first), else INFINITY. */
static double nearest(const Bvh *h, const double p[3], double cut) {
  uint32_t st[128];
  int sp = 0;
  double best = cut * cut;
  const Mesh *me = h->me;
  if (!me->nt || bx_d2(&h->node[0].box, p) >= best) return INFINITY;
  st[sp++] = 0;
  while (sp) {
    const Node *nd = &h->node[st[--sp]];
    if (nd->leaf) {
      for (uint32_t t = nd->a; t < nd->b; t++) {
        const int *tv = me->t + 3 * (size_t)h->tri[t];
        double q = tri_d2(p, me->v + 3 * (size_t)(unsigned)tv[0],
                          me->v + 3 * (size_t)(unsigned)tv[1],
                          me->v + 3 * (size_t)(unsigned)tv[2]);
        if (q < best) return sqrt(q);
      }
      continue;
    }
    double e0 = bx_d2(&h->node[nd->a].box, p), e1 = bx_d2(&h->node[nd->b].box, p);
    uint32_t n0 = nd->a, n1 = nd->b;
    if (e1 < e0) {
      double x = e0;
      e0 = e1;
      e1 = x;
      n0 = nd->b;
      n1 = nd->a;
    }
    if (e1 < best && sp < 127) st[sp++] = n1;
    if (e0 < best && sp < 127) st[sp++] = n0;
  }
  return INFINITY;
}

/* The distance from p to the nearest triangle (for the tests). */
static double nearest_all(const Bvh *h, const double p[3]) {
  uint32_t st[128];
  int sp = 0;
  double best = INFINITY;
  const Mesh *me = h->me;
  if (!me->nt) return INFINITY;
  st[sp++] = 0;
  while (sp) {
    const Node *nd = &h->node[st[--sp]];
    if (bx_d2(&nd->box, p) >= best) continue;
    if (nd->leaf) {
      for (uint32_t t = nd->a; t < nd->b; t++) {
        const int *tv = me->t + 3 * (size_t)h->tri[t];
        best = fmin(best, tri_d2(p, me->v + 3 * (size_t)(unsigned)tv[0],
                                 me->v + 3 * (size_t)(unsigned)tv[1],
                                 me->v + 3 * (size_t)(unsigned)tv[2]));
      }
      continue;
    }
    if (sp < 126) { /* the tree is under 100 deep */
      st[sp++] = nd->a;
      st[sp++] = nd->b;
    }
  }
  return sqrt(best);
}

/* ---- the proof ---------------------------------------------------------- */

typedef struct {
  const Bvh *h;
  const double *boxes;
  size_t nboxes;
  double e, margin;
  MeshCoverClass cl;
  unsigned char *bad;
  size_t next;             /* the next box to take (atomic) */
} Job;

typedef struct {
  Job *job;
  void *ctx;
  double bound;
  long boxes, unproven;
  long budget;             /* boxes left for the given box */
  size_t first;            /* the least box index not proven */
  double at[3];            /* a part of it not proven */
  double last[3];          /* the last part not proven */
} Part;

/* 1 if every surface point in [lo, hi] is within e of the mesh. */
static int cover_box(Part *p, const double lo[3], const double hi[3]) {
  const Job *j = p->job;
  double c[3], r = 0;
  for (int k = 0; k < 3; k++) {
    c[k] = 0.5 * (lo[k] + hi[k]);
    r += (hi[k] - lo[k]) * (hi[k] - lo[k]);
  }
  /* the half diagonal, rounded up past sqrt's and the sums' rounding */
  r = 0.5 * sqrt(r) * (1 + 0x1p-48);
  p->boxes++;
  if (--p->budget < 0) {
    memcpy(p->last, c, sizeof c);
    return 0;
  }
  double cut = j->e - r - j->margin;
  if (cut > 0) {
    double d = nearest(j->h, c, cut);
    if (d < cut) {
      p->bound = fmax(p->bound, d + r + j->margin);
      return 1;
    }
  }
  if (!j->cl(p->ctx, lo, hi)) return 1;
  if (hi[0] - lo[0] <= j->e / 1024) {
    memcpy(p->last, c, sizeof c);
    return 0;
  }
  int ok = 1;
  for (int q = 0; q < 8 && ok; q++) {
    double l2[3], h2[3];
    for (int k = 0; k < 3; k++) {
      int up = q >> k & 1;
      l2[k] = up ? c[k] : lo[k];
      h2[k] = up ? hi[k] : c[k];
    }
    ok &= cover_box(p, l2, h2);
  }
  return ok;
}

static void *scan(void *arg) {
  Part *p = arg;
  Job *j = p->job;
  for (;;) {
    size_t i0 = __atomic_fetch_add(&j->next, 64, __ATOMIC_RELAXED);
    if (i0 >= j->nboxes) break;
    for (size_t i = i0; i < i0 + 64 && i < j->nboxes; i++) {
      p->budget = BOX_BUDGET(j->boxes[6 * i + 3] - j->boxes[6 * i], j->e);
      int ok = cover_box(p, j->boxes + 6 * i, j->boxes + 6 * i + 3);
      if (j->bad) j->bad[i] = (unsigned char)!ok;
      if (ok) continue;
      p->unproven++;
      if (i < p->first) {
        p->first = i;
        memcpy(p->at, p->last, sizeof p->at);
      }
    }
  }
  return NULL;
}

int mesh_cover(const Mesh *me, const double *boxes, size_t nboxes, double e,
               double margin, MeshCoverClass cl, void **ctx, int nctx,
               unsigned char *bad, MeshCover *out) {
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  memset(out, 0, sizeof *out);
  Bvh h;
  if (bvh_build(&h, me) < 0) return -1;
  Job job = {&h, boxes, nboxes, e, margin, cl, bad, 0};
  Part part[2];
  pthread_t th[2];
  if (nctx > 2) nctx = 2;
  if (nctx < 1 || nboxes < 256) nctx = 1;
  memset(part, 0, sizeof part);
  for (int t = 0; t < nctx; t++) {
    part[t].job = &job;
    part[t].ctx = ctx[t];
    part[t].first = SIZE_MAX;
  }
  int started = 1;
  for (int t = 1; t < nctx; t++)
    if (pthread_create(&th[t], NULL, scan, &part[t]) == 0) started++;
    else break;
  scan(&part[0]);
  for (int t = 1; t < started; t++) pthread_join(th[t], NULL);
  size_t first = SIZE_MAX;
  for (int t = 0; t < started; t++) {
    out->bound = fmax(out->bound, part[t].bound);
    out->boxes += part[t].boxes;
    out->unproven += part[t].unproven;
    if (part[t].unproven && part[t].first < first) {
      first = part[t].first;
      memcpy(out->at, part[t].at, sizeof out->at);
    }
  }
  free(h.node);
  free(h.tri);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  out->seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  return 0;
}

int mesh_cover_nearest(const Mesh *me, const double *p, size_t np,
                       double *dist) {
  Bvh h;
  if (bvh_build(&h, me) < 0) return -1;
  for (size_t i = 0; i < np; i++) dist[i] = nearest_all(&h, p + 3 * i);
  free(h.node);
  free(h.tri);
  return 0;
}
