/* parse.h: tokens to items (definitions, type declarations, expressions).
 *
 * A recursive-descent parser with precedence climbing for operators, and
 * a layout rule in the spirit of Clean and Haskell: in a script a line
 * that starts in column 1 begins a new item (so ';' is optional), and the
 * bindings of a `where` or `let` block line up in one column. Errors are
 * raised with qcs_error (qcs_error_incomplete when the text ends too
 * soon, so the REPL can ask for another line). Everything is allocated in
 * the GC heap. */
#ifndef QCS_PARSE_H
#define QCS_PARSE_H

#include "lang/ast.h"
#include "lang/interp.h"
#include "lang/value.h"

/* Parse all items of src. */
Item **parse_program(Interp *I, const Src *src, RunMode mode, int *nitems);

/* Parse src as a single expression (for -e and --set). */
Expr *parse_expression(Interp *I, const Src *src);

/* Operator token to its spelling, e.g. T_PLUS -> "+". */
const char *op_text(TokKind op);
#endif
