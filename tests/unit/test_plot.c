/* test_plot.c: the numbers behind plotSlice. The isolines of a smoothed
 * unit cube over the plane z = 0.5, away from its edges, are the
 * isosurfaces of one smoothed halfspace: at x = 1 + Displacement r t
 * (eq. 5, outward positive) and likewise at the other faces. */
#include "check.h"
#include "bind/plot.h"

static dt_tape *unit_cube(double r) {
  dt_builder *b = dt_builder_new();
  static const double n[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                 {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  static const double d[6] = {1, 0, 1, 0, 1, 0};
  for (int i = 0; i < 6; i++) {
    dt_builder_leaf(b, n[i], d[i], r);
    if (i) dt_builder_op(b, DT_PRODUCT);
  }
  return dt_builder_finish(b, NULL);
}

int main(void) {
  check_prefix = "plot";
  double r = 0.1;
  dt_tape *t = unit_cube(r);
  CHECK("unit cube tape builds", t != NULL);
  if (!t) return 1;
  double c[3] = {0.5, 0.5, 0.5}, u[3] = {0.8, 0, 0}, v[3] = {0, 0.8, 0};
  static const double levels[3] = {0.25, 0.5, 0.75};
  double *ab = malloc(2 * 100000 * sizeof *ab);
  for (int li = 0; li < 3; li++) {
    double t_ = levels[li], D = dt_displacement(r, t_);
    int n = plot_isoline(t, c, u, v, 150, 150, t_, ab, 100000);
    char name[120];
    snprintf(name, sizeof name, "isoline %g has vertices", t_);
    CHECK(name, n > 100);
    /* on the face x = 1, |y - 0.5| < 0.3 (away from the edges' blend) */
    int face = 0;
    double worst = 0;
    for (int k = 0; k < n; k++) {
      double x = c[0] + ab[2 * k] * u[0], y = c[1] + ab[2 * k + 1] * v[1];
      if (x > 0.8 && fabs(y - 0.5) < 0.3) {
        face++;
        worst = fmax(worst, fabs(x - (1 + D)));
      }
    }
    snprintf(name, sizeof name, "isoline %g on the face x = 1 lies at "
             "1 + Displacement r %g (%d vertices, worst %.2g)", t_, t_, face,
             worst);
    CHECK(name, face > 10 && worst < 1e-12);
  }
  free(ab);
  dt_tape_free(t);
  return check_failed_count != 0;
}
