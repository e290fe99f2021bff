/* mesh_merge.c: flat regions of a mesh triangulated again (mesh_merge.h). */
#include "render/mesh_merge.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/mix.h"
#include "render/mesh.h"
#include "render/mesh_check.h"

/* Largest polygon (boundary vertices of one region, bridges counted) the
   clipping takes: it is quadratic in them. */
#define MERGE_MAX_POLY 20000
/* A region with more boundary edges than this is merged in patches of at
   most MERGE_PATCH triangles (mesh_merge_run). */
#define MERGE_LONG 96
#define MERGE_PATCH 64
/* The same for a face of a polyhedral part (every triangle across its
   boundary flat too: its corners are all that is left of the boundary).
   Its triangles across it meet no columns of the surface-to-mesh proof
   (flat cells are proven by boxes), and the self-intersection check
   takes its long triangles by the pairs their boxes meet: a plate with a
   360-sided hole, its top one polygon of 364 corners. */
#define MERGE_LONG_FACE 2048

typedef struct {
  const Mesh *m;
  size_t *vs;   /* triangles around vertex v: vt[vs[v] .. vs[v + 1]) */
  int *vt;
  int *nb;      /* the triangle across each edge (across), or NULL */
} Adj;

/* The triangle across edge e (t[e] -> t[e + 1]) of triangle i, or -1
   (from the table once made). */
static int across_find(const Adj *A, int i, int e);
static int across(const Adj *A, int i, int e) {
  return A->nb ? A->nb[3 * i + e] : across_find(A, i, e);
}
static int across_find(const Adj *A, int i, int e) {
  const int *t = A->m->t;
  int a = t[3 * i + e], b = t[3 * i + (e + 1) % 3];
  for (size_t k = A->vs[b]; k < A->vs[b + 1]; k++) {
    int j = A->vt[k];
    for (int f = 0; f < 3; f++)
      if (t[3 * j + f] == b && t[3 * j + (f + 1) % 3] == a) return j;
  }
  return -1;
}

static void tri_normal(const Mesh *m, int i, double n[3]) {
  const double *a = m->v + 3 * m->t[3 * i], *b = m->v + 3 * m->t[3 * i + 1],
               *c = m->v + 3 * m->t[3 * i + 2];
  double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  n[0] = u[1] * w[2] - u[2] * w[1];
  n[1] = u[2] * w[0] - u[0] * w[2];
  n[2] = u[0] * w[1] - u[1] * w[0];
  double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(l > 0) || !isfinite(l)) {
    n[0] = n[1] = n[2] = 0;
    return;
  }
  for (int k = 0; k < 3; k++) n[k] /= l;
}

/* A boundary edge a -> b of region r. */
typedef struct {
  int r, a, b;
} BEdge;

static int bedge_cmp(const void *x, const void *y) {
  const BEdge *p = x, *q = y;
  if (p->r != q->r) return p->r < q->r ? -1 : 1;
  return p->a < q->a ? -1 : p->a > q->a;
}

typedef struct {
  const BEdge *e;
  size_t *rs;   /* region r's edges: e[rs[r] .. rs[r + 1]) */
} Bound;

/* Index of region r's boundary edge leaving a, or -1 (binary search: the
   edges are sorted by region, then by a). */
static long edge_at(const Bound *B, int r, int a) {
  size_t lo = B->rs[r], hi = B->rs[r + 1];
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (B->e[mid].a < a) lo = mid + 1;
    else hi = mid;
  }
  return lo < B->rs[r + 1] && B->e[lo].a == a ? (long)lo : -1;
}

/* The vertex after a on region r's boundary, or -1. */
static int next_on(const Bound *B, int r, int a) {
  long k = edge_at(B, r, a);
  return k < 0 ? -1 : B->e[k].b;
}

/* ---- ear clipping in a plane, exact signs ------------------------------ */

typedef struct {
  const double *v;  /* the mesh's vertices */
  int ax, ay;       /* the plane's coordinates */
  int *id;          /* the polygon: vertex indices, circular */
  int *prev, *next;
  int n;
} Poly;

static int orient(const Poly *P, int a, int b, int c) {
  return mesh_orient2d(P->v + 3 * a, P->v + 3 * b, P->v + 3 * c, P->ax, P->ay,
                       NULL);
}

/* Is vertex index q inside or on the closed triangle (a, b, c), counter-
   clockwise? */
static int in_tri(const Poly *P, int a, int b, int c, int q) {
  return orient(P, a, b, q) >= 0 && orient(P, b, c, q) >= 0 &&
         orient(P, c, a, q) >= 0;
}

/* Are a, b, c nearly on a line: twice the area below 1e-10 of the
   longest side squared? Vertices on one straight edge are not exactly
   collinear once rounded, and the exact sign then calls them convex: a
   triangle of them would be a sliver along the edge, no wider than the
   rounding. */
static int flat3(const Poly *P, int a, int b, int c) {
  const double *x = P->v + 3 * a, *y = P->v + 3 * b, *z = P->v + 3 * c;
  int i = P->ax, j = P->ay;
  double ux = y[i] - x[i], uy = y[j] - x[j], vx = z[i] - x[i], vy = z[j] - x[j];
  double wx = z[i] - y[i], wy = z[j] - y[j];
  double l = fmax(ux * ux + uy * uy, fmax(vx * vx + vy * vy, wx * wx + wy * wy));
  return !(fabs(ux * vy - uy * vx) > 1e-10 * l);
}

/* Position k of the polygon an ear: strictly convex, not a sliver
   (flat3), and no other vertex (by index: a bridge's ends appear twice)
   inside or on it. */
static int is_ear(const Poly *P, int k) {
  int a = P->id[P->prev[k]], b = P->id[k], c = P->id[P->next[k]];
  if (orient(P, a, b, c) <= 0 || flat3(P, a, b, c)) return 0;
  const double *x = P->v + 3 * a, *y = P->v + 3 * b, *z = P->v + 3 * c;
  int i = P->ax, j2 = P->ay;
  double lx = fmin(x[i], fmin(y[i], z[i])), hx = fmax(x[i], fmax(y[i], z[i]));
  double ly = fmin(x[j2], fmin(y[j2], z[j2])), hy = fmax(x[j2], fmax(y[j2], z[j2]));
  for (int j = P->next[P->next[k]]; j != P->prev[k]; j = P->next[j]) {
    int q = P->id[j];
    const double *w = P->v + 3 * q;
    /* outside the ear's box: outside the ear (the box is exact) */
    if (w[i] < lx || w[i] > hx || w[j2] < ly || w[j2] > hy) continue;
    if (q == a || q == b || q == c) continue;
    if (in_tri(P, a, b, c, q)) return 0;
    /* nor within rounding of its diagonal, outside: cut off, it would
       leave a spike that flat3 refuses */
    double dx = z[i] - x[i], dy = z[j2] - x[j2], qx = w[i] - x[i], qy = w[j2] - x[j2];
    double l2 = dx * dx + dy * dy, t = qx * dx + qy * dy;
    if (t > 0 && t < l2 && !(fabs(dx * qy - dy * qx) > 1e-10 * l2)) return 0;
  }
  return 1;
}

