/* lg.h: finding every 0.5 crossing of a density tape along a ray (paper
 * Section 3.4: LG bounds 3.4.1, ShortEnough eq. (6), Figure 9).
 *
 * Over a ray segment the LG evaluator bounds the density range [lo, hi],
 * L >= |d rho/dt| and G >= |d2 rho/dt2| (G bounds the Lipschitz constant
 * of d rho/dt) in units of the ray parameter t, for a direction of any
 * length.  For one leaf, alpha(t) = (n.o - d + t n.d)/r, so
 *   d rho/dt   = 3/4 (alpha^2 - 1) (n.d)/r,
 *   d2 rho/dt2 = 3/2 alpha (n.d)^2/r^2          (|alpha| < 1, else 0),
 * giving L = 3/4 (1 - min|alpha|^2) |n.d|/r and G = 3/2 max|alpha| (n.d/r)^2
 * over the part of the segment inside the filter (the paper prints them
 * per unit of alpha and for a unit direction).  Ops combine by the sum,
 * product and (for the density Union 1-(1-x)(1-y)) product rules with
 * M = max |value| from the ranges.  Leaves whose filter the segment misses
 * are constants and are pruned (density.h, dt_prune_ray) before the
 * segment is evaluated; a sharp (r = 0) leaf whose plane the segment
 * crosses has L = G = infinity and makes the segment split at its plane.
 *
 * ShortEnough, derived here rather than copied (eq. (6) as printed
 * over-counts the turn-around distance: with f = 0 and f' = g at the start
 * a touching second root can come 2.41 g/G in, eq. (6) assumes 3 g/G).
 * With f = rho - 0.5, two roots (or a double root) in [a, b] force a
 * point c with f'(c) = 0 after the first root and before the last, so
 *   c - a >= A = max(|f(a)|/L, |f'(a)|/G, s*(a))
 * where s*(a) is the first zero of |f(a)| + g' s - G s^2/2 (g' = the
 * derivative of |f| moving inwards), and likewise b - c >= B.  Hence
 * A + B > b - a proves at most one root, counted with multiplicity.
 *
 * The search (Figure 9) is iterative with an explicit stack, left half
 * first, so roots come out in ascending order; a short segment with a sign
 * change is solved within its bracket by Newton steps interleaved with
 * bisection (safeguarded like rtsafe; the paper uses regula falsi) until
 * a step is below max(tol, 4 ulp): with quadratic convergence the root is
 * then far closer than tol.  Segments shorter than tol are not split further
 * ("l negligibly small"): with a sign change they give one root (several
 * crossings closer than tol may merge); without one, the density is
 * sampled at the extremum the end derivatives predict, and
 *   - a sign change there gives both crossings;
 *   - else, if the quadratic bounds from G cannot keep |f| away from 0
 *     on the segment, one LG_TOUCH root is reported at that sample (a
 *     tangent or near-tangent graze within ~tol); with G infinite (a
 *     sharp step) nothing is reported.
 * Guarantee: every crossing separated from its neighbours by more than tol
 * is found.  A density constant at exactly 0.5 along the ray reports
 * nothing.
 *
 * Memory and threads: no allocation except, for tapes longer than
 * LG_LOCAL_CODE instructions, one malloc/free per call; no global state;
 * counters go to the caller's lg_stats (may be NULL). */
#ifndef QCS_LG_H
#define QCS_LG_H

#include "core/csg.h"
#include "core/density.h"

#define LG_LOCAL_CODE 512
#define LG_STACK 256
/* The most segments one interval's search may split (Figure 9). A ray that
 * runs within rounding of the 0.5 level over a long stretch (a near-touch
 * that doubles cannot settle, e.g. a filter radius of 1e15) would split
 * down to the tolerance all along it; past the budget a segment is decided
 * by the tiny-segment rule instead, which still finds every sign change
 * but may miss a pair of crossings closer than the segment. Such segments
 * are counted in lg_stats.overflows so that callers can say so. */
#define LG_MAX_SEGMENTS 20000

typedef struct lg_stats {
  long evals;        /* density (+ derivative) evaluations */
  long segments;     /* segments visited */
  long rf_steps;     /* root polishing steps (Newton or bisection) */
  long touches;      /* LG_TOUCH roots reported */
  long overflows;    /* segments left unsplit: the stack was full or the
                        search's LG_MAX_SEGMENTS budget was spent */
} lg_stats;

enum { LG_EXIT = -1, LG_TOUCH = 0, LG_ENTER = 1 };

typedef struct lg_root {
  double t;
  int kind;   /* LG_ENTER: density rises through 0.5 (into the solid) */
} lg_root;

/* LG bounds of a tape over the ray segment [a, b]. */
typedef struct lg_bounds {
  double lo, hi;   /* density range */
  double L, G;     /* |rho'| <= L, |rho''| <= G, in units of t */
  double split;    /* a sharp leaf's plane inside (a, b), else NAN */
} lg_bounds;

/* Section 3.4.1 for the (pruned or full) tape t over [a, b]. */
void lg_eval_bounds(const dt_tape *t, const double o[3], const double d[3],
                    double a, double b, lg_bounds *out);

/* eq. (6), in the sound form above: returns A + B for ends (a, f0, df0),
 * (b, f1, df1) with f = rho - 0.5; the segment holds at most one root when
 * the result exceeds b - a. */
double lg_multiroot_length(double f0, double df0, double f1, double df1,
                           double L, double G);

