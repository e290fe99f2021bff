/* progressive.h: a picture coarse first, then finer, for people waiting.
 *
 * What it owns. One render of a scene at a final size, done as a ladder of
 * renders at 1/8, 1/4, 1/2 and the full size (every 8th pixel of each
 * side, then every 4th, 2nd, all), on a thread of its own, so that a
 * caller can show the first picture within a few milliseconds and replace
 * it as the finer ones arrive (the REPL's pictures at the prompt; a viewer).
 * The camera is the same at every rung: each rung keeps the full size's
 * aspect ratio exactly (the full size is rounded to a multiple of 8 first,
 * see prog_size).
 *
 * Threads. prog_start copies the settings and borrows the scene, which
 * must stay alive and unchanged until prog_stop returns. The ladder runs
 * on its own thread (and each rung on rs->threads workers); the caller
 * waits for rungs with prog_wait from one thread. prog_stop cancels what
 * is left at once (the render workers read the cancel flag per tile) and
 * joins.
 *
 * Failure. A rung that fails (out of memory, bad settings) ends the ladder
 * with its message; nothing here prints. */
#ifndef QCS_PROGRESSIVE_H
#define QCS_PROGRESSIVE_H

#include "render/render.h"

typedef struct Progressive Progressive;

/* The rungs: 8, 4, 2, 1 (pixels of the full size per pixel of the rung). */
#define PROG_RUNGS 4

/* The full size a ladder renders for a wanted w x h: each side rounded
   down to a multiple of 8 (at least 8). */
void prog_size(int w, int h, int *fw, int *fh);

/* Start the ladder for s with settings rs (its width and height are the
   full size, already a multiple of 8: see prog_size). NULL with a message
   in err when memory or a thread cannot be had. */
Progressive *prog_start(const Scene *s, const RenderSettings *rs, char *err,
                        size_t errlen);

enum { PROG_TIMEOUT = 0, PROG_RUNG = 1, PROG_DONE = 2, PROG_FAILED = 3 };

/* Wait up to timeout_ms (-1: no limit) for the next finished rung.
   PROG_RUNG: *im is that rung's image (owned by the ladder, valid until
   the next prog_wait or prog_stop), *step its 8, 4, 2 or 1 and *rep its
   report. PROG_DONE: every rung has been handed out. PROG_FAILED: a rung
   failed; its message is in err. PROG_TIMEOUT: nothing new yet. */
int prog_wait(Progressive *p, int timeout_ms, const Image **im, int *step,
              RenderReport *rep, char *err, size_t errlen);

/* Cancel what is left, join the thread, free everything. NULL is fine. */
void prog_stop(Progressive *p);
#endif
