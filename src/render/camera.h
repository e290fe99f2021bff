/* camera.h: the one pinhole camera of every picture qcs makes.
 *
 * What it owns. The camera basis (eye, unit forward, right and up), the
 * automatic framing of a scene (what is looked at, from where, when the
 * settings name no camera), and the primary ray through a point of the
 * image. The renderer (render.c) and the tolerance study
 * (study/tradeoff.c) both use it, so the study's sample rays are exactly
 * the renderer's primary rays; later tools (a viewer, terminal previews)
 * should too.
 *
 * Framing. The framed box is camera_scene_box's: the union of the boxes
 * of the scene's bounded primitives (the top-level union split as the
 * renderer splits it; an unbounded floor does not count; a soft object
 * boxed by soft_surface_bounds, where its surface can be), or the unit
 * box [0, 1]^3 if there are none. The eye looks at the box's centre from
 * the direction (0.45, 0.6, 1), far enough that the bounding sphere
 * (radius R, half the diagonal, at least 1e-9) fits the vertical field
 * of view (capped at 120 degrees for the distance), with 5% to spare.
 * With RenderSettings.camera_set, eye and at are the settings' own and
 * the box serves only the lights, the shadow offset and the tolerance
 * report (the renderer's business).
 *
 * Units. Positions and distances are scene units; fov is the vertical
 * field of view in degrees; image positions are pixels from the top-left
 * corner of the image (x right, y down), so pixel (x, y)'s centre is
 * (x + 0.5, y + 0.5). Ray directions are unit length, so a ray's t is a
 * distance from the eye.
 *
 * Invariants. After a successful camera_setup, fwd, right and upv are an
 * orthonormal right-handed frame (right = fwd x up, normalised; upv =
 * right x fwd), and camera_ray is a pure function of the Camera and its
 * arguments: any number of threads may call it on one Camera at once.
 * The arithmetic is fixed: the same settings give bit-identical rays
 * (and pictures) whatever calls it.
 *
 * Failure. camera_setup returns -1 with a message in err when eye and at
 * coincide (or are not finite) or up is zero or parallel to the view;
 * nothing here allocates, prints or exits. camera_scene_box returns -1
 * only when memory runs out. */
#ifndef QCS_CAMERA_H
#define QCS_CAMERA_H

#include <stddef.h>

#include "core/vec.h"
#include "render/render.h"
#include "scene/scene.h"

typedef struct Camera {
  double eye[3];                  /* the centre of projection */
  double fwd[3], right[3], upv[3]; /* orthonormal: view, image x, image up */
  double tan_half;                /* tan(fov / 2) */
  double aspect;                  /* width / height */
  int width, height;              /* pixels */
  double lo[3], hi[3];            /* the framed box (see above) */
  int has_box;                    /* 0: no bounded primitive (unit box) */
  double centre[3], radius;       /* its centre and bounding radius R */
} Camera;

/* The box automatic framing frames (see above): 1 and lo, hi set when the
   scene has a bounded primitive, 0 if none (lo, hi untouched), -1 when
   memory runs out. */
int camera_scene_box(const Scene *s, double lo[3], double hi[3]);

/* The camera of rs for a scene whose framed box is lo..hi (has_box 0:
   none, the unit box stands in). 0, or -1 with a message in err. */
int camera_setup(Camera *cam, const RenderSettings *rs, int has_box,
                 const double lo[3], const double hi[3], char *err,
                 size_t errlen);

/* The unit direction of the primary ray through image position (px, py)
   (pixels from the top-left corner); the ray starts at cam->eye. */
void camera_ray(const Camera *cam, double px, double py, double d[3]);

/* camera_ray in three steps, for a renderer that shares a column's or a
   row's factor among its rays (the same values): camera_ray(cam, px, py,
   d) is camera_dir(cam, camera_u(cam, px), camera_v(cam, py), d). */
static inline double camera_u(const Camera *cam, double px) {
  return (2 * px / cam->width - 1) * cam->tan_half * cam->aspect;
}
static inline double camera_v(const Camera *cam, double py) {
  return (1 - 2 * py / cam->height) * cam->tan_half;
}
static inline void camera_dir(const Camera *cam, double u, double v,
                              double d[3]) {
  for (int i = 0; i < 3; i++)
    d[i] = cam->fwd[i] + u * cam->right[i] + v * cam->upv[i];
  double len = sqrt(vec3_dot(d, d));
  for (int i = 0; i < 3; i++) d[i] /= len;
}
#endif