/* Trace decisions, one per visited segment. */
enum {
  LG_SEG_EXCLUDED,   /* density range misses 0.5 */
  LG_SEG_FLAT,       /* L = 0: constant density */
  LG_SEG_NO_ROOT,    /* at most one root (eq. 6 false), no sign change */
  LG_SEG_ROOT,       /* at most one root, sign change: regula falsi */
  LG_SEG_SPLIT,      /* eq. (6) true: subdivide */
  LG_SEG_TINY,       /* shorter than tol: decided by the tolerance rule */
  LG_SEG_PLANE,      /* one leaf live: the density is monotone along the
                        ray and its 0.5 level is the leaf's plane, so the
                        crossing, if the ends' signs differ, is that
                        plane's, by one division (no splitting, no
                        polishing) */
  LG_SEG_CONCAVE     /* the view is a product of smoothed halfspaces,
                        log-concave along the ray, so the solid meets the
                        segment in one interval or none: ends of unlike
                        sign hold one crossing (polished), ends inside
                        none, ends outside none when tangents of log rho
                        keep it below log 0.5, else two around a point
                        found inside (nroots says which) */
};

typedef struct lg_trace_event {
  double t0, t1;       /* the segment */
  double f0, f1;       /* rho - 0.5 at its ends */
  double df0, df1;     /* d rho/dt at its ends */
  double L, G, lo, hi; /* its LG bounds and density range */
  double lhs;          /* A + B of eq. (6) (compare with t1 - t0) */
  int decision;        /* LG_SEG_* */
  int depth;           /* subdivision depth */
  int ncode;           /* instructions left after pruning */
  int nroots;          /* roots this segment reported */
} lg_trace_event;

typedef void (*lg_trace_fn)(void *ctx, const lg_trace_event *ev);
typedef struct lg_hook {
  lg_trace_fn fn;
  void *ctx;
} lg_hook;

/* What a search reports (lg_query.mode). */
typedef enum {
  LG_ALL = 0,    /* every crossing, in order (the probes, CSG spans) */
  LG_FIRST = 1,  /* up to the first crossing after t0 (a primary ray) */
  LG_ANY = 2     /* whether there is a crossing after t0 (a shadow ray) */
} lg_mode;

/* One search along o + t d: the tape, where to look ([t0, t1]; t1 may be
 * infinite), how finely (tol > 0 in units of t), where to put the roots
 * (out, at most maxout), the counters (stats, may be NULL), a trace hook
 * (may be NULL), what to report (mode) and, for LG_FIRST and LG_ANY, grad
 * (may be NULL): see lg_first_bounded. */
typedef struct lg_query {
  const dt_tape *tape;
  const double *o, *d;
  double t0, t1, tol;
  lg_root *out;
  int maxout;
  lg_stats *stats;
  const lg_hook *hook;
  lg_mode mode;
  double *grad;
} lg_query;

/* Figure 7: the search of q where the outer bound and not the inner one
 * is (inner may be NULL), each span widened by tol (plus a few ulps), as
 * lg_roots_bounded (LG_ALL) and lg_first_bounded (LG_FIRST, LG_ANY) say.
 * Returns the count, or -1 if out of memory. The functions below are this
 * with their arguments named in a query. */
int lg_search_bounded(const lg_query *q, const csg_tape *outer,
                      const csg_tape *inner);

/* Figure 9: every 0.5 crossing in [t0, t1] (clipped to where any filter
 * is touched, so infinite ends are fine), ascending, at most maxout of
 * them (the search stops at maxout, so maxout = 1 gives the first hit).
 * tol > 0 in units of t.  Returns the count, or -1 if out of memory. */
int lg_roots(const dt_tape *t, const double o[3], const double d[3],
             double t0, double t1, double tol, lg_root *out, int maxout,
             lg_stats *stats);

/* As lg_roots, searching only the given sorted spans (e.g. outer bound
 * minus inner bound), each widened by tol (plus a few ulps) and clipped to
 * [t0, t1], since a crossing may sit exactly on a bound's surface.
 * hook may be NULL. */
int lg_roots_spans(const dt_tape *t, const double o[3], const double d[3],
                   double t0, double t1, const csg_span *spans, int nspans,
                   double tol, lg_root *out, int maxout, lg_stats *stats,
                   const lg_hook *hook);

/* Figure 7: spans of outer minus inner (csg.h), then lg_roots_spans.
 * inner may be NULL. */
int lg_roots_bounded(const dt_tape *t, const csg_tape *outer,
                     const csg_tape *inner, const double o[3],
                     const double d[3], double t0, double t1, double tol,
                     lg_root *out, int maxout, lg_stats *stats,
                     const lg_hook *hook);

/* As lg_roots_bounded, but the search stops as soon as it reports a
 * crossing (LG_ENTER or LG_EXIT, not a touch) after t0: that crossing is
 * the first one in (t0, t1] and the last root returned.  The roots before
 * it (touches, crossings at t0) are those lg_roots_bounded returns, so the
 * first crossing is the same; only the search after it is skipped (a
 * primary ray needs the nearest hit).  With any != 0 (a shadow ray, which
 * only asks whether there is a crossing after t0) a crossing bracketed
 * after t0 is not polished: its reported t is the bracket's far end, in
 * (t0, t1] like the crossing, and the answer (a crossing after t0 or
 * none) is the same.  grad (may be NULL) receives, when the search stops
 * at such a crossing, the density gradient (dt_density_grad) at
 * o + t d, evaluated on the tape pruned to the crossing's segment (the
 * leaves that are constant there contribute nothing), for the normal. */
int lg_first_bounded(const dt_tape *t, const csg_tape *outer,
                     const csg_tape *inner, const double o[3],
                     const double d[3], double t0, double t1, double tol,
                     lg_root *out, int maxout, lg_stats *stats, int any,
                     double grad[3]);

#endif
