/* fuzz_parse: the lexer and the parser on arbitrary bytes, as a script and
 * as a REPL entry, and as a single expression. Nothing is evaluated.
 * Every input must end in items or in an error, never a crash. */
#include "fuzz.h"

#include <gc.h>

#include "lang/error.h"
#include "lang/lex.h"
#include "lang/parse.h"

static Interp *I;

static void parse_as(const Src *src, RunMode mode, int expr) {
  ErrFrame f;
  if (ERR_TRY(f)) {
    int n = 0;
    if (expr)
      (void)parse_expression(I, src);
    else
      (void)parse_program(I, src, mode, &n);
  }
  err_pop(&f);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (!I) I = bind_interp_new();
  FUZZ_STACK(I);
  Src src = {"<fuzz>", fuzz_text(data, size), 0, NULL, 0};
  parse_as(&src, MODE_SCRIPT, 0);
  parse_as(&src, MODE_REPL, 0);
  parse_as(&src, MODE_REPL, 1);
  free((char *)src.text);
  return 0;
}
