/* poly.h: real polynomials of degree <= POLY_MAX_DEG (6), the numerical
 * kernel under the soft-object ray tracer (Wyvill and Trotman's eq. (4) is a
 * sextic in the ray parameter).
 *
 * A polynomial is an array c[0..deg] of doubles, c[i] the coefficient of
 * x^i. Nothing here allocates: every function writes into arrays its caller
 * owns (POLY_MAX_DEG + 1 coefficients, POLY_MAX_DEG roots), there is no
 * global mutable state, and counters go to a caller-provided poly_stats, so
 * every function may be called from several threads at once.
 *
 * Roots are reported as CROSSINGS: the points of (a, b) where p changes
 * sign, ascending. A root of even multiplicity, where p touches zero without
 * changing sign (a ray grazing a surface), is deliberately not reported: the
 * caller is a CSG ray tracer that keeps inside/outside parity from
 * crossings, and a touch changes neither. "Positive" means p > 0; p == 0
 * counts as not positive, so every point has a definite state. */
#ifndef QCS_POLY_H
#define QCS_POLY_H

#define POLY_MAX_DEG 6

/* Work counters, summed into by the root finders (caller zeroes them). */
typedef struct {
  long solves;     /* calls of poly_roots / poly_crossings */
  long quick;      /* settled by a range bound, no iteration at all */
  long laguerre;   /* settled by Laguerre + verification */
  long fallbacks;  /* Laguerre rejected (cluster, multiple root, no
                      convergence, parity mismatch): derivative cascade */
  long laguerre_steps; /* Laguerre iterations: finding the roots of the
                          deflated polynomials, then polishing each */
  long bracket_steps;  /* Newton/bisection steps on monotone brackets */
} poly_stats;

/* Options of poly_crossings. */
enum {
  POLY_CASCADE_ONLY = 1  /* skip Laguerre, isolate by the derivative cascade */
};

/* Degree after dropping zero leading coefficients (0 for the zero poly). */
int poly_degree(const double *c, int deg);

/* p(x) by Horner's rule. If err is not NULL it receives a running bound on
 * |computed - exact| for exact coefficients and x (Higham, Alg. 5.1). */
double poly_eval(const double *c, int deg, double x, double *err);

/* p(x) and p'(x) together; err as for poly_eval (bound on p only). */
double poly_eval_d(const double *c, int deg, double x, double *dp,
                   double *err);

/* out[0..deg-1] = coefficients of p'; returns deg - 1 (0 for deg 0, with
 * out[0] = 0). out may not alias c. */
int poly_deriv(const double *c, int deg, double *out);

/* Taylor shift: out[i] = p^(i)(x0) / i!, so that p(x0 + u) = sum out[i] u^i.
 * out may alias c. */
void poly_shift(const double *c, int deg, double x0, double *out);

/* Every crossing of p in (a, b), ascending, into roots[0..deg-1]; returns
 * the count. The states at the ends are those of p(a) and p(b). */
int poly_roots(const double *c, int deg, double a, double b, double *roots,
               poly_stats *st);

/* As poly_roots, but the caller imposes the state at each end (pos_a,
 * pos_b: nonzero for "p > 0"). The crossings returned are consistent with
 * them: their count is odd exactly when pos_a != pos_b. Piecewise callers
 * pass the state they computed for a shared boundary to both neighbouring
 * intervals, so a root on the boundary is counted once. If an imposed state
 * disagrees with p near that end, the crossing lands at that end.
 * Method: range bounds first; then Laguerre's method with deflation and
 * polishing on the original polynomial, verified by the signs between the
 * roots it found; on any doubt, the derivative cascade (crossings of p' split
 * [a, b] into monotone pieces, each solved by safeguarded Newton/bisection),
 * which cannot miss a sign change. */
int poly_crossings(const double *c, int deg, double a, double b, int pos_a,
                   int pos_b, unsigned opts, double *roots, poly_stats *st);

#endif
