/* report.c: render reports and progress as text. See report.h. */
#include "bind/report.h"

void report_render(FILE *out, const RenderReport *r, const char *path) {
  long rays = r->primary + r->shadow;
  fprintf(out, "%s: %dx%d, %d sample%s/pixel, %.3f s on %d thread%s\n", path,
          r->width, r->height, r->spp, r->spp == 1 ? "" : "s", r->seconds,
          r->threads, r->threads == 1 ? "" : "s");
  fprintf(out, "  rays: %ld primary, %ld shadow (%.2f M rays/s)\n", r->primary,
          r->shadow, r->seconds > 0 ? (double)rays / r->seconds / 1e6 : 0.0);
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

void report_progress(void *ud, double frac, double seconds_left) {
  (void)ud;
  if (frac >= 1) fprintf(stderr, "\r%40s\r", "");
  else fprintf(stderr, "\rrendering %3d%%, %.1f s left ", (int)(100 * frac),
               seconds_left);
  fflush(stderr);
}
