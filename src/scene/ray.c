/* ray.c: span lists of a ray through a compiled scene. See ray.h. */
#include "scene/ray.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CHUNK_SPANS 4096
#define MAX_LEAF_ROOTS 256

struct SpanChunk {
  SpanChunk *next;
  size_t cap;          /* CHUNK_SPANS, or more for one large request */
  csg_span spans[];
};

RayCtx *ray_ctx_new(const Scene *s, double tol) {
  RayCtx *c = calloc(1, sizeof *c);
  if (!c) return NULL;
  c->tol = tol;
  c->unresolved_node = -1;
  if (s->max_keys) {
    c->soft = soft_scratch_new(s->max_keys);
    if (!c->soft) {
      free(c);
      return NULL;
    }
  }
  /* Intersections of halfspaces (children have lower indices). Without
     memory the table is simply absent: the merges do the same work. */
  int any = 0;
  c->convex = s->n > 0 ? malloc((size_t)s->n) : NULL;
  for (int i = 0; c->convex && i < s->n; i++) {
    const ScNode *n = &s->nodes[i];
    c->convex[i] = n->kind == SC_HALFSPACE ||
                   (n->kind == SC_INTER && c->convex[n->a] && c->convex[n->b]);
    any |= n->kind == SC_INTER && c->convex[i];
  }
  if (!any) {
    free(c->convex);
    c->convex = NULL;
  }
  c->conv_scene = s;
  c->conv_n = c->convex ? s->n : 0;
  return c;
}

void ray_ctx_free(RayCtx *c) {
  if (!c) return;
  for (SpanChunk *k = c->chunks, *nx; k; k = nx) {
    nx = k->next;
    free(k);
  }
  if (c->soft) soft_scratch_free(c->soft);
  free(c->frames);
  free(c->convex);
  free(c->cstack);
  free(c);
}

void ray_reset(RayCtx *c) {
  c->cur = c->chunks;
  c->used = 0;
}

/* n contiguous spans from the arena, or NULL when memory runs out. The
   chunks are kept across rays; a request larger than a chunk gets a chunk
   of its own, inserted before the next one. */
static csg_span *alloc_spans(RayCtx *c, int n) {
  if (!c->cur || c->used + (size_t)n > c->cur->cap) {
    SpanChunk *next = c->cur ? c->cur->next : c->chunks;
    if (!next || next->cap < (size_t)n) {
      size_t cap = (size_t)n > CHUNK_SPANS ? (size_t)n : CHUNK_SPANS;
      SpanChunk *k = malloc(sizeof *k + sizeof(csg_span) * cap);
      if (!k) return NULL;
      k->cap = cap;
      k->next = next;
      if (c->cur) c->cur->next = k;
      else c->chunks = k;
      next = k;
    }
    c->cur = next;
    c->used = 0;
  }
  csg_span *s = c->cur->spans + c->used;
  c->used += (size_t)n;
  return s;
}

static void set_span(csg_span *s, double t0, double t1, int id0, int id1,
                     int flip0, int flip1) {
  s->t0 = t0;
  s->t1 = t1;
  s->id0 = id0;
  s->id1 = id1;
  s->flip0 = (unsigned char)flip0;
  s->flip1 = (unsigned char)flip1;
}

static int halfspace_spans(const ScNode *n, int id, const double o[3],
                           const double d[3], double t0, double t1,
                           csg_span *out) {
  double no = n->n[0] * o[0] + n->n[1] * o[1] + n->n[2] * o[2];
  double nd = n->n[0] * d[0] + n->n[1] * d[1] + n->n[2] * d[2];
  if (nd == 0) { /* parallel: inside everywhere or nowhere */
    if (no < n->d) {
      set_span(out, t0, t1, -1, -1, 0, 0);
      return 1;
    }
    return 0;
  }
  double t = (n->d - no) / nd;
  if (nd > 0) { /* inside before t */
    if (t <= t0) return 0;
    if (t < t1) set_span(out, t0, t, -1, id, 0, 0);
    else set_span(out, t0, t1, -1, -1, 0, 0);
  } else { /* inside after t */
    if (t >= t1) return 0;
    if (t > t0) set_span(out, t, t1, id, -1, 0, 0);
    else set_span(out, t0, t1, -1, -1, 0, 0);
  }
  return 1;
}

