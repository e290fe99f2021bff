/* soft.c: soft objects -- the field of eq. (1), its gradient, and all ray
 * crossings by the interval method of Wyvill and Trotman, with a BVH over
 * the key bounds ("spatial sorting") walked front to back. */
#include "core/soft.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "core/bvh.h"
#include "core/heap.h"
#include "core/interval.h"
#include "core/vec.h"

/* eq. (1) as a cubic in s = r^2/R^2: C = 1 + A1 s + A2 s^2 + A3 s^3. */
#define A1 (-22.0 / 9.0)
#define A2 (17.0 / 9.0)
#define A3 (-4.0 / 9.0)
/* Keys a leaf of the key BVH holds at most: at 16 (median splits leave
 * about 10 a leaf at soft-cloud's sizes) a ray pops fewer nodes than at 4
 * or 8 for more key tests, which read keys in a row; the walk is bound by
 * its dependent loads more than by instructions (bench/NOTES.md,
 * 2026-11-26: CPU paired, 10^4 keys: 8 0.885 of 4, 16 0.964 of 8, 32
 * 1.014 of 16, 64 1.115). */
#define LEAF_MAX 16

/* A key normalised to s(x) = (x-x0)' A (x-x0) + k, A already divided by
 * R^2 (for a sphere A = I/R^2, k = 0); the key acts where s < 1. */
typedef struct {
  double x0[3];
  double a[6];     /* A: xx yy zz xy xz yz */
  double k;
  double w;
  double cmax;     /* C(k): the key's largest field value */
  double lo[3], hi[3];  /* bounding box of s < 1 (empty: lo > hi) */
  int sphere;      /* A = a[0] I */
  int empty;       /* acts nowhere */
} nkey;

struct soft_obj {
  nkey *keys;       /* in BVH leaf order */
  size_t nkeys;
  bvh tree;         /* over the keys' bounds, leaves index keys directly */
  double magic;
  double lo[3], hi[3];
};

/* A BVH node met by the ray at t, and a key met from te to tx. */
typedef struct { double t; int i; } node_ent;
typedef struct { double te, tx; int i; } key_event;
HEAP_DEFINE(nheap, node_ent, t)    /* BVH nodes by entry */
HEAP_DEFINE(kheap, key_event, te)  /* discovered keys by entry */

struct soft_scratch {
  size_t cap;        /* keys */
  node_ent *nheap;   /* BVH nodes by entry, 2 cap */
  key_event *kheap;  /* discovered keys by entry, cap */
  key_event *act;    /* active keys, cap */
  double *sq;        /* s(v) coefficients of the active keys, 3 cap */
  int plain;         /* soft_scratch_plain: no quick miss in hit_key */
};

/* eq. (1) in the factored form C(s) = (1 - s)^2 (1 - 4s/9): the same
 * polynomial, but with full relative accuracy near the edge of the key's
 * bound (s -> 1), where the expanded form's cancellation leaves only an
 * absolute eps. */
static double cfield(double s) {
  if (s >= 1) return 0;
  double u = 1 - s;
  return u * u * (1 - s * (4.0 / 9.0));
}

/* dC/ds */
static double cslope(double s) {
  return s >= 1 ? 0 : A1 + s * (2 * A2 + s * 3 * A3);
}

/* ---- building -------------------------------------------------------- */

const char *soft_strerror(int err) {
  switch (err) {
  case SOFT_OK: return "no error";
  case SOFT_ERR_RADIUS: return "radius of influence must be finite and > 0";
  case SOFT_ERR_NONFINITE: return "key has a non-finite centre, matrix entry or weight";
  case SOFT_ERR_KIND: return "unknown key kind";
  case SOFT_ERR_UNBOUNDED: return "quadric key is unbounded (its 3x3 block is not positive definite)";
  case SOFT_ERR_MAGIC: return "magic must be finite and > 0";
  case SOFT_ERR_NOMEM: return "out of memory";
  }
  return "unknown error";
}

/* Normalise one key; returns an error code. */
static int make_key(const soft_key *in, nkey *k) {
  memset(k, 0, sizeof *k);
  if (!(in->R > 0) || !isfinite(in->R)) return SOFT_ERR_RADIUS;
  if (!isfinite(in->w)) return SOFT_ERR_NONFINITE;
  double r2 = in->R * in->R;
  k->w = in->w;
  if (in->kind == SOFT_SPHERE) {
    for (int i = 0; i < 3; i++) {
      if (!isfinite(in->c[i])) return SOFT_ERR_NONFINITE;
      k->x0[i] = in->c[i];
      k->lo[i] = in->c[i] - in->R;
      k->hi[i] = in->c[i] + in->R;
    }
    k->a[0] = k->a[1] = k->a[2] = 1 / r2;
    k->sphere = 1;
    k->cmax = 1;
    return SOFT_OK;
  }
  if (in->kind != SOFT_QUADRIC) return SOFT_ERR_KIND;
  double m[4][4];
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      if (!isfinite(in->m[i][j])) return SOFT_ERR_NONFINITE;
      m[i][j] = 0.5 * (in->m[i][j] + in->m[j][i]);
    }
  /* Sylvester: leading minors of the 3x3 block positive. */
  double d1 = m[0][0], d2 = m[0][0] * m[1][1] - m[0][1] * m[0][1];
  double c00 = m[1][1] * m[2][2] - m[1][2] * m[1][2];
  double c01 = m[0][2] * m[1][2] - m[0][1] * m[2][2];
  double c02 = m[0][1] * m[1][2] - m[0][2] * m[1][1];
  double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
  if (!(d1 > 0 && d2 > 0 && det > 0)) return SOFT_ERR_UNBOUNDED;
  double inv[3][3];  /* A^-1 by the adjugate */
  inv[0][0] = c00 / det;
  inv[0][1] = inv[1][0] = c01 / det;
  inv[0][2] = inv[2][0] = c02 / det;
  inv[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[0][2]) / det;
  inv[1][2] = inv[2][1] = (m[0][1] * m[0][2] - m[0][0] * m[1][2]) / det;
  inv[2][2] = d2 / det;
  /* centre x0 = -A^-1 b, k = m33 + b.x0 */
  double kk = m[3][3];
  for (int i = 0; i < 3; i++) {
    k->x0[i] = -(inv[i][0] * m[0][3] + inv[i][1] * m[1][3] + inv[i][2] * m[2][3]);
    kk += m[i][3] * k->x0[i];
  }
  k->a[0] = m[0][0] / r2; k->a[1] = m[1][1] / r2; k->a[2] = m[2][2] / r2;
  k->a[3] = m[0][1] / r2; k->a[4] = m[0][2] / r2; k->a[5] = m[1][2] / r2;
  k->k = kk / r2;
  k->cmax = k->k < 1 ? cfield(k->k) : 0;
  if (!isfinite(k->k) || !(k->k < 1)) {  /* acts nowhere */
    k->empty = 1;
    for (int i = 0; i < 3; i++) { k->lo[i] = INFINITY; k->hi[i] = -INFINITY; }
    return isfinite(k->k) || k->k > 0 ? SOFT_OK : SOFT_ERR_NONFINITE;
  }
  /* Ellipsoid (x-x0)'(A/R^2)(x-x0) < 1 - k: half extent on axis i is
   * sqrt((1 - k) R^2 (A^-1)_ii). Padded a little against rounding. */
  for (int i = 0; i < 3; i++) {
    double e = sqrt((1 - k->k) * r2 * inv[i][i]) * (1 + 1e-12);
    if (!isfinite(e)) return SOFT_ERR_UNBOUNDED;
    k->lo[i] = k->x0[i] - e;
    k->hi[i] = k->x0[i] + e;
  }
  return SOFT_OK;
}

