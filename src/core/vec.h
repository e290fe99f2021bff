/* vec.h: 3-vectors as double[3], for every layer below the interpreter.
 *
 * Owns nothing: small static inline helpers, so the hot loops that call
 * them (the tracer, the soft-object and density kernels) keep their speed.
 * Each is written in one fixed order of operations (dot: x, then y, then
 * z, left to right), which the kernels' bit-for-bit results depend on: do
 * not reassociate.  No state, no allocation, any thread. */
#ifndef QCS_VEC_H
#define QCS_VEC_H

#include <math.h>

static inline double vec3_dot(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* c = a x b (c must not alias a or b). */
static inline void vec3_cross(const double a[3], const double b[3],
                              double c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

/* The range [*rl, *rh] of n.x - d over the box [lo, hi], widened by the
   rounding of its evaluation (a relative 1e-12), so that a box proven on
   one side of the plane is on that side. */
static inline void vec3_plane_range(const double n[3], double d,
                                    const double lo[3], const double hi[3],
                                    double *rl, double *rh) {
  double c = -d, r = 0;
  for (int i = 0; i < 3; i++) {
    double m = 0.5 * (lo[i] + hi[i]), e = 0.5 * (hi[i] - lo[i]);
    c += n[i] * m;
    r += fabs(n[i]) * e;
  }
  r += 1e-12 * (fabs(c) + r + 1);
  *rl = c - r;
  *rh = c + r;
}

#endif
