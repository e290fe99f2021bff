/* mesh_cover.c: every part of the surface within e of the mesh, proven
   box by box (mesh_cover.h). */
#include "render/mesh_cover.h"

#include "render/mesh_check.h"

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
  const MeshField *fld;
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
  long columns, col_boxes;
  long col_budget;         /* columns left for the given box */
  const double **tv;       /* a prism's triangles: 3 vertices each */
  size_t ntv, captv;
  int nomem;
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

/* ---- the column proof (MeshField boxes) --------------------------------- */

/* The sign of det(a - d, b - d, c - d), exactly (mesh_check's filtered
   predicate, GMP where the filter cannot tell): 0 only when degenerate. */
static int orient(const double *a, const double *b, const double *c,
                  const double *d) {
  return mesh_orient3d(a, b, c, d, NULL);
}

/* Calls fn on each triangle whose box meets q and, if pl is not NULL,
   the slab pl[3] <= x . n <= pl[4] (n = pl[0 .. 2]), until fn returns
   nonzero (which is returned). */
static int each_tri(const Bvh *h, const Bx *q, const double *pl,
                    int (*fn)(void *arg, const double *a, const double *b,
                              const double *c),
                    void *arg) {
  uint32_t st[128];
  int sp = 0;
  const Mesh *me = h->me;
  if (!me->nt) return 0;
  st[sp++] = 0;
  while (sp) {
    const Node *nd = &h->node[st[--sp]];
    int apart = 0;
    for (int k = 0; k < 3; k++)
      apart |= nd->box.lo[k] > q->hi[k] || nd->box.hi[k] < q->lo[k];
    if (apart) continue;
    if (pl) { /* the box's extent along the plane's normal */
      double c = 0, r = 0;
      for (int k = 0; k < 3; k++) {
        c += 0.5 * (nd->box.lo[k] + nd->box.hi[k]) * pl[k];
        r += 0.5 * (nd->box.hi[k] - nd->box.lo[k]) * fabs(pl[k]);
      }
      if (c - r > pl[4] || c + r < pl[3]) continue;
    }
    if (nd->leaf) {
      for (uint32_t t = nd->a; t < nd->b; t++) {
        const int *tv = me->t + 3 * (size_t)h->tri[t];
        int r = fn(arg, me->v + 3 * (size_t)(unsigned)tv[0],
                   me->v + 3 * (size_t)(unsigned)tv[1],
                   me->v + 3 * (size_t)(unsigned)tv[2]);
        if (r) return r;
      }
      continue;
    }
    if (sp >= 126) return 1; /* never (the tree is under 100 deep): fail */
    st[sp++] = nd->a;
    st[sp++] = nd->b;
  }
  return 0;
}

static void cross(const double *a, const double *b, double *r) {
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
}

/* The rectangle z + s e1 + t e2 (|s| <= ra, |t| <= rb), and a margin. */
typedef struct {
  const double *z, *e1, *e2;
  double ra, rb, m;
} Face;

/* 1 unless an axis separates triangle abc from the face by more than
   the margin (the separating axes of two convex polygons: their normals,
   the edges' cross products, and the face's edge normals in its plane). */
static int face_meets(void *arg, const double *a, const double *b,
                      const double *c) {
  const Face *f = arg;
  double ax[3], ed[3][3];
  for (int k = 0; k < 3; k++) {
    ed[0][k] = b[k] - a[k];
    ed[1][k] = c[k] - b[k];
    ed[2][k] = a[k] - c[k];
  }
  /* the cheapest first: the face's normal and its edges' normals in its
     plane, then the triangle's normal and the edges' cross products */
  for (int i = 0; i < 10; i++) {
    const double *l = ax;
    if (i == 0) cross(f->e1, f->e2, ax);
    else if (i == 1) l = f->e1;
    else if (i == 2) l = f->e2;
    else if (i == 3) cross(ed[0], ed[1], ax);
    else cross(i & 1 ? f->e1 : f->e2, ed[(i - 4) >> 1], ax);
    double len = sqrt(dot(l, l));
    if (!(len > 0)) continue;
    double zc = dot(f->z, l);
    double fr = f->ra * fabs(dot(f->e1, l)) + f->rb * fabs(dot(f->e2, l)) + f->m * len;
    double pa = dot(a, l), pb = dot(b, l), pc = dot(c, l);
    double tl = fmin(pa, fmin(pb, pc)), th = fmax(pa, fmax(pb, pc));
    if (tl > zc + fr || th < zc - fr) return 0;
  }
  return 1;
}