/* Triangulate P (counter-clockwise, n >= 3) into out (3 (n - 2) ints),
   looking for ears from position k0 on. 0, or -1 when no ear is left. */
static int clip_from(Poly *P, int *out, int k0) {
  int n = P->n, k = k0, made = 0, stall = 0;
  for (int i = 0; i < n; i++) {
    P->prev[i] = (i + n - 1) % n;
    P->next[i] = (i + 1) % n;
  }
  while (n > 3) {
    if (is_ear(P, k)) {
      out[3 * made] = P->id[P->prev[k]];
      out[3 * made + 1] = P->id[k];
      out[3 * made + 2] = P->id[P->next[k]];
      made++;
      int p = P->prev[k], q = P->next[k];
      P->next[p] = q;
      P->prev[q] = p;
      n--;
      k = p;
      stall = 0;
    } else {
      k = P->next[k];
      if (++stall > n) return -1;
    }
  }
  int a = P->id[P->prev[k]], b = P->id[k], c = P->id[P->next[k]];
  if (orient(P, a, b, c) <= 0 || flat3(P, a, b, c)) return -1;
  out[3 * made] = a;
  out[3 * made + 1] = b;
  out[3 * made + 2] = c;
  return 0;
}

/* Is d inside the circle through a, b, c (counter-clockwise), by more
   than rounding? In doubles: it only chooses among valid triangulations. */
static int in_circle(const Poly *P, int a, int b, int c, int d) {
  const double *A = P->v + 3 * a, *B = P->v + 3 * b, *C = P->v + 3 * c,
               *D = P->v + 3 * d;
  int i = P->ax, j = P->ay;
  double ax = A[i] - D[i], ay = A[j] - D[j], bx = B[i] - D[i], by = B[j] - D[j];
  double cx = C[i] - D[i], cy = C[j] - D[j];
  double a2 = ax * ax + ay * ay, b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  double det = a2 * (bx * cy - by * cx) - b2 * (ax * cy - ay * cx) +
               c2 * (ax * by - ay * bx);
  double mag = a2 * (fabs(bx * cy) + fabs(by * cx)) + b2 * (fabs(ax * cy) + fabs(ay * cx)) +
               c2 * (fabs(ax * by) + fabs(ay * bx));
  return det > 1e-12 * mag;
}

/* Lawson's flips over the n triangles of one region (out, counter-
   clockwise): an inner edge whose opposite vertex lies inside the other
   triangle's circumcircle is flipped when both new triangles are
   strictly convex by the exact signs and no sliver (flat3), so the
   triangulation stays one of the same polygon, with fatter triangles
   (ear clipping makes fans). At most 16 n flips. */
static void flip_region(const Poly *P, int *out, int n) {
  int budget = 16 * n;
  for (int changed = 1; changed && budget > 0;) {
    changed = 0;
    for (int x = 0; x < n && budget > 0; x++)
      for (int e = 0; e < 3 && budget > 0; e++) {
        int u = out[3 * x + e], v = out[3 * x + (e + 1) % 3], c = out[3 * x + (e + 2) % 3];
        for (int y = 0; y < n; y++) {
          if (y == x) continue;
          int f = -1;
          for (int g = 0; g < 3; g++)
            if (out[3 * y + g] == v && out[3 * y + (g + 1) % 3] == u) f = g;
          if (f < 0) continue;
          int d = out[3 * y + (f + 2) % 3];
          if (d != c && in_circle(P, u, v, c, d) && orient(P, u, d, c) > 0 &&
              orient(P, v, c, d) > 0 && !flat3(P, u, d, c) && !flat3(P, v, c, d)) {
            out[3 * x] = u, out[3 * x + 1] = d, out[3 * x + 2] = c;
            out[3 * y] = v, out[3 * y + 1] = c, out[3 * y + 2] = d;
            changed = 1;
            budget--;
            e = 3; /* x changed: on to the next */
          }
          break;
        }
      }
  }
}

/* clip_from from up to 8 starting places spread around the polygon (the
   first ear found is taken, and on a face whose straight runs are
   collinear only to rounding one start can leave a run no ear can cut
   where another does not). 0, or -1: the region keeps its triangles. */
static int clip(Poly *P, int *out) {
  int tries = P->n < 8 ? P->n : 8;
  for (int t = 0; t < tries; t++)
    if (clip_from(P, out, (int)((long)t * P->n / tries)) == 0) return 0;
  return -1;
}

/* Do the closed segments pq and cd meet? */
static int seg_meet(const Poly *P, int p, int q, int c, int d) {
  int o1 = orient(P, p, q, c), o2 = orient(P, p, q, d);
  int o3 = orient(P, c, d, p), o4 = orient(P, c, d, q);
  if (o1 * o2 < 0 && o3 * o4 < 0) return 1;
  /* a touch or a collinear overlap: by boxes on the line */
  const double *v = P->v;
  int ax = P->ax, ay = P->ay;
#define ON(a, b, x)                                                            \
  (fmin(v[3 * a + ax], v[3 * b + ax]) <= v[3 * x + ax] &&                      \
   v[3 * x + ax] <= fmax(v[3 * a + ax], v[3 * b + ax]) &&                      \
   fmin(v[3 * a + ay], v[3 * b + ay]) <= v[3 * x + ay] &&                      \
   v[3 * x + ay] <= fmax(v[3 * a + ay], v[3 * b + ay]))
  if (o1 == 0 && ON(p, q, c)) return 1;
  if (o2 == 0 && ON(p, q, d)) return 1;
  if (o3 == 0 && ON(c, d, p)) return 1;
  if (o4 == 0 && ON(c, d, q)) return 1;
#undef ON
  return 0;
}

