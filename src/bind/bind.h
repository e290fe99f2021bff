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
 * the probes and the renderer's, and the prelude.
 *
 * Errors: this layer speaks both styles and translates between them. It
 * is called by the evaluator, so it raises the interpreter's positioned
 * errors (qcs_error, lang/error.h) at the user's constructor or call; what
 * it gets back from the layers below is a return code and a message
 * (render_scene, mesh_scene, mesh_write, img_write_*), which it raises
 * at the same position. Memory it mallocs for a scene or an image while a call may
 * still raise is registered on the error frame's cleanup list, so an
 * error frees it.
 *
 * Memory: a compiled Scene is malloc'd, holds no pointer into the
 * garbage-collected heap (source positions are integer tags), and belongs
 * to the caller (scene_free); it may outlive the interpreter, which is how
 * the preview and the viewer render beside the prompt and in server
 * threads.
 *
 * Threads: everything here runs on the interpreter's thread, which is the
 * only one that may touch Values; the renders it starts use worker threads
 * that see only the Scene. */
#ifndef QCS_BIND_H
#define QCS_BIND_H

#include "lang/interp.h"

/* A new interpreter with every built-in of qcs and the prelude. */
Interp *bind_interp_new(void);

/* Install the probes and the render built-ins into I (what
   bind_interp_new passes to interp_new). */
void bind_install(Interp *I);
#endif
