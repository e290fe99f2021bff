/* render.h: the ray tracer.
 *
 * The render layer: it reads a compiled scene (scene/) and the geometry
 * core (core/), returns an image and a report, and prints nothing: the
 * report is turned into text by the layer above (bind/report.h), and
 * progress goes to a callback the caller may give.
 *
 * Renders a compiled scene (scene.h) with the geometry core's guaranteed
 * roots: primary rays through a pinhole camera, hard shadows, Lambert plus
 * Blinn-Phong, n x n stratified supersampling. The top-level union of the
 * scene is split into primitives (CSG subtrees); the bounded ones go into
 * a bounding volume hierarchy whose boxes come from the sharp outer-bound
 * polyhedra (the paper's "boundable" objects, Section 3.5) with CSG-aware
 * box algebra, and the unbounded ones (a floor) are tested on every ray.
 * A ray pays only for the primitives whose boxes it meets, and only for
 * the kinds of object they contain.
 *
 * Threads take 16 x 16 tiles from an atomic counter; each has its own ray
 * context and counters; every pixel depends only on its coordinates, so
 * the image is identical whatever the thread count. An abort flag is read
 * per tile (Ctrl-C in the REPL): an atomic int, read with a relaxed load,
 * so a signal handler or another thread may set it at any time.
 *
 * The camera (basis, automatic framing of the bounded primitives, primary
 * rays) is render/camera.h's, shared with the tradeoff study.
 *
 * Depth: no walk of the scene here recurses with the tree (primitive
 * collection, node boxes, spans): a scene as deep as the interpreter can
 * build renders on worker threads' default stacks. An intersection of
 * more than 64 planes is boxed conservatively as two boxes' intersection.
 *
 * Failure: if a worker runs out of memory (a span list, a root search),
 * it raises a shared atomic flag, every worker stops at its next tile,
 * and render_scene returns NULL with "out of memory for the render" in
 * err: never a picture with silently missing surfaces.
 *
 * Memory: render_scene returns an Image the caller frees with img_free; it
 * does not keep the scene. Shared state read by the workers is the scene
 * and the Tracer (written before the threads start), the tile counters
 * and flags (atomics), and the progress time (under a lock); each worker
 * writes only its own pixels and its own counters, summed after the join. */
#ifndef QCS_RENDER_H
#define QCS_RENDER_H

#include <stdatomic.h>
#include <stddef.h>

#include "render/image.h"
#include "scene/scene.h"

#define RENDER_MAX_LIGHTS 8

typedef struct RenderSettings {
  int width, height;
  int spp;                  /* samples per pixel, a square: 1, 4, 9, ... */
  int threads;              /* 0: all cores */
  int camera_set;           /* 0: frame the scene's bounds automatically */
  double eye[3], at[3], up[3];
  double fov;               /* vertical, degrees */
  int nlights;              /* 0: the conventional light */
  double lights[RENDER_MAX_LIGHTS][3];
  double light_intensity[RENDER_MAX_LIGHTS];
  double ambient;
  double background[3];
  double object_colour[3];
  double floor_colour[3];
  double tol;               /* root tolerance, a distance in scene units */
  int shadows;
  int aovs;                 /* IMG_Z | IMG_N | IMG_COST */
  /* A part of the picture (a crop, a farm's tile): pixels [crop_x0,
     crop_x1) x [crop_y0, crop_y1) of the width x height picture, framed
     as in the whole picture (the camera sees width x height) and
     bit-identical to those pixels of it. All 0: the whole picture. */
  int crop_x0, crop_x1, crop_y0, crop_y1;
  /* 1: where no sample meets a surface the pixel is transparent (RGBA
     0; a pixel's A is the share of its samples that hit, its RGB the
     hits' light, premultiplied); 0: the background colour with A = 1. */
  int alpha;
  /* Progress (may be NULL): called from a worker thread, under a lock,
     at most every 0.1 s once the render has run 0.5 s, with the fraction
     done and an estimate of the seconds left; and once at the end with
     frac = 1 if it was ever called before. */
  void (*progress)(void *ud, double frac, double seconds_left);
  void *progress_ud;
} RenderSettings;

/* The conventions of the canonical scenes: 600 x 380, 1 sample, one
   white light, ambient 0.15, sky (0.55, 0.65, 0.85), object colour
   (0.80, 0.78, 0.72), floor (0.5, 0.5, 0.5), shadows, Z and N planes. */
void render_defaults(RenderSettings *rs);

typedef struct RenderReport {
  int width, height, spp, threads;
  double seconds;            /* wall time of the render */
  long primary, shadow;      /* rays */
  long hits;                 /* primary rays that met a surface */
  long evals;                /* density evaluations */
  long segments, steps;      /* root-search segments, regula falsi steps */
  long soft_solves;          /* soft-object polynomial solves */
  long max_ray_work;         /* the most segments + steps one ray took */
  long rounded_hits;         /* primary rays whose hit is a rounded surface */
  long rounded_hit_evals;    /* density evaluations those rays took */
  double tol;
  double tol_in_force;       /* tol, or what doubles resolve at the scene's
                                and the eye's coordinates if that is more */
  double coord_scale;        /* the largest of those coordinates (>= 1) */
  long unresolved;           /* root-search segments left unsplit (lg.h,
                                LG_MAX_SEGMENTS): a touch may be missing */
  int unresolved_node;       /* the first scene node where that happened,
                                or -1 */
  int interrupted;
  int prims, bounded_prims;
} RenderReport;

/* The image returned is the crop (or the whole picture): width x height
   of the crop, with x0, y0, full_width, full_height saying where it lies,
   the camera matrices (worldToCamera, worldToNDC) and the render's
   settings as "qcs.*" string attributes (size, samples, camera, lights,
   shading, tolerance, alpha, a fingerprint of the scene): what tiles of
   one render share, and what qcs merge checks.

   Render s. Returns NULL with a message in err if the settings are bad
   or memory runs out; with *cancel set (non-zero) during the render,
   returns NULL with rep->interrupted = 1. cancel may be NULL. */
Image *render_scene(const Scene *s, const RenderSettings *rs,
                    RenderReport *rep, atomic_int *cancel,
                    char *err, size_t errlen);

/* The axis-aligned bounds of a scene node: 1 if bounded (lo, hi set), 0
   if unbounded. Boxes are conservative: they contain the node. */
int render_node_box(const Scene *s, int node, double lo[3], double hi[3]);
#endif
