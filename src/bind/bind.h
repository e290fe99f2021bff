/* bind.h: the layer that sees both sides.
 *
 * Below it, the geometry core (core/), the compiled scene (scene/) and the
 * renderer (render/) know nothing of the language; beside them the
 * language (lang/) knows nothing of geometry. This layer joins them:
 * values compiled into scenes (compile.h), the probes (probes.h), the
 * render built-ins and the command line's render overrides
 * (render_lang.h), and reports as text (report.h).
 *
 * bind_interp_new is how a front end (app/, the fuzz targets, the tests)
 * gets the whole language: an interpreter with the language's built-ins,
 * the probes and the renderer's, and the prelude. */
#ifndef QCS_BIND_H
#define QCS_BIND_H

#include "lang/interp.h"

/* A new interpreter with every built-in of qcs and the prelude. */
Interp *bind_interp_new(void);

/* Install the probes and the render built-ins into I (what
   bind_interp_new passes to interp_new). */
void bind_install(Interp *I);
#endif
