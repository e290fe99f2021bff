/* camera.c: the pinhole camera and the automatic framing. See camera.h. */
#include "render/camera.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/soft.h"
#include "core/vec.h"


/* The primitives in the renderer's order (the top-level union, a before
   b, Empty skipped), boxed by render_node_box (a soft object by
   soft_surface_bounds: where its surface can be); an explicit stack. */
int camera_scene_box(const Scene *s, double lo[3], double hi[3]) {
  int local[32], *st = local, cap = 32, n = 0, any = 0;
  double blo[3] = {INFINITY, INFINITY, INFINITY};
  double bhi[3] = {-INFINITY, -INFINITY, -INFINITY};
  if (s->root < 0) return 0;
  st[n++] = s->root;
  while (n) {
    const int node = st[--n];
    const ScNode *nd = &s->nodes[node];
    if (nd->kind == SC_UNION) {
      if (n + 2 > cap) {
        int cap2 = 2 * cap;
        int *q = st == local ? malloc(sizeof *q * (size_t)cap2)
                             : realloc(st, sizeof *q * (size_t)cap2);
        if (!q) {
          if (st != local) free(st);
          return -1;
        }
        if (st == local) memcpy(q, local, sizeof local);
        st = q;
        cap = cap2;
      }
      st[n++] = nd->b;
      st[n++] = nd->a;
      continue;
    }
    if (nd->kind == SC_EMPTY) continue;
    double plo[3], phi[3];
    /* a soft object by where its surface can be, not by its keys' reach */
    if (nd->kind == SC_SOFT) {
      if (!soft_surface_bounds(nd->soft, plo, phi)) continue;
    } else if (!render_node_box(s, node, plo, phi)) {
      continue; /* unbounded */
    }
    for (int i = 0; i < 3; i++) {
      blo[i] = fmin(blo[i], plo[i]);
      bhi[i] = fmax(bhi[i], phi[i]);
    }
  }
  if (st != local) free(st);
  any = !(blo[0] > bhi[0] || blo[1] > bhi[1] || blo[2] > bhi[2]);
  if (any) {
    memcpy(lo, blo, sizeof blo);
    memcpy(hi, bhi, sizeof bhi);
  }
  return any;
}

int camera_setup(Camera *cam, const RenderSettings *rs, int has_box,
                 const double lo[3], const double hi[3], char *err,
                 size_t errlen) {
  memset(cam, 0, sizeof *cam);
  cam->has_box = has_box;
  for (int i = 0; i < 3; i++) {
    cam->lo[i] = has_box ? lo[i] : 0;
    cam->hi[i] = has_box ? hi[i] : 1;
  }
  double R = 0, at[3];
  for (int i = 0; i < 3; i++) {
    cam->centre[i] = 0.5 * (cam->lo[i] + cam->hi[i]);
    R += 0.25 * (cam->hi[i] - cam->lo[i]) * (cam->hi[i] - cam->lo[i]);
  }
  R = fmax(sqrt(R), 1e-9);
  cam->radius = R;
  if (rs->camera_set) {
    memcpy(cam->eye, rs->eye, sizeof cam->eye);
    memcpy(at, rs->at, sizeof at);
  } else {
    /* Frame the box: look at its centre from the front, above and to the
       right, far enough that the bounding sphere fits the view. */
    double dir[3] = {0.45, 0.6, 1};
    double len = sqrt(vec3_dot(dir, dir));
    double dist = R / sin(fmin(rs->fov, 120) * M_PI / 360) * 1.05;
    for (int i = 0; i < 3; i++) {
      at[i] = cam->centre[i];
      cam->eye[i] = cam->centre[i] + dir[i] / len * dist;
    }
  }
  for (int i = 0; i < 3; i++) cam->fwd[i] = at[i] - cam->eye[i];
  double fl = sqrt(vec3_dot(cam->fwd, cam->fwd));
  if (!(fl > 0) || !isfinite(fl)) {
    snprintf(err, errlen, "the camera's eye and at must differ");
    return -1;
  }
  for (int i = 0; i < 3; i++) cam->fwd[i] /= fl;
  vec3_cross(cam->fwd, rs->up, cam->right);
  double rl = sqrt(vec3_dot(cam->right, cam->right));
  if (!(rl > 1e-12)) {
    snprintf(err, errlen, "the camera's up direction is zero or parallel to its view");
    return -1;
  }
  for (int i = 0; i < 3; i++) cam->right[i] /= rl;
  vec3_cross(cam->right, cam->fwd, cam->upv);
  cam->width = rs->width;
  cam->height = rs->height;
  cam->tan_half = tan(rs->fov * M_PI / 360);
  cam->aspect = (double)rs->width / rs->height;
  return 0;
}

void camera_ray(const Camera *cam, double px, double py, double d[3]) {
  camera_dir(cam, camera_u(cam, px), camera_v(cam, py), d);
}
