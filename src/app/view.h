/* view.h: `qcs view FILE` and `:view`, a live viewer in the browser.
 *
 * What it owns. A local HTTP server (libmicrohttpd) serving one page
 * (app/view_page.html, embedded at build time) that shows the scene's
 * picture coarse first, follows the file (inotify on its folder, so an
 * editor's write-rename-delete counts as a save), orbits, pans and zooms,
 * and answers a click with the probes of that pixel's ray.
 *
 * Threads. The interpreter (Boehm heap) is used only by the caller's
 * thread, the one that calls view_file or view_scene: it evaluates the
 * file, compiles the scene and publishes it, with the per-node source
 * positions turned into text, as an immutable, reference-counted
 * snapshot. The server's threads (one per connection, at most
 * VIEW_MAX_CLIENTS) and one render thread read only snapshots: they never
 * touch a Value. A new camera cancels the frame being rendered at once
 * (render_scene's cancel flag, read per tile).
 *
 * Parameters. The interpreter of the last good evaluation stays alive (on
 * the caller's thread). A slider's value, checked by the server thread
 * against the published table of declared parameters (name, finite,
 * within range), is stored and the caller's thread woken through a pipe;
 * it re-binds the parameter (interp_set_param: only what depends on it is
 * evaluated again), re-runs the scripts' expressions and publishes. A save
 * of the file evaluates it in a new interpreter and applies the values
 * again.
 *
 * Security. 127.0.0.1 only unless --listen says otherwise; a random token
 * in the URL is required on every request; a Host or Origin header that
 * names another host is refused (DNS rebinding). Nothing is written but
 * the explicit "save" button's image, into the scene's folder, through
 * the atomic writers (render/image.h).
 *
 * Memory. Requests carry no body (one is refused); a connection's buffers
 * are bounded by libmicrohttpd (VIEW_CONN_MEMORY); frames are at most one
 * picture per rung, shared by all clients. */
#ifndef QCS_VIEW_H
#define QCS_VIEW_H

#include <stddef.h>

#include "lang/interp.h"
#include "scene/scene.h"

#define VIEW_MAX_CLIENTS 64

typedef struct ViewOptions {
  const char *listen;  /* "ADDR:PORT", or NULL: 127.0.0.1 and a free port */
  int threads;         /* render threads (0: the scene's, else all cores) */
  /* qcs view FILE: a fresh interpreter for every evaluation, set up as the
     command line's (stack, limits, --set); NULL: bind_interp_new alone. */
  Interp *(*new_interp)(void *ud);
  void *ud;
  int quiet;           /* do not echo evaluation errors on stderr */
} ViewOptions;

/* Parse "ADDR:PORT" (ADDR an IPv4 address); 0, or -1 with a message. */
int view_parse_listen(const char *s, char *err, size_t errlen);

/* Serve FILE until SIGINT or SIGTERM, re-evaluating it on every save.
   Returns the exit status (0, or 1 when the server cannot start). */
int view_file(const char *file, const ViewOptions *o);

/* Serve one compiled scene (taken: freed here) with settings rs, src_I the
   interpreter it came from (for the nodes' source positions), until
   Ctrl-C or a line on standard input (the REPL's :view). 0, or -1. */
struct RenderSettings;
int view_scene(Interp *src_I, Scene *s, const struct RenderSettings *rs,
               const ViewOptions *o);

/* Evaluate expr (a scene object) in I as the prompt would and serve it
   with view_scene; -1 (the error reported) if it is not a scene. */
int view_expr(Interp *I, const char *expr, const ViewOptions *o);
#endif
