/* resolve.c: the static pass: settle, check and resolve. See resolve.h. */
#include "lang/resolve.h"

#include <gc.h>
#include <string.h>

#include "lang/limits.h"

/* The names one Env frame will hold, in the order they will be bound. */
typedef struct Scope {
  struct Scope *up;
  int n, cap;
  Sym **names;
  Def *owner;    /* the definition of a clause's frame, or NULL */
} Scope;

typedef struct Resolver {
  Interp *I;
  Item **items;  /* the run's items, whose definitions count as known */
  int nitems;
  int depth;     /* of resolve_expr calls: one per 8 KB of max-stack */
  Def *top;      /* the top-level definition being resolved, or NULL */
} Resolver;

/* Notes that the top-level definition being resolved names the global s. */
static void note_use(Resolver *R, Sym *s) {
  Def *d = R->top;
  if (!d) return;
  for (int i = 0; i < d->nuses; i++)
    if (d->uses[i] == s) return;
  if ((d->nuses & (d->nuses - 1)) == 0) {
    Sym **a = GC_MALLOC(sizeof(Sym *) * (size_t)(d->nuses ? 2 * d->nuses : 1));
    if (d->nuses) memcpy(a, d->uses, sizeof(Sym *) * (size_t)d->nuses);
    d->uses = a;
  }
  d->uses[d->nuses++] = s;
}

static void scope_add(Scope *s, Sym *name) {
  if (s->n == s->cap) {
    s->cap = s->cap ? 2 * s->cap : 8;
    Sym **a = GC_MALLOC(sizeof(Sym *) * (size_t)s->cap);
    if (s->n) memcpy(a, s->names, sizeof(Sym *) * (size_t)s->n);
    s->names = a;
  }
  s->names[s->n++] = name;
}

/* ---- settling what the parser left open ---- */

static int is_upper(const Sym *s) { return s->name[0] >= 'A' && s->name[0] <= 'Z'; }
static int is_con_def(const Def *d) {
  return d->name && is_upper(d->name) && d->name->con_arity >= 0;
}

/* A where or let block's `C args = e` with C a constructor is a pattern
   binding, not a function C: the parser cannot tell (it registers no
   constructors), so the block is rewritten here, once constructors are
   installed. Clauses the parser merged (`C a = ..; C b = ..`) become one
   pattern binding each. */
static void settle_defs(int *n, Def ***defs) {
  int extra = 0, any = 0;
  for (int i = 0; i < *n; i++)
    if (is_con_def((*defs)[i])) {
      any = 1;
      extra += (*defs)[i]->nclauses - 1;
    }
  if (!any) return;
  Def **out = GC_MALLOC(sizeof(Def *) * (size_t)(*n + extra));
  int m = 0;
  for (int i = 0; i < *n; i++) {
    Def *d = (*defs)[i];
    if (!is_con_def(d)) {
      out[m++] = d;
      continue;
    }
    for (int c = 0; c < d->nclauses; c++) {
      Clause *cl = d->clauses[c];
      if (cl->nbodies > 1 || cl->guards[0])
        qcs_error(c == 0 && d->guard_pos.line ? d->guard_pos
                  : cl->guards[0] ? cl->guards[0]->pos : cl->pos,
                  "a pattern binding takes no guards");
      Pat *p = GC_MALLOC(sizeof *p);
      p->kind = P_CON;
      p->pos = cl->pos;
      p->u.con.con = d->name;
      p->u.con.n = cl->npats;
      p->u.con.args = cl->pats;
      Clause *pc = GC_MALLOC(sizeof *pc);
      *pc = *cl;
      pc->npats = 0;
      pc->pats = NULL;
      Def *pd = GC_MALLOC(sizeof *pd);
      pd->pos = cl->pos;
      pd->pat = p;
      pd->nclauses = 1;
      pd->clauses = GC_MALLOC(sizeof(Clause *));
      pd->clauses[0] = pc;
      out[m++] = pd;
    }
  }
  *n = m;
  *defs = out;
}

/* ---- patterns ---- */

/* Adds p's variables to s in the order match and pat_bind_vars bind them,
   checking its constructors. */
static void pat_scope(Pat *p, Scope *s) {
  switch (p->kind) {
  case P_VAR: scope_add(s, p->u.var); break;
  case P_CON:
    if (p->u.con.con->con_arity < 0) {
      qcs_error(p->pos, "'%s' in a pattern is not a constructor",
                p->u.con.con->name);
    }
    if (p->u.con.con->con_arity != p->u.con.n)
      qcs_error(p->pos, "constructor %s takes %d argument%s, this pattern "
                "gives %d", p->u.con.con->name, p->u.con.con->con_arity,
                p->u.con.con->con_arity == 1 ? "" : "s", p->u.con.n);
    for (int i = 0; i < p->u.con.n; i++) pat_scope(p->u.con.args[i], s);
    break;
  case P_TUPLE: case P_LIST:
    for (int i = 0; i < p->u.tuple.n; i++) pat_scope(p->u.tuple.items[i], s);
    break;
  case P_CONS:
    pat_scope(p->u.cons.head, s);
    pat_scope(p->u.cons.tail, s);
    break;
  default: break;
  }
}