/* Is the direction from vertex u (loop neighbours u0 before, u1 after) to
   w inside the region at u (the region lies left of its boundary)? */
static int in_cone(const Poly *P, int u0, int u, int u1, int w) {
  if (orient(P, u0, u, u1) >= 0) /* convex (or straight) at u */
    return orient(P, u, w, u0) > 0 && orient(P, w, u, u1) > 0;
  return !(orient(P, u, w, u1) >= 0 && orient(P, w, u, u0) >= 0);
}

/* ---- the merge ---------------------------------------------------------- */

typedef struct {
  Mesh *m;
  double delta;
  int nreg;
  int *reg;          /* per triangle */
  int *rcount;       /* triangles per region */
  double (*rplane)[4];
  unsigned char *rbad;
  int *seed;    /* the triangles, largest first: regions' seeds */
  const unsigned char *frozen; /* per triangle: a region of its own, not
                                  merged (NULL: none) */
  Bound B;
  BEdge *edges;
  size_t nedges;
} Ctx;

static int region_normal_ok(const Ctx *C, int j, const double n[3], double d) {
  double nj[3];
  tri_normal(C->m, j, nj);
  if (!(nj[0] * n[0] + nj[1] * n[1] + nj[2] * n[2] > 0.5)) return 0;
  for (int k = 0; k < 3; k++) {
    const double *p = C->m->v + 3 * C->m->t[3 * j + k];
    if (!(fabs(n[0] * p[0] + n[1] * p[1] + n[2] * p[2] - d) <= C->delta)) return 0;
  }
  return 1;
}

/* A slot for key in a table of cap (a power of two) entries. */
static size_t ends_slot(uint64_t key, size_t cap) {
  return (size_t)mix64(key) & (cap - 1);
}

/* Straight vertices: on the common boundary of exactly two merged regions
   and nothing else, between the same two neighbours on both; removed in
   chains whose every vertex is within delta of the chord between the
   chain's ends, unless a chain removed before had the same two ends:
   two creases between the same two corners (the top and
   bottom of a neck of no width, where two prisms touching edge to edge
   overlap by a rounding) would become one edge of four triangles. */
static void straight(Ctx *C, const Adj *A, unsigned char *gone) {
  const Mesh *m = C->m;
  size_t nv = m->nv;
  int *ra = malloc(nv * sizeof *ra), *rb = malloc(nv * sizeof *rb);
  int *na = malloc(nv * sizeof *na), *nb = malloc(nv * sizeof *nb);
  unsigned char *seen = calloc(nv, 1);
  int *chain = malloc(nv * sizeof *chain);
  /* the chains removed: their ends (lower << 32 | higher + 1), a set by
     open addressing, at most half full */
  uint64_t *ends = NULL;
  size_t nends = 0, capends = 0;
  if (!ra || !rb || !na || !nb || !seen || !chain) goto out;
  for (size_t v = 0; v < nv; v++) {
    ra[v] = -1;
    int r1 = -1, r2 = -1, ok = A->vs[v] < A->vs[v + 1];
    for (size_t k = A->vs[v]; k < A->vs[v + 1] && ok; k++) {
      int r = C->reg[A->vt[k]];
      if (r == r1 || r == r2) continue;
      if (r1 < 0) r1 = r;
      else if (r2 < 0) r2 = r;
      else ok = 0;
    }
    if (!ok || r2 < 0) continue;
    if (r1 > r2) { int x = r1; r1 = r2; r2 = x; }
    if (C->rcount[r1] < 2 || C->rcount[r2] < 2 || C->rbad[r1] || C->rbad[r2])
      continue;
    int b = next_on(&C->B, r1, (int)v), a = next_on(&C->B, r2, (int)v);
    if (a < 0 || b < 0 || a == b || next_on(&C->B, r2, b) != (int)v ||
        next_on(&C->B, r1, a) != (int)v)
      continue;
    ra[v] = r1;
    rb[v] = r2;
    na[v] = b; /* forward along r1's boundary */
    nb[v] = a; /* forward along r2's: backward along r1's */
  }
  for (size_t v = 0; v < nv; v++) {
    if (ra[v] < 0 || seen[v]) continue;
    int r1 = ra[v], r2 = rb[v];
#define SAME(x) (ra[x] == r1 && rb[x] == r2)
    /* back to the chain's start (after a vertex that is not straight) */
    int s = (int)v, guard = 0;
    while (SAME(nb[s]) && nb[s] != (int)v && guard++ < (int)nv) s = nb[s];
    if (SAME(nb[s])) { /* a ring of straight vertices: left alone */
      seen[v] = 1;
      continue;
    }
    int p = nb[s], len = 0, x = s;
    while (SAME(x) && !seen[x]) {
      seen[x] = 1;
      chain[len++] = x;
      x = na[x];
    }
    int q = x;
    if (SAME(q) || p == q) continue;
#undef SAME
    const double *P0 = m->v + 3 * p, *P1 = m->v + 3 * q;
    double dir[3] = {P1[0] - P0[0], P1[1] - P0[1], P1[2] - P0[2]};
    double L2 = dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2];
    int ok = L2 > 0;
    for (int i = 0; i < len && ok; i++) {
      const double *X = m->v + 3 * chain[i];
      double w[3] = {X[0] - P0[0], X[1] - P0[1], X[2] - P0[2]};
      double s1 = (w[0] * dir[0] + w[1] * dir[1] + w[2] * dir[2]) / L2;
      double e[3] = {w[0] - s1 * dir[0], w[1] - s1 * dir[1], w[2] - s1 * dir[2]};
      ok = s1 > 0 && s1 < 1 &&
           sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) <= C->delta;
    }
    uint64_t key = ((uint64_t)(uint32_t)(p < q ? p : q) << 32 | (uint32_t)(p < q ? q : p)) + 1;
    if (ok && 2 * (nends + 1) > capends) { /* grown: every key placed again */
      size_t cap = capends ? 2 * capends : 64;
      uint64_t *n2 = calloc(cap, sizeof *n2);
      if (!n2) ok = 0;
      for (size_t k = 0; k < capends && n2; k++) {
        if (!ends[k]) continue;
        size_t h = ends_slot(ends[k], cap);
        while (n2[h]) h = (h + 1) & (cap - 1);
        n2[h] = ends[k];
      }
      if (n2) {
        free(ends);
        ends = n2;
        capends = cap;
      }
    }
    if (ok) {
      size_t h = ends_slot(key, capends);
      while (ends[h] && ends[h] != key) h = (h + 1) & (capends - 1);
      ok = !ends[h];
      if (ok) {
        ends[h] = key;
        nends++;
        for (int i = 0; i < len; i++) gone[chain[i]] = 1;
      }
    }
  }
