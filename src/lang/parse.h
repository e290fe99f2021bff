/* parse.h: tokens to items (definitions, type declarations, expressions).
 *
 * A recursive-descent parser with precedence climbing for operators, and
 * a layout rule in the spirit of Clean and Haskell: in a script a line
 * that starts in column 1 begins a new item (so ';' is optional), and the
 * bindings of a `where` or `let` block line up in one column. Errors are
 * raised with qcs_error (qcs_error_incomplete when the text ends too
 * soon, so the REPL can ask for another line). Everything is allocated in
 * the GC heap.
 *
 * State: parsing defines nothing. The only change it makes to the Interp
 * is interning names (sym_intern adds a Sym with no value, which is not a
 * definition: the checker, completion and :browse look at values and
 * constructors, not at the table's size). It reads the stack limit for
 * its nesting check (limits.h). Type declarations come back as ITEM_TYPE
 * items; their constructors are installed when the items run (interp.c),
 * so a text that fails to parse, or is only parsed (fuzz_parse), leaves
 * the interpreter as it found it. Whether a where/let binding `C x = e` is
 * a function C or a pattern binding depends on whether C is a constructor
 * then, so it is settled by resolve.c, not here.
 *
 * Threads: one parse at a time per Interp (sym_intern is not locked). */
#ifndef QCS_PARSE_H
#define QCS_PARSE_H

#include "lang/ast.h"
#include "lang/interp.h"
#include "lang/value.h"

/* Parse all items of src. */
Item **parse_program(Interp *I, const Src *src, RunMode mode, int *nitems);

/* Parse the items of src's text from byte start, which begins line
   `line`, to byte end, where a line begins outside any comment or
   string (MODE_SCRIPT): one of the prelude's definitions (interp.c). */
Item **parse_range(Interp *I, const Src *src, size_t start, size_t end,
                   int line, int *nitems);

/* Parse src as a single expression (for -e and --set). */
Expr *parse_expression(Interp *I, const Src *src);

/* Operator token to its spelling, e.g. T_PLUS -> "+". */
const char *op_text(TokKind op);
#endif
