/* conv.h: the true convolution that Lobb's quasi-convolution stands in
 * for (his Figure 5): the fraction of the ball of radius r about p that
 * lies inside the sharp polyhedron, integrated from exact chord lengths.
 *
 * A kernel of the geometry core: libc and libm only, no allocation beyond
 * the csg tape conv_sharp_of returns (the caller frees it with
 * csg_tape_free); every function may be called from several threads. */
#ifndef QCS_CONV_H
#define QCS_CONV_H

#include "core/csg.h"
#include "core/density.h"

/* The sharp polyhedron a density tape describes (Product = Intersection,
   Sum and Union = Union, Difference = set difference). Caller frees with
   csg_tape_free. NULL on failure. */
csg_tape *conv_sharp_of(const dt_tape *t);

/* The fraction of the ball of radius r about p inside the sharp object t,
   to an absolute accuracy of about tol (the quadrature's error estimate;
   verified against exact values by the tests). *evals, if not NULL, is
   increased by the number of chords cast. */
double conv_fraction(const csg_tape *t, const double p[3], double r,
                     double tol, long *evals);

/* The crossing of the true convolution's 0.5 level along o + s d near
   s = guess: bracketed by steps of r/8 (at most 16, the way the value
   there points), then Illinois regula falsi to 1e-7 r. -1 if no bracket
   is found. *points (if not NULL) counts the evaluations, *chords the
   chords they cast; tol is conv_fraction's. */
double conv_crossing(const csg_tape *t, double r, const double o[3],
                     const double d[3], double guess, double tol,
                     long *points, long *chords);

#endif
