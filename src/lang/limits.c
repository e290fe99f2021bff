/* limits.c: the errors of the resource limits. See limits.h. */
#include "lang/limits.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "lang/interp.h"

_Noreturn void eval_limit_error(Interp *I, Pos pos, const char *limit,
                                const char *fmt, ...) {
  char msg[700];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  const char *arg =
      !strcmp(limit, "max-stack") || !strcmp(limit, "max-memory") ? "SIZE"
                                                                  : "N";
  qcs_error(pos.line ? pos : I->item_pos, "%s (limit %s; raise it with :set "
            "%s %s or --%s %s)", msg, limit, limit, arg, limit, arg);
}

void eval_stack_error(Interp *I, Pos pos, const char *what,
                      const char *after) {
  char sz[32];
  interp_format_size(sz, sizeof sz, I->stack_limit);
  eval_limit_error(I, pos, "max-stack", "%s more than %s of stack%s", what, sz,
                   after);
}