/* Keys given one at a time, normalised as they come (soft.h). */
struct soft_builder {
  nkey *all;        /* the keys that act somewhere, normalised */
  size_t live, cap;
  size_t n;         /* keys added */
  int err;          /* the first key's error, or SOFT_OK */
  size_t bad;       /* that key's index */
};

soft_builder *soft_builder_new(void) {
  soft_builder *b = calloc(1, sizeof *b);
  if (!b) return NULL;
  b->cap = 64;
  b->all = malloc(b->cap * sizeof *b->all);
  if (!b->all) { free(b); return NULL; }
  return b;
}

void soft_builder_free(void *b) {
  if (!b) return;
  free(((soft_builder *)b)->all);
  free(b);
}

int soft_builder_add(soft_builder *b, const soft_key *key) {
  if (b->err) { b->n++; return SOFT_OK; }  /* the build fails anyway */
  if (b->n >= (size_t)(1 << 28)) return SOFT_ERR_NOMEM;
  if (b->live == b->cap) {
    nkey *a = realloc(b->all, 2 * b->cap * sizeof *a);
    if (!a) return SOFT_ERR_NOMEM;
    b->all = a;
    b->cap *= 2;
  }
  nkey *k = &b->all[b->live];
  int err = make_key(key, k);
  if (err) {
    b->err = err;
    b->bad = b->n;
  } else if (!k->empty && k->w != 0) {
    b->live++;  /* others act nowhere */
  }
  b->n++;
  return SOFT_OK;
}

/* a[j] = a[idx[j]] for j < n, idx a permutation, in place: each cycle of
 * idx is walked once, with one key held aside, and idx[j] = j marks slot
 * j filled; idx ends as the identity, true of the keys now in leaf order.
 * The key moved next is fetched one move ahead (a cache miss each: the
 * keys come in the user's order, the leaves in space's). */
static void gather(nkey *a, int *idx, size_t n) {
  for (size_t s = 0; s < n; s++) {
    if ((size_t)idx[s] == s) continue;
    nkey held = a[s];
    size_t j = s;
    for (;;) {
      size_t k = (size_t)idx[j];
      idx[j] = (int)j;
      if (k == s) { a[j] = held; break; }
#if defined(__GNUC__)
      const char *next = (const char *)&a[idx[k]];
      __builtin_prefetch(next);
      __builtin_prefetch(next + 64);
      __builtin_prefetch(next + 128);
      __builtin_prefetch(next + sizeof *a - 1);
#endif
      a[j] = a[k];
      j = k;
    }
  }
}

int soft_builder_finish(soft_builder *b, double magic, soft_obj **out,
                        size_t *bad_key) {
  *out = NULL;
  *bad_key = b->n;
  int err = SOFT_OK;
  if (!(magic > 0) || !isfinite(magic)) {
    err = SOFT_ERR_MAGIC;  /* before any key's, as soft_build checks */
  } else if (b->err) {
    err = b->err;
    *bad_key = b->bad;
  }
  soft_obj *o = err ? NULL : calloc(1, sizeof *o);
  if (!err && !o) err = SOFT_ERR_NOMEM;
  if (err) { soft_builder_free(b); return err; }
  nkey *all = b->all;
  size_t live = b->live;
  free(b);
  o->magic = magic;
  o->nkeys = live;
  o->keys = all;
  /* The BVH over the keys' bounds, split at the median of their centres,
   * read from the keys themselves; the keys (152 bytes each) then move
   * once into its leaf order, in place. */
  bvh_items items = {all->lo, all->hi, all->x0, sizeof *all};
  if (bvh_build_view(&o->tree, items, (int)live, LEAF_MAX, BVH_SELECT) !=
      BVH_OK) {
    free(all); free(o);
    return SOFT_ERR_NOMEM;
  }
  gather(all, o->tree.idx, live);
  for (int i = 0; i < 3; i++) { o->lo[i] = INFINITY; o->hi[i] = -INFINITY; }
  for (size_t j = 0; j < live; j++)
    if (all[j].w > 0)
      for (int i = 0; i < 3; i++) {
        o->lo[i] = fmin(o->lo[i], all[j].lo[i]);
        o->hi[i] = fmax(o->hi[i], all[j].hi[i]);
      }
  *out = o;
  return SOFT_OK;
}