/* ---- names ---- */

static int defined_in_batch(Resolver *R, Sym *s) {
  for (int i = 0; i < R->nitems; i++)
    if (R->items[i]->kind == ITEM_DEF && R->items[i]->def->name == s) return 1;
  return 0;
}

static _Noreturn void unknown(Resolver *R, Sym *s, Scope *sc, Pos pos) {
  const char *best = NULL;
  int bestd = s->name[1] ? 3 : 1;
  for (Scope *x = sc; x; x = x->up)
    for (int i = 0; i < x->n; i++) {
      int d = edit_distance(s->name, x->names[i]->name);
      if (d < bestd && x->names[i]->name[0] != '%')
        bestd = d, best = x->names[i]->name;
    }
  for (int i = 0; i < R->nitems; i++)
    if (R->items[i]->kind == ITEM_DEF && R->items[i]->def->name) {
      int d = edit_distance(s->name, R->items[i]->def->name->name);
      if (d < bestd) bestd = d, best = R->items[i]->def->name->name;
    }
  resolve_unknown_name(R->I, s, best, bestd, pos);
}

void resolve_unknown_name(Interp *I, Sym *s, const char *best, int bestd,
                          Pos pos) {
  for (size_t h = 0; h < I->symcap; h++)
    for (Sym *g = I->symtab[h]; g; g = g->next)
      if ((g->global || g->lazy || g->con_arity >= 0) && g->name[0] != '%') {
        int d = edit_distance(s->name, g->name);
        if (d < bestd) bestd = d, best = g->name;
      }
  if (best) qcs_error(pos, "unknown name '%s' (did you mean '%s'?)", s->name, best);
  qcs_error(pos, "unknown name '%s'", s->name);
}

static void set_var(Expr *e, int depth, int slot) {
  if (e->u.vslot == RES_SCAN) return;
  if (e->u.vslot && (e->u.vslot != slot || e->u.vdepth != depth)) {
    e->u.vslot = RES_SCAN; /* reached in two scopes: look it up by name */
    return;
  }
  e->u.vdepth = depth;
  e->u.vslot = slot;
}

/* The innermost binding of e's name: the frame `depth` up, the latest
   binding of the name in it (a where binding over a pattern variable of
   the same clause, as the evaluator's scan from the end finds). */
/* Parts.x where Parts names no import, or its file defines no x. */
static _Noreturn void unknown_qualified(Interp *I, Sym *s, Pos pos) {
  const char *dot = strchr(s->name, '.');
  int ql = (int)(dot - s->name);
  for (int i = 0; i < I->nquals; i++)
    if ((int)strlen(I->quals[i]->name) == ql &&
        !strncmp(I->quals[i]->name, s->name, (size_t)ql))
      qcs_error(pos, "unknown name '%s': %s defines no %s", s->name,
                I->qual_files[i], dot + 1);
  qcs_error(pos, "unknown name '%s': no import is named %.*s (import "
            "\"FILE\" as %.*s; for composition write '%.*s . %s')",
            s->name, ql, s->name, ql, s->name, ql, s->name, dot + 1);
}

static void resolve_var(Resolver *R, Expr *e, Scope *sc) {
  Sym *s = e->u.var;
  int depth = 0;
  for (Scope *x = sc; x; x = x->up, depth++)
    for (int i = x->n - 1; i >= 0; i--)
      if (x->names[i] == s) {
        set_var(e, depth, i + 1);
        /* the definitions whose frames were crossed capture it */
        for (Scope *y = sc; y != x; y = y->up)
          if (y->owner) y->owner->closed = 2;
        return;
      }
  /* a global of the prelude's not read yet: read now (one being read,
     a recursion, is defined already) */
  if (s->lazy) {
    interp_materialize(R->I, s);
    if (interp_lazy_pending(s)) {
      note_use(R, s);
      set_var(e, 0, RES_GLOBAL);
      return;
    }
  }
  /* an import's own name that another import took: its qualified one */
  for (int i = 0; i < R->I->nrename; i++)
    if (R->I->rename_from[i] == s) {
      e->u.var = s = R->I->rename_to[i];
      break;
    }
  /* (the prelude's code, read when first used, is resolved as it was
     at start-up, before any import could make a name ambiguous) */
  if (s->ambiguous && !R->I->loading_prelude && !defined_in_batch(R, s))
    qcs_error(e->pos, "'%s' is defined by two imports, %s: write which",
              s->name, s->ambiguous);
  if (s->alias_of) e->u.var = s = s->alias_of;
  if (!s->global && !defined_in_batch(R, s) && s->con_arity < 0 &&
      strchr(s->name, '.'))
    unknown_qualified(R->I, s, e->pos);
  if (s->con_arity >= 0 || s->global || defined_in_batch(R, s)) {
    if (s->con_arity < 0) note_use(R, s);
    set_var(e, 0, RES_GLOBAL);
    return;
  }
  unknown(R, s, sc, e->pos);
}