typedef struct {
  const double *p, *q;
  long n;                  /* crossings */
  const double *e1, *e2;   /* across the segment, and a margin: a */
  double m;                /* triangle beside it by more is passed by */
} Seg;

/* Counts a crossing of segment pq through triangle abc; 1 (stop) when
   it passes through an edge or a vertex, or an end lies in the plane. */
static int seg_meets(void *arg, const double *a, const double *b,
                     const double *c) {
  Seg *sg = arg;
  for (int k = 0; k < 2; k++) { /* the cheap test first: wholly beside */
    const double *u = k ? sg->e2 : sg->e1;
    double z = dot(sg->p, u), pa = dot(a, u) - z, pb = dot(b, u) - z,
           pc = dot(c, u) - z;
    if ((pa > sg->m && pb > sg->m && pc > sg->m) ||
        (pa < -sg->m && pb < -sg->m && pc < -sg->m))
      return 0;
  }
  int o1 = orient(a, b, c, sg->p), o2 = orient(a, b, c, sg->q);
  if (o1 && o1 == o2) return 0; /* both ends on one side */
  int t1 = orient(sg->p, sg->q, a, b), t2 = orient(sg->p, sg->q, b, c),
      t3 = orient(sg->p, sg->q, c, a);
  if ((t1 > 0 || t2 > 0 || t3 > 0) && (t1 < 0 || t2 < 0 || t3 < 0))
    return 0; /* the line passes beside the triangle */
  if (!o1 || !o2 || !t1 || !t2 || !t3) return 1;
  sg->n++;
  return 0;
}

/* Keeps triangle abc (Part's list). */
static int keep_tri(void *arg, const double *a, const double *b,
                    const double *c) {
  Part *p = arg;
  if (p->ntv + 3 > p->captv) {
    size_t cap = p->captv ? 2 * p->captv : 768;
    const double **t = realloc(p->tv, cap * sizeof *t);
    if (!t) {
      p->nomem = 1;
      return 1;
    }
    p->tv = t;
    p->captv = cap;
  }
  p->tv[p->ntv++] = a;
  p->tv[p->ntv++] = b;
  p->tv[p->ntv++] = c;
  return 0;
}

/* 1 when the mesh may come within the margin of either face, or the
   crossings of the segment zb zt between their centres cannot be told
   or are even; the triangles are those whose boxes meet q (a box
   holding the prism grown by twice the margin), found once. */
static int prism_fails(Part *p, const Bx *q, Face *ft, Face *fb,
                       const double *zb, const double *zt) {
  /* the faces' planes along their unit normal n; a triangle wholly
     beyond either (by 4 margins: room for the dot products' rounding)
     meets neither face nor the segment, one wholly between them only
     the segment */
  double pl[5], m4 = 4 * ft->m;
  cross(ft->e1, ft->e2, pl);
  double len = sqrt(dot(pl, pl)), lo, hi;
  for (int k = 0; k < 3; k++) pl[k] /= len;
  lo = fmin(dot(zb, pl), dot(zt, pl));
  hi = fmax(dot(zb, pl), dot(zt, pl));
  pl[3] = lo - m4;
  pl[4] = hi + m4;
  p->ntv = 0;
  if (each_tri(p->job->h, q, pl, keep_tri, p)) return 1;
  Seg sg = {zb, zt, 0, ft->e1, ft->e2, ft->m};
  for (size_t i = 0; i < p->ntv; i += 3) {
    const double *a = p->tv[i], *b = p->tv[i + 1], *c = p->tv[i + 2];
    double da = dot(a, pl), db = dot(b, pl), dc = dot(c, pl);
    double tl = fmin(da, fmin(db, dc)), th = fmax(da, fmax(db, dc));
    if (th < pl[3] || tl > pl[4]) continue;
    int inside = tl > lo + m4 && th < hi - m4;
    if ((!inside && (face_meets(ft, a, b, c) || face_meets(fb, a, b, c))) ||
        seg_meets(&sg, a, b, c))
      return 1;
  }
  return sg.n % 2 == 0;
}

