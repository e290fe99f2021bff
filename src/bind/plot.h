/* plot.h: pictures for teaching, as functions of the language.
 *
 *   plotRay "ray.svg" obj o d       density (or soft field) along a ray,
 *                                   the bounds, the Figure 9 segments with
 *                                   their LG cones, the roots
 *   plotSlice "s.png" r tree (c, u, v)
 *                                   density over the plane piece c + a u +
 *                                   b v (|a|, |b| <= 1) as colour, with
 *                                   isolines, the polyhedron's edges and the
 *                                   outer and inner bounds (Figure 8); the
 *                                   axes and legend go to s.svg beside it
 *   plotDisplacement "d.svg"        eq. (5): the isosurface offset against t
 *   plotField "c.svg" soft o d      Wyvill's C(r) and the field along a line
 *   plotConvolution "f.svg" r tree o d
 *                                   Figure 5: the quasi- against the true
 *                                   convolution along a ray, their
 *                                   difference and both 0.5 crossings
 *
 * Every number plotted comes from the kernels the probes call (density.h,
 * bounds.h, lg.h, soft.h, conv.h), and every file is written whole or not at all
 * (img_write_bytes, img_write). The SVGs carry the plotted data in
 * data-* attributes so that tests can check them against the probes.
 * Each plot returns the name of the file it wrote. */
#ifndef QCS_PLOT_H
#define QCS_PLOT_H

#include "core/density.h"
#include "lang/value.h"

void plot_install(Interp *I);

/* An isoline of a density tape over the plane piece c + a u + b v,
 * sampled on an nx x ny grid (marching squares) with every vertex moved
 * onto the level along its grid edge by bisection on the density itself:
 * at most max vertices (a, b) into ab (pairs: a segment is two
 * consecutive vertices). Returns the number of vertices. */
int plot_isoline(const dt_tape *t, const double c[3], const double u[3],
                 const double v[3], int nx, int ny, double level,
                 double *ab, int max);

#endif