/* Spans from ascending crossings that alternate in and out, starting
   inside or not. Touches are skipped. */
static int crossings_to_spans(const double *t, const int *kind, int nroots,
                              int inside, int id, double t0, double t1,
                              csg_span *out) {
  int n = 0;
  double start = t0;
  int sid = -1;
  for (int i = 0; i < nroots; i++) {
    int enter = kind ? kind[i] == LG_ENTER : !inside;
    if (kind && kind[i] == LG_TOUCH) continue;
    if (enter && !inside) {
      start = t[i];
      sid = id;
      inside = 1;
    } else if (!enter && inside) {
      if (t[i] > start) set_span(&out[n++], start, t[i], sid, id, 0, 0);
      inside = 0;
    }
  }
  if (inside && t1 > start) set_span(&out[n++], start, t1, sid, -1, 0, 0);
  return n;
}

/* fmax(a, b) without the call into libm (gcc and clang call it): the
   larger, or the one that is not NaN. Callers pass no -0. */
static inline double max_nn(double a, double b) {
  return isnan(b) || a > b ? a : b;
}

double ray_dist_tol(const RayCtx *c, const double o[3], const double d[3]) {
  double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  double scale = max_nn(1.0, max_nn(fabs(o[0]), max_nn(fabs(o[1]), fabs(o[2]))));
  return max_nn(c->tol, RAY_TOL_FLOOR * scale) / len;
}

static int rounded_spans(const ScNode *n, int id, const double o[3],
                         const double d[3], double t0, double t1, RayCtx *c,
                         csg_span *out) {
  lg_root roots[MAX_LEAF_ROOTS];
  long unsplit = c->stats.lg.overflows;
  const dt_tape *tape = c->tapes && c->tapes[id] ? c->tapes[id] : n->tape;
  lg_query q = {.tape = tape, .o = o, .d = d, .t0 = t0, .t1 = t1,
                .tol = ray_dist_tol(c, o, d), .out = roots,
                .maxout = MAX_LEAF_ROOTS, .stats = &c->stats.lg,
                .hook = c->hook, .mode = LG_ALL};
  int nr = lg_search_bounded(&q, n->outer, n->inner);
  if (c->stats.lg.overflows != unsplit) c->unresolved_node = id;
  if (nr < 0) return -1;
  double t[MAX_LEAF_ROOTS];
  int kind[MAX_LEAF_ROOTS];
  for (int i = 0; i < nr; i++) {
    t[i] = roots[i].t;
    kind[i] = roots[i].kind;
  }
  /* The state at t0 follows from the first real crossing when there is
     one (robust at a surface exactly at t0); else from the density
     there. */
  int i = 0;
  while (i < nr && kind[i] == LG_TOUCH) i++;
  int inside;
  if (i < nr) {
    inside = kind[i] == LG_EXIT;
  } else {
    double p[3] = {o[0] + t0 * d[0], o[1] + t0 * d[1], o[2] + t0 * d[2]};
    inside = isfinite(t0) ? dt_density(n->tape, p) > 0.5 : 0;
  }
  return crossings_to_spans(t, kind, nr, inside, id, t0, t1, out);
}

static int soft_spans(const ScNode *n, int id, const double o[3],
                      const double d[3], double t0, double t1, RayCtx *c,
                      csg_span *out) {
  double t[MAX_LEAF_ROOTS];
  int nr = soft_roots_traced(n->soft, o, d, t0, t1, t, MAX_LEAF_ROOTS,
                             c->soft, &c->stats.soft, c->soft_hook);
  if (nr < 0) return -1;
  /* The state before the first crossing, sampled halfway to it; a
     crossing reported at t0 itself (the origin on the surface, or within
     rounding of it) is dropped and the state after it sampled instead. */
  double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  double near = 1e-12 * (1 + fabs(t0) * len) / len;
  int skip = 0;
  while (skip < nr && isfinite(t0) && t[skip] - t0 <= near) skip++;
  double end = skip < nr ? t[skip] : (isfinite(t1) ? t1 : t0 + 1 / len);
  double tm = isfinite(t0) ? 0.5 * (t0 + end) : end - 1 / len;
  double p[3] = {o[0] + tm * d[0], o[1] + tm * d[1], o[2] + tm * d[2]};
  int inside = soft_field(n->soft, p) > soft_magic(n->soft);
  return crossings_to_spans(t + skip, NULL, nr - skip, inside, id, t0, t1,
                            out);
}