/* A smooth box's frame and extent. */
typedef struct {
  const double *lo, *hi;
  int node;
  double c[3], n0[3], e1[3], e2[3];
  double f0, f1;           /* the box's extent along n0 from c (grown) */
  double skew;             /* bounds |n0 . v| / |v| for v in span(e1, e2) */
  double pos;              /* bounds the rounding of a computed point */
} Frame;

static void frame_pt(const Frame *fr, double s, double t, double tau,
                     double p[3]) {
  for (int k = 0; k < 3; k++)
    p[k] = fr->c[k] + s * fr->e1[k] + t * fr->e2[k] + tau * fr->n0[k];
}

/* The box of the points s, t in the rectangle, tau in [t0, t1], grown by
   the margin. */
static void frame_box(const Frame *fr, double s, double t, double ra,
                      double rb, double t0, double t1, double m, Bx *b) {
  bx_empty(b);
  for (int i = 0; i < 8; i++) {
    double p[3];
    frame_pt(fr, s + (i & 1 ? ra : -ra), t + (i & 2 ? rb : -rb),
             i & 4 ? t1 : t0, p);
    bx_add(b, p);
  }
  for (int k = 0; k < 3; k++) {
    b->lo[k] -= m;
    b->hi[k] += m;
  }
}

/* 1 if every surface point of the box on the column over the rectangle
   (s, t) +- (ra, rb) lies within e of the mesh (see mesh_cover.h). */