out:
  free(ends);
  free(ra);
  free(rb);
  free(na);
  free(nb);
  free(seen);
  free(chain);
}

static int grow_ints(int **p, size_t *cap, size_t need) {
  if (need <= *cap) return 0;
  size_t c = *cap ? *cap : 1024;
  while (c < need) c *= 2;
  int *q = realloc(*p, c * sizeof *q);
  if (!q) return -1;
  *p = q;
  *cap = c;
  return 0;
}

typedef struct {
  int *ids;          /* loops' vertices, back to back */
  int *start;        /* loop k: ids[start[k] .. start[k + 1]) */
  int nloops;
  size_t cap, scap;
} Loops;

/* A directed edge and the region of its new triangle (-1: a triangle
   kept as it was). */
typedef struct {
  uint64_t k;
  int r;
} DEdge;

static int dedge_cmp(const void *x, const void *y) {
  uint64_t a = ((const DEdge *)x)->k, b = ((const DEdge *)y)->k;
  return a < b ? -1 : a > b;
}

/* After a pass: a directed edge used twice in the mesh it would make (the
   triangles of the regions not merged and the new ones) is two sheets
   along one line made one edge of four triangles: a region's diagonal
   along a line of contact where another part's crease, its straight run
   dropped, has the same ends (a prism's corner touching a box's top from
   below: the top's diagonal and the bore's crease). The regions with a
   new triangle there that lost straight vertices get them back (their
   neighbours' sides too); if none did, those regions are not merged
   (rbad). 1 when a region changed (another pass), 0 if none, -1 out of
   memory. */
static int dup_edges(Ctx *C, const unsigned char *merged, const int *newt,
                     const int *newr, size_t nnew, unsigned char *gone) {
  const Mesh *m = C->m;
  size_t n = 3 * nnew;
  for (size_t i = 0; i < m->nt; i++) n += merged[C->reg[i]] ? 0 : 3;
  DEdge *e = malloc((n ? n : 1) * sizeof *e);
  if (!e) return -1;
  size_t w = 0;
  for (size_t i = 0; i < m->nt; i++)
    if (!merged[C->reg[i]])
      for (int q = 0; q < 3; q++)
        e[w++] = (DEdge){(uint64_t)(uint32_t)m->t[3 * i + (size_t)q] << 32 |
                             (uint32_t)m->t[3 * i + (size_t)(q + 1) % 3], -1};
  for (size_t i = 0; i < nnew; i++)
    for (int q = 0; q < 3; q++)
      e[w++] = (DEdge){(uint64_t)(uint32_t)newt[3 * i + (size_t)q] << 32 |
                           (uint32_t)newt[3 * i + (size_t)(q + 1) % 3], newr[i]};
  qsort(e, n, sizeof *e, dedge_cmp);
  int changed = 0;
  for (size_t i = 0; i < n;) {
    size_t j = i;
    while (j < n && e[j].k == e[i].k) j++;
    if (j - i > 1) {
      int had = 0;
      for (size_t x = i; x < j; x++) {
        int r = e[x].r;
        if (r < 0) continue;
        for (size_t b = C->B.rs[r]; b < C->B.rs[r + 1]; b++)
          if (gone[C->edges[b].a]) {
            gone[C->edges[b].a] = 0;
            had = 1;
          }
      }
      for (size_t x = i; x < j && !had; x++)
        if (e[x].r >= 0) C->rbad[e[x].r] = 1;
      for (size_t x = i; x < j; x++) changed |= e[x].r >= 0;
    }
    i = j;
  }
  free(e);
  return changed;
}

/* Region r's boundary as loops of the vertices not gone. 0, -1 when a
   loop is too short or the boundary does not close, -2 out of memory. */
static int region_loops(const Ctx *C, int r, const unsigned char *gone,
                        unsigned char *used, Loops *L) {
  size_t e0 = C->B.rs[r], e1 = C->B.rs[r + 1];
  L->nloops = 0;
  size_t n = 0;
  for (size_t k = e0; k < e1; k++) used[k - e0] = 0;
  for (size_t k = e0; k < e1; k++) {
    if (used[k - e0]) continue;
    if ((size_t)(L->nloops + 2) > L->scap) {
      size_t c = L->scap ? 2 * L->scap : 64;
      int *q = realloc(L->start, c * sizeof *q);
      if (!q) return -2;
      L->start = q;
      L->scap = c;
    }
    L->start[L->nloops] = (int)n;
    int a = C->B.e[k].a, cur = a, steps = 0;
    do {
      long x = edge_at(&C->B, r, cur);
      if (x < 0 || used[(size_t)x - e0] || steps++ > (int)(e1 - e0)) return -1;
      used[(size_t)x - e0] = 1;
      if (!gone[cur]) {
        if (grow_ints(&L->ids, &L->cap, n + 1) < 0) return -2;
        L->ids[n++] = cur;
      }
      cur = C->B.e[x].b;
    } while (cur != a);
    if ((int)n - L->start[L->nloops] < 3) return -1;
    L->nloops++;
  }
  L->start[L->nloops] = (int)n;
  return 0;
}

/* Twice the signed area of loop k in the plane's coordinates. */
static double loop_area(const Poly *P, const Loops *L, int k) {
  double s = 0;
  int a = L->start[k], b = L->start[k + 1];
  for (int i = a; i < b; i++) {
    const double *p = P->v + 3 * L->ids[i];
    const double *q = P->v + 3 * L->ids[i + 1 < b ? i + 1 : a];
    s += p[P->ax] * q[P->ay] - q[P->ax] * p[P->ay];
  }
  return s;
}

/* Does segment (h, p) meet any edge of the polygon's sequence seq[0 .. n)
   or of the loops not yet joined, other than edges at h or p? */
static int bridge_blocked(const Poly *P, const int *seq, int n, const Loops *L,
                          int outer, const unsigned char *joined, int h, int p) {
  for (int i = 0; i < n; i++) {
    int c = seq[i], d = seq[(i + 1) % n];
    if (c == h || c == p || d == h || d == p) continue;
    if (seg_meet(P, h, p, c, d)) return 1;
  }
  for (int k = 0; k < L->nloops; k++) {
    if (k == outer || joined[k]) continue;
    int a = L->start[k], b = L->start[k + 1];
    for (int i = a; i < b; i++) {
      int c = L->ids[i], d = L->ids[i + 1 < b ? i + 1 : a];
      if (c == h || c == p || d == h || d == p) continue;
      if (seg_meet(P, h, p, c, d)) return 1;
    }
  }
  return 0;
}

