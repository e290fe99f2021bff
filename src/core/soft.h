/* soft.h: soft objects (Wyvill and Trotman, "Ray-Tracing Soft Objects"):
 * the surface field == magic of a sum of weighted key fields, and every ray
 * crossing of it, found by solving the sextic of eq. (4) between
 * consecutive entries/exits of the keys' bounds along the ray.
 *
 * Memory: soft_build copies the keys into a soft_obj it mallocs (with its
 * BVH over the key bounds, bvh.h); the caller owns it and releases it with
 * soft_free. It is read-only afterwards, so any number of threads may query
 * it at once. Each tracing thread owns one soft_scratch (soft_scratch_new /
 * soft_scratch_free), sized for the largest object it will trace; soft_roots
 * allocates nothing per ray. Counters go to a caller-provided soft_stats
 * (one per thread; the caller zeroes and sums them). No global state. */
#ifndef QCS_SOFT_H
#define QCS_SOFT_H

#include <stddef.h>

#include "core/poly.h"

enum { SOFT_SPHERE = 0, SOFT_QUADRIC = 1 };

/* One key point. A SPHERE key at c contributes w * C(r^2 / R^2), r the
 * distance to c. A QUADRIC key uses u'Mu, u = (x, y, z, 1), in place of
 * r^2 (eq. 5); only the symmetric part of M matters. It must be bounded:
 * the upper-left 3x3 block of M must be positive definite (ellipsoids;
 * cylinders and cones are rejected). Writing u'Mu = (x-x0)'A(x-x0) + k, the
 * key acts inside the ellipsoid (x-x0)'A(x-x0) < R^2 - k; if k >= R^2 it
 * acts nowhere, and if k < 0 its field exceeds w at the centre. R > 0, all
 * values finite; w may be negative (negative keys only subtract). */
typedef struct {
  int kind;          /* SOFT_SPHERE or SOFT_QUADRIC */
  double c[3];       /* SPHERE: centre */
  double m[4][4];    /* QUADRIC: the matrix M */
  double R;          /* radius of influence */
  double w;          /* weight */
} soft_key;

/* Errors of soft_build. */
enum {
  SOFT_OK = 0,
  SOFT_ERR_RADIUS,     /* R <= 0 or not finite */
  SOFT_ERR_NONFINITE,  /* a centre, matrix entry or weight not finite */
  SOFT_ERR_KIND,       /* kind is neither SOFT_SPHERE nor SOFT_QUADRIC */
  SOFT_ERR_UNBOUNDED,  /* quadric whose 3x3 block is not positive definite */
  SOFT_ERR_MAGIC,      /* magic <= 0 or not finite (empty space would be
                          inside) */
  SOFT_ERR_NOMEM
};

typedef struct soft_obj soft_obj;
typedef struct soft_scratch soft_scratch;

typedef struct {
  long rays;        /* soft_roots calls */
  long nodes;       /* BVH nodes visited */
  long keys;        /* keys whose bound the ray met */
  long intervals;   /* intervals between consecutive bound events */
  long skipped;     /* intervals settled by a bound without a solve */
  poly_stats poly;  /* polynomial solves, Laguerre, fallbacks */
} soft_stats;

/* Build from n keys (copied). magic is the surface value (0.5 is Wyvill's
 * usual choice; must be > 0). On error returns the code, sets *bad_key to
 * the offending key's index (n for an error not about a key) and *out to
 * NULL. */
int soft_build(const soft_key *keys, size_t n, double magic, soft_obj **out,
               size_t *bad_key);

/* The same, with the keys given one at a time as they are made (a list
 * of a million keys need not be held whole first): soft_builder_add
 * normalises each (SOFT_ERR_NOMEM is its only error; a key's own error,
 * the first, waits for finish), soft_builder_finish builds and returns
 * what soft_build would for those keys and frees the builder, whatever
 * the outcome. soft_builder_free (taking void * to serve as a cleanup)
 * drops a builder not finished. */
typedef struct soft_builder soft_builder;
soft_builder *soft_builder_new(void);  /* NULL when out of memory */
int soft_builder_add(soft_builder *b, const soft_key *key);
int soft_builder_finish(soft_builder *b, double magic, soft_obj **out,
                        size_t *bad_key);
void soft_builder_free(void *b);
void soft_free(soft_obj *obj);
const char *soft_strerror(int err);

size_t soft_nkeys(const soft_obj *obj);
double soft_magic(const soft_obj *obj);

/* Axis-aligned box holding the object's inside (field > magic): the union
 * of the bounds of the positive keys. Returns 0 (and lo > hi) if empty. */
int soft_bounds(const soft_obj *obj, double lo[3], double hi[3]);

/* A tighter box holding the surface and the inside (field >= magic), for
 * framing: where the field is >= magic, some positive key i gives at least
 * magic / n_i of it, n_i the positive keys whose bounds meet key i's
 * (every key acting there does); so the box is the union over the
 * positive keys of where w_i C(s) >= magic / n_i. A lone key of weight 1
 * and magic 0.5: radius R / 2, not R. Negative keys only subtract and
 * are left out. A key met by more than 32 others keeps its whole bound,
 * and past 20000 keys this is soft_bounds. Returns 0 (and lo > hi) if
 * empty. */