static int column(Part *p, const Frame *fr, double s0, double s1, double t0,
                  double t1) {
  /* the rectangle [s0, s1] x [t0, t1], its children sharing a computed
     midpoint, so they tile it exactly; centre and half sides rounded up */
  double s = 0.5 * (s0 + s1), t = 0.5 * (t0 + t1);
  double ra = fmax(s - s0, s1 - s) * (1 + 0x1p-50), rb = fmax(t - t0, t1 - t) * (1 + 0x1p-50);
  const Job *j = p->job;
  const MeshField *fd = j->fld;
  double m = j->margin, e = j->e;
  p->columns++;
  if (--p->col_budget < 0) return 0;
  /* the column's part in the box */
  Bx in;
  frame_box(fr, s, t, ra, rb, fr->f0, fr->f1, m, &in);
  for (int k = 0; k < 3; k++) {
    in.lo[k] = fmax(in.lo[k], fr->lo[k]);
    in.hi[k] = fmin(in.hi[k], fr->hi[k]);
    if (in.lo[k] > in.hi[k]) return 1;
  }
  if (!j->cl(p->ctx, in.lo, in.hi)) return 1;
  /* the field's root on the centre line, by regula falsi (Illinois) */
  double ta = fr->f0 - e, tb = fr->f1 + e, pt[3];
  frame_pt(fr, s, t, ta, pt);
  double va = fd->value(p->ctx, fr->node, pt);
  frame_pt(fr, s, t, tb, pt);
  double vb = fd->value(p->ctx, fr->node, pt);
  int side = 0;
  if (!(va < 0 && vb > 0)) goto split;
  for (int it = 0; it < 60 && tb - ta > e / 64; it++) {
    double tm = (ta * vb - tb * va) / (vb - va);
    if (!(tm > ta && tm < tb)) tm = 0.5 * (ta + tb);
    frame_pt(fr, s, t, tm, pt);
    double vm = fd->value(p->ctx, fr->node, pt);
    if (vm < 0) {
      ta = tm;
      va = vm;
      if (side == -1) vb *= 0.5;
      side = -1;
    } else if (vm > 0) {
      tb = tm;
      vb = vm;
      if (side == 1) va *= 0.5;
      side = 1;
    } else {
      ta = tb = tm;
    }
  }
  {
    double tc = 0.5 * (ta + tb);
    double hh = 0.5 * (e - 4 * m) * (1 - 1e-12); /* half the prism's height */
    if (!(hh > 0)) goto split;
    Bx q, u;
    frame_box(fr, s, t, ra, rb, tc - hh, tc + hh, m, &q);
    double gmin, wp, gmax, gminu, wpu, gmaxu;
    if (fd->grad(p->ctx, fr->node, q.lo, q.hi, fr->n0, &gmin, &wp, &gmax, NULL) < 0 ||
        !(gmin > 0))
      goto split;
    u = q; /* the hull of the prism and the column's part in the box */
    bx_add(&u, in.lo);
    bx_add(&u, in.hi);
    if (fd->grad(p->ctx, fr->node, u.lo, u.hi, fr->n0, &gminu, &wpu, &gmaxu, NULL) < 0 ||
        !(gminu > 0))
      goto split;
    /* the field over each face: its value at the face's centre (bounded
       over a box holding the true point) moved by at most the face's
       radius times the gradient's bound along the face */
    double rad = sqrt(ra * ra + rb * rb) * (1 + 1e-12);
    double dev = rad * (wp + gmax * fr->skew) * (1 + 1e-9) + 1e-300;
    double zt[3], zb[3], l, hgh;
    frame_pt(fr, s, t, tc + hh, zt);
    frame_pt(fr, s, t, tc - hh, zb);
    double bl[3], bh[3];
    for (int k = 0; k < 3; k++) {
      bl[k] = zt[k] - fr->pos;
      bh[k] = zt[k] + fr->pos;
    }
    fd->range(p->ctx, fr->node, bl, bh, &l, &hgh);
    if (!(l - dev > 0)) goto split;
    for (int k = 0; k < 3; k++) {
      bl[k] = zb[k] - fr->pos;
      bh[k] = zb[k] + fr->pos;
    }
    fd->range(p->ctx, fr->node, bl, bh, &l, &hgh);
    if (!(hgh + dev < 0)) goto split;
    /* the mesh clear of both faces, and crossing the centre line an odd
       number of times between them */
    Face ft = {zt, fr->e1, fr->e2, ra, rb, m}, fb = {zb, fr->e1, fr->e2, ra, rb, m};
    Bx qq = q;
    for (int k = 0; k < 3; k++) {
      qq.lo[k] -= 2 * m;
      qq.hi[k] += 2 * m;
    }
    if (prism_fails(p, &qq, &ft, &fb, zb, zt)) goto split;
    /* two points of one line of the prism: within its height */
    p->bound = fmax(p->bound, 2 * hh * (1 + 1e-12) + 2 * fr->pos);
    return 1;
  }
split:
  if (ra <= e / 32 && rb <= e / 32) {
    frame_pt(fr, s, t, 0.5 * (fr->f0 + fr->f1), p->last);
    return 0;
  }
  {
    int ok = 1;
    double se[3] = {s0, ra > e / 32 ? s : s1, s1}, te[3] = {t0, rb > e / 32 ? t : t1, t1};
    int na = ra > e / 32 ? 2 : 1, nb = rb > e / 32 ? 2 : 1;
    for (int a = 0; a < na && ok; a++)
      for (int b = 0; b < nb && ok; b++)
        ok &= column(p, fr, se[a], na == 2 ? se[a + 1] : s1, te[b],
                     nb == 2 ? te[b + 1] : t1);
    return ok;
  }
}

/* 1 if every surface point in the box (node's level set there) is within
   e of the mesh, proven by columns. */
