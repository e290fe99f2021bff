/* resolve.h: the static pass between parsing and running.
 *
 * One walk over the AST of a run's items (or of one --set expression),
 * before anything is installed or evaluated. It
 *   - settles what the parser could not know because it registers nothing
 *     (see parse.h): a where/let binding `C x = e` whose C is a
 *     constructor is rewritten into the pattern binding it is;
 *   - checks every pattern's constructor (known, right arity);
 *   - resolves every variable: to a local, as (vdepth, vslot) in the
 *     Expr (the frame `vdepth` links up the Env chain the evaluator will
 *     have there, and the binding `vslot - 1` in it), or to a global
 *     (vslot == RES_GLOBAL: the evaluator goes straight to the Sym);
 *   - reports an unknown name, with a "did you mean" among the names in
 *     scope there, the run's own definitions and the globals;
 *   - bounds the depth of expressions, so evaluation cannot recurse a
 *     million deep into one (max-stack).
 *
 * Invariant: the scopes here are the Env frames of eval.c, one for one and
 * bound in the same order: a clause's frame holds its pattern variables
 * (left to right, depth first, as match binds them) then its where
 * bindings (as bind_defs binds them); a let makes one frame; a 0-ary local
 * binding whose one body has no guard and no where runs in its block's
 * frame and makes none, every other definition makes one per clause. A
 * change to how eval.c makes frames must change this file too. The
 * evaluator checks each resolved slot's name (one pointer compare) and
 * scans by name if it differs, so a mismatch would cost speed, not
 * correctness; an E_VAR the pass never saw (vslot 0) is scanned for too.
 *
 * Globals are never resolved to values here: they are looked up at run
 * time through the Sym, so REPL redefinitions, --set overrides and the
 * prelude's view of its own definitions (Sym.prelude_value) are as before.
 *
 * Failure modes: the first problem is raised with qcs_error (error.h);
 * the AST may then be partly resolved and partly rewritten, which is
 * harmless, as a run that fails here runs nothing.
 *
 * Threads: as the Interp, one thread at a time; it reads the symbol table
 * (constructors, globals) and writes only the AST it is given. */
#ifndef QCS_RESOLVE_H
#define QCS_RESOLVE_H

#include "lang/ast.h"
#include "lang/value.h"

/* The vslot of a variable resolved to a global (or a constructor). */
#define RES_GLOBAL (-1)
/* The vslot of one that must be looked up by name (an Expr reached twice
   in different scopes; the parser shares none today). */
#define RES_SCAN (-2)

/* Check and resolve the n items of one run. Constructors of the run's
   type declarations must be installed already; its definitions need not
   be (a name defined anywhere in the items is known everywhere in them). */
void resolve_items(Interp *I, Item **items, int n);

/* Check and resolve one expression at the top level (qcs --set). */
void resolve_expr(Interp *I, Expr *e);

/* The error for an unknown name at pos: "did you mean" the closest of
   best (a local candidate the caller found at distance bestd, or NULL)
   and every global name. Also the evaluator's, for a name it cannot find
   at run time. */
_Noreturn void resolve_unknown_name(Interp *I, Sym *s, const char *best,
                                    int bestd, Pos pos);

#endif