int soft_build(const soft_key *keys, size_t n, double magic, soft_obj **out,
               size_t *bad_key) {
  *out = NULL;
  *bad_key = n;
  if (!(magic > 0) || !isfinite(magic)) return SOFT_ERR_MAGIC;
  if (n > (size_t)(1 << 28)) return SOFT_ERR_NOMEM;
  soft_builder *b = soft_builder_new();
  if (!b) return SOFT_ERR_NOMEM;
  for (size_t i = 0; i < n; i++)
    if (soft_builder_add(b, &keys[i])) {
      soft_builder_free(b);
      return SOFT_ERR_NOMEM;
    }
  return soft_builder_finish(b, magic, out, bad_key);
}

void soft_free(soft_obj *obj) {
  if (!obj) return;
  free(obj->keys);
  bvh_free(&obj->tree);
  free(obj);
}

size_t soft_nkeys(const soft_obj *obj) { return obj->nkeys; }
double soft_magic(const soft_obj *obj) { return obj->magic; }

int soft_bounds(const soft_obj *obj, double lo[3], double hi[3]) {
  for (int i = 0; i < 3; i++) { lo[i] = obj->lo[i]; hi[i] = obj->hi[i]; }
  return obj->lo[0] <= obj->hi[0];
}

/* Positive keys whose bounds overlap key j's (j among them), through the
 * BVH; counting stops past cap. */
static size_t overlaps(const soft_obj *o, const nkey *kj, size_t cap) {
  size_t n = 0;
  int stack[BVH_STACK], sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const bvh_node *nd = &o->tree.nodes[stack[--sp]];
    int meets = 1;
    for (int i = 0; i < 3; i++)
      if (nd->hi[i] < kj->lo[i] || nd->lo[i] > kj->hi[i]) meets = 0;
    if (!meets) continue;
    if (nd->count == 0) {
      stack[sp++] = nd->first;
      stack[sp++] = nd->first + 1;
      continue;
    }
    for (int j = nd->first; j < nd->first + nd->count; j++) {
      const nkey *k = &o->keys[j];
      if (!(k->w > 0)) continue;
      int over = 1;
      for (int i = 0; i < 3; i++)
        if (k->hi[i] < kj->lo[i] || k->lo[i] > kj->hi[i]) over = 0;
      n += (size_t)over;
      if (n > cap) return n;
    }
  }
  return n;
}

/* Past this many overlapping keys a key's level magic / n is so low that
 * its surface box is nearly its whole bound: the bound is used. */
#define OVERLAP_CAP 32
/* Past this many keys soft_surface_bounds gives soft_bounds' box (the
 * counting would cost more than the framing gains: about 7,000
 * instructions a key, 0.2 s for 100,000 keys). */
#define SURFACE_BOUNDS_MAX_KEYS 20000

/* The s at which C(s) = level, for 0 < level <= C(k0), k0 <= s <= 1:
 * bisection on the decreasing C, the upper end of the bracket (so that
 * C(s) <= level: conservative). */
static double cinverse(double level, double k0) {
  double lo = k0 > 0 ? k0 : 0, hi = 1;
  for (int it = 0; it < 200 && hi - lo > 1e-15; it++) {
    double mid = 0.5 * (lo + hi);
    if (cfield(mid) >= level) lo = mid;
    else hi = mid;
  }
  return hi;
}

int soft_surface_bounds(const soft_obj *o, double lo[3], double hi[3]) {
  if (o->nkeys > SURFACE_BOUNDS_MAX_KEYS) return soft_bounds(o, lo, hi);
  for (int i = 0; i < 3; i++) { lo[i] = INFINITY; hi[i] = -INFINITY; }
  for (size_t j = 0; j < o->nkeys; j++) {
    const nkey *k = &o->keys[j];
    if (!(k->w > 0)) continue;
    size_t n = overlaps(o, k, OVERLAP_CAP);
    if (n < 1) n = 1;
    double f = 1;
    if (n <= OVERLAP_CAP) {
      double level = o->magic / ((double)n * k->w);
      if (level > k->cmax) continue; /* never the largest part of magic */
      double sstar = cinverse(level, k->k);
      f = sqrt((sstar - k->k) / (1 - k->k)) * (1 + 1e-9);
      if (!(f <= 1)) f = 1;
    }
    for (int i = 0; i < 3; i++) {
      double e = (k->hi[i] - k->lo[i]) * 0.5 * f;
      lo[i] = fmin(lo[i], k->x0[i] - e);
      hi[i] = fmax(hi[i], k->x0[i] + e);
    }
  }
  return lo[0] <= hi[0];
}

/* ---- the field's range over a box ------------------------------------ */

/* Squared distances from the origin to the nearest and farthest points of
 * the box [lo, hi]. */
static void box_dist2(const double lo[3], const double hi[3], double *dmin2,
                      double *dmax2) {
  double a = 0, b = 0;
  for (int i = 0; i < 3; i++) {
    double n = lo[i] > 0 ? lo[i] : (hi[i] < 0 ? -hi[i] : 0);
    double f = fabs(lo[i]) > fabs(hi[i]) ? fabs(lo[i]) : fabs(hi[i]);
    a += n * n;
    b += f * f;
  }
  *dmin2 = a;
  *dmax2 = b;
}

/* The range [*smin, *smax] of key k's s over the box whose offsets from
 * its centre are [ol, oh], widened for rounding: |p|^2 times A's
 * eigenvalue bounds (Gershgorin's discs for a quadric), and for a quadric
 * also the centred form s(c + e) = s(c) + 2 (A c) . e + e'Ae with
 * 0 <= e'Ae <= lmax |e|^2, which is tight for a small box far from the
 * centre (where the eigenvalue spread would give a wide range). */
