/* mesh_lang.h: the mesh built-ins of the language and qcs -o FILE.stl.
 *
 *   mesh "part.stl" obj
 *   meshWith [Tolerance e, Bounds lo hi, MaxTriangles n, Quiet] "part.obj" obj
 *
 * The mesh is written whole or not at all (render/mesh.h); the report
 * goes to stderr; the value is the file name. */
#ifndef QCS_MESH_LANG_H
#define QCS_MESH_LANG_H

#include <stddef.h>

#include "lang/interp.h"

struct Scene;
struct RenderSettings;

void mesh_lang_install(Interp *I);

/* qcs -o FILE.stl's settings (main.c): the interpreter, whose max-memory
   bounds the mesh; the tolerance (--mesh-tolerance; <= 0: the default,
   1/100 of the object's largest side); the box (--bounds). */
typedef struct MeshCli {
  Interp *I;
  double tol;
  int has_bounds;
  double lo[3], hi[3];
} MeshCli;

/* A RenderCapture (render_lang.h) for qcs -o FILE.stl / FILE.obj: meshes
   the scene a render would draw and writes it. ctx is a MeshCli, or NULL
   (the defaults). */
int mesh_lang_capture(void *ctx, const struct Scene *s,
                      const struct RenderSettings *rs, const char *path,
                      char *err, size_t errlen);
#endif
