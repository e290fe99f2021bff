/* parse.c: the qcs parser. See parse.h; the grammar is lang/grammar.ebnf. */
#include "lang/parse.h"

#include <gc.h>
#include <string.h>

#include "lang/limits.h"

#define LAYOUT_MAX 256

typedef struct Parser {
  Interp *I;
  const Src *src;
  Token *toks;
  int ntoks, i;
  int lay_col[LAYOUT_MAX], lay_br[LAYOUT_MAX], nlay;
  int bracket;   /* depth of open ( and [ */
  Token *open_tok[LAYOUT_MAX]; /* the innermost open brackets */
  int sep_used;  /* index of the token whose virtual separator was used */
  RunMode mode;
  int depth, max_depth; /* nesting of operand/binary calls (see below) */
} Parser;

static Expr *expr(Parser *P);
static Expr *app(Parser *P);
static Expr *binary(Parser *P, int minprec);

/* Deep nesting ((((... a million brackets, - - - ... 1, a : b : ...) is
   stopped under the max-stack limit, as deep recursion in evaluation is:
   by a count of nested operand and binary calls (a bracket is two), one
   per 8 KB of the limit (16384 brackets with the default 256M), so that
   where it stops does not depend on how large the compiler made the
   frames (AddressSanitizer's are five times gcc's); and by the stack
   itself. */
#define NESTING_CHECK(P)                                                       \
  eval_stack_check((P)->I, (P)->toks[(P)->i].pos,                              \
                   "expression nested too deeply: parsing it needs")
static void nesting_enter(Parser *P) {
  if (++P->depth > P->max_depth)
    eval_limit_error(P->I, P->toks[P->i].pos, "max-stack",
                     "expression nested too deeply to parse");
  NESTING_CHECK(P);
}
static Def *binding(Parser *P, int toplevel, int *is_expr, Expr **ex);

/* ---- tokens and layout ---- */

static Token *cur(Parser *P) { return &P->toks[P->i]; }

/* Tokens that continue an item even at the start of a line in the layout
   column: the paper puts `where`, guards and `=` there. */
static int continues(TokKind k) {
  return k == T_WHERE || k == T_BAR || k == T_EQUALS;
}

/* The kind of the next token, with the layout rule applied: a token that
   starts a line in the current block's column is a virtual separator, one
   left of it ends the block. Inside brackets opened within the block the
   rule is off. */
static TokKind peek(Parser *P) {
  Token *t = cur(P);
  if (t->kind != T_EOF && t->bol && P->nlay > 0 && P->sep_used != P->i) {
    int top = P->nlay - 1;
    if (P->lay_br[top] == P->bracket) {
      int c = P->lay_col[top];
      if (t->pos.col < c) return T_VEND;
      if (t->pos.col == c && !continues(t->kind)) return T_VSEP;
    }
  }
  return t->kind;
}

static Pos pos_here(Parser *P) { return cur(P)->pos; }

static Token *next(Parser *P) {
  Token *t = cur(P);
  if (t->kind == T_LPAREN || t->kind == T_LBRACK) {
    if (P->bracket >= 0 && P->bracket < LAYOUT_MAX) P->open_tok[P->bracket] = t;
    P->bracket++;
  }
  if (t->kind == T_RPAREN || t->kind == T_RBRACK) P->bracket--;
  if (t->kind != T_EOF) P->i++;
  return t;
}

static void use_sep(Parser *P) { P->sep_used = P->i; }