/* An intersection of halfspaces only (RayCtx.convex), for this scene. */
static int is_convex(const Scene *s, int node, const RayCtx *c) {
  return c->convex && c->conv_scene == s && node < c->conv_n &&
         s->nodes[node].kind == SC_INTER && c->convex[node];
}

/* The span of such a node: its halfspaces' spans in the order the
   recursion visits them (a before b), clipped one after another: the
   larger start and the smaller end, the earlier on ties, empty as soon
   as a halfspace misses or start >= end, which is what the pairwise
   merges (csg_spans_inter) give in any tree shape; the ids and flips
   are the winning halfspaces'. *out: one span; the count, or -1 when
   memory runs out. */
static int convex_spans(const Scene *s, int node, const double o[3],
                        const double d[3], double t0, double t1, RayCtx *c,
                        csg_span *out) {
  size_t sp = 0;
  int have = 0;
  csg_span cur = {0, 0, -1, -1, 0, 0};
  if (!c->cap_cstack) {
    c->cstack = malloc(64 * sizeof *c->cstack);
    if (!c->cstack) return -1;
    c->cap_cstack = 64;
  }
  c->cstack[sp++] = node;
  while (sp) {
    int k = c->cstack[--sp];
    const ScNode *n = &s->nodes[k];
    if (n->kind == SC_INTER) {   /* a first: pushed last */
      if (sp + 2 > c->cap_cstack) {
        int *q = realloc(c->cstack, 2 * c->cap_cstack * sizeof *q);
        if (!q) return -1;
        c->cstack = q;
        c->cap_cstack *= 2;
      }
      c->cstack[sp++] = n->b;
      c->cstack[sp++] = n->a;
      continue;
    }
    csg_span h;
    if (!halfspace_spans(n, k, o, d, t0, t1, &h)) return 0;
    if (!have) {
      cur = h;
      have = 1;
      continue;
    }
    const csg_span *lo = cur.t0 >= h.t0 ? &cur : &h;
    const csg_span *hi = cur.t1 <= h.t1 ? &cur : &h;
    if (!(lo->t0 < hi->t1)) return 0;
    csg_span m = {lo->t0, hi->t1, lo->id0, hi->id1, lo->flip0, hi->flip1};
    cur = m;
  }
  *out = cur;
  return 1;
}

/* The spans of a leaf node (not a set operation) into *spans: the count,
   or -1 when memory runs out. */
static int leaf_spans(const Scene *s, int node, const double o[3],
                      const double d[3], double t0, double t1, RayCtx *c,
                      csg_span **spans) {
  const ScNode *n = &s->nodes[node];
  csg_span *out;
  int cnt;
  if (is_convex(s, node, c)) {
    out = alloc_spans(c, 1);
    if (!out) return -1;
    *spans = out;
    return convex_spans(s, node, o, d, t0, t1, c, out);
  }
  switch (n->kind) {
  case SC_HALFSPACE:
    out = alloc_spans(c, 1);
    if (!out) return -1;
    cnt = halfspace_spans(n, node, o, d, t0, t1, out);
    break;
  case SC_ROUNDED:
    out = alloc_spans(c, MAX_LEAF_ROOTS / 2 + 1);
    if (!out) return -1;
    cnt = rounded_spans(n, node, o, d, t0, t1, c, out);
    break;
  case SC_SOFT:
    out = alloc_spans(c, MAX_LEAF_ROOTS / 2 + 1);
    if (!out) return -1;
    cnt = soft_spans(n, node, o, d, t0, t1, c, out);
    break;
  case SC_ALL:
    out = alloc_spans(c, 1);
    if (!out) return -1;
    set_span(out, t0, t1, -1, -1, 0, 0);
    cnt = 1;
    break;
  default: /* SC_EMPTY */
    out = NULL;
    cnt = 0;
    break;
  }
  *spans = out;
  return cnt;
}