int soft_surface_bounds(const soft_obj *obj, double lo[3], double hi[3]);

/* Bounds [*flo, *fhi] on the field over the closed box [lo, hi] (interval
 * arithmetic per key, widened for rounding): the mesher's proof that a
 * cell is wholly inside or outside. Only the keys whose bounds meet the
 * box are visited, found through the key BVH in index order (the sum is
 * the same, bit for bit, as over all keys). Returns 0. */
int soft_field_box(const soft_obj *obj, const double lo[3], const double hi[3],
                   double *flo, double *fhi);

/* Bounds [gl[j], gh[j]] on each component of the field's gradient over
 * the closed box [lo, hi]: per key, 2 w C'(s) A (x - x0), with C'(s)
 * over the range of s on the box (C' rises on s < 1, where it reaches
 * 0) and each component of A (x - x0) exactly (it is linear), their
 * product by interval multiplication; summed, widened for rounding. The
 * mesher's proof that the surface in a cell is smooth enough. The keys
 * are visited as by soft_field_box. Returns 0. */
int soft_grad_box(const soft_obj *obj, const double lo[3], const double hi[3],
                  double gl[3], double gh[3]);

/* eq. (1) summed over the keys: the field at p. */
double soft_field(const soft_obj *obj, const double p[3]);

/* Field at p and its gradient g (the outward normal is -g/|g|). */
double soft_field_grad(const soft_obj *obj, const double p[3], double g[3]);

/* Scratch for one thread, enough for objects of up to max_keys keys. */
soft_scratch *soft_scratch_new(size_t max_keys);
void soft_scratch_free(soft_scratch *s);

/* With plain nonzero, the walks on this scratch test every key they meet
 * in full, without the quick miss that refuses a spherical key whose
 * nearest point to the line is clearly outside it: the reference the
 * tests hold the quick miss to (the same crossings, bit for bit). */
void soft_scratch_plain(soft_scratch *s, int plain);

/* The crossings of the surface by the ray o + t d, t0 < t < t1 (t1 may be
 * INFINITY), ascending, into out[0..maxout-1]; returns their number, or -1
 * if d is zero or not finite, o or t0/t1 is NaN, or the scratch is too
 * small. d may have any
 * length. Crossings alternate between entering and leaving; the state
 * before the first is that of o + t0 d (inside iff soft_field > magic).
 * Touches (even-multiplicity roots) are not reported. The search runs
 * front to back and stops at the maxout-th crossing, so maxout = 1 costs
 * only what the nearest hit costs. */
int soft_roots(const soft_obj *obj, const double o[3], const double d[3],
               double t0, double t1, double *out, int maxout,
               soft_scratch *scratch, soft_stats *stats);

/* Whether the ray crosses the surface in (t0, t1): soft_roots with
 * maxout 1 returning 1, 0 or -1, the same answer on every ray (a shadow
 * ray needs no more). It stops at the first interval between key-bound
 * events whose ends lie on the two sides of the surface, without solving
 * for the crossing there. On 1, *t (t may be NULL) is a t in (t0, t1]
 * by which the ray has crossed: the crossing, or the end of the interval
 * holding it. */
int soft_any(const soft_obj *obj, const double o[3], const double d[3],
             double t0, double t1, double *t, soft_scratch *scratch,
             soft_stats *stats);

/* Trace of soft_roots_traced: one event per interval between consecutive
 * key-bound events along the ray (the paper's step 1), saying how it was
 * decided (step 2). */
enum {
  SOFT_IV_EMPTY,     /* no key acts: the field is 0 < magic */
  SOFT_IV_BOUND,     /* the field's range [flo, fhi] stays on one side */
  SOFT_IV_COEFF,     /* the sextic's constant term outweighs the others */
  SOFT_IV_QUICK,     /* solved: settled by the polynomial's range bound */
  SOFT_IV_LAGUERRE,  /* solved: Laguerre's method, verified by signs */
  SOFT_IV_CASCADE    /* solved: the derivative cascade (Laguerre rejected) */
};

typedef struct soft_trace_event {
  double t0, t1;     /* the interval, in units of t */
  double flo, fhi;   /* bounds on the field over it (NAN for EMPTY) */
  int nkeys;         /* keys acting on it */
  int decision;      /* SOFT_IV_* */
  int nroots;        /* crossings it reported, at roots[] (units of t) */
  double roots[POLY_MAX_DEG];
  long lsteps;       /* Laguerre iterations spent on it (poly_stats) */
  long bsteps;       /* Newton/bisection steps spent on it */
} soft_trace_event;

typedef struct soft_hook {
  void (*fn)(void *ctx, const soft_trace_event *ev);
  void *ctx;
} soft_hook;

/* soft_roots, calling hook (may be NULL) once per interval. */
int soft_roots_traced(const soft_obj *obj, const double o[3],
                      const double d[3], double t0, double t1, double *out,
                      int maxout, soft_scratch *scratch, soft_stats *stats,
                      const soft_hook *hook);

#endif