static void key_s_range(const nkey *k, const double ol[3], const double oh[3],
                        double *smin, double *smax) {
  double dmin2, dmax2, lmin, lmax;
  box_dist2(ol, oh, &dmin2, &dmax2);
  if (k->sphere) {
    lmin = lmax = k->a[0];
  } else { /* Gershgorin's discs bound A's eigenvalues */
    double r0 = fabs(k->a[3]) + fabs(k->a[4]);
    double r1 = fabs(k->a[3]) + fabs(k->a[5]);
    double r2 = fabs(k->a[4]) + fabs(k->a[5]);
    lmin = fmin(k->a[0] - r0, fmin(k->a[1] - r1, k->a[2] - r2));
    lmax = fmax(k->a[0] + r0, fmax(k->a[1] + r1, k->a[2] + r2));
    if (lmin < 0) lmin = 0;
  }
  double l = lmin * dmin2 + k->k, h = lmax * dmax2 + k->k;
  if (!k->sphere) {
    double c[3], e[3], ac[3], e2 = 0, lin = 0;
    for (int j = 0; j < 3; j++) {
      c[j] = 0.5 * (ol[j] + oh[j]);
      e[j] = 0.5 * (oh[j] - ol[j]);
      e2 += e[j] * e[j];
    }
    ac[0] = k->a[0] * c[0] + k->a[3] * c[1] + k->a[4] * c[2];
    ac[1] = k->a[3] * c[0] + k->a[1] * c[1] + k->a[5] * c[2];
    ac[2] = k->a[4] * c[0] + k->a[5] * c[1] + k->a[2] * c[2];
    for (int j = 0; j < 3; j++) lin += 2 * fabs(ac[j]) * e[j];
    double sc = vec3_dot(c, ac) + k->k;
    /* rounding of the centred form: a relative 1e-12 of its terms */
    double err = 1e-12 * (fabs(sc) + lin + lmax * e2 + fabs(k->k) + 1);
    l = fmax(l, sc - lin - err);
    h = fmin(h, sc + lin + lmax * e2 + err);
  }
  *smin = l - 1e-12 * (fabs(l) + 1);
  *smax = h + 1e-12 * (fabs(h) + 1);
}

/* The keys whose bounds may meet the box [lo, hi], in index order: a
 * left-first walk of the key BVH that skips the subtrees whose box misses
 * it (leaves hold consecutive keys, so the walk meets them in increasing
 * order, as a scan of all keys would). The caller still tests each key:
 * this only leaves out keys a scan would skip, so sums over the keys come
 * out bit for bit as a scan's, in O(log n + met) instead of O(n) a box,
 * which the mesher asks for every cell. */
typedef struct {
  const soft_obj *o;
  const double *lo, *hi;
  int st[BVH_STACK], sp;
  int j, jend;
} key_walk;

static void key_walk_start(key_walk *w, const soft_obj *o, const double lo[3],
                           const double hi[3]) {
  w->o = o;
  w->lo = lo;
  w->hi = hi;
  w->sp = 0;
  w->j = w->jend = 0;
  if (o->nkeys > 0) w->st[w->sp++] = 0;
}

static const nkey *key_walk_next(key_walk *w) {
  for (;;) {
    if (w->j < w->jend) return &w->o->keys[w->j++];
    if (!w->sp) return NULL;
    const bvh_node *nd = &w->o->tree.nodes[w->st[--w->sp]];
    int apart = 0;
    for (int a = 0; a < 3; a++)
      if (w->hi[a] < nd->lo[a] || w->lo[a] > nd->hi[a]) apart = 1;
    if (apart) continue;
    if (nd->count) {
      w->j = nd->first;
      w->jend = nd->first + nd->count;
    } else {
      w->st[w->sp++] = nd->first + 1;  /* the right child after the left */
      w->st[w->sp++] = nd->first;
    }
  }
}

/* The next key of the walk whose bounds meet the box, with the box's
 * corners relative to the key's centre (ol, oh) and the range [*smin,
 * *smax] of its s over the box (keys apart from the box have s >= 1
 * there and add nothing); NULL at the end. */
static const nkey *key_walk_range(key_walk *w, double ol[3], double oh[3],
                                  double *smin, double *smax) {
  for (const nkey *k; (k = key_walk_next(w));) {
    if (k->empty) continue;
    int apart = 0;
    for (int j = 0; j < 3; j++)
      if (w->hi[j] < k->lo[j] || w->lo[j] > k->hi[j]) apart = 1;
    if (apart) continue;
    for (int j = 0; j < 3; j++) {
      ol[j] = w->lo[j] - k->x0[j];
      oh[j] = w->hi[j] - k->x0[j];
    }
    key_s_range(k, ol, oh, smin, smax);
    return k;
  }
  return NULL;
}

int soft_field_box(const soft_obj *obj, const double lo[3], const double hi[3],
                   double *flo, double *fhi) {
  double fl = 0, fh = 0, mag = 0;
  key_walk kw;
  key_walk_start(&kw, obj, lo, hi);
  double ol[3], oh[3], smin, smax;
  for (const nkey *k; (k = key_walk_range(&kw, ol, oh, &smin, &smax));) {
    double cl = cfield(smax), ch = cfield(smin); /* C falls for s < 1 */
    if (ch > k->cmax) ch = k->cmax;
    if (k->w >= 0) {
      fl += k->w * cl;
      fh += k->w * ch;
    } else {
      fl += k->w * ch;
      fh += k->w * cl;
    }
    mag += fabs(k->w) * k->cmax;
  }
  *flo = fl - 1e-12 * mag;
  *fhi = fh + 1e-12 * mag;
  return 0;
}