static int is_op(ScKind k) { return k == SC_UNION || k == SC_INTER || k == SC_DIFF; }

/* Room for one more frame on the ctx's stack; 0, or -1 without memory. */
static int grow_frames(RayCtx *c) {
  size_t cap = c->cap_frames ? 2 * c->cap_frames : 64;
  RayFrame *f = realloc(c->frames, sizeof *f * cap);
  if (!f) return -1;
  c->frames = f;
  c->cap_frames = cap;
  return 0;
}

/* The recursion "spans(a), then (unless an empty a decides) spans(b),
   then combine" run on an explicit stack of set-operation frames, so the
   C stack stays flat however deep the tree: the same calls in the same
   order as the recursive form, hence the same spans and counters. */
int ray_spans(const Scene *s, int node, const double o[3], const double d[3],
              double t0, double t1, RayCtx *c, csg_span **spans) {
  const ScNode *nodes = s->nodes;
  size_t sp = 0;
  csg_span *res;
  int cnt;
  for (;;) {
    /* Descend the left spine of node to a leaf, a frame per operation
       (an intersection of halfspaces counts as a leaf). */
    while (is_op(nodes[node].kind) && !is_convex(s, node, c)) {
      if (sp == c->cap_frames && grow_frames(c)) goto oom;
      c->frames[sp].node = node;
      c->frames[sp].na = -1; /* a not done yet */
      sp++;
      node = nodes[node].a;
    }
    cnt = leaf_spans(s, node, o, d, t0, t1, c, &res);
    if (cnt < 0) goto oom;
    /* Return the result up the stack until a frame needs its b. */
    for (;;) {
      if (!sp) {
        *spans = res;
        return cnt;
      }
      RayFrame *f = &c->frames[sp - 1];
      const ScNode *n = &nodes[f->node];
      if (f->na < 0) {
        /* An empty left side of an intersection or difference decides. */
        if (cnt == 0 && n->kind != SC_UNION) {
          res = NULL;
          sp--;
          continue;
        }
        f->a = res;
        f->na = cnt;
        node = n->b;
        break; /* descend into b */
      }
      csg_span *out = alloc_spans(c, f->na + cnt + 1);
      if (!out) goto oom;
      if (n->kind == SC_UNION) cnt = csg_spans_union(f->a, f->na, res, cnt, out);
      else if (n->kind == SC_INTER) cnt = csg_spans_inter(f->a, f->na, res, cnt, out);
      else cnt = csg_spans_diff(f->a, f->na, res, cnt, out);
      res = out;
      sp--;
    }
  }
oom:
  c->failed = 1;
  return -1;
}

void ray_normal_grad(const double g[3], int flip, double n[3]) {
  double len = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  if (!(len > 0) || !isfinite(len)) {
    n[0] = n[1] = 0;
    n[2] = 1;
    return;
  }
  double sgn = flip ? -1 : 1;
  for (int i = 0; i < 3; i++) n[i] = sgn * g[i] / len;
}

void ray_normal(const Scene *s, int id, int flip, const double p[3],
                double n[3]) {
  const ScNode *nd = &s->nodes[id];
  double g[3] = {0, 0, 0};
  switch (nd->kind) {
  case SC_HALFSPACE:   /* ray_normal_grad of its n, made by scene_add */
    memcpy(n, nd->un[flip != 0], sizeof nd->un[0]);
    return;
  case SC_ROUNDED: /* outward is down the density gradient */
    dt_density_grad(nd->tape, p, g);
    for (int i = 0; i < 3; i++) g[i] = -g[i];
    break;
  case SC_SOFT:
    soft_field_grad(nd->soft, p, g);
    for (int i = 0; i < 3; i++) g[i] = -g[i];
    break;
  default:
    break;
  }
  ray_normal_grad(g, flip, n);
}
