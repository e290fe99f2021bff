/* interval.h: the interval rules of the density ops, one definition.
 *
 * A density subtree's range [lo, hi] follows from its operands' ranges
 * (x below, y on top of the stack) by exact interval arithmetic in double
 * precision: Sum, Difference, Product, and the density Union
 * 1 - (1-x)(1-y) as a product of complements.  The tape's M bound
 * (density.c), the bounds' per-subtree ranges (bounds.c) and the LG
 * ranges over a ray segment (lg.c) all use these, so the three always
 * agree to the last bit.  No rounding control: callers that need a safe
 * side add their own margin.  static inline (lg.c's evaluator is hot); no
 * state, any thread.  NaN operands give NaN-dependent results (callers
 * never pass them: leaf ranges are [0,1] or constants). */
#ifndef QCS_INTERVAL_H
#define QCS_INTERVAL_H

/* [a0,a1] * [b0,b1]: the least and greatest of the four corner products. */
static inline void iv_mul(double a0, double a1, double b0, double b1,
                          double *lo, double *hi) {
  double p[4] = {a0 * b0, a0 * b1, a1 * b0, a1 * b1};
  double l = p[0], h = p[0];
  for (int i = 1; i < 4; i++) {
    if (p[i] < l) l = p[i];
    if (p[i] > h) h = p[i];
  }
  *lo = l;
  *hi = h;
}

/* [xl,xh] + [yl,yh]. */
static inline void iv_add(double xl, double xh, double yl, double yh,
                          double *lo, double *hi) {
  *lo = xl + yl;
  *hi = xh + yh;
}

/* [xl,xh] - [yl,yh]. */
static inline void iv_sub(double xl, double xh, double yl, double yh,
                          double *lo, double *hi) {
  *lo = xl - yh;
  *hi = xh - yl;
}

/* The density Union x + y - xy = 1 - (1-x)(1-y) of [xl,xh] and [yl,yh]. */
static inline void iv_union(double xl, double xh, double yl, double yh,
                            double *lo, double *hi) {
  double l, h;
  iv_mul(1 - xh, 1 - xl, 1 - yh, 1 - yl, &l, &h);
  *lo = 1 - h;
  *hi = 1 - l;
}

#endif
