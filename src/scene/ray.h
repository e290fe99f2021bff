/* ray.h: a ray against a compiled scene: the inside spans of every node,
 * combined by Roth's span lists so that CSG finds the right crossing even
 * when it is not the nearest (Wyvill and Trotman's "all intersections").
 *
 * Leaves: a halfspace gives one span; a rounded density tree gives the
 * crossings of the guaranteed root search (lg.h) restricted to its outer
 * minus inner bound; a soft object gives its polynomial crossings
 * (soft.h). Each span end names the node whose surface it is (id) and
 * whether the solid lies on the far side (flip, for subtracted objects),
 * so the caller can compute the normal there.
 *
 * Depth. ray_spans walks the CSG tree on an explicit stack of frames
 * kept in the RayCtx (a left operand's spans waiting for the right's), so
 * the C stack does not grow with the tree: a scene a million nodes deep
 * is evaluated on a worker thread's default stack. It makes the same
 * calls in the same order as the recursive form (an empty left side of
 * an intersection or difference still skips the right side), so spans
 * and counters are those of the recursion.
 *
 * Memory and threads: a RayCtx is per thread (ray_ctx_new /
 * ray_ctx_free); it owns the span arena, the frame stack and the
 * soft-object scratch and holds the counters. A query allocates nothing
 * once the arena and the stack have grown to the scene's needs; the arena
 * takes a request of any size (a chunk of its own). The Scene is only
 * read, so any number of threads, each with its own RayCtx, may query it.
 *
 * Failure: when memory runs out (the arena, the frame stack, or a leaf's
 * root search) ray_spans returns -1 and sets RayCtx.failed, which stays
 * set: a caller that treats -1 as "no spans" can still find out, once per
 * tile, that its answers are incomplete (the renderer does: render.h).
 * Nothing here prints or exits. Units: t along o + t d (d need not be
 * unit length); tol is a distance in scene units (ray_dist_tol). */
#ifndef QCS_RAY_H
#define QCS_RAY_H

#include "core/csg.h"
#include "core/lg.h"
#include "scene/scene.h"
#include "core/soft.h"

typedef struct RayStats {
  long rays;
  lg_stats lg;         /* density evaluations, segments, regula falsi */
  soft_stats soft;     /* keys, intervals, polynomial solves */
  long max_steps;      /* the most root-finder steps one ray took */
} RayStats;

typedef struct SpanChunk SpanChunk;

/* A set operation waiting for its right side (ray.c's explicit stack). */
typedef struct RayFrame {
  int node;
  int na;              /* the left side's span count, -1 until known */
  csg_span *a;         /* the left side's spans */
} RayFrame;

typedef struct RayCtx {
  soft_scratch *soft;
  SpanChunk *chunks;   /* the span arena */
  SpanChunk *cur;
  size_t used;
  double tol;          /* root tolerance as a distance (scene units) */
  RayFrame *frames;    /* ray_spans' stack, grown on demand */
  size_t cap_frames;
  RayStats stats;
  const lg_hook *hook; /* optional trace of every root search segment */
  const soft_hook *soft_hook; /* optional trace of every soft interval */
  int failed;          /* a query ran out of memory (sticky; ray_spans
                          sets it, and so may the caller's own queries) */
  int unresolved_node; /* a rounded node whose search left segments unsplit
                          (lg_stats.overflows grew), or -1 */
  /* Optional (NULL: none), per scene node: a rounded node's tape pruned
     to a region (dt_prune_class), searched in its place. The caller
     (render.c's tiles) sets it only for rays whose searched intervals
     lie in that region, where both give the same views and roots. */
  const dt_tape *const *tapes;
  /* Per node of the scene the ctx was made for (conv_scene, conv_n
     nodes): 1 if its subtree only intersects halfspaces, whose one span
     ray_spans clips plane by plane (the spans and ids the merges would
     give) on the stack cstack. NULL: no such node, or no memory. */
  const Scene *conv_scene;
  unsigned char *convex;
  int conv_n;
  int *cstack;
  size_t cap_cstack;
} RayCtx;

/* The finest root tolerance doubles allow at coordinates of size scale
   (>= 1): RAY_TOL_FLOOR * scale. */
#define RAY_TOL_FLOOR 4e-16

/* The root tolerance in units of t along o + t d: c->tol as a distance,
   never below what doubles resolve at the ray's origin. */
double ray_dist_tol(const RayCtx *c, const double o[3], const double d[3]);

RayCtx *ray_ctx_new(const Scene *s, double tol);
void ray_ctx_free(RayCtx *c);

/* The inside spans of node along o + t d, t in [t0, t1] (t1 may be
   infinite), sorted and disjoint, in an array owned by the ctx and valid
   until ray_reset. Returns the count; *spans points at them. Returns -1
   and sets c->failed when memory runs out (or a leaf's root search does:
   lg.h, soft.h). */
int ray_spans(const Scene *s, int node, const double o[3], const double d[3],
              double t0, double t1, RayCtx *c, csg_span **spans);

/* Forget the spans of earlier queries (call once per ray). */
void ray_reset(RayCtx *c);

/* The outward unit normal of node's surface at p (the span end's id). */
void ray_normal(const Scene *s, int id, int flip, const double p[3],
                double n[3]);

/* The unit normal along g, an outward (unnormalised) normal, as
   ray_normal makes it; negated with flip; (0, 0, 1) if g is 0. */
void ray_normal_grad(const double g[3], int flip, double n[3]);
#endif
