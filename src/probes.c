/* probes.c: the geometry core as functions of the language. See probes.h.
 *
 * Each probe compiles what it is given (scene.c) and calls the kernels
 * the renderer calls. The compiled scene is freed before the probe
 * returns, also when an error unwinds (the ScopedScene handler below). */
#include "probes.h"

#include <math.h>
#include <string.h>

#include "density.h"
#include "eval.h"
#include "scene.h"
#include "soft.h"

static void get_point(Interp *I, Value *v, Pos pos, const char *what,
                      double p[3]) {
  force_vec3(I, v, pos, what, p);
  if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
    qcs_error(pos, "%s must be finite, not (%g, %g, %g)", what, p[0], p[1],
              p[2]);
}

static double get_radius(Interp *I, Value *v, Pos pos) {
  double r = force_num(I, v, pos, "the radius");
  if (!isfinite(r) || r < 0)
    qcs_error(pos, "the radius must be finite and >= 0, not %g", r);
  return r;
}

/* Runs body on a compiled tape/scene and frees it even if body raises. */
#define WITH_CLEANUP(cleanup, body)          \
  do {                                       \
    ErrFrame f_;                             \
    if (ERR_TRY(f_)) {                       \
      body;                                  \
      err_pop(&f_);                          \
      cleanup;                               \
    } else {                                 \
      err_pop(&f_);                          \
      cleanup;                               \
      ErrInfo e_ = *err_info();              \
      qcs_error(e_.pos, "%s", e_.msg);       \
    }                                        \
  } while (0)

/* Density r p tree: Figure 4. */
static Value *pr_density(Interp *I, Value **args, Pos pos) {
  double r = get_radius(I, args[0], pos), p[3];
  get_point(I, args[1], pos, "the point", p);
  dt_tape *t = scene_density_tape(I, args[2], r, pos);
  double rho = dt_density(t, p);
  dt_tape_free(t);
  return val_num(rho);
}

/* Gradient r p tree: Section 2.4. */
static Value *pr_gradient(Interp *I, Value **args, Pos pos) {
  double r = get_radius(I, args[0], pos), p[3], g[3];
  get_point(I, args[1], pos, "the point", p);
  dt_tape *t = scene_density_tape(I, args[2], r, pos);
  dt_density_grad(t, p, g);
  dt_tape_free(t);
  return val_tuple3(g[0], g[1], g[2]);
}

/* PointInObject p obj: Figure 4, for every kind of object. */
static Value *pr_inside(Interp *I, Value **args, Pos pos) {
  double p[3];
  get_point(I, args[0], pos, "the point", p);
  Scene *s = scene_compile(I, args[1], pos);
  int in = scene_inside(s, s->root, p);
  scene_free(s);
  return val_bool(I, in);
}

/* Displacement r t: eq. (5). */
static Value *pr_displacement(Interp *I, Value **args, Pos pos) {
  double r = get_radius(I, args[0], pos);
  double t = force_num(I, args[1], pos, "the density level");
  if (!(t >= 0 && t <= 1))
    qcs_error(pos, "the density level of Displacement must be in [0, 1], "
              "not %g", t);
  return val_num(dt_displacement(r, t));
}

/* Field p soft: Wyvill and Trotman eq. (1), summed over the keys. */
static Value *pr_field(Interp *I, Value **args, Pos pos) {
  double p[3];
  get_point(I, args[0], pos, "the point", p);
  Scene *s = scene_compile(I, args[1], pos);
  double f = 0;
  int found = 0;
  for (int i = 0; i < s->n; i++)
    if (s->nodes[i].kind == SC_SOFT) {
      f += soft_field(s->nodes[i].soft, p);
      found = 1;
    }
  scene_free(s);
  if (!found)
    qcs_error(pos, "Field needs a soft object (SoftObject magic [keys])");
  return val_num(f);
}

#define PROBES(X)                                                            \
  X("Density", 3, pr_density,                                                \
    "Density r p tree: the density of the tree smoothed with radius r at p") \
  X("Gradient", 3, pr_gradient,                                              \
    "Gradient r p tree: the density's gradient at p")                        \
  X("PointInObject", 2, pr_inside,                                           \
    "PointInObject p obj: is p inside the object?")                          \
  X("Displacement", 2, pr_displacement,                                      \
    "Displacement r t: distance from a plane to its t-isosurface, outward")  \
  X("Field", 2, pr_field, "Field p soft: the soft object's field at p")

static const Builtin probes[] = {
#define X(name, arity, fn, doc) {name, arity, fn, doc},
    PROBES(X)
#undef X
};

void probes_install(Interp *I) {
  for (size_t i = 0; i < sizeof probes / sizeof *probes; i++) {
    Sym *s = sym_intern(I, probes[i].name, (int)strlen(probes[i].name));
    s->global = val_builtin(&probes[i]);
    s->sig = probes[i].doc;
  }
}
