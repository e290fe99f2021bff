/* print.h: values printed in the language's own syntax, so that what the
 * REPL shows can be typed back: Reals in the shortest decimal that reads
 * back to the same double, tuples, lists, strings with escapes, and
 * constructor trees as applications with parentheses where needed.
 *
 * Printing forces what it prints, so it can raise any evaluation error
 * (and the limits: max-list for a long list, max-memory for show's text);
 * output written before the error stays written. Same thread rules as the
 * evaluator. */
#ifndef QCS_PRINT_H
#define QCS_PRINT_H

#include <stdio.h>

#include "lang/value.h"

/* Print v, forcing it completely (an infinite list prints until
   interrupted). */
void print_value(Interp *I, FILE *out, Value *v);
/* The printed form as a GC string. */
const char *show_value(Interp *I, Value *v);
/* Print v without forcing anything: thunks show as "...", and lists and
   trees are cut after a few elements or `depth` levels. */
void print_brief(FILE *out, Value *v, int depth);
/* The shortest decimal form of x that reads back as x ("0.1", "1e-12",
   "3"); buf needs 32 bytes. */
void format_real(char *buf, double x);
/* As format_real with digits <= 0; else x rounded to that many significant
   digits (at most 17), trailing zeros dropped ("1" for 1.000000000000001
   at 15 digits). The REPL's :set digits N and showReal use it. */
void format_real_digits(char *buf, double x, int digits);
#endif
