/* report.c: render reports and progress as text. See report.h. */
#include "bind/report.h"

#include <math.h>
#include <string.h>

#include "render/camera.h"

void report_render(FILE *out, const RenderReport *r, const char *path) {
  long rays = r->primary + r->shadow;
  fprintf(out, "%s: %dx%d, %d sample%s/pixel, %.3f s on %d thread%s\n", path,
          r->width, r->height, r->spp, r->spp == 1 ? "" : "s", r->seconds,
          r->threads, r->threads == 1 ? "" : "s");
  fprintf(out, "  rays: %ld primary, %ld shadow (%.2f M rays/s)\n", r->primary,
          r->shadow, r->seconds > 0 ? (double)rays / r->seconds / 1e6 : 0.0);
  if (r->primary > 0 && r->hits == 0)
    fprintf(out, "  nothing hit: 0 of %ld primary rays met a surface (an "
            "empty scene, a density that never reaches 0.5, or a camera "
            "looking away)\n", r->primary);
  if (r->evals || r->segments)
    fprintf(out, "  density: %ld evaluations, %ld segments, %ld polishing "
            "steps; %.2f steps per ray (most in one ray: %ld)\n",
            r->evals, r->segments, r->steps,
            rays ? (double)(r->segments + r->steps) / (double)rays : 0.0,
            r->max_ray_work);
  if (r->rounded_hits)
    fprintf(out, "  rays hitting a rounded surface: %ld, %.1f density "
            "evaluations each\n", r->rounded_hits,
            (double)r->rounded_hit_evals / (double)r->rounded_hits);
  if (r->soft_solves)
    fprintf(out, "  soft objects: %ld polynomial solves\n", r->soft_solves);
  if (r->tol_in_force > r->tol && r->coord_scale > 1e3)
    fprintf(out, "  root tolerance %g requested, %.2g in force: doubles "
            "resolve no finer at coordinates of %.3g (the eye or the "
            "scene); move them nearer the origin for more\n", r->tol,
            r->tol_in_force, r->coord_scale);
  else if (r->tol_in_force > r->tol)
    fprintf(out, "  root tolerance %g requested, %.2g in force: doubles "
            "resolve no finer (4e-16 x the coordinates, up to %.3g here)\n",
            r->tol, r->tol_in_force, r->coord_scale);
  if (r->unresolved)
    fprintf(out, "  %ld root-search segment%s left undecided (rays within "
            "rounding of a surface for a long stretch; see the warning)\n",
            r->unresolved, r->unresolved == 1 ? "" : "s");
  fprintf(out, "  root tolerance %g (scene units); %d primitive%s, %d in the "
          "BVH\n", r->tol_in_force > r->tol ? r->tol_in_force : r->tol,
          r->prims, r->prims == 1 ? "" : "s", r->bounded_prims);
}

void report_written(FILE *out, double seconds) {
  fprintf(out, "  file written in %.3f s\n", seconds);
}

void report_progress(void *ud, double frac, double seconds_left) {
  (void)ud;
  if (frac >= 1) fprintf(stderr, "\r%40s\r", "");
  else fprintf(stderr, "\rrendering %3d%%, %.1f s left ", (int)(100 * frac),
               seconds_left);
  fflush(stderr);
}

void report_scene(char *buf, size_t n, const Scene *s, const char *what) {
  long leaves = 0;
  int sharp = 0, rounded = 0, soft = 0, ops = 0;
  for (int i = 0; i < s->n; i++) {
    const ScNode *nd = &s->nodes[i];
    switch (nd->kind) {
    case SC_HALFSPACE: leaves++, sharp = 1; break;
    case SC_ROUNDED: leaves += nd->tape->nleaves, rounded = 1; break;
    case SC_SOFT: leaves += (long)soft_nkeys(nd->soft), soft = 1; break;
    case SC_UNION: case SC_INTER: case SC_DIFF: ops++; break;
    default: break;
    }
  }
  char kind[64] = "";
  if (!leaves) snprintf(kind, sizeof kind, "%s",
                        s->n && s->nodes[s->root].kind == SC_ALL ? "everything"
                                                                  : "empty");
  else
    snprintf(kind, sizeof kind, "%s%s%s%s%s%s",
             rounded ? "rounded" : "", rounded && (sharp || soft) ? " + " : "",
             sharp ? "sharp" : "", sharp && soft ? " + " : "",
             soft ? "soft" : "", ops ? " CSG" : "");
  double lo[3], hi[3];
  char box[160];
  if (s->n && render_node_box(s, s->root, lo, hi)) {
    /* Soft objects by where their surface can be, as the camera frames
       them, not by their keys' reach: the tighter of the two true boxes. */
    double flo[3], fhi[3];
    if (camera_scene_box(s, flo, fhi) == 1)
      for (int i = 0; i < 3; i++) {
        lo[i] = fmax(lo[i], flo[i]);
        hi[i] = fmin(hi[i], fhi[i]);
      }
    /* The box is conservative by a hair (the bounds' padding): show it to
       4 digits of its own size, so that the unit cube reads 0 .. 1. */
    double ext = 0;
    for (int i = 0; i < 3; i++)
      ext = fmax(ext, fmax(fabs(lo[i]), fabs(hi[i])));
    for (int i = 0; i < 3; i++) {
      if (fabs(lo[i]) < 1e-6 * ext) lo[i] = 0;
      if (fabs(hi[i]) < 1e-6 * ext) hi[i] = 0;
    }
    snprintf(box, sizeof box, "box (%.4g, %.4g, %.4g) .. (%.4g, %.4g, %.4g)",
             lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
  }
  else
    snprintf(box, sizeof box, "unbounded");
  snprintf(buf, n, "%s: %s, %ld %s, %s", what, kind, leaves,
           soft && !sharp && !rounded ? (leaves == 1 ? "key" : "keys")
                                      : (leaves == 1 ? "leaf" : "leaves"),
           box);
}
