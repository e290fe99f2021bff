/* tradeoff.h: what accuracy costs (issue 6, "Error against run time").
 *
 * 1. The root tolerance ladder (qcs tradeoff FILE, :tradeoff FILE): the
 *    scene a script renders (or its `scene`) is captured through the
 *    render hook of render_lang.h instead of being written, rendered at
 *    tolerances 1e-2, 1e-3, ..., 1e-12 (best wall time of a few runs each)
 *    and every rung is compared with the tightest: hit-distance error from
 *    the Z plane, RMS RGB error, pixels whose hit changed. A table goes to
 *    a stream and a log-log SVG plot of error against time to a file.
 *
 * 2. The approximation itself (qcs convolution): the quasi-convolutional
 *    density (Lobb, eq. 1 approximated by products and sums of smoothed
 *    halfspaces) against the true convolution of the sharp polyhedron with
 *    the spherical filter: the fraction of the ball of radius r about p
 *    that lies inside. The true value is computed by integrating exact
 *    chord lengths (sharp CSG span lists, csg.h) over the disc of parallel
 *    chords through the ball with nested adaptive Gauss-Kronrod (7-15)
 *    quadrature (core/conv.h); see conv_fraction for its accuracy.
 *
 * Memory: nothing here keeps a caller's pointer after returning. The
 * scene and settings handed to the capture hook are borrowed for the
 * call; images made for the ladder are freed before returning; rows are
 * written to caller-provided arrays. */
#ifndef QCS_TRADEOFF_H
#define QCS_TRADEOFF_H

#include <stdio.h>

#include "core/csg.h"
#include "core/conv.h"
#include "core/density.h"

/* Kept light (no value.h) so that repl.c can include it. */
struct Scene;
struct RenderSettings;
struct Interp;

#define TRADEOFF_RUNGS 11 /* 1e-2 ... 1e-12 */

typedef struct TradeoffOptions {
  int width, height;    /* 0: the script's size */
  int threads;          /* 0: the script's (all cores) */
  int repeats;          /* timing runs per rung, best kept (0: 3) */
  const char *svg;      /* plot file (NULL: tradeoff.svg; "" for none) */
  FILE *out;            /* the table (NULL: stdout) */
  int spp_ladder;       /* 1: the samples-per-pixel ladder instead */
  int mesh_ladder;      /* 1: the mesh-tolerance ladder instead */
} TradeoffOptions;

typedef struct TradeoffRow {
  double tol;
  double seconds;       /* best wall time of the repeats */
  double worst;         /* slowest of the repeats (run-to-run noise) */
  int spp;              /* samples per pixel (the spp ladder; else 0) */
  long evals, steps;    /* density evaluations, root-search steps */
  double max_dz, rms_dz;/* hit-distance error against the reference, over
                           pixels hit on the same surface in both */
  double rms_rgb;       /* RMS RGB difference, all pixels */
  long changed;         /* hit vs miss, or a different surface */
  long both;            /* pixels hit on the same surface in both */
  int mesh;             /* a row of the mesh ladder: tol is the mesh
                           tolerance, max_dz and rms_dz the sampled
                           distance of the mesh to the surface */
  size_t triangles;     /* the mesh ladder: triangles made */
  double certified;     /* the mesh ladder: the mesher's proven bound */
} TradeoffRow;

/* Render s at every rung and fill rows[TRADEOFF_RUNGS] (the last row, the
   reference, has zero errors). Prints the table to o->out and writes the
   plot. 0, or -1 with a message in err. */
int tradeoff_scene(const struct Scene *s, const struct RenderSettings *base,
                   const TradeoffOptions *o, const char *name,
                   TradeoffRow *rows, char *err, size_t errlen);

/* 3. The samples-per-pixel ladder (qcs tradeoff --spp FILE): s rendered
   at 1, 4, 16 and 64 samples per pixel (best wall time of the repeats)
   and once at 256, the reference; RMS RGB error of each rung against it.
   Without o->width the script's size is capped to TRADEOFF_SPP_WIDTH
   pixels wide (the 256-sample reference is costly); the report says so.
   Fills rows[TRADEOFF_SPP_RUNGS + 1] (the last, the reference, error 0).
   Table to o->out, plot to o->svg (NULL: tradeoff.svg). 0, or -1. */
#define TRADEOFF_SPP_RUNGS 4 /* 1, 4, 16, 64; then the 256 reference */
#define TRADEOFF_SPP_REF 256
#define TRADEOFF_SPP_WIDTH 160
int tradeoff_spp(const struct Scene *s, const struct RenderSettings *base,
                 const TradeoffOptions *o, const char *name,
                 TradeoffRow *rows, char *err, size_t errlen);

/* 4. The mesh-tolerance ladder (qcs tradeoff --mesh FILE): the bounded
   part of s (the scene's root if it is bounded, else the bounded parts of
   its unions: a floor is left out, and the report says so) meshed
   (render/mesh.h) at tolerances of 1/10, 1/20, 1/40 and 1/80 of its
   size, best wall time of the repeats (default 1); for each rung the
   triangles, the time, the mesher's certified bound and a sampled
   distance: from the centre and edge midpoints of up to
   TRADEOFF_MESH_SAMPLES triangles along the triangle's normal to the
   nearest crossing of the true surface (exact ray spans, scene/ray.h).
   Fills rows[TRADEOFF_MESH_RUNGS]. Table to o->out, plot (error against
   time) to o->svg. 0, or -1 with a message in err. */
#define TRADEOFF_MESH_RUNGS 4
#define TRADEOFF_MESH_SAMPLES 4000
int tradeoff_mesh(const struct Scene *s, const TradeoffOptions *o,
                  const char *name, TradeoffRow *rows, char *err,
                  size_t errlen);

/* Run the script path in I with its first render captured (or, if it
   renders nothing, its `scene`) and report its tradeoff. The other
   renders of the script are skipped. 0 on success, 1 on an error (already
   reported on stderr). */
int tradeoff_file(struct Interp *I, const char *path, const TradeoffOptions *o);

/* Write the plot of rows to path (log-log: error against time). Rows
   with spp > 0 are plotted as the spp ladder (RMS RGB error). */
int tradeoff_svg(const TradeoffRow *rows, int n, const char *title,
                 const char *path, char *err, size_t errlen);

/* The convolution report: canonical objects and radii, the distance
   between the 0.5-isosurfaces of both fields along sample rays, and the
   time per evaluation of each, as a Markdown table on out. 0 on success. */
int conv_report(FILE *out);

#endif
