/* repl.h: the interactive front end of qcs.
 *
 * On a terminal, a GNU readline loop: "qcs> " and "...> " prompts, entries
 * that continue while the interpreter says RUN_INCOMPLETE, ":{ ... :}"
 * blocks, :commands, Tab completion, history in ~/.qcs_history and Ctrl-C
 * that stops an evaluation (or abandons the line being typed). Readline is
 * driven through its callback interface from a select() loop, so signals
 * are seen by this module, never inside readline.
 *
 * When stdin is not a terminal the same entries are read plainly, line by
 * line, with no prompts and no history, so scripts can pipe text in.
 *
 * Memory: this module allocates with malloc and frees what it allocates;
 * nothing it hands out needs freeing. It uses only the interpreter's face,
 * interp.h. */
#ifndef QCS_REPL_H
#define QCS_REPL_H

#include "lang/interp.h"

/* Run the REPL on stdin until end of input or :quit. Returns the process
   exit status: 0 after an interactive session; with a non-terminal stdin,
   1 if any entry reported an error, else 0. */
int repl_run(Interp *I);

/* Install the SIGINT handler that asks a running evaluation to stop
   (interp_request_interrupt). A third Ctrl-C during one evaluation that
   does not stop quits the process with status 130. repl_run installs it
   itself on a terminal; main may call it before running scripts too.
   Idempotent. */
void repl_install_sigint(void);

#endif
