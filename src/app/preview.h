/* preview.h: pictures in the terminal.
 *
 * What it owns. Showing a compiled scene as a picture where the user types:
 * a progressive render (render/progressive.h: every 8th pixel first, then
 * every 4th, 2nd, all) drawn in place with libchafa, the library behind
 * the `chafa` command, in the best form the terminal understands: kitty's
 * graphics protocol, iTerm2's inline images, sixels, or Unicode symbol art
 * in 24-bit colour (which works everywhere: tmux, SSH, a plain xterm).
 *
 * Detection. PREVIEW_AUTO asks chafa's terminal database what the
 * terminal is, from the environment (TERM, TERM_PROGRAM, KITTY_WINDOW_ID,
 * VTE_VERSION, TMUX, ...), as `chafa` does, and, where that leaves the
 * terminal unnamed, what the terminal answers to DA1 at start-up
 * (preview_query_terminal); inside tmux or screen, which do not pass
 * graphics through by default, it uses symbols. Nothing is
 * drawn automatically when the output is not a terminal: for PREVIEW_AUTO
 * preview_resolve answers PREVIEW_OFF for a pipe or a file. A mode asked
 * for by name is drawn wherever the output goes, as `chafa -f` does.
 *
 * Interruption. A key waiting on the input (the user has started typing)
 * or the stop flag (Ctrl-C) ends the ladder at once; the key stays unread
 * for the prompt. Every exit path leaves the terminal's attributes reset
 * and the cursor on the line after the picture.
 *
 * Threads. preview_show runs on the caller's thread and waits for the
 * render threads it starts; the scene is borrowed for the call. */
#ifndef QCS_PREVIEW_H
#define QCS_PREVIEW_H

#include <stdatomic.h>
#include <stdio.h>

#include "render/render.h"

typedef enum {
  PREVIEW_OFF,
  PREVIEW_AUTO,
  PREVIEW_KITTY,
  PREVIEW_ITERM,
  PREVIEW_SIXEL,
  PREVIEW_SYMBOLS
} PreviewMode;

/* "off", "auto", "kitty", "iterm", "sixel", "symbols". */
const char *preview_mode_name(PreviewMode m);
/* 0 with *m set, or -1 if s names no mode. */
int preview_mode_parse(const char *s, PreviewMode *m);

/* The mode to draw with on fd: for PREVIEW_AUTO, PREVIEW_OFF if fd is not
   a terminal, else the detected one; any other m as it is. */
PreviewMode preview_resolve(PreviewMode m, int fd);

/* Ask the terminal on in_fd/out_fd what it is, as chafa does where the
   environment leaves it unsaid: DA1 (ESC [ c), which every VT100-like
   terminal answers, and whose attribute 4 means sixels. Only when both are
   terminals and the terminal is not tmux, screen or dumb; the input is
   read raw for at most timeout_ms and restored. Meant for start-up, before
   the first prompt (a key typed meanwhile would be read with the answer).
   Remembered for preview_resolve's PREVIEW_AUTO. Returns 0 (not asked, or
   no answer in time), 1 (no sixels) or 2 (sixels). */
int preview_query_terminal(int in_fd, int out_fd, int timeout_ms);

/* The DA1 reply "ESC [ ? P1 ; ... c" within buf: 1 if there is one, with
   *sixel = 1 when an attribute is 4; 0 if none is complete. */
int preview_parse_da1(const char *buf, size_t n, int *sixel);

/* The largest preview, in character cells. */
#define PREVIEW_MAX_COLS 400
#define PREVIEW_MAX_ROWS 200

typedef struct PreviewOptions {
  PreviewMode mode;   /* resolved: not PREVIEW_AUTO or PREVIEW_OFF */
  int cols, rows;     /* size in cells; 0: from the terminal, capped */
  int out_fd;         /* the terminal drawn on (for its size) */
  int input_fd;       /* a key waiting here stops the ladder; -1: none */
  atomic_int *stop;   /* set (Ctrl-C) stops the ladder; may be NULL */
} PreviewOptions;

typedef struct PreviewResult {
  int rungs;          /* pictures drawn (0 .. 4) */
  int finest;         /* the step of the last one drawn: 8, 4, 2 or 1 */
  int stopped;        /* a key or the stop flag ended it early */
  double t_first;     /* seconds from the call to the first picture drawn */
  double t_full;      /* ... to the full one (0 if not reached) */
  int width, height;  /* the full picture's pixels */
  RenderReport rep;   /* the report of the finest rung */
} PreviewResult;

/* The cells and pixels a preview of an aspect w:h takes on the terminal
   out_fd for mode m, given cols x rows (0: automatic). */
void preview_geometry(PreviewMode m, int out_fd, int cols, int rows,
                      double aspect, int *out_cols, int *out_rows, int *px_w,
                      int *px_h);

/* Draw s progressively on out with base's settings (its size is replaced
   by the preview's). 0 on success (also when stopped early), or -1 with a
   message in err (out of memory, a render that failed); res may be NULL. */
int preview_show(FILE *out, const Scene *s, const RenderSettings *base,
                 const PreviewOptions *o, PreviewResult *res, char *err,
                 size_t errlen);
#endif
