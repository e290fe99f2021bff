/* test_tradeoff.c: the true-convolution integrator of tradeoff.c against
 * exact values: a halfspace (the cap volume of the paper's eq. 2), the
 * centre of a cube edge (1/4) and a cube corner (1/8) for r smaller than
 * the cube, and the sharp polyhedron read off a density tape. */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "study/tradeoff.h"

static dt_tape *cube(double r) {
  dt_builder *b = dt_builder_new();
  for (int k = 0; k < 3; k++) {
    double n[3] = {0, 0, 0};
    n[k] = 1;
    dt_builder_leaf(b, n, 1, r);
    if (k) dt_builder_op(b, DT_PRODUCT);
    n[k] = -1;
    dt_builder_leaf(b, n, 0, r);
    dt_builder_op(b, DT_PRODUCT);
  }
  return dt_builder_finish(b, NULL);
}

int main(void) {
  check_prefix = "tradeoff";
  const double tol = 1e-6, acc = 1e-7; /* the stated accuracy */
  /* Halfspace x < 0 at signed distances s = -0.9r ... 0.9r. */
  dt_builder *b = dt_builder_new();
  double n[3] = {1, 0, 0};
  dt_builder_leaf(b, n, 0, 0.5);
  dt_tape *h = dt_builder_finish(b, NULL);
  csg_tape *hs = conv_sharp_of(h);
  CHECK("sharp halfspace from a tape", hs && hs->nplanes == 1);
  for (int i = -9; i <= 9; i += 3) {
    double r = 0.5, s = 0.1 * i * r, p[3] = {s, 0.2, -0.3};
    double x = s / r, exact = (1 - x) * (1 - x) * (2 + x) / 4; /* eq. (2) */
    char name[64];
    snprintf(name, sizeof name, "halfspace cap at s = %+.1fr", 0.1 * i);
    CHECK_NEAR(name, conv_fraction(hs, p, r, tol, NULL), exact, acc);
    CHECK_NEAR("eq. (2) agrees with dt_halfspace", dt_halfspace(s, r), exact,
               1e-12);
  }
  dt_tape *c = cube(0.1);
  csg_tape *cs = conv_sharp_of(c);
  CHECK("sharp cube from a tape", cs != NULL);
  double radii[3] = {0.05, 0.2, 0.45};
  for (int i = 0; i < 3; i++) {
    double e[3] = {1, 1, 0.5}, k[3] = {1, 1, 1}, f[3] = {0, 0.5, 0.5};
    double in[3] = {0.5, 0.5, 0.5};
    char name[64];
    snprintf(name, sizeof name, "cube edge 1/4, r = %g", radii[i]);
    CHECK_NEAR(name, conv_fraction(cs, e, radii[i], tol, NULL), 0.25, acc);
    snprintf(name, sizeof name, "cube corner 1/8, r = %g", radii[i]);
    CHECK_NEAR(name, conv_fraction(cs, k, radii[i], tol, NULL), 0.125, acc);
    snprintf(name, sizeof name, "cube face 1/2, r = %g", radii[i]);
    CHECK_NEAR(name, conv_fraction(cs, f, radii[i], tol, NULL), 0.5, acc);
    snprintf(name, sizeof name, "cube centre 1, r = %g", radii[i]);
    CHECK_NEAR(name, conv_fraction(cs, in, radii[i], tol, NULL), 1.0, acc);
  }
  /* Halving the requested tolerance changes the value by less than the
     stated accuracy, off the special points too. */
  double q[3] = {1.03, 0.97, 0.91};
  double v1 = conv_fraction(cs, q, 0.1, tol, NULL);
  double v2 = conv_fraction(cs, q, 0.1, tol / 2, NULL);
  CHECK_NEAR("halving the tolerance, near a corner", v1, v2, acc);
  csg_tape_free(hs);
  csg_tape_free(cs);
  dt_tape_free(h);
  dt_tape_free(c);
  CHECK_DONE();
}