static int cover_columns(Part *p, const double lo[3], const double hi[3],
                         int node) {
  const Job *j = p->job;
  Frame fr;
  fr.lo = lo;
  fr.hi = hi;
  fr.node = node;
  double g0[3], gmin, wp, gmax, a = 0, scale = 0;
  for (int k = 0; k < 3; k++) {
    fr.c[k] = 0.5 * (lo[k] + hi[k]);
    a = fmax(a, hi[k] - lo[k]);
    scale = fmax(scale, fmax(fabs(lo[k]), fabs(hi[k])));
  }
  if (j->fld->grad(p->ctx, node, lo, hi, NULL, &gmin, &wp, &gmax, g0) < 0)
    return 0;
  double len = sqrt(dot(g0, g0));
  if (!(len > 0) || !isfinite(len)) return 0;
  for (int k = 0; k < 3; k++) fr.n0[k] = g0[k] / len;
  /* e1: n0 crossed with the axis least along it; e2 = n0 x e1 */
  int ax = 0;
  for (int k = 1; k < 3; k++)
    if (fabs(fr.n0[k]) < fabs(fr.n0[ax])) ax = k;
  double ea[3] = {0, 0, 0};
  ea[ax] = 1;
  cross(fr.n0, ea, fr.e1);
  len = sqrt(dot(fr.e1, fr.e1));
  for (int k = 0; k < 3; k++) fr.e1[k] /= len;
  cross(fr.n0, fr.e1, fr.e2);
  len = sqrt(dot(fr.e2, fr.e2));
  for (int k = 0; k < 3; k++) fr.e2[k] /= len;
  fr.skew = fabs(dot(fr.n0, fr.e1)) + fabs(dot(fr.n0, fr.e2)) + 1e-14;
  /* computed points are within a few units in the last place of the
     coordinates; the margin is far above that */
  fr.pos = j->margin / 16 + 64 * 0x1p-52 * (scale + 4 * a);
  /* the argument needs the margin well above the points' rounding */
  if (!(fr.pos <= j->margin / 4)) return 0;
  /* the box's corners in the frame (the frame is orthonormal to 1e-15:
     a relative 1e-9 and the margin hold the true coordinates) */
  double sl = INFINITY, sh = -INFINITY, tl = INFINITY, th = -INFINITY;
  fr.f0 = INFINITY;
  fr.f1 = -INFINITY;
  for (int i = 0; i < 8; i++) {
    double d[3];
    for (int k = 0; k < 3; k++) d[k] = (i >> k & 1 ? hi[k] : lo[k]) - fr.c[k];
    double u = dot(d, fr.e1), v = dot(d, fr.e2), w = dot(d, fr.n0);
    sl = fmin(sl, u);
    sh = fmax(sh, u);
    tl = fmin(tl, v);
    th = fmax(th, v);
    fr.f0 = fmin(fr.f0, w);
    fr.f1 = fmax(fr.f1, w);
  }
  double gr = 1e-9 * a + j->margin;
  fr.f0 -= gr;
  fr.f1 += gr;
  p->col_budget = 4096;
  return column(p, &fr, sl - gr, sh + gr, tl - gr, th + gr);
}

static void *scan(void *arg) {
  Part *p = arg;
  Job *j = p->job;
  for (;;) {
    size_t i0 = __atomic_fetch_add(&j->next, 64, __ATOMIC_RELAXED);
    if (i0 >= j->nboxes) break;
    for (size_t i = i0; i < i0 + 64 && i < j->nboxes; i++) {
      int ok = 0;
      if (j->fld && j->fld->node[i] >= 0) {
        ok = cover_columns(p, j->boxes + 6 * i, j->boxes + 6 * i + 3,
                           j->fld->node[i]);
        p->col_boxes += ok;
      }
      if (!ok) {
        p->budget = BOX_BUDGET(j->boxes[6 * i + 3] - j->boxes[6 * i], j->e);
        ok = cover_box(p, j->boxes + 6 * i, j->boxes + 6 * i + 3);
      }
      if (j->bad) j->bad[i] = (unsigned char)!ok;
      if (ok) continue;
      p->unproven++;
      if (i < p->first) {
        p->first = i;
        memcpy(p->at, p->last, sizeof p->at);
      }
    }
  }
  mesh_check_release(); /* the exact predicates' scratch */
  return NULL;
}

int mesh_cover(const Mesh *me, const double *boxes, size_t nboxes, double e,
               double margin, MeshCoverClass cl, void **ctx, int nctx,
               const MeshField *fld, unsigned char *bad, MeshCover *out) {
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  memset(out, 0, sizeof *out);
  Bvh h;
  if (bvh_build(&h, me) < 0) return -1;
  Job job = {&h, boxes, nboxes, e, margin, cl, fld, bad, 0};
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
  int nomem = 0;
  for (int t = 0; t < nctx; t++) {
    free(part[t].tv);
    nomem |= part[t].nomem;
  }
  for (int t = 0; t < started; t++) {
    out->bound = fmax(out->bound, part[t].bound);
    out->boxes += part[t].boxes;
    out->unproven += part[t].unproven;
    out->columns += part[t].columns;
    out->col_boxes += part[t].col_boxes;
    if (part[t].unproven && part[t].first < first) {
      first = part[t].first;
      memcpy(out->at, part[t].at, sizeof out->at);
    }
  }
  free(h.node);
  free(h.tri);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  out->seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  return nomem ? -1 : 0;
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
