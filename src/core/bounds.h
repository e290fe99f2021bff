/* bounds.h: outer and inner bounds of a density tape as sharp CSG tapes
 * (paper Section 3.2-3.3, Figure 8, Appendix Theorems 1-6).
 *
 * bnd_outer(t, level) is a CSG object O with  x not in O => rho(x) <= level
 * (eq. 3); bnd_inner(t, level) is I with  x in I => rho(x) >= level
 * (eq. 4).  Every 0.5 crossing of a ray therefore lies in
 * outer(0.5) - inner(0.5), up to the surfaces themselves.
 *
 * The theorems are used in a generalised form that carries each subtree's
 * density range [lo, hi] (exact interval arithmetic with leaves in [0,1])
 * instead of assuming every subtree lies in [0,1]; with ranges in [0,1]
 * they reduce to the paper's.  They stay valid for Figure 15b's summed
 * overlapping cubes.  Where no theorem applies (e.g. a product of factors
 * that may be negative) the bound falls back to the filter supports (a
 * leaf's plane moved out by r, Product -> intersection, others -> union),
 * or to Everything / Empty, and BND_FALLBACK is set.  Thresholds are
 * rounded towards the safe side and every plane is moved out (outer) or in
 * (inner) by a few ulps, so rounding cannot lose a crossing.
 *
 * Memory: the returned tape is owned by the caller (csg_tape_free); NULL
 * only when out of memory.  Thread-safe (no shared state). */
#ifndef QCS_BOUNDS_H
#define QCS_BOUNDS_H

#include "core/csg.h"
#include "core/density.h"

enum {
  BND_RANGE = 1,     /* some subtree may exceed density 1 (M > 1): the
                        paper's [0,1] assumption is not guaranteed, seams
                        may bulge (Figure 15b); the bounds stay safe */
  BND_FALLBACK = 2   /* a looser support-based bound had to be used */
};

/* Figure 8: OuterBounds.  *flags (if not NULL) receives BND_* bits. */
csg_tape *bnd_outer(const dt_tape *t, double level, int *flags);
/* The same, with every product of smoothed halfspaces (all radii > 0)
 * also cut by a plane per pair and per triple of its faces (not nearly
 * opposite, not nearly coplanar): beyond it the pair's (triple's) product
 * is below level, since the kernel is log-concave (bounds.c).  A rounded
 * polyhedron's edges and corners, where the sharp bound is loosest, are
 * cut off: what the tracer and the mesher search.  A plane is kept only
 * when it cuts the sharp polyhedron by 5% of its extent across the plane
 * (each costs every ray a little); at most 48 per product, none for a
 * product of more than 16 leaves or without corners. */
csg_tape *bnd_outer_chamfered(const dt_tape *t, double level, int *flags);
/* The InnerBounds counterpart (Theorems 4-6). */
csg_tape *bnd_inner(const dt_tape *t, double level, int *flags);

#endif