static _Noreturn void error_at_token(Parser *P, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* An error at the current token; at the end of the text it is marked
   incomplete so that the REPL reads another line. */
static _Noreturn void error_at_token(Parser *P, const char *fmt, ...) {
  char buf[900];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  Token *t = cur(P);
  if (t->kind == T_EOF) {
    /* At the end of the text the likely mistake is an unclosed bracket. */
    int b = P->bracket - 1;
    if (b >= 0 && b < LAYOUT_MAX && !strstr(buf, "(to close")) {
      Token *o = P->open_tok[b];
      qcs_error_incomplete(t->pos, "%s (to close '%c' at %d:%d)", buf,
                           o->kind == T_LPAREN ? '(' : '[', o->pos.line,
                           o->pos.col);
    }
    qcs_error_incomplete(t->pos, "%s", buf);
  }
  qcs_error(t->pos, "%s", buf);
}

static const char *describe(Parser *P) {
  TokKind k = peek(P);
  Token *t = cur(P);
  static _Thread_local char buf[128];
  if (k == T_VSEP || k == T_VEND)
    snprintf(buf, sizeof buf, "'%.*s' at the start of a line (a new "
             "definition begins there)", t->len > 40 ? 40 : t->len, t->start);
  else if (k == T_NAME || k == T_CNAME || k == T_NUM)
    snprintf(buf, sizeof buf, "'%.*s'", t->len > 40 ? 40 : t->len, t->start);
  else
    snprintf(buf, sizeof buf, "%s", tok_kind_name(k));
  return buf;
}

static void expect(Parser *P, TokKind k, const char *what) {
  if (peek(P) != k) error_at_token(P, "expected %s %s, found %s",
                                   tok_kind_name(k), what, describe(P));
  next(P);
}

/* Expect a closing bracket, naming where it was opened. */
static void expect_close(Parser *P, TokKind k, Pos open) {
  if (peek(P) != k)
    error_at_token(P, "expected %s (to close '%c' at %d:%d), found %s",
                   tok_kind_name(k), k == T_RPAREN ? '(' : '[', open.line,
                   open.col, describe(P));
  next(P);
}

static void layout_push(Parser *P, int col) {
  if (P->nlay == LAYOUT_MAX) error_at_token(P, "blocks nested too deeply");
  P->lay_col[P->nlay] = col;
  P->lay_br[P->nlay] = P->bracket;
  P->nlay++;
}

static void layout_pop(Parser *P) { P->nlay--; }

/* ---- node construction ---- */

static Expr *mk(ExprKind k, Pos pos) {
  Expr *e = GC_MALLOC(sizeof *e);
  e->kind = k;
  e->pos = pos;
  return e;
}

static Pat *mkpat(PatKind k, Pos pos) {
  Pat *p = GC_MALLOC(sizeof *p);
  p->kind = k;
  p->pos = pos;
  return p;
}

typedef struct Vec {
  void **items;
  int n, cap;
} Vec;

static void vec_push(Vec *v, void *x) {
  if (v->n == v->cap) {
    v->cap = v->cap ? 2 * v->cap : 4;
    void **a = GC_MALLOC(sizeof(void *) * (size_t)v->cap);
    if (v->n) memcpy(a, v->items, sizeof(void *) * (size_t)v->n);
    v->items = a;
  }
  v->items[v->n++] = x;
}

static Sym *tok_sym(Parser *P, Token *t) {
  return sym_intern(P->I, t->start, t->len);
}

static Expr *mk_var(Parser *P, Pos pos, const char *name) {
  Expr *e = mk(E_VAR, pos);
  e->u.var = sym_intern(P->I, name, (int)strlen(name));
  return e;
}

static Expr *mk_app(Pos pos, Expr *fn, int n, Expr **args) {
  Expr *e = mk(E_APP, pos);
  e->u.app.fn = fn;
  e->u.app.n = n;
  e->u.app.args = GC_MALLOC(sizeof(Expr *) * (size_t)n);
  memcpy(e->u.app.args, args, sizeof(Expr *) * (size_t)n);
  return e;
}

static Clause *mk_clause(Pos pos, int npats, Pat **pats, Expr *body) {
  Clause *c = GC_MALLOC(sizeof *c);
  c->pos = pos;
  c->npats = npats;
  c->pats = pats;
  c->nbodies = 1;
  c->guards = GC_MALLOC(sizeof(Expr *));
  c->bodies = GC_MALLOC(sizeof(Expr *));
  c->bodies[0] = body;
  return c;
}

/* A lambda with the given clauses (all of arity npats). */
static Expr *mk_lambda(Pos pos, int npats, int nclauses, Clause **clauses) {
  Def *d = GC_MALLOC(sizeof *d);
  d->pos = pos;
  d->arity = npats;
  d->nclauses = nclauses;
  d->clauses = GC_MALLOC(sizeof(Clause *) * (size_t)nclauses);
  memcpy(d->clauses, clauses, sizeof(Clause *) * (size_t)nclauses);
  Expr *e = mk(E_LAMBDA, pos);
  e->u.lambda = d;
  return e;
}

static Pat *mk_pvar(Parser *P, Pos pos, const char *name) {
  Pat *p = mkpat(P_VAR, pos);
  p->u.var = sym_intern(P->I, name, (int)strlen(name));
  return p;
}

/* (op) is \%a %b -> %a op %b; the % names cannot clash with user names. */
static Expr *op_function(Parser *P, TokKind op, Pos pos) {
  Pat **pats = GC_MALLOC(2 * sizeof(Pat *));
  pats[0] = mk_pvar(P, pos, "%a");
  pats[1] = mk_pvar(P, pos, "%b");
  Expr *b = mk(E_BINOP, pos);
  b->u.bin.op = op;
  b->u.bin.a = mk_var(P, pos, "%a");
  b->u.bin.b = mk_var(P, pos, "%b");
  Clause *c = mk_clause(pos, 2, pats, b);
  return mk_lambda(pos, 2, 1, &c);
}

/* f . g is \%x -> f (g %x). */
static Expr *compose(Parser *P, Expr *f, Expr *g, Pos pos) {
  Pat **pats = GC_MALLOC(sizeof(Pat *));
  pats[0] = mk_pvar(P, pos, "%x");
  Expr *x = mk_var(P, pos, "%x");
  Expr *gx = mk_app(pos, g, 1, &x);
  Expr *body = mk_app(pos, f, 1, &gx);
  Clause *c = mk_clause(pos, 1, pats, body);
  return mk_lambda(pos, 1, 1, &c);
}

const char *op_text(TokKind op) {
  switch (op) {
  case T_PLUS: return "+";
  case T_MINUS: return "-";
  case T_STAR: return "*";
  case T_SLASH: return "/";
  case T_CARET: return "^";
  case T_APPEND: return "++";
  case T_EQ: return "==";
  case T_NE: return "<>";
  case T_LT: return "<";
  case T_LE: return "<=";
  case T_GT: return ">";
  case T_GE: return ">=";
  case T_AND: case T_KAND: return "&&";
  case T_OR: case T_KOR: return "||";
  case T_COLON: return ":";
  case T_INDEX: return "!!";
  case T_COMPOSE: return ".";
  default: return "?";
  }
}

/* ---- patterns, converted from expressions ---- */

static int is_upper(const Sym *s) { return s->name[0] >= 'A' && s->name[0] <= 'Z'; }

static Pat *to_pat(Parser *P, Expr *e) {
  Pat *p;
  switch (e->kind) {
  case E_VAR:
    if (is_upper(e->u.var)) {
      p = mkpat(P_CON, e->pos);
      p->u.con.con = e->u.var;
    } else {
      p = mkpat(P_VAR, e->pos);
      p->u.var = e->u.var;
    }
    return p;
  case E_WILD: return mkpat(P_WILD, e->pos);
  case E_NUM:
    p = mkpat(P_NUM, e->pos);
    p->u.num = e->u.num;
    return p;
  case E_STR:
    p = mkpat(P_STR, e->pos);
    p->u.str = e->u.str;
    return p;
  case E_BOOL:
    p = mkpat(P_BOOL, e->pos);
    p->u.b = e->u.b;
    return p;
  case E_APP:
    if (e->u.app.fn->kind == E_VAR && is_upper(e->u.app.fn->u.var)) {
      p = mkpat(P_CON, e->pos);
      p->u.con.con = e->u.app.fn->u.var;
      p->u.con.n = e->u.app.n;
      p->u.con.args = GC_MALLOC(sizeof(Pat *) * (size_t)e->u.app.n);
      for (int i = 0; i < e->u.app.n; i++)
        p->u.con.args[i] = to_pat(P, e->u.app.args[i]);
      return p;
    }
    qcs_error(e->pos, "a pattern may apply only a constructor (a "
              "capitalised name) to patterns");
  case E_TUPLE:
  case E_LIST:
    if (e->kind == E_LIST && e->u.tuple.n == 0) return mkpat(P_NIL, e->pos);
    p = mkpat(e->kind == E_TUPLE ? P_TUPLE : P_LIST, e->pos);
    p->u.tuple.n = e->u.tuple.n;
    p->u.tuple.items = GC_MALLOC(sizeof(Pat *) * (size_t)(e->u.tuple.n + 1));
    for (int i = 0; i < e->u.tuple.n; i++)
      p->u.tuple.items[i] = to_pat(P, e->u.tuple.items[i]);
    return p;
  case E_BINOP:
    if (e->u.bin.op == T_COLON) {
      p = mkpat(P_CONS, e->pos);
      p->u.cons.head = to_pat(P, e->u.bin.a);
      p->u.cons.tail = to_pat(P, e->u.bin.b);
      return p;
    }
    qcs_error(e->pos, "operator '%s' cannot appear in a pattern",
              op_text(e->u.bin.op));
  default:
    qcs_error(e->pos, "this expression cannot be a pattern (patterns are "
              "names, _, literals, tuples, lists and constructors)");
  }
}

/* Every variable of a pattern, to reject repeats in one clause. */
static void pat_vars(Pat *p, Vec *out) {
  switch (p->kind) {
  case P_VAR:
    for (int i = 0; i < out->n; i++)
      if (((Pat *)out->items[i])->u.var == p->u.var)
        qcs_error(p->pos, "'%s' is bound twice in the same patterns",
                  p->u.var->name);
    vec_push(out, p);
    break;
  case P_CON:
    for (int i = 0; i < p->u.con.n; i++) pat_vars(p->u.con.args[i], out);
    break;
  case P_TUPLE:
  case P_LIST:
    for (int i = 0; i < p->u.tuple.n; i++) pat_vars(p->u.tuple.items[i], out);
    break;
  case P_CONS:
    pat_vars(p->u.cons.head, out);
    pat_vars(p->u.cons.tail, out);
    break;
  default:
    break;
  }
}

/* ---- expressions ---- */

static int starts_atom(TokKind k) {
  switch (k) {
  case T_NUM: case T_STR: case T_NAME: case T_CNAME: case T_WILD:
  case T_LPAREN: case T_LBRACK: case T_TRUE: case T_FALSE:
    return 1;
  default:
    return 0;
  }
}

static int is_binop(TokKind k) {
  switch (k) {
  case T_PLUS: case T_MINUS: case T_STAR: case T_SLASH: case T_CARET:
  case T_APPEND: case T_EQ: case T_NE: case T_LT: case T_LE: case T_GT:
  case T_GE: case T_AND: case T_OR: case T_KAND: case T_KOR: case T_COLON:
  case T_INDEX: case T_COMPOSE:
    return 1;
  default:
    return 0;
  }
}

/* Binding power and associativity (1 right, 0 left, 2 none). */
static int prec(TokKind k, int *assoc) {
  switch (k) {
  case T_OR: case T_KOR: *assoc = 1; return 2;
  case T_AND: case T_KAND: *assoc = 1; return 3;
  case T_EQ: case T_NE: case T_LT: case T_LE: case T_GT: case T_GE:
    *assoc = 2; return 4;
  case T_COLON: case T_APPEND: *assoc = 1; return 5;
  case T_PLUS: case T_MINUS: *assoc = 0; return 6;
  case T_STAR: case T_SLASH: *assoc = 0; return 7;
  case T_CARET: *assoc = 1; return 8;
  case T_INDEX: *assoc = 0; return 9;
  case T_COMPOSE: *assoc = 1; return 9;
  default: *assoc = 0; return -1;
  }
}

/* qual -> pat '<-' expr | expr */
static void qualifiers(Parser *P, Vec *quals) {
  for (;;) {
    Expr *e = expr(P);
    Qual *q = GC_MALLOC(sizeof *q);
    if (peek(P) == T_LARROW) {
      next(P);
      q->pat = to_pat(P, e);
      Vec vars = {0};
      pat_vars(q->pat, &vars);
      q->e = expr(P);
    } else {
      q->e = e;
    }
    vec_push(quals, q);
    if (peek(P) == T_COMMA || peek(P) == T_BAR) {
      next(P);
      continue;
    }
    return;
  }
}

/* [e | q, ...] becomes concatMap / if:
     [e | ]            = [e]
     [e | pat <- xs, Q] = %concatMap (\pat -> [e | Q]; \_ -> []) xs
     [e | cond, Q]      = if cond then [e | Q] else [] */
static Expr *desugar_comp(Parser *P, Expr *head, Qual **q, int n) {
  if (n == 0) {
    Expr *e = mk(E_LIST, head->pos);
    e->u.tuple.n = 1;
    e->u.tuple.items = GC_MALLOC(sizeof(Expr *));
    e->u.tuple.items[0] = head;
    return e;
  }
  Expr *rest = desugar_comp(P, head, q + 1, n - 1);
  Pos pos = q[0]->e->pos;
  Expr *nil = mk(E_LIST, pos);
  if (!q[0]->pat) {
    Expr *e = mk(E_IF, pos);
    e->u.cond.c = q[0]->e;
    e->u.cond.t = rest;
    e->u.cond.f = nil;
    return e;
  }
  Pat **pats = GC_MALLOC(sizeof(Pat *));
  pats[0] = q[0]->pat;
  Clause *cl[2];
  cl[0] = mk_clause(pos, 1, pats, rest);
  int ncl = 1;
  if (q[0]->pat->kind != P_VAR && q[0]->pat->kind != P_WILD) {
    Pat **wild = GC_MALLOC(sizeof(Pat *));
    wild[0] = mkpat(P_WILD, pos);
    cl[ncl++] = mk_clause(pos, 1, wild, nil);
  }
  Expr *args[2] = {mk_lambda(pos, 1, ncl, cl), q[0]->e};
  return mk_app(pos, mk_var(P, pos, "%concatMap"), 2, args);
}

static Expr *finish_comp(Parser *P, Expr *head, Pos pos, Pos open) {
  Vec quals = {0};
  qualifiers(P, &quals);
  expect_close(P, T_RBRACK, open);
  (void)pos;
  return desugar_comp(P, head, (Qual **)quals.items, quals.n);
}

static Expr *finish_range(Parser *P, Expr *from, Expr *then, Pos pos,
                          Pos open) {
  next(P); /* .. */
  Expr *e = mk(E_RANGE, pos);
  e->u.range.from = from;
  e->u.range.then = then;
  e->u.range.to = peek(P) == T_RBRACK || peek(P) == T_EOF ? NULL : expr(P);
  expect_close(P, T_RBRACK, open);
  return e;
}

/* Whether the tokens [from, to) are one bracketed group, ( ... ) or
   [ ... ] (a list in tail form is a cons node too). */
static int bracketed(Parser *P, int from, int to) {
  if (to - from < 2 ||
      (P->toks[from].kind != T_LPAREN && P->toks[from].kind != T_LBRACK))
    return 0;
  int depth = 0;
  for (int j = from; j < to; j++) {
    TokKind k = P->toks[j].kind;
    if (k == T_LPAREN || k == T_LBRACK) depth++;
    else if (k == T_RPAREN || k == T_RBRACK) depth--;
    if (depth == 0 && j < to - 1) return 0;
  }
  return 1;
}

/* list -> '[' ']' | '[' expr '..' [expr] ']' | '[' expr ',' expr '..' ...
         | '[' expr ('\\' | '|') quals ']' | '[' expr {',' expr} ']'
   Inside brackets a final unbracketed `a : rest` is Clean's tail syntax
   [x, y : rest]; a bracketed one, [(a : rest)] or [[a : rest]], is an
   element. */
static Expr *list_expr(Parser *P) {
  Pos open = pos_here(P);
  next(P);
  if (peek(P) == T_RBRACK) {
    next(P);
    Expr *e = mk(E_LIST, open);
    return e;
  }
  int first_tok = P->i;
  Expr *first = expr(P);
  if (peek(P) == T_DOTDOT) return finish_range(P, first, NULL, open, open);
  if (peek(P) == T_BACKSLASH2 || peek(P) == T_BAR) {
    next(P);
    return finish_comp(P, first, open, open);
  }
  Vec items = {0};
  vec_push(&items, first);
  int last_start = first_tok, last_end = P->i;
  while (peek(P) == T_COMMA) {
    next(P);
    last_start = P->i;
    Expr *x = expr(P);
    last_end = P->i;
    if (items.n == 1 && peek(P) == T_DOTDOT)
      return finish_range(P, first, x, open, open);
    vec_push(&items, x);
  }
  expect_close(P, T_RBRACK, open);
  Expr *tail = NULL;
  Expr *last = items.items[items.n - 1];
  if (last->kind == E_BINOP && last->u.bin.op == T_COLON &&
      !bracketed(P, last_start, last_end)) {
    /* [a, b : rest] */
    items.items[items.n - 1] = last->u.bin.a;
    tail = last->u.bin.b;
  }
  if (tail) {
    Expr *e = tail;
    for (int i = items.n - 1; i >= 0; i--) {
      Expr *c = mk(E_BINOP, ((Expr *)items.items[i])->pos);
      c->u.bin.op = T_COLON;
      c->u.bin.a = items.items[i];
      c->u.bin.b = e;
      e = c;
    }
    return e;
  }
  Expr *e = mk(E_LIST, open);
  e->u.tuple.n = items.n;
  e->u.tuple.items = (Expr **)items.items;
  return e;
}

/* A section: (op e) is \%a -> %a op e, (e op) is \%b -> e op %b. */
static Expr *section(Parser *P, TokKind op, Expr *left, Expr *right, Pos pos) {
  Pat **pats = GC_MALLOC(sizeof(Pat *));
  const char *v = left ? "%b" : "%a";
  pats[0] = mk_pvar(P, pos, v);
  Expr *a = left ? left : mk_var(P, pos, v);
  Expr *b = right ? right : mk_var(P, pos, v);
  Expr *body;
  if (op == T_COMPOSE) {
    body = compose(P, a, b, pos);
  } else {
    body = mk(E_BINOP, pos);
    body->u.bin.op = op == T_KAND ? T_AND : op == T_KOR ? T_OR : op;
    body->u.bin.a = a;
    body->u.bin.b = b;
  }
  Clause *c = mk_clause(pos, 1, pats, body);
  return mk_lambda(pos, 1, 1, &c);
}

/* paren -> '(' ')' | '(' binop ')' | '(' binop expr ')' | '(' expr binop ')'
          | '(' expr ')' | '(' expr {',' expr} ')'
   (- e) is negation, not a section. */
static Expr *paren_expr(Parser *P) {
  Pos open = pos_here(P);
  next(P);
  TokKind k = peek(P);
  if (k == T_RPAREN) {
    next(P);
    Expr *e = mk(E_TUPLE, open);
    return e;
  }
  if (is_binop(k) && P->toks[P->i + 1].kind == T_RPAREN) {
    next(P);
    next(P);
    if (k == T_COMPOSE) {
      Pat **pats = GC_MALLOC(2 * sizeof(Pat *));
      pats[0] = mk_pvar(P, open, "%f");
      pats[1] = mk_pvar(P, open, "%g");
      Clause *c = mk_clause(open, 2, pats, compose(P, mk_var(P, open, "%f"),
                                                   mk_var(P, open, "%g"), open));
      return mk_lambda(open, 2, 1, &c);
    }
    return op_function(P, k == T_KAND ? T_AND : k == T_KOR ? T_OR : k, open);
  }
  if (is_binop(k) && k != T_MINUS) { /* a right section (op e) */
    Pos opos = pos_here(P);
    next(P);
    Expr *right = expr(P);
    expect_close(P, T_RPAREN, open);
    return section(P, k, NULL, right, opos);
  }
  Expr *first = expr(P);
  k = peek(P);
  if (is_binop(k) && P->toks[P->i + 1].kind == T_RPAREN) { /* (e op) */
    Pos opos = pos_here(P);
    next(P);
    next(P);
    return section(P, k, first, NULL, opos);
  }
  if (peek(P) != T_COMMA) {
    expect_close(P, T_RPAREN, open);
    return first;
  }
  Vec items = {0};
  vec_push(&items, first);
  while (peek(P) == T_COMMA) {
    next(P);
    vec_push(&items, expr(P));
  }
  expect_close(P, T_RPAREN, open);
  Expr *e = mk(E_TUPLE, open);
  e->u.tuple.n = items.n;
  e->u.tuple.items = (Expr **)items.items;
  return e;
}

/* atom -> NUM | STR | True | False | NAME | CNAME | '_' | paren | list */
static Expr *atom(Parser *P) {
  Token *t = cur(P);
  Expr *e;
  switch (peek(P)) {
  case T_NUM:
    next(P);
    e = mk(E_NUM, t->pos);
    e->u.num = t->num;
    return e;
  case T_STR:
    next(P);
    e = mk(E_STR, t->pos);
    e->u.str = t->str;
    return e;
  case T_TRUE:
  case T_FALSE:
    next(P);
    e = mk(E_BOOL, t->pos);
    e->u.b = t->kind == T_TRUE;
    return e;
  case T_NAME:
  case T_CNAME:
    next(P);
    e = mk(E_VAR, t->pos);
    e->u.var = tok_sym(P, t);
    return e;
  case T_WILD:
    next(P);
    return mk(E_WILD, t->pos);
  case T_LPAREN:
    return paren_expr(P);
  case T_LBRACK:
    return list_expr(P);
  default:
    error_at_token(P, "expected an expression, found %s", describe(P));
  }
}

/* app -> atom {atom} */
static Expr *app(Parser *P) {
  Expr *f = atom(P);
  if (!starts_atom(peek(P))) return f;
  Vec args = {0};
  while (starts_atom(peek(P))) vec_push(&args, atom(P));
  Expr *e = mk(E_APP, f->pos);
  e->u.app.fn = f;
  e->u.app.n = args.n;
  e->u.app.args = (Expr **)args.items;
  return e;
}

static Def *lambda_def(Parser *P, Pos pos) {
  Vec pats = {0}, vars = {0};
  while (starts_atom(peek(P))) {
    Pat *p = to_pat(P, atom(P));
    pat_vars(p, &vars);
    vec_push(&pats, p);
  }
  if (pats.n == 0) error_at_token(P, "expected a parameter after '\\'");
  if (peek(P) != T_ARROW)
    error_at_token(P, "expected '->' after the lambda's parameters, found %s",
                   describe(P));
  next(P);
  Clause *c = GC_MALLOC(sizeof *c);
  c->pos = pos;
  c->npats = pats.n;
  c->pats = (Pat **)pats.items;
  c->nbodies = 1;
  c->guards = GC_MALLOC(sizeof(Expr *));
  c->bodies = GC_MALLOC(sizeof(Expr *));
  c->bodies[0] = expr(P);
  Def *d = GC_MALLOC(sizeof *d);
  d->pos = pos;
  d->arity = pats.n;
  d->nclauses = 1;
  d->clauses = GC_MALLOC(sizeof(Clause *));
  d->clauses[0] = c;
  return d;
}

/* Bindings of a where or let block, lined up in one column. */
static void block_bindings(Parser *P, Vec *defs, int stop_at_in);

/* After an entry of a where, let or case block: consumes the separator
   (';' or a new line in the block's column) and says whether another
   entry follows. */
static int block_more(Parser *P) {
  TokKind k = peek(P);
  if (k == T_VSEP) {
    use_sep(P);
    return 1;
  }
  if (k != T_SEMI) return 0;
  next(P);
  k = peek(P);
  if (k == T_VSEP) {
    use_sep(P);
    return 1;
  }
  return !(k == T_VEND || k == T_EOF || k == T_SEMI || k == T_IN ||
           k == T_RPAREN || k == T_RBRACK);
}

/* alts -> alt {sep alt}, lined up in one column like bindings
   alt -> pat '->' expr | pat {'|' expr '->' expr} */
static void case_alts(Parser *P, Vec *alts, Pos casepos) {
  TokKind k = peek(P);
  if (k == T_EOF || k == T_VEND || k == T_VSEP)
    error_at_token(P, "expected an alternative, indented, after 'of' (for "
                   "'case' at %d:%d)", casepos.line, casepos.col);
  int col = cur(P)->pos.col;
  if (P->nlay > 0 && P->lay_br[P->nlay - 1] == P->bracket &&
      col <= P->lay_col[P->nlay - 1])
    error_at_token(P, "indent the alternatives of 'case' (right of column "
                   "%d)", P->lay_col[P->nlay - 1]);
  layout_push(P, col);
  use_sep(P);
  for (;;) {
    Pos apos = pos_here(P);
    Pat **pats = GC_MALLOC(sizeof(Pat *));
    pats[0] = to_pat(P, expr(P));
    Vec vars = {0};
    pat_vars(pats[0], &vars);
    Vec guards = {0}, bodies = {0};
    if (peek(P) == T_BAR) {
      while (peek(P) == T_BAR) {
        next(P);
        vec_push(&guards, expr(P));
        expect(P, T_ARROW, "after the guard of a case alternative");
        vec_push(&bodies, expr(P));
      }
    } else {
      expect(P, T_ARROW, "after the pattern of a case alternative");
      vec_push(&guards, NULL);
      vec_push(&bodies, expr(P));
    }
    Clause *c = GC_MALLOC(sizeof *c);
    c->pos = apos;
    c->npats = 1;
    c->pats = pats;
    c->nbodies = bodies.n;
    c->guards = (Expr **)guards.items;
    c->bodies = (Expr **)bodies.items;
    vec_push(alts, c);
    if (!block_more(P)) break;
  }
  layout_pop(P);
}

/* prefix -> '\' pats '->' expr | 'let' bindings 'in' expr
           | 'case' expr 'of' alts
           | 'if' expr 'then' expr 'else' expr | '-' operand | app */
static Expr *operand_body(Parser *P, int minprec);
static Expr *operand(Parser *P, int minprec) {
  nesting_enter(P);
  Expr *e = operand_body(P, minprec);
  P->depth--;
  return e;
}
static Expr *operand_body(Parser *P, int minprec) {
  Pos pos = pos_here(P);
  switch (peek(P)) {
  case T_LAMBDA: {
    next(P);
    Expr *e = mk(E_LAMBDA, pos);
    e->u.lambda = lambda_def(P, pos);
    return e;
  }
  case T_LET: {
    next(P);
    Vec defs = {0};
    block_bindings(P, &defs, 1);
    if (peek(P) != T_IN)
      error_at_token(P, "expected 'in' after the bindings of 'let' at %d:%d, "
                     "found %s", pos.line, pos.col, describe(P));
    next(P);
    Expr *e = mk(E_LET, pos);
    e->u.let.n = defs.n;
    e->u.let.defs = (Def **)defs.items;
    e->u.let.body = expr(P);
    return e;
  }
  case T_CASE: { /* case e of alts: a one-argument lambda applied to e */
    next(P);
    Expr *scrut = expr(P);
    if (peek(P) != T_OF)
      error_at_token(P, "expected 'of' (for 'case' at %d:%d), found %s",
                     pos.line, pos.col, describe(P));
    next(P);
    Vec alts = {0};
    case_alts(P, &alts, pos);
    Expr *lam = mk_lambda(pos, 1, alts.n, (Clause **)alts.items);
    lam->u.lambda->name = sym_intern(P->I, "case", 4);
    return mk_app(pos, lam, 1, &scrut);
  }
  case T_IF: {
    next(P);
    Expr *e = mk(E_IF, pos);
    e->u.cond.c = expr(P);
    if (peek(P) != T_THEN)
      error_at_token(P, "expected 'then' (for 'if' at %d:%d), found %s",
                     pos.line, pos.col, describe(P));
    next(P);
    e->u.cond.t = expr(P);
    if (peek(P) != T_ELSE)
      error_at_token(P, "expected 'else' (for 'if' at %d:%d), found %s",
                     pos.line, pos.col, describe(P));
    next(P);
    e->u.cond.f = expr(P);
    return e;
  }
  case T_MINUS: {
    next(P);
    /* Unary minus binds like binary minus (level 6): it takes the operators
       of level 7 and above with it, parsed by their own precedence, so
       -a*b is -(a*b), -a^2 is -(a^2) and -2*3^2 is -(2*(3^2)). */
    Expr *x = binary(P, 7);
    if (x->kind == E_NUM && x->pos.line == pos.line) {
      x->u.num = -x->u.num;
      x->pos = pos;
      return x;
    }
    Expr *e = mk(E_NEG, pos);
    e->u.neg = x;
    return e;
  }
  default:
    (void)minprec;
    return app(P);
  }
}

/* Precedence climbing over the binary operators. */
static Expr *binary_body(Parser *P, int minprec);
static Expr *binary(Parser *P, int minprec) {
  nesting_enter(P);
  Expr *e = binary_body(P, minprec);
  P->depth--;
  return e;
}
static Expr *binary_body(Parser *P, int minprec) {
  Expr *lhs = operand(P, minprec);
  for (;;) {
    TokKind op = peek(P);
    int assoc;
    int p = prec(op, &assoc);
    if (p < 0 || p < minprec) return lhs;
    /* (e op): a left section, finished by paren_expr */
    if (P->toks[P->i + 1].kind == T_RPAREN && P->bracket > 0) return lhs;
    Pos opos = pos_here(P);
    next(P);
    Expr *rhs = binary(P, assoc == 1 ? p : p + 1);
    if (assoc == 2) {
      int a2;
      int p2 = prec(peek(P), &a2);
      if (p2 == p)
        error_at_token(P, "comparisons do not chain: write (a %s b) && (b %s "
                       "c)", op_text(op), op_text(peek(P)));
    }
    if (op == T_COMPOSE) {
      lhs = compose(P, lhs, rhs, opos);
      continue;
    }
    Expr *e = mk(E_BINOP, opos);
    e->u.bin.op = op;
    e->u.bin.a = lhs;
    e->u.bin.b = rhs;
    lhs = e;
  }
}

static Expr *expr(Parser *P) { return binary(P, 0); }

/* ---- definitions ---- */

/* rhs -> '=' expr [where] | {'|' expr '=' expr} ['=' expr] [where] */
static Clause *rhs(Parser *P, Pos pos, int npats, Pat **pats) {
  Clause *c = GC_MALLOC(sizeof *c);
  c->pos = pos;
  c->npats = npats;
  c->pats = pats;
  Vec guards = {0}, bodies = {0};
  if (peek(P) == T_BAR) {
    while (peek(P) == T_BAR) {
      next(P);
      vec_push(&guards, expr(P));
      expect(P, T_EQUALS, "after the guard");
      vec_push(&bodies, expr(P));
    }
    if (peek(P) == T_EQUALS) { /* Clean: a last '= e' is the otherwise case */
      next(P);
      vec_push(&guards, NULL);
      vec_push(&bodies, expr(P));
    }
  } else {
    expect(P, T_EQUALS, "in the definition");
    vec_push(&guards, NULL);
    vec_push(&bodies, expr(P));
  }
  c->nbodies = bodies.n;
  c->guards = (Expr **)guards.items;
  c->bodies = (Expr **)bodies.items;
  if (peek(P) == T_WHERE) {
    next(P);
    Vec defs = {0};
    block_bindings(P, &defs, 0);
    c->nwhere = defs.n;
    c->where = (Def **)defs.items;
  }
  return c;
}

/* Adds a clause to the last definition if it has the same name; returns 1
   if it did. */
static int merge_clause(Vec *defs, Def *d) {
  if (!d->name || defs->n == 0) return 0;
  Def *last = defs->items[defs->n - 1];
  if (last->name != d->name || last->pat) return 0;
  if (last->arity != d->arity)
    qcs_error(d->pos, "this clause of %s has %d argument%s but the one at "
              "%d:%d has %d", d->name->name, d->arity,
              d->arity == 1 ? "" : "s", last->pos.line, last->pos.col,
              last->arity);
  Clause **cl = GC_MALLOC(sizeof(Clause *) * (size_t)(last->nclauses + 1));
  memcpy(cl, last->clauses, sizeof(Clause *) * (size_t)last->nclauses);
  cl[last->nclauses++] = d->clauses[0];
  last->clauses = cl;
  return 1;
}

/* A definition or (where allowed) an expression:
   binding -> lhs rhs ; lhs -> name {apat} | pattern (in where/let) */
static Def *binding(Parser *P, int toplevel, int *is_expr, Expr **ex) {
  Pos pos = pos_here(P);
  Expr *lhs = expr(P);
  TokKind k = peek(P);
  if (k != T_EQUALS && k != T_BAR) {
    if (is_expr) {
      *is_expr = 1;
      *ex = lhs;
      return NULL;
    }
    error_at_token(P, "expected '=' in this binding, found %s", describe(P));
  }
  Def *d = GC_MALLOC(sizeof *d);
  d->pos = pos;
  Expr *head = lhs->kind == E_APP ? lhs->u.app.fn : lhs;
  if (head->kind == E_VAR) {
    /* `C x = e` with C capitalised: a function C, unless C is a
       constructor when the program runs (a pattern binding in where/let,
       an error at the top level). The parser registers nothing, so that is
       settled after parsing (interp.c, settle_defs). */
    Sym *name = head->u.var;
    if (!toplevel && is_upper(name) && peek(P) == T_BAR)
      d->guard_pos = pos_here(P);
    int n = lhs->kind == E_APP ? lhs->u.app.n : 0;
    Pat **pats = GC_MALLOC(sizeof(Pat *) * (size_t)(n + 1));
    Vec vars = {0};
    for (int i = 0; i < n; i++) {
      pats[i] = to_pat(P, lhs->u.app.args[i]);
      pat_vars(pats[i], &vars);
    }
    d->name = name;
    d->pos = head->pos;
    d->arity = n;
    d->nclauses = 1;
    d->clauses = GC_MALLOC(sizeof(Clause *));
    d->clauses[0] = rhs(P, pos, n, pats);
    return d;
  }
  if (toplevel)
    qcs_error(lhs->pos, "a top-level definition must start with a name "
              "(pattern bindings like (a, b) = ... belong in where or let)");
  d->pat = to_pat(P, lhs);
  Vec vars = {0};
  pat_vars(d->pat, &vars);
  if (peek(P) != T_EQUALS)
    error_at_token(P, "a pattern binding takes no guards");
  d->nclauses = 1;
  d->clauses = GC_MALLOC(sizeof(Clause *));
  d->clauses[0] = rhs(P, pos, 0, NULL);
  return d;
}

static void block_bindings(Parser *P, Vec *defs, int stop_at_in) {
  TokKind k = peek(P);
  if (k == T_EOF)
    error_at_token(P, "expected a binding after '%s'",
                   stop_at_in ? "let" : "where");
  if (k == T_VEND || k == T_VSEP)
    error_at_token(P, "expected a binding, indented, after '%s'",
                   stop_at_in ? "let" : "where");
  int col = cur(P)->pos.col;
  if (P->nlay > 0 && P->lay_br[P->nlay - 1] == P->bracket &&
      col <= P->lay_col[P->nlay - 1])
    error_at_token(P, "indent the bindings of '%s' (right of column %d)",
                   stop_at_in ? "let" : "where", P->lay_col[P->nlay - 1]);
  layout_push(P, col);
  use_sep(P);
  for (;;) {
    Def *d = binding(P, 0, NULL, NULL);
    if (!merge_clause(defs, d)) vec_push(defs, d);
    if (!block_more(P)) break;
  }
  layout_pop(P);
  (void)stop_at_in;
}

/* ---- types ---- */

/* Skips a type expression: atype -> CNAME | NAME | '(' ... ')' | '[' ... ']'
   | '!' atype. Returns 0 if the next token cannot start one. */
static int skip_atype(Parser *P) {
  NESTING_CHECK(P);
  TokKind k = peek(P);
  if (k == T_BANG) {
    next(P);
    return skip_atype(P);
  }
  if (k == T_CNAME || k == T_NAME) {
    next(P);
    return 1;
  }
  if (k == T_LPAREN || k == T_LBRACK) {
    Pos open = pos_here(P);
    TokKind close = k == T_LPAREN ? T_RPAREN : T_RBRACK;
    next(P);
    int depth = P->bracket;
    while (!(P->bracket == depth && peek(P) == close)) {
      if (peek(P) == T_EOF)
        error_at_token(P, "expected %s (to close '%c' at %d:%d)",
                       tok_kind_name(close), k == T_LPAREN ? '(' : '[',
                       open.line, open.col);
      next(P);
    }
    next(P);
    return 1;
  }
  return 0;
}

/* type -> atype {atype} {'->' type} */
static void skip_type(Parser *P) {
  for (;;) {
    if (skip_atype(P)) continue;
    if (peek(P) == T_ARROW) {
      next(P);
      continue;
    }
    return;
  }
}

/* typedecl -> '::' CNAME {NAME} ('=' alt {'|' alt} | ':==' type)
   alt -> CNAME {atype} */
static Item *type_decl(Parser *P, Pos pos) {
  next(P); /* :: */
  if (peek(P) != T_CNAME)
    error_at_token(P, "expected a type name after '::', found %s",
                   describe(P));
  Item *it = GC_MALLOC(sizeof *it);
  it->kind = ITEM_TYPE;
  it->pos = pos;
  it->type = tok_sym(P, next(P));
  while (peek(P) == T_NAME) next(P);
  if (peek(P) == T_SYNONYM) {
    next(P);
    skip_type(P);
    return it;
  }
  expect(P, T_EQUALS, "in the type declaration");
  if (peek(P) != T_CNAME) { /* (Vector, Real), [Key], ...: a synonym */
    skip_type(P);
    return it;
  }
  Vec cons = {0};
  for (;;) {
    if (peek(P) != T_CNAME)
      error_at_token(P, "expected a constructor name, found %s", describe(P));
    Token *t = next(P);
    ConDecl *c = GC_MALLOC(sizeof *c);
    c->name = tok_sym(P, t);
    c->pos = t->pos;
    while (skip_atype(P)) c->arity++;
    vec_push(&cons, c);
    if (peek(P) != T_BAR) break;
    next(P);
  }
  /* `:: Scene = SceneObject;` names a type: a synonym, not a constructor. */
  if (cons.n == 1 && ((ConDecl *)cons.items[0])->arity == 0) return it;
  it->ncons = cons.n;
  it->cons = GC_MALLOC(sizeof(ConDecl) * (size_t)cons.n);
  for (int i = 0; i < cons.n; i++) it->cons[i] = *(ConDecl *)cons.items[i];
  /* Registered when the items are installed (interp.c), not here: parsing
     changes no definition, so a text that fails to parse leaves none. */
  return it;
}

/* sig -> name '::' type ; the text is kept for :browse, not checked. */
static Item *type_sig(Parser *P, Pos pos) {
  Item *it = GC_MALLOC(sizeof *it);
  it->kind = ITEM_SIG;
  it->pos = pos;
  Token *name = next(P);
  it->signame = tok_sym(P, name);
  next(P); /* :: */
  const char *start = cur(P)->start;
  const char *end = start;
  while (skip_atype(P) || peek(P) == T_ARROW) {
    Token *prev = &P->toks[P->i - 1];
    end = prev->start + prev->len;
    if (peek(P) == T_ARROW) next(P);
  }
  size_t len = (size_t)(end - start);
  char *s = GC_MALLOC_ATOMIC(len + 1);
  memcpy(s, start, len);
  s[len] = 0;
  it->sigtext = s;
  return it;
}

/* param -> 'param' name '=' expr ['in' '[' expr ',' expr ']'] [string]
   A string literal last in the default (`param n = 100 "doc"`) is the doc
   string, not an argument: bracket a default that ends in a string. */
static Item *param_item(Parser *P, Pos pos) {
  next(P); /* param */
  if (peek(P) != T_NAME)
    error_at_token(P, "expected a parameter's name after 'param', found %s",
                   describe(P));
  Token *name = next(P);
  expect(P, T_EQUALS, "after the parameter's name");
  const char *start = cur(P)->start;
  Expr *e = expr(P);
  Param *pm = GC_MALLOC(sizeof *pm);
  Token *last = &P->toks[P->i - 1];
  if (e->kind == E_APP && e->u.app.args[e->u.app.n - 1]->kind == E_STR &&
      peek(P) != T_IN) {
    pm->doc = e->u.app.args[e->u.app.n - 1]->u.str;
    last = &P->toks[P->i - 2];
    if (e->u.app.n == 1) e = e->u.app.fn;
    else e->u.app.n--;
  }
  size_t len = (size_t)(last->start + last->len - start);
  char *text = GC_MALLOC_ATOMIC(len + 1);
  memcpy(text, start, len);
  text[len] = 0;
  pm->text = text;
  if (peek(P) == T_IN) {
    next(P);
    Pos open = pos_here(P);
    expect(P, T_LBRACK, "after 'in' (a range is [LOW, HIGH])");
    pm->lo = expr(P);
    expect(P, T_COMMA, "in the range [LOW, HIGH]");
    pm->hi = expr(P);
    expect_close(P, T_RBRACK, open);
  }
  if (peek(P) == T_STR) {
    if (pm->doc) error_at_token(P, "a parameter has one doc string");
    pm->doc = next(P)->str;
  }
  Def *d = GC_MALLOC(sizeof *d);
  d->name = tok_sym(P, name);
  d->pos = name->pos;
  d->nclauses = 1;
  d->clauses = GC_MALLOC(sizeof(Clause *));
  d->clauses[0] = mk_clause(pos, 0, NULL, e);
  Item *it = GC_MALLOC(sizeof *it);
  it->kind = ITEM_DEF;
  it->pos = pos;
  it->def = d;
  it->param = pm;
  return it;
}

/* setting -> ':' 'set' 'digits' NUMBER
   The REPL's `:set digits N` written in a script: the Reals its top-level
   expressions print from this line on have N significant digits (0: the
   shortest form that reads back). The limits stay command-line options. */
static Item *set_item(Parser *P, Pos pos) {
  next(P); /* : */
  next(P); /* set */
  Token *name = cur(P);
  if (peek(P) != T_NAME || name->len != 6 || memcmp(name->start, "digits", 6))
    error_at_token(P, "a script's :set changes only digits (`:set digits "
                   "6`), found %s; limits are options (--max-steps N)",
                   describe(P));
  next(P);
  Token *v = cur(P);
  if (peek(P) != T_NUM || !(v->num >= 0 && v->num <= 17) ||
      v->num != (int)v->num)
    error_at_token(P, ":set digits needs a whole number from 0 (shortest "
                   "that reads back) to 17, found %s", describe(P));
  next(P);
  Item *it = GC_MALLOC(sizeof *it);
  it->kind = ITEM_SET;
  it->pos = pos;
  it->digits = (int)v->num;
  return it;
}

/* item -> typedecl | sig | param | import | setting | binding | expr */
static Item *item(Parser *P) {
  Pos pos = pos_here(P);
  if (peek(P) == T_PARAM) return param_item(P, pos);
  if (peek(P) == T_COLON && P->toks[P->i + 1].kind == T_NAME &&
      P->toks[P->i + 1].len == 3 && !memcmp(P->toks[P->i + 1].start, "set", 3))
    return set_item(P, pos);
  if (peek(P) == T_IMPORT) {
    next(P);
    if (peek(P) != T_STR)
      error_at_token(P, "expected a file name in quotes after 'import', "
                     "found %s", describe(P));
    Item *it = GC_MALLOC(sizeof *it);
    it->kind = ITEM_IMPORT;
    it->pos = pos;
    it->import = next(P)->str;
    /* import "FILE" as Name: its definitions are also Name.def */
    if (peek(P) == T_NAME && cur(P)->len == 2 && !memcmp(cur(P)->start, "as", 2)) {
      next(P);
      if (peek(P) != T_CNAME)
        error_at_token(P, "expected a name with a capital letter after "
                       "'as' (import \"FILE\" as Parts), found %s",
                       describe(P));
      it->import_as = tok_sym(P, next(P));
    }
    return it;
  }
  if (peek(P) == T_COLONCOLON) return type_decl(P, pos);
  if ((peek(P) == T_NAME || peek(P) == T_CNAME) &&
      P->toks[P->i + 1].kind == T_COLONCOLON)
    return type_sig(P, pos);
  Item *it = GC_MALLOC(sizeof *it);
  it->pos = pos;
  int is_expr = 0;
  Expr *e = NULL;
  Def *d = binding(P, 1, &is_expr, &e);
  if (is_expr) {
    it->kind = ITEM_EXPR;
    it->expr = e;
  } else {
    it->kind = ITEM_DEF;
    it->def = d;
  }
  return it;
}

static void parser_init(Parser *P, Interp *I, const Src *src, RunMode mode) {
  memset(P, 0, sizeof *P);
  P->I = I;
  P->src = src;
  P->mode = mode;
  P->sep_used = -1;
  P->max_depth = (int)(I->stack_limit >> 13 < 1000000000 ? I->stack_limit >> 13
                                                         : 1000000000);
}

static Item **parse_items(Parser *P, int *nitems);

Item **parse_program(Interp *I, const Src *src, RunMode mode, int *nitems) {
  Parser P;
  parser_init(&P, I, src, mode);
  P.toks = lex_all(src, &P.ntoks);
  return parse_items(&P, nitems);
}

Item **parse_range(Interp *I, const Src *src, size_t start, size_t end,
                   int line, int *nitems) {
  Parser P;
  parser_init(&P, I, src, MODE_SCRIPT);
  P.toks = lex_range(src, start, end, line, &P.ntoks);
  return parse_items(&P, nitems);
}

static Item **parse_items(Parser *P, int *nitems) {
  RunMode mode = P->mode;
  if (mode == MODE_SCRIPT) layout_push(P, 1);
  Vec items = {0};
  for (;;) {
    while (peek(P) == T_SEMI || peek(P) == T_VSEP) {
      if (peek(P) == T_VSEP) use_sep(P);
      else next(P);
    }
    if (peek(P) == T_EOF) break;
    Item *it = item(P);
    /* Clauses of one function on adjacent items form one definition. */
    if (it->kind == ITEM_DEF && !it->param && items.n > 0) {
      Item *last = items.items[items.n - 1];
      if (last->kind == ITEM_DEF && !last->param) {
        Vec one = {(void **)&last->def, 1, 1};
        if (merge_clause(&one, it->def)) goto ended;
      }
    }
    vec_push(&items, it);
  ended:;
    TokKind k = peek(P);
    if (k == T_SEMI || k == T_VSEP || k == T_EOF) continue;
    if (k == T_RPAREN || k == T_RBRACK)
      error_at_token(P, "unbalanced %s: nothing here to close",
                     tok_kind_name(k));
    error_at_token(P, "expected ';' or a new line after this %s, found %s",
                   it->kind == ITEM_EXPR ? "expression" : "definition",
                   describe(P));
  }
  *nitems = items.n;
  lex_free(P->toks); /* nothing made points into the tokens */
  return (Item **)items.items;
}

Expr *parse_expression(Interp *I, const Src *src) {
  Parser P;
  parser_init(&P, I, src, MODE_REPL);
  P.toks = lex_all(src, &P.ntoks);
  Expr *e = expr(&P);
  if (peek(&P) == T_SEMI) next(&P);
  if (peek(&P) != T_EOF)
    error_at_token(&P, "unexpected %s after the expression", describe(&P));
  lex_free(P.toks);
  return e;
}
