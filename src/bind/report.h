/* report.h: what the lower layers return, as text for people.
 *
 * The render layer returns a RenderReport and calls a progress callback;
 * neither prints. This is where they become lines on a stream: the
 * render's cost (size, time, rays, evaluations, segments, steps, the
 * tolerance in force) and the progress line on a terminal. */
#ifndef QCS_REPORT_H
#define QCS_REPORT_H

#include <stdio.h>

#include "render/render.h"

/* The report of one render written to path: size, time, rays,
   evaluations, segments, steps (mean and maximum per ray) and the root
   tolerance in force. */
void report_render(FILE *out, const RenderReport *rep, const char *path);

/* The report's last line: the seconds spent encoding and writing the file
   (PNG compression, EXR, PPM), which the render's time leaves out. */
void report_written(FILE *out, double seconds);

/* One line about a compiled scene, for the picture at the prompt:
   "WHAT: KIND, N leaves, box (x, y, z) .. (x, y, z)" (or "unbounded"),
   where WHAT is the caller's short text (the value as printed, cut). */
void report_scene(char *buf, size_t n, const Scene *s, const char *what);

/* A RenderSettings progress callback that keeps one line updated on
   stderr ("rendering 42%, 1.3 s left") and clears it at the end; ud is
   unused. Meant for a terminal: callers set it only when stderr is one. */
void report_progress(void *ud, double frac, double seconds_left);
#endif