/* The polygon of a region: loop `outer` the outside, the others its
   holes, joined by bridges into seq (n returned; -1 when no bridge is
   found). A hole's bridge runs from its vertex farthest along the first
   axis to the nearest vertex of the polygon so far that it reaches inside
   the region at both ends and crossing no edge. */
static int join_holes(const Poly *P, const Loops *L, int outer, int *seq, int cap,
                      unsigned char *joined) {
  int n = L->start[outer + 1] - L->start[outer];
  for (int i = 0; i < n; i++) seq[i] = L->ids[L->start[outer] + i];
  for (int k = 0; k < L->nloops; k++) joined[k] = 0;
  for (int left = L->nloops - 1; left > 0; left--) {
    int best = -1, bh = -1;
    for (int k = 0; k < L->nloops; k++) {
      if (k == outer || joined[k]) continue;
      for (int i = L->start[k]; i < L->start[k + 1]; i++)
        if (best < 0 || P->v[3 * L->ids[i] + P->ax] > P->v[3 * L->ids[bh] + P->ax]) {
          best = k;
          bh = i;
        }
    }
    int a = L->start[best], b = L->start[best + 1], len = b - a;
    int h = L->ids[bh];
    int h0 = L->ids[bh > a ? bh - 1 : b - 1], h1 = L->ids[bh + 1 < b ? bh + 1 : a];
    int at = -1;
    double bd = INFINITY;
    for (int i = 0; i < n; i++) {
      int p = seq[i];
      const double *x = P->v + 3 * p, *y = P->v + 3 * h;
      double dx = x[P->ax] - y[P->ax], dy = x[P->ay] - y[P->ay];
      double d2 = dx * dx + dy * dy;
      if (d2 >= bd) continue;
      if (!in_cone(P, seq[(i + n - 1) % n], p, seq[(i + 1) % n], h) ||
          !in_cone(P, h0, h, h1, p))
        continue;
      joined[best] = 1; /* its own edges: below */
      int blocked = bridge_blocked(P, seq, n, L, outer, joined, h, p);
      joined[best] = 0;
      /* the hole's own edges */
      for (int j = a; j < b && !blocked; j++) {
        int c = L->ids[j], d = L->ids[j + 1 < b ? j + 1 : a];
        if (c == h || d == h || c == p || d == p) continue;
        blocked = seg_meet(P, h, p, c, d);
      }
      if (!blocked) {
        bd = d2;
        at = i;
      }
    }
    if (at < 0 || n + len + 2 > cap) return -1;
    /* seq: ... p, h, (the hole from after h around to h), p, ... */
    int p = seq[at];
    memmove(seq + at + len + 3, seq + at + 1, (size_t)(n - at - 1) * sizeof *seq);
    int w = at + 1;
    for (int j = 0; j <= len; j++) seq[w++] = L->ids[a + (bh - a + j) % len];
    seq[w] = p;
    n += len + 2;
    joined[best] = 1;
  }
  return n;
}

/* Twice triangle i's area, squared (|u x w|^2, as tri_normal's cross
   product before it is normalised). */