int soft_grad_box(const soft_obj *obj, const double lo[3], const double hi[3],
                  double gl[3], double gh[3]) {
  double mag = 0;
  for (int j = 0; j < 3; j++) gl[j] = gh[j] = 0;
  key_walk kw;
  key_walk_start(&kw, obj, lo, hi);
  double ol[3], oh[3], smin, smax;
  for (const nkey *k; (k = key_walk_range(&kw, ol, oh, &smin, &smax));) {
    if (smin >= 1) continue;
    /* dC/ds rises on s < 17/12 (its vertex) and is 0 at s = 1 */
    double cl = cslope(smin), ch = smax >= 1 ? 0 : cslope(smax);
    iv_mul(2 * k->w, 2 * k->w, cl, ch, &cl, &ch);
    /* grad s = 2 A p: each row of A p is linear in p, exact over the box */
    static const int row[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    for (int j = 0; j < 3; j++) {
      double al = 0, ah = 0;
      for (int q = 0; q < 3; q++) {
        double a = k->sphere ? (q == j ? k->a[0] : 0) : k->a[row[j][q]];
        al += a * (a > 0 ? ol[q] : oh[q]);
        ah += a * (a > 0 ? oh[q] : ol[q]);
      }
      double l, h;
      iv_mul(cl, ch, al, ah, &l, &h);
      gl[j] += l;
      gh[j] += h;
      mag += fmax(fabs(l), fabs(h));
    }
  }
  for (int j = 0; j < 3; j++) {
    gl[j] -= 1e-12 * mag + 1e-300;
    gh[j] += 1e-12 * mag + 1e-300;
  }
  return 0;
}

/* ---- field and gradient ---------------------------------------------- */

/* ap = A p for the key's matrix A. */
static inline void apply_a(const nkey *k, const double p[3], double ap[3]) {
  if (k->sphere) {
    for (int i = 0; i < 3; i++) ap[i] = k->a[0] * p[i];
  } else {
    ap[0] = k->a[0] * p[0] + k->a[3] * p[1] + k->a[4] * p[2];
    ap[1] = k->a[3] * p[0] + k->a[1] * p[1] + k->a[5] * p[2];
    ap[2] = k->a[4] * p[0] + k->a[5] * p[1] + k->a[2] * p[2];
  }
}

/* s of eq. (1) (r^2/R^2, or u'Mu/R^2 for a quadric, eq. 5) for key k at the
 * point whose offset from the centre is p, with A p into ap. */
static inline double key_s(const nkey *k, const double p[3], double ap[3]) {
  apply_a(k, p, ap);
  return vec3_dot(p, ap) + k->k;
}

/* eq. (1), summed (the paper's "sum of the effects of the individual keys"):
 * keys found through the BVH, depth first. */
static double field_at(const soft_obj *o, const double x[3], double g[3]) {
  double f = 0;
  if (g) g[0] = g[1] = g[2] = 0;
  if (o->nkeys == 0) return 0;
  int stack[BVH_STACK], sp = 0;  /* enough for any tree (bvh.h) */
  /* only nodes holding x are stacked: those the walk descends into, in
     the same order (the right child first), so the sum's order is kept */
  if (bvh_node_has(&o->tree.nodes[0], x)) stack[sp++] = 0;
  while (sp > 0) {
    const bvh_node *nd = &o->tree.nodes[stack[--sp]];
    if (nd->count == 0) {
      if (bvh_node_has(&o->tree.nodes[nd->first], x)) stack[sp++] = nd->first;
      if (bvh_node_has(&o->tree.nodes[nd->first + 1], x)) stack[sp++] = nd->first + 1;
      continue;
    }
    for (int j = nd->first; j < nd->first + nd->count; j++) {
      const nkey *k = &o->keys[j];
      double p[3] = {x[0] - k->x0[0], x[1] - k->x0[1], x[2] - k->x0[2]}, ap[3];
      double s = key_s(k, p, ap);
      if (s >= 1) continue;
      f += k->w * cfield(s);
      if (g) {  /* grad s = 2 A p */
        double dc = 2 * k->w * cslope(s);
        for (int i = 0; i < 3; i++) g[i] += dc * ap[i];
      }
    }
  }
  return f;
}

double soft_field(const soft_obj *obj, const double p[3]) {
  return field_at(obj, p, NULL);
}

double soft_field_grad(const soft_obj *obj, const double p[3], double g[3]) {
  return field_at(obj, p, g);
}

/* ---- scratch ----------------------------------------------------------- */

soft_scratch *soft_scratch_new(size_t max_keys) {
  soft_scratch *s = calloc(1, sizeof *s);
  if (!s) return NULL;
  size_t cap = max_keys ? max_keys : 1;
  s->cap = cap;
  s->nheap = malloc((2 * cap + 2) * sizeof *s->nheap);
  s->kheap = malloc(cap * sizeof *s->kheap);
  s->act = malloc(cap * sizeof *s->act);
  s->sq = malloc(3 * cap * sizeof *s->sq);
  if (!s->nheap || !s->kheap || !s->act || !s->sq) { soft_scratch_free(s); return NULL; }
  return s;
}

void soft_scratch_plain(soft_scratch *s, int plain) { s->plain = plain != 0; }

void soft_scratch_free(soft_scratch *s) {
  if (!s) return;
  free(s->nheap);
  free(s->kheap);
  free(s->act);
  free(s->sq);
  free(s);
}

/* ---- ray tracing --------------------------------------------------------- */

typedef struct {
  double o[3], d[3], inv[3];  /* origin, unit direction, 1/direction */
  double ta, tb;              /* the search range, in units of length */
  size_t near[3], far[3];     /* per axis: the offsets in a bvh_node of the
                                 box side the ray meets first and last */
} soft_ray;

/* The slab test of node nd; returns entry in *tn or 0 if the box is
 * missed in [ta, tb]. Per axis the nearer side's t, (lo - o) / d where d
 * > 0, is the smaller of the two whatever the rounding (it is monotone),
 * so taking the sides by the direction's signs gives what ordering the
 * two t's would, bit for bit, without the compare and swap. */
static inline int hit_box(const soft_ray *r, const bvh_node *nd, double *tn) {
  const char *b = (const char *)nd;
  double t0 = r->ta, t1 = r->tb;
#define SIDE(s, i) ((*(const double *)(b + r->s[i]) - r->o[i]) * r->inv[i])
  double a0 = SIDE(near, 0), c0 = SIDE(far, 0);
  double a1 = SIDE(near, 1), c1 = SIDE(far, 1);
  double a2 = SIDE(near, 2), c2 = SIDE(far, 2);
#undef SIDE
  if (a0 > t0) t0 = a0;
  if (c0 < t1) t1 = c0;
  if (a1 > t0) t0 = a1;
  if (c1 < t1) t1 = c1;
  if (a2 > t0) t0 = a2;
  if (c2 < t1) t1 = c2;
  *tn = t0;
  return t0 <= t1;
}

/* eq. (2) into the key's quadric: s(t) = a2 (t - tc)^2 + smin along the
 * ray; the key acts where s < 1. Returns 0 if the ray misses its bound. */
static int hit_key(const soft_ray *r, const nkey *k, double *te, double *tx,
                   int plain) {
  double p[3] = {r->o[0] - k->x0[0], r->o[1] - k->x0[1], r->o[2] - k->x0[2]};
  if (k->sphere && !plain) {
    /* A quick miss: s at the point of the line nearest the centre, a0
       (|p|^2 - (p.d)^2), clearly >= 1. Its rounding, and smin's below, are
       within a few eps of a0 |p|^2 (d is unit to an eps), far inside the
       margin, so only keys the test below refuses are refused here. */
    double pd = vec3_dot(p, r->d), pp = vec3_dot(p, p);
    if (k->a[0] * (pp - pd * pd) > 1 + 1e-9 * (1 + k->a[0] * pp)) return 0;
  }
  double ad[3], ap[3];
  apply_a(k, r->d, ad);
  double a2 = vec3_dot(r->d, ad), b = vec3_dot(p, ad);
  double tc = -b / a2;
  double pc[3] = {p[0] + tc * r->d[0], p[1] + tc * r->d[1], p[2] + tc * r->d[2]};
  double smin = key_s(k, pc, ap);
  if (!(smin < 1)) return 0;
  double half = sqrt((1 - smin) / a2);
  *te = tc - half;
  *tx = tc + half;
  return *tx > r->ta && *te < r->tb;
}

/* eq. (3) for each active key along the interval [tm - h, tm + h]: s(v) =
 * s0 + s1 v + s2 v^2 with t = tm + h v, built from the key's offset at the
 * midpoint, so it stays well conditioned however far the interval lies from
 * the ray origin. Also bounds the field over the interval: C falls as s
 * grows, and s is convex in v, so each key's field lies between C at the
 * largest s (an end) and C at the smallest. */
static void interval_s(const soft_obj *o, const soft_ray *r, const key_event *act,
                       int nact, double tm, double h, double *sq,
                       double *flo, double *fhi) {
  double x[3] = {r->o[0] + tm * r->d[0], r->o[1] + tm * r->d[1], r->o[2] + tm * r->d[2]};
  double lo = 0, hi = 0, wsum = 0;
  for (int j = 0; j < nact; j++) {
    const nkey *k = &o->keys[act[j].i];
    double p[3] = {x[0] - k->x0[0], x[1] - k->x0[1], x[2] - k->x0[2]}, ap[3], ad[3];
    double s0 = key_s(k, p, ap);
    apply_a(k, r->d, ad);
    double s1 = 2 * h * vec3_dot(r->d, ap), s2 = h * h * vec3_dot(r->d, ad);
    sq[3 * j] = s0; sq[3 * j + 1] = s1; sq[3 * j + 2] = s2;
    double smax = s0 + fabs(s1) + s2;
    double smin = fabs(s1) < 2 * s2 ? s0 - s1 * s1 / (4 * s2) : s0 - fabs(s1) + s2;
    double cl = cfield(smax), ch = cfield(smin), w = k->w;
    if (w > 0) { lo += w * cl; hi += w * ch; }
    else { lo += w * ch; hi += w * cl; }
    wsum += fabs(w);
  }
  *flo = lo - 1e-12 * wsum;  /* margin for the rounding of s and C */
  *fhi = hi + 1e-12 * wsum;
}

/* eq. (4): the weighted sum of C(s(v)) over the active keys, minus magic,
 * as a sextic in v in [-1, 1]. */
static void interval_poly(const soft_obj *o, const key_event *act, int nact,
                          const double *sq, double *c) {
  double w0 = 0, w1[3] = {0, 0, 0}, w2[5] = {0, 0, 0, 0, 0}, w3[7] = {0};
  for (int j = 0; j < nact; j++) {
    double w = o->keys[act[j].i].w;
    double s0 = sq[3 * j], s1 = sq[3 * j + 1], s2 = sq[3 * j + 2];
    /* s^2 and s^3 of s = s0 + s1 v + s2 v^2 */
    double q0 = s0 * s0, q1 = 2 * s0 * s1, q2 = s1 * s1 + 2 * s0 * s2,
           q3 = 2 * s1 * s2, q4 = s2 * s2;
    w0 += w;
    w1[0] += w * s0; w1[1] += w * s1; w1[2] += w * s2;
    w2[0] += w * q0; w2[1] += w * q1; w2[2] += w * q2; w2[3] += w * q3; w2[4] += w * q4;
    w3[0] += w * q0 * s0;
    w3[1] += w * (q1 * s0 + q0 * s1);
    w3[2] += w * (q2 * s0 + q1 * s1 + q0 * s2);
    w3[3] += w * (q3 * s0 + q2 * s1 + q1 * s2);
    w3[4] += w * (q4 * s0 + q3 * s1 + q2 * s2);
    w3[5] += w * (q4 * s1 + q3 * s2);
    w3[6] += w * q4 * s2;
  }
  c[0] = w0 + A1 * w1[0] + A2 * w2[0] + A3 * w3[0] - o->magic;
  c[1] = A1 * w1[1] + A2 * w2[1] + A3 * w3[1];
  c[2] = A1 * w1[2] + A2 * w2[2] + A3 * w3[2];
  c[3] = A2 * w2[3] + A3 * w3[3];
  c[4] = A2 * w2[4] + A3 * w3[4];
  c[5] = A3 * w3[5];
  c[6] = A3 * w3[6];
}

/* The paper's algorithm: 1. find the intersections with the keys' bounds
 * and order them along the ray; 2. solve eq. (4) for f = magic in each
 * interval; 3. keep the solutions inside it. Bounds are discovered front to
 * back from the BVH: an interval is solved only once every node that could
 * hold a key entering before its end has been opened. The state (inside or
 * not) at each interval boundary is computed once and imposed on both
 * neighbours, so a root on a boundary is found once. */
static int roots_walk(const soft_obj *obj, const double o[3],
                      const double d[3], double t0, double t1, double *out,
                      int maxout, soft_scratch *scratch, soft_stats *stats,
                      const soft_hook *hook, int any);

int soft_roots(const soft_obj *obj, const double o[3], const double d[3],
               double t0, double t1, double *out, int maxout,
               soft_scratch *scratch, soft_stats *stats) {
  return roots_walk(obj, o, d, t0, t1, out, maxout, scratch, stats, NULL, 0);
}

int soft_roots_traced(const soft_obj *obj, const double o[3],
                      const double d[3], double t0, double t1, double *out,
                      int maxout, soft_scratch *scratch, soft_stats *stats,
                      const soft_hook *hook) {
  return roots_walk(obj, o, d, t0, t1, out, maxout, scratch, stats, hook, 0);
}

int soft_any(const soft_obj *obj, const double o[3], const double d[3],
             double t0, double t1, double *t, soft_scratch *scratch,
             soft_stats *stats) {
  double by;
  int n = roots_walk(obj, o, d, t0, t1, &by, 1, scratch, stats, NULL, 1);
  if (n > 0 && t) *t = by < t1 ? by : t1;
  return n;
}

/* The walk of soft_roots_traced; with any (maxout 1, no hook: soft_any)
 * an interval whose end states differ ends the search with a crossing
 * unsolved for (poly_crossings reports an odd number there, and with
 * maxout 1 nothing before it can cancel its first: out[] holds only
 * whether there is one). */
static int roots_walk(const soft_obj *obj, const double o[3],
                      const double d[3], double t0, double t1, double *out,
                      int maxout, soft_scratch *scratch, soft_stats *stats,
                      const soft_hook *hook, int any) {
  soft_stats dummy;
  if (!stats) { memset(&dummy, 0, sizeof dummy); stats = &dummy; }
  stats->rays++;
  double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(len > 0) || !isfinite(len)) {  /* maybe only overflowed: rescale */
    double m = fmax(fabs(d[0]), fmax(fabs(d[1]), fabs(d[2])));
    if (!(m > 0) || !isfinite(m)) return -1;
    double e[3] = {d[0] / m, d[1] / m, d[2] / m};
    len = m * sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    if (!(len > 0) || !isfinite(len)) return -1;
  }
  if (!isfinite(o[0]) || !isfinite(o[1]) || !isfinite(o[2]) || t0 != t0 || t1 != t1)
    return -1;
  /* No keys (SoftObject m []): nothing to cross, and no scratch needed. */
  if (maxout <= 0 || obj->nkeys == 0 || !(t0 < t1)) return 0;
  if (!scratch || scratch->cap < obj->nkeys) return -1;

  /* Work in units of length along the unit direction (tau = t |d|). */
  soft_ray r;
  for (int i = 0; i < 3; i++) {
    r.o[i] = o[i];
    r.d[i] = d[i] / len;
    double di = fabs(r.d[i]) < 1e-300 ? copysign(1e-300, r.d[i]) : r.d[i];
    r.inv[i] = 1 / di;
    size_t lo = offsetof(bvh_node, lo) + (size_t)i * sizeof(double);
    size_t hi = offsetof(bvh_node, hi) + (size_t)i * sizeof(double);
    r.near[i] = r.inv[i] < 0 ? hi : lo;
    r.far[i] = r.inv[i] < 0 ? lo : hi;
  }
  r.ta = t0 * len;
  r.tb = t1 * len;

  int plain = scratch->plain;
  node_ent *nheap = scratch->nheap;
  key_event *kheap = scratch->kheap, *act = scratch->act;
  int nn = 0, nk = 0, na = 0, nout = 0;
  double tn;
  const bvh_node *root = &obj->tree.nodes[0];
  if (hit_box(&r, root, &tn))
    nheap_push(nheap, &nn, (node_ent){tn, 0});

  double cur = r.ta;
  int state = -1;          /* at cur: 1 inside, 0 outside, -1 not yet known */
  double prev_h = 0;       /* half-width of the last solved interval */
  long last_from = -1;     /* interval index of the last crossing */
  long iv = 0;
  double amin = INFINITY;  /* earliest exit among the active keys */
  for (;;) {
    double tnext = r.tb;
    if (nk && kheap[0].te < tnext) tnext = kheap[0].te;
    if (amin < tnext) tnext = amin;
    /* Discover while a key may still enter before tnext; a key found
     * lowers tnext as it would the top of the key heap. */
    while (nn && nheap[0].t < tnext) {
      node_ent e = nheap_pop(nheap, &nn);
      const bvh_node *nd;
    open:
      nd = &obj->tree.nodes[e.i];
      stats->nodes++;
      if (nd->count == 0) {
        /* The nearer child met is opened at once when the heap would pop
           it next (it enters no later than the heap's top, and before
           tnext): the same nodes in the same order of entry, one push and
           pop fewer (only ties may go the other way). */
        int f = nd->first;
        const bvh_node *ch = &obj->tree.nodes[f];
        double ta_ = INFINITY, tb_ = INFINITY;
        int ha = hit_box(&r, ch, &ta_), hb = hit_box(&r, ch + 1, &tb_);
        ta_ = ta_ > cur ? ta_ : cur;  /* fmax(tn, cur), no call */
        tb_ = tb_ > cur ? tb_ : cur;
        node_ent near_ = {ta_, f}, far_ = {tb_, f + 1};
        int hn = ha, hf = hb;
        if (hb && (!ha || tb_ < ta_)) {
          near_ = far_;
          far_ = (node_ent){ta_, f};
          hn = hb;
          hf = ha;
        }
        if (hf) nheap_push(nheap, &nn, far_);
        if (hn) {
          if (near_.t < tnext && (nn == 0 || near_.t <= nheap[0].t)) {
            e = near_;
            goto open;
          }
          nheap_push(nheap, &nn, near_);
        }
      } else {
        for (int j = nd->first; j < nd->first + nd->count; j++) {
          key_event ev;
          if (!hit_key(&r, &obj->keys[j], &ev.te, &ev.tx, plain) || ev.tx <= cur)
            continue;
          stats->keys++;
          ev.te = ev.te > cur ? ev.te : cur;  /* fmax: te is not NaN */
          ev.i = j;
          kheap_push(kheap, &nk, ev);
          if (ev.te < tnext) tnext = ev.te;
        }
      }
    }
    if (!isfinite(tnext)) {  /* nothing active, nothing left to find */
      if (state == 1 && na == 0 && iv > 0 && nout < maxout) out[nout++] = cur / len;
      break;
    }

    /* The interval [cur, tnext]: the active set is fixed inside it. */
    if (tnext > cur && na > 0) {
      double tm = 0.5 * (cur + tnext), h = 0.5 * (tnext - cur), c[7];
      stats->intervals++;
      iv++;
      double flo, fhi;
      int settled = 0;  /* no crossing possible in the interval */
      interval_s(obj, &r, act, na, tm, h, scratch->sq, &flo, &fhi);
      if (state < 0 && (flo > obj->magic || fhi <= obj->magic)) state = flo > obj->magic;
      if ((fhi <= obj->magic && state == 0) || (flo > obj->magic && state == 1))
        settled = 1;  /* the field stays on one side of magic */
      if (!settled) {
        interval_poly(obj, act, na, scratch->sq, c);
        if (state < 0) state = poly_eval(c, 6, -1.0, NULL) > 0;
        double s1 = fabs(c[1]) + fabs(c[2]) + fabs(c[3]) + fabs(c[4]) + fabs(c[5]) + fabs(c[6]);
        if (fabs(c[0]) > s1 * (1 + 1e-12) + 1e-300 && (c[0] > 0) == state)
          settled = 1;  /* |p(v) - p(0)| < |p(0)| on [-1, 1] */
      }
      soft_trace_event ev;
      if (hook) {
        ev.t0 = cur / len;
        ev.t1 = tnext / len;
        ev.flo = flo;
        ev.fhi = fhi;
        ev.nkeys = na;
        ev.nroots = 0;
        ev.lsteps = ev.bsteps = 0;
        ev.decision = (fhi <= obj->magic && state == 0) ||
                              (flo > obj->magic && state == 1)
                          ? SOFT_IV_BOUND : SOFT_IV_COEFF;
      }
      if (settled) {
        stats->skipped++;
        if (hook) hook->fn(hook->ctx, &ev);
      } else {
        int sb = poly_eval(c, 6, 1.0, NULL) > 0;
        if (any && sb != state) {
          out[nout++] = tnext / len;  /* a crossing in (cur, tnext] */
          break;
        }
        double v[POLY_MAX_DEG];
        poly_stats before = stats->poly;
        int nv = poly_crossings(c, 6, -1.0, 1.0, state, sb, 0, v, &stats->poly);
        if (hook) {
          ev.lsteps = stats->poly.laguerre_steps - before.laguerre_steps;
          ev.bsteps = stats->poly.bracket_steps - before.bracket_steps;
        }
        if (hook)
          ev.decision = stats->poly.fallbacks > before.fallbacks
                            ? SOFT_IV_CASCADE
                        : stats->poly.laguerre > before.laguerre
                            ? SOFT_IV_LAGUERRE : SOFT_IV_QUICK;
        for (int j = 0; j < nv; j++) {
          double t = tm + h * v[j];
          /* A root on the boundary with the two neighbouring sextics
           * disagreeing in the last bit shows as a pair of crossings
           * straddling it: the pair cancels (the state is unchanged). */
          double tol = 1e-10 * (h + prev_h) + 8 * DBL_EPSILON * fabs(cur);
          if (j == 0 && nout > 0 && last_from == iv - 1 &&
              fabs(out[nout - 1] * len - cur) <= tol && fabs(t - cur) <= tol) {
            nout--;
            continue;
          }
          if (nout < maxout) out[nout++] = t / len;
          if (hook) ev.roots[ev.nroots++] = t / len;
          last_from = iv;
        }
        if (hook) hook->fn(hook->ctx, &ev);
        state = sb;
        prev_h = h;
        if (nout >= maxout) break;
      }
    } else if (na == 0 && tnext > cur) {
      /* no key acts on a stretch: field 0 < magic (not at an empty
         [cur, cur], where keys holding the origin are about to be
         opened). If the last interval ended "inside" (its end state is the
         sign of a sextic whose value there is rounding noise when magic
         is tiny: the field vanishes at a key's bound), the exit is at its
         end: crossings must alternate. */
      if (hook) {
        soft_trace_event ev = {cur / len, tnext / len, NAN, NAN, 0,
                               SOFT_IV_EMPTY, 0, {0}, 0, 0};
        if (state == 1 && iv > 0) ev.roots[ev.nroots++] = cur / len;
        hook->fn(hook->ctx, &ev);
      }
      if (state == 1 && iv > 0) {
        if (nout < maxout) out[nout++] = cur / len;
        last_from = iv;
        if (nout >= maxout) { state = 0; break; }
      }
      state = 0;
    }
    cur = tnext;
    if (cur >= r.tb) break;
    /* events at cur: exits, then entries */
    for (int j = 0; j < na;) {
      if (act[j].tx <= cur) act[j] = act[--na];
      else j++;
    }
    while (nk && kheap[0].te <= cur) act[na++] = kheap_pop(kheap, &nk);
    amin = INFINITY;
    for (int j = 0; j < na; j++) if (act[j].tx < amin) amin = act[j].tx;
  }
  return nout;
}
