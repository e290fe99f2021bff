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

/* A RenderCapture (render_lang.h) for qcs -o FILE.stl / FILE.obj: meshes
   the scene a render would draw, with the default tolerance, and writes
   it. ctx is unused. */
int mesh_lang_capture(void *ctx, const struct Scene *s,
                      const struct RenderSettings *rs, const char *path,
                      char *err, size_t errlen);
#endif