static double tri_area2(const Mesh *m, int i) {
  const double *p[3];
  for (int k = 0; k < 3; k++) p[k] = m->v + 3 * m->t[3 * i + k];
  double u[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
  double w[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
  double c[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                 u[0] * w[1] - u[1] * w[0]};
  return c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
}

/* Triangle i's longest side, squared. */
static double tri_long2(const Mesh *m, int i) {
  double l2 = 0;
  for (int k = 0; k < 3; k++) {
    const double *a = m->v + 3 * m->t[3 * i + k], *b = m->v + 3 * m->t[3 * i + (k + 1) % 3];
    double e2 = (b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                (b[2] - a[2]) * (b[2] - a[2]);
    if (e2 > l2) l2 = e2;
  }
  return l2;
}

/* Whether triangle i is thin: its least height under a twentieth of its
   longest side (twice the area is the longest side times that height). */
static int thin(const Mesh *m, int i) {
  double l2 = tri_long2(m, i);
  return !(tri_area2(m, i) * 400 >= l2 * l2);
}

typedef struct {
  float a;
  int i;
} SeedKey;

/* Largest first; equal areas in index order (qsort is not stable). */
static int seed_cmp(const void *x, const void *y) {
  const SeedKey *p = x, *q = y;
  if (p->a != q->a) return p->a > q->a ? -1 : 1;
  return (p->i > q->i) - (p->i < q->i);
}

/* Regions from every triangle not yet in one (reg < 0): grown across
   edges while their vertices stay within delta of the seed's plane, at
   most cap triangles, within the seed's region of `within` (if given). */
static void grow_regions(Ctx *C, const Adj *A, int *stack, const int *within,
                         int cap) {
  const Mesh *m = C->m;
  /* seeds first that are not thin, largest first (C->seed), then those
     whose normal is not rounding, then the rest alone: a region's plane
     is its seed's, and a small or thin seed's (a sliver where a sharp
     cell's plane nearly meets a corner) is tilted by its vertices'
     rounding over its short sides: 5.8e-13 on a 100-sided hole's side
     left a triangle of the same side beyond delta of it, alone, and the
     plate's top beside it counted as a rounded part's face: 6,073
     triangles where 104 do */
  for (int pass = C->seed ? 0 : 1; pass < 3; pass++)
    for (size_t si = 0; si < m->nt; si++) {
      size_t i = C->seed ? (size_t)C->seed[si] : si;
      if (C->reg[i] >= 0) continue;
      if (pass == 0 && thin(m, (int)i)) continue;
      double n[3];
      tri_normal(m, (int)i, n);
      const double *p0 = m->v + 3 * m->t[3 * i];
      double d = n[0] * p0[0] + n[1] * p0[1] + n[2] * p0[2];
      /* a thin seed's normal is rounding: its own vertices must be
         within delta of its plane too, else it stays alone */
      int off = n[0] == 0 && n[1] == 0 && n[2] == 0;
      for (int k = 1; k < 3; k++) {
        const double *q = m->v + 3 * m->t[3 * i + (size_t)k];
        off |= !(fabs(n[0] * q[0] + n[1] * q[1] + n[2] * q[2] - d) <= C->delta);
      }
      int fz = C->frozen && C->frozen[i];
      if (off && pass < 2 && !fz) continue;
      int r = C->nreg++;
      C->reg[i] = r;
      C->rcount[r] = 1;
      memcpy(C->rplane[r], n, sizeof n);
      C->rplane[r][3] = d;
      if (off || fz) continue;
      size_t sp = 0;
      stack[sp++] = (int)i;
      /* breadth first (the stack read from its bottom): compact patches */
      size_t head = 0;
      while (head < sp) {
        int x = stack[head++];
        for (int e = 0; e < 3; e++) {
          int j = across(A, x, e);
          if (j >= 0 && C->reg[j] < 0 && C->rcount[r] < cap &&
              !(C->frozen && C->frozen[j]) &&
              (!within || within[j] == within[i]) && region_normal_ok(C, j, n, d)) {
            C->reg[j] = r;
            C->rcount[r]++;
            stack[sp++] = j;
          }
        }
      }
    }
}

/* The boundary edges of every region of two or more triangles, sorted
   (C->edges, C->B), and C->rbad for a region with a vertex twice on its
   boundary. 0, or -1 out of memory. */
static int bound_build(Ctx *C, const Adj *A) {
  const Mesh *m = C->m;
  size_t nt = m->nt, ne = 0;
  free(C->edges);
  free(C->B.rs);
  C->edges = NULL;
  C->B.rs = NULL;
  C->nedges = 0;
  memset(C->rbad, 0, nt);
  for (size_t i = 0; i < nt; i++) {
    int r = C->reg[i];
    if (C->rcount[r] < 2) continue;
    for (int e = 0; e < 3; e++) {
      int j = across(A, (int)i, e);
      ne += j < 0 || C->reg[j] != r;
    }
  }
  C->edges = malloc((ne ? ne : 1) * sizeof *C->edges);
  C->B.rs = calloc((size_t)C->nreg + 1, sizeof *C->B.rs);
  if (!C->edges || !C->B.rs) return -1;
  ne = 0;
  for (size_t i = 0; i < nt; i++) {
    int r = C->reg[i];
    if (C->rcount[r] < 2) continue;
    for (int e = 0; e < 3; e++) {
      int j = across(A, (int)i, e);
      if (j < 0 || C->reg[j] != r) {
        BEdge b = {r, m->t[3 * i + (size_t)e], m->t[3 * i + (size_t)(e + 1) % 3]};
        C->edges[ne++] = b;
      }
    }
  }
  qsort(C->edges, ne, sizeof *C->edges, bedge_cmp);
  C->nedges = ne;
  C->B.e = C->edges;
  for (size_t k = 0; k < ne; k++) C->B.rs[C->edges[k].r + 1]++;
  for (int r = 0; r < C->nreg; r++) C->B.rs[r + 1] += C->B.rs[r];
  for (size_t k = 1; k < ne; k++)
    if (C->edges[k].r == C->edges[k - 1].r && C->edges[k].a == C->edges[k - 1].a)
      C->rbad[C->edges[k].r] = 1; /* a vertex twice on its boundary */
  return 0;
}

static int mesh_merge_run(Mesh *m, double delta, const unsigned char *frozen,
                          int **from, MeshMerge *st) {
  size_t nv = m->nv, nt = m->nt;
  int rc = -2;
  Adj A = {m, malloc((nv + 1) * sizeof *A.vs), malloc(3 * nt * sizeof *A.vt), NULL};
  Ctx C = {0};
  C.m = m;
  C.delta = delta;
  C.frozen = frozen;
  C.reg = malloc(nt * sizeof *C.reg);
  C.rcount = malloc(nt * sizeof *C.rcount);
  C.rplane = malloc(nt * sizeof *C.rplane);
  C.rbad = calloc(nt, 1);
  int *stack = malloc(nt * sizeof *stack);
  unsigned char *gone = calloc(nv ? nv : 1, 1), *merged = NULL, *used = NULL,
                *joined = NULL, *vused = NULL;
  int *newt = NULL, *seq = NULL, *outt = NULL, *remap = NULL, *newr = NULL;
  size_t newcap = 0, nnew = 0, newrcap = 0;
  Loops L = {0};
  Poly P = {0};
  C.B.rs = NULL;
  if (!A.vs || !A.vt || !C.reg || !C.rcount || !C.rplane || !C.rbad || !stack ||
      !gone)
    goto out;
  /* triangles around each vertex */
  memset(A.vs, 0, (nv + 1) * sizeof *A.vs);
  for (size_t i = 0; i < 3 * nt; i++) A.vs[m->t[i] + 1]++;
  for (size_t v = 0; v < nv; v++) A.vs[v + 1] += A.vs[v];
  for (size_t i = 0; i < nt; i++)
    for (size_t e = 0; e < 3; e++) A.vt[A.vs[m->t[3 * i + e]]++] = (int)i;
  for (size_t v = nv; v > 0; v--) A.vs[v] = A.vs[v - 1];
  A.vs[0] = 0;
  {
    int *nb = malloc(3 * nt * sizeof *nb);
    if (!nb) goto out;
    for (size_t i = 0; i < nt; i++)
      for (int e = 0; e < 3; e++) nb[3 * i + (size_t)e] = across_find(&A, (int)i, e);
    A.nb = nb;
  }
  /* flat regions, grown across edges from a seed's plane; then a region
     whose boundary is long once its straight runs are dropped is grown
     again in patches of at most MERGE_PATCH triangles (a polygon of many
     boundary vertices and none inside triangulates into triangles across
     it, long and thin, whose boxes meet many others: the
     self-intersection check's cost). A flat face cut by the octree has
     hundreds of boundary edges, most of them on straight runs between
     two faces: counted before the runs were dropped, the top of a plate
     with a 50-sided hole went in some 125 patches. */
  for (size_t i = 0; i < nt; i++) C.reg[i] = -1;
  {
    SeedKey *sk = malloc(nt * sizeof *sk);
    C.seed = malloc(nt * sizeof *C.seed);
    if (sk && C.seed) {
      for (size_t i = 0; i < nt; i++) {
        sk[i].i = (int)i;
        sk[i].a = (float)tri_area2(m, (int)i);
      }
      qsort(sk, nt, sizeof *sk, seed_cmp);
      for (size_t i = 0; i < nt; i++) C.seed[i] = sk[i].i;
    } else { /* in index order */
      free(C.seed);
      C.seed = NULL;
    }
    free(sk);
  }
  grow_regions(&C, &A, stack, NULL, 1 << 30);
  if (bound_build(&C, &A) < 0) goto out;
  straight(&C, &A, gone);
  int *old = malloc(nt * sizeof *old), *blen = calloc((size_t)C.nreg, sizeof *blen);
  if (!old || !blen) {
    free(old);
    free(blen);
    goto out;
  }
  /* per region, its boundary's vertices not gone when every triangle
     across its boundary is in a flat region too (a face of a polyhedral
     part, whose corners are all that is left); else every boundary edge
     (a region bordering curved triangles: the flat face of a rounded
     part, its boundary jagged at the cells' scale: whole, it would be
     cut into triangles across the face, whose boxes meet the columns of
     the surface-to-mesh proof all along it, 1.2x its time on Rounded
     0.1 UnitCube at 1e-4). A region with a vertex twice on its boundary
     is counted by its edges: it is not clipped. */
  unsigned char *curved = calloc((size_t)C.nreg, 1);
  if (!curved) {
    free(old);
    free(blen);
    goto out;
  }
  /* a single triangle across counts when the surface bends smoothly
     onto it (within 30 degrees: a fillet's first triangle beside a
     rounded part's flat face), not across a crease (a prism's side
     clipped by a box to one triangle: the face beside it was cut into
     patches for it, 393 triangles where 26 do) */
  for (size_t i = 0; i < nt; i++)
    for (int e = 0; e < 3; e++) {
      int j = across(&A, (int)i, e);
      if (j < 0) curved[C.reg[i]] = 1;
      else if (C.reg[j] != C.reg[i] && C.rcount[C.reg[j]] < 2 && !curved[C.reg[i]]) {
        double ni[3], nj[3];
        tri_normal(m, (int)i, ni);
        tri_normal(m, j, nj);
        if (!(ni[0] * nj[0] + ni[1] * nj[1] + ni[2] * nj[2] < 0.8660254037844386))
          curved[C.reg[i]] = 1;
      }
    }
  for (size_t k = 0; k < C.nedges; k++) {
    int r = C.edges[k].r;
    blen[r] += !gone[C.edges[k].a] || C.rbad[r] || curved[r];
  }
  int longb = 0;
  for (size_t i = 0; i < nt; i++) {
    old[i] = C.reg[i];
    if (blen[C.reg[i]] > (curved[C.reg[i]] ? MERGE_LONG : MERGE_LONG_FACE)) {
      C.reg[i] = -1;
      longb = 1;
    }
  }
  if (longb) {
    /* renumber the regions kept, then grow the others in patches */
    int *num = blen; /* reused: old region -> new number */
    int nr = 0;
    for (int r = 0; r < C.nreg; r++) num[r] = -1;
    /* in increasing order of the old numbers, so each moves down into a
       place already read */
    for (size_t i = 0; i < nt; i++)
      if (C.reg[i] >= 0 && num[C.reg[i]] < 0) num[C.reg[i]] = -2; /* kept */
    for (int r = 0; r < C.nreg; r++)
      if (num[r] == -2) {
        num[r] = nr;
        C.rcount[nr] = C.rcount[r];
        memcpy(C.rplane[nr], C.rplane[r], sizeof C.rplane[nr]);
        nr++;
      }
    for (size_t i = 0; i < nt; i++)
      if (C.reg[i] >= 0) C.reg[i] = num[C.reg[i]];
    C.nreg = nr;
    /* patches in index order, as the cells made the triangles: compact
       (seeds largest first scatter them, and a rounded part's flat face
       ends with more triangles: the bracket 4% more) */
    free(C.seed);
    C.seed = NULL;
    grow_regions(&C, &A, stack, old, MERGE_PATCH);
  }
  free(curved);
  free(old);
  free(blen);
  if (longb) { /* the boundaries and the straight runs again */
    memset(gone, 0, nv);
    if (bound_build(&C, &A) < 0) goto out;
    straight(&C, &A, gone);
  }
  size_t ne = C.nedges;
  /* each region again, by ear clipping */
  merged = calloc((size_t)C.nreg, 1);
  used = malloc(ne ? ne : 1);
  joined = malloc(ne + 1); /* per loop: a loop has three edges or more */
  int seqcap = 1024;
  seq = malloc((size_t)seqcap * sizeof *seq);
  outt = malloc(3 * (size_t)seqcap * sizeof *outt);
  P.id = malloc((size_t)seqcap * sizeof *P.id);
  P.prev = malloc((size_t)seqcap * sizeof *P.prev);
  P.next = malloc((size_t)seqcap * sizeof *P.next);
  if (!merged || !used || !joined || !seq || !outt || !P.id || !P.prev || !P.next)
    goto out;
  P.v = m->v;
  /* Passes: a region that fails with a straight vertex gone from its
     boundary gets its boundary's vertices back (its neighbour's side
     too), and the regions are done again; after 8 such passes, with no
     vertex removed. */
  for (int pass = 0;; pass++) {
  int again = 0;
  nnew = 0;
  st->regions = st->kept = 0;
  memset(merged, 0, (size_t)C.nreg);
  for (int r = 0; r < C.nreg; r++) {
    if (C.rcount[r] < 2 || C.rbad[r]) continue;
    int had_gone = 0;
    for (size_t e = C.B.rs[r]; e < C.B.rs[r + 1]; e++) had_gone |= gone[C.edges[e].a];
    int lr = region_loops(&C, r, gone, used, &L);
    if (lr == -2) goto out;
    int ok = lr == 0;
    const double *n = C.rplane[r];
    int k = fabs(n[0]) >= fabs(n[1]) && fabs(n[0]) >= fabs(n[2]) ? 0
          : fabs(n[1]) >= fabs(n[2]) ? 1 : 2;
    P.ax = n[k] > 0 ? (k + 1) % 3 : (k + 2) % 3;
    P.ay = n[k] > 0 ? (k + 2) % 3 : (k + 1) % 3;
    int outer = -1;
    if (ok) {
      /* the outside: the one loop turning counter-clockwise */
      for (int q = 0; q < L.nloops && ok; q++) {
        double a = loop_area(&P, &L, q);
        if (a > 0) ok = outer < 0, outer = q;
        else if (!(a < 0)) ok = 0;
      }
      ok = ok && outer >= 0;
    }
    int total = ok ? L.start[L.nloops] + 2 * (L.nloops - 1) : 0;
    if (ok && total > MERGE_MAX_POLY) ok = 0;
    if (ok && total > seqcap) {
      seqcap = total;
      int *a1 = realloc(seq, (size_t)seqcap * sizeof *seq);
      if (a1) seq = a1;
      int *a2 = realloc(outt, 3 * (size_t)seqcap * sizeof *outt);
      if (a2) outt = a2;
      int *a3 = realloc(P.id, (size_t)seqcap * sizeof *P.id);
      if (a3) P.id = a3;
      int *a4 = realloc(P.prev, (size_t)seqcap * sizeof *P.prev);
      if (a4) P.prev = a4;
      int *a5 = realloc(P.next, (size_t)seqcap * sizeof *P.next);
      if (a5) P.next = a5;
      if (!a1 || !a2 || !a3 || !a4 || !a5) goto out;
    }
    int np = ok ? join_holes(&P, &L, outer, seq, seqcap, joined) : -1;
    if (np >= 3) {
      memcpy(P.id, seq, (size_t)np * sizeof *seq);
      P.n = np;
      /* taken when it has fewer triangles, or must be (a straight
         vertex gone from its boundary) */
      if (clip(&P, outt) == 0 && (had_gone || np - 2 < C.rcount[r])) {
        flip_region(&P, outt, np - 2);
        if (grow_ints(&newt, &newcap, 3 * (nnew + (size_t)np - 2)) < 0 ||
            grow_ints(&newr, &newrcap, nnew + (size_t)np - 2) < 0)
          goto out;
        memcpy(newt + 3 * nnew, outt, 3 * (size_t)(np - 2) * sizeof *outt);
        for (int q = 0; q < np - 2; q++) newr[nnew + (size_t)q] = r;
        nnew += (size_t)np - 2;
        merged[r] = 1;
        st->regions++;
        continue;
      }
    }
    if (had_gone) { /* its neighbour lost the vertex too: both keep it */
      for (size_t e = C.B.rs[r]; e < C.B.rs[r + 1]; e++) gone[C.edges[e].a] = 0;
      again = 1;
      continue;
    }
    st->kept += np < 3 || np - 2 < C.rcount[r]; /* else: no gain, not a failure */
  }
  if (!again) {
    int de = dup_edges(&C, merged, newt, newr, nnew, gone);
    if (de < 0) goto out;
    again = de;
  }
  if (!again) break;
  if (pass == 7) memset(gone, 0, nv); /* 8 passes with removals, then none */
  }
  if (!st->regions) { /* nothing merged: m as it was */
    rc = 0;
    goto out;
  }
  /* the mesh again: the triangles of regions not merged, then the new */
  size_t keep = 0;
  for (size_t i = 0; i < nt; i++) keep += !merged[C.reg[i]];
  size_t tot = keep + nnew;
  int *t2 = malloc(3 * (tot ? tot : 1) * sizeof *t2);
  remap = malloc((nv ? nv : 1) * sizeof *remap);
  vused = calloc(nv ? nv : 1, 1);
  if (!t2 || !remap || !vused) {
    free(t2);
    goto out;
  }
  size_t w = 0;
  for (size_t i = 0; i < nt; i++)
    if (!merged[C.reg[i]]) {
      memcpy(t2 + 3 * w, m->t + 3 * i, 3 * sizeof *t2);
      w++;
    }
  if (nnew) memcpy(t2 + 3 * w, newt, 3 * nnew * sizeof *t2);
  for (size_t i = 0; i < 3 * tot; i++) vused[t2[i]] = 1;
  size_t nv2 = 0;
  for (size_t v = 0; v < nv; v++) {
    remap[v] = vused[v] ? (int)nv2 : -1;
    if (vused[v]) {
      memmove(m->v + 3 * nv2, m->v + 3 * v, 3 * sizeof *m->v);
      if (m->rgb) memmove(m->rgb + 3 * nv2, m->rgb + 3 * v, 3 * sizeof *m->rgb);
      nv2++;
    }
  }
  for (size_t i = 0; i < 3 * tot; i++) t2[i] = remap[t2[i]];
  if (from) { /* each triangle's origin: kept, or new of region r */
    int *f = malloc((tot ? tot : 1) * sizeof *f);
    if (!f) {
      free(t2);
      goto out;
    }
    size_t q = 0;
    for (size_t i = 0; i < nt; i++)
      if (!merged[C.reg[i]]) f[q++] = (int)i;
    for (size_t j = 0; j < nnew; j++) f[q++] = -1 - newr[j];
    *from = f;
    /* and the region of each triangle merged, after them */
    int *g = realloc(f, (tot + nt) * sizeof *f);
    if (!g) {
      free(f);
      *from = NULL;
      free(t2);
      goto out;
    }
    for (size_t i = 0; i < nt; i++) g[tot + i] = merged[C.reg[i]] ? C.reg[i] : -1;
    *from = g;
  }
  free(m->t);
  m->t = t2;
  m->nt = tot;
  m->nv = nv2;
  if (nv2) {
    double *v2 = realloc(m->v, 3 * nv2 * sizeof *m->v);
    if (v2) m->v = v2;
  }
  st->after = tot;
  st->moved = st->regions ? 2 * sqrt(3.0) * delta + delta : 0;
  rc = 0;
out:
  free(A.vs);
  free(A.vt);
  free(A.nb);
  free(C.reg);
  free(C.rcount);
  free(C.rplane);
  free(C.rbad);
  free(C.seed);
  free(C.edges);
  free(C.B.rs);
  free(stack);
  free(gone);
  free(merged);
  free(used);
  free(joined);
  free(newt);
  free(newr);
  free(seq);
  free(outt);
  free(remap);
  free(vused);
  free(L.ids);
  free(L.start);
  free(P.id);
  free(P.prev);
  free(P.next);
  return rc;
}

int mesh_merge_flat_frozen(Mesh *m, double delta, const unsigned char *frozen,
                           int **from, MeshMerge *st) {
  memset(st, 0, sizeof *st);
  st->before = st->after = m->nt;
  if (from) *from = NULL;
  if (!(delta > 0) || m->nt < 2 || m->nt > (size_t)INT32_MAX / 3) return 0;
  int rc = mesh_merge_run(m, delta, frozen, from, st);
  mesh_check_release();
  return rc;
}

int mesh_merge_flat(Mesh *m, double delta, MeshMerge *st) {
  return mesh_merge_flat_frozen(m, delta, NULL, NULL, st);
}