/* ---- definitions and expressions ---- */

static void resolve(Resolver *R, Expr *e, Scope *sc);

/* Each clause of d runs in a frame of its own (select_clause): its
   patterns, then its where bindings. */
static void resolve_def(Resolver *R, Def *d, Scope *sc);

/* A 0-ary local binding with one plain body: bind_defs makes it a thunk of
   the body in the block's own frame, with no frame of its own. */
static int plain_local(const Def *d) {
  if (d->pat || d->arity > 0 || d->nclauses != 1) return 0;
  const Clause *c = d->clauses[0];
  return c->nbodies == 1 && !c->guards[0] && c->nwhere == 0;
}

/* A where or let block, bound in the frame s (which the caller made). */
static void resolve_block(Resolver *R, int *n, Def ***defs, Scope *s) {
  settle_defs(n, defs);
  for (int i = 0; i < *n; i++) {
    Def *w = (*defs)[i];
    if (w->pat) pat_scope(w->pat, s);
    else scope_add(s, w->name);
  }
  for (int i = 0; i < *n; i++) {
    Def *w = (*defs)[i];
    if (plain_local(w)) resolve(R, w->clauses[0]->bodies[0], s);
    else resolve_def(R, w, s);
  }
}

static void resolve_def(Resolver *R, Def *d, Scope *sc) {
  if (!d->closed) d->closed = 1;
  for (int c = 0; c < d->nclauses; c++) {
    Clause *cl = d->clauses[c];
    Scope s = {sc, 0, 0, NULL, d};
    for (int i = 0; i < cl->npats; i++) pat_scope(cl->pats[i], &s);
    if (cl->nwhere) resolve_block(R, &cl->nwhere, &cl->where, &s);
    for (int b = 0; b < cl->nbodies; b++) {
      if (cl->guards[b]) resolve(R, cl->guards[b], &s);
      resolve(R, cl->bodies[b], &s);
    }
  }
}

/* The AST's depth is bounded here, before anything runs: a chain of a
   million '+' would otherwise recurse a million deep in eval. */
static void resolve_body(Resolver *R, Expr *e, Scope *sc);
static void resolve(Resolver *R, Expr *e, Scope *sc) {
  if ((size_t)++R->depth > R->I->stack_limit >> 13)
    eval_limit_error(R->I, e->pos, "max-stack",
                     "expression nested too deeply to evaluate");
  eval_stack_check(R->I, e->pos,
                   "expression nested too deeply: checking it needs");
  resolve_body(R, e, sc);
  R->depth--;
}

static void resolve_body(Resolver *R, Expr *e, Scope *sc) {
  switch (e->kind) {
  case E_VAR: resolve_var(R, e, sc); break;
  case E_WILD: qcs_error(e->pos, "'_' stands only in patterns");
  case E_APP:
    resolve(R, e->u.app.fn, sc);
    for (int i = 0; i < e->u.app.n; i++) resolve(R, e->u.app.args[i], sc);
    break;
  case E_LAMBDA: resolve_def(R, e->u.lambda, sc); break;
  case E_LET: {
    Scope s = {sc, 0, 0, NULL, NULL};
    resolve_block(R, &e->u.let.n, &e->u.let.defs, &s);
    resolve(R, e->u.let.body, &s);
    break;
  }
  case E_IF:
    resolve(R, e->u.cond.c, sc);
    resolve(R, e->u.cond.t, sc);
    resolve(R, e->u.cond.f, sc);
    break;
  case E_TUPLE: case E_LIST:
    for (int i = 0; i < e->u.tuple.n; i++) resolve(R, e->u.tuple.items[i], sc);
    break;
  case E_RANGE:
    resolve(R, e->u.range.from, sc);
    if (e->u.range.then) resolve(R, e->u.range.then, sc);
    if (e->u.range.to) resolve(R, e->u.range.to, sc);
    break;
  case E_BINOP:
    resolve(R, e->u.bin.a, sc);
    resolve(R, e->u.bin.b, sc);
    break;
  case E_NEG: resolve(R, e->u.neg, sc); break;
  case E_DEFBODY: resolve_def(R, e->u.def, sc); break;
  default: break;
  }
}

void resolve_items(Interp *I, Item **items, int n) {
  Resolver R = {I, items, n, 0, NULL};
  for (int i = 0; i < n; i++) {
    if (items[i]->kind == ITEM_DEF) {
      R.top = items[i]->def;
      R.top->nuses = 0;
      resolve_def(&R, items[i]->def, NULL);
      if (items[i]->param) {
        if (items[i]->param->lo) resolve(&R, items[i]->param->lo, NULL);
        if (items[i]->param->hi) resolve(&R, items[i]->param->hi, NULL);
      }
      R.top = NULL;
    } else if (items[i]->kind == ITEM_EXPR) {
      resolve(&R, items[i]->expr, NULL);
    }
  }
}

void resolve_expr(Interp *I, Expr *e) {
  Resolver R = {I, NULL, 0, 0, NULL};
  resolve(&R, e, NULL);
}
