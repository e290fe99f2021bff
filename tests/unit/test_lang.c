#define _GNU_SOURCE /* dladdr */
/* test_lang.c: unit tests of the lexer, the parser, the evaluator and the
 * printer, through their C interfaces. */
#include <dlfcn.h>
#include <gc.h>
#include <gc/gc_mark.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "lang/eval.h"
#include "bind/bind.h"
#include "lang/interp.h"
#include "lang/lex.h"
#include "lang/parse.h"
#include "lang/print.h"

static Interp *I;

static Src mksrc(const char *text) { return (Src){"<test>", text, 0, NULL, 0}; }

/* Lexes text; returns the token count or -1 on a lexical error. */
static int lex(const char *text, Token **toks) {
  static Src src;
  src = mksrc(text);
  ErrFrame f;
  int n = -1;
  if (ERR_TRY(f)) {
    *toks = lex_all(&src, &n);
    err_pop(&f);
  } else {
    err_pop(&f);
  }
  return n;
}

static void test_lexer(void) {
  Token *t;
  int n = lex("f1' x = [1..5] \\\\ \\y -> y", &t);
  CHECK("lex: token count", n == 14);
  if (n == 14) {
    CHECK("lex: primed name", t[0].kind == T_NAME && t[0].len == 3);
    CHECK("lex: 1..5 is NUM DOTDOT NUM",
          t[4].kind == T_NUM && t[5].kind == T_DOTDOT && t[6].kind == T_NUM &&
              t[4].num == 1 && t[6].num == 5);
    CHECK("lex: \\\\ and \\", t[8].kind == T_BACKSLASH2 && t[9].kind == T_LAMBDA);
    CHECK("lex: -> ", t[11].kind == T_ARROW);
    CHECK("lex: eof", t[13].kind == T_EOF);
  }
  n = lex("a\n  b /* c\n */ d\n\te f", &t);
  CHECK("lex: comments skipped", n == 6);
  if (n == 6) {
    CHECK("lex: line and column", t[1].pos.line == 2 && t[1].pos.col == 3);
    CHECK("lex: begins line (a comment is not a token)",
          t[0].bol && t[1].bol && t[2].bol && t[3].bol);
    CHECK("lex: tab to column 9", t[3].pos.col == 9);
    CHECK("lex: second token on a line", !t[4].bol);
  }
  n = lex("1e-3 0.07 2.5e+2 \"a\\n\\\"b\"", &t);
  CHECK("lex: numbers and strings", n == 5 && t[0].num == 1e-3 &&
                                        t[1].num == 0.07 && t[2].num == 250 &&
                                        !strcmp(t[3].str, "a\n\"b"));
  CHECK("lex: unterminated string is an error", lex("x = \"abc", &t) < 0 &&
                                                   err_info()->pos.col == 5);
  CHECK("lex: unterminated comment is incomplete",
        lex("/* a", &t) < 0 && err_info()->incomplete);
  CHECK("lex: huge literal is an error", lex("1e400", &t) < 0);
  CHECK("lex: tiny literal is an error", lex("1e-400", &t) < 0);
  CHECK("lex: invalid UTF-8 is an error", lex("\xff", &t) < 0);
  CHECK("lex: UTF-8 in a comment is fine", lex("// \xc3\xa9t\xc3\xa9\n1", &t) == 2);
}

static int parse(const char *text, RunMode mode, Item ***items) {
  static Src src;
  src = mksrc(text);
  ErrFrame f;
  int n = -1;
  if (ERR_TRY(f)) {
    *items = parse_program(I, &src, mode, &n);
    err_pop(&f);
  } else {
    err_pop(&f);
  }
  return n;
}

static void test_parser(void) {
  Item **it;
  int n = parse("f 0 = 1;\nf n = n * f (n - 1);\nf 3\n", MODE_SCRIPT, &it);
  CHECK("parse: clauses merge into one definition", n == 2);
  if (n == 2) {
    CHECK("parse: two clauses", it[0]->kind == ITEM_DEF &&
                                    it[0]->def->nclauses == 2 &&
                                    it[0]->def->arity == 1);
    CHECK("parse: expression item", it[1]->kind == ITEM_EXPR);
  }
  n = parse("a = 1\nb = 2\nc = a +\n  b\n", MODE_SCRIPT, &it);
  CHECK("parse: column 1 starts a new item, indented lines continue", n == 3);
  n = parse("g x\n  | x > 0 = 1\n  | otherwise = 2\nwhere\n  y = 3\n  z = 4\nh = 5\n",
            MODE_SCRIPT, &it);
  CHECK("parse: guards and a where block at column 1", n == 2);
  if (n == 2)
    CHECK("parse: where bindings", it[0]->def->clauses[0]->nwhere == 2 &&
                                       it[0]->def->clauses[0]->nbodies == 2);
  n = parse(":: T = A Real | B T T | C;\n:: S = T;\n", MODE_SCRIPT, &it);
  CHECK("parse: type declaration and synonym", n == 2 && it[0]->ncons == 3 &&
                                                  it[0]->cons[1].arity == 2 &&
                                                  it[1]->ncons == 0);
  n = parse("f x = (x +", MODE_REPL, &it);
  CHECK("parse: open bracket at the end is incomplete",
        n < 0 && err_info()->incomplete);
  n = parse("f x = x)", MODE_REPL, &it);
  CHECK("parse: stray bracket is an error, not incomplete",
        n < 0 && !err_info()->incomplete);
  n = parse("1 < 2 < 3", MODE_REPL, &it);
  CHECK("parse: comparisons do not chain", n < 0);
  n = parse("f (a, a) = a", MODE_REPL, &it);
  CHECK("parse: repeated pattern variable", n < 0);
  /* Parsing defines nothing: a type's constructors are installed when the
     items run (interp.c), so a text that fails to parse, or one only
     parsed (fuzz/fuzz_parse.c), leaves the interpreter as it was. */
  n = parse(":: Parsed = Zorkon Real | Zorkoff;\nf Zorkoff = 1\n", MODE_SCRIPT,
            &it);
  CHECK("parse: a type declaration registers no constructor",
        n == 2 && sym_intern(I, "Zorkon", 6)->con_arity < 0 &&
            sym_intern(I, "Zorkoff", 7)->con_arity < 0);
  n = parse("f = a where Zorkon a = Zorkon 1", MODE_SCRIPT, &it);
  CHECK("parse: a capitalised local binding is left for the checker",
        n == 1 && it[0]->def->clauses[0]->nwhere == 1 &&
            !it[0]->def->clauses[0]->where[0]->pat);
}

/* Evaluates text and returns its printed value, or "error: MSG". */
static const char *ev(const char *text) {
  static Src src;
  src = mksrc(text);
  ErrFrame f;
  const char *out;
  int nforcing = I->nforcing;
  if (ERR_TRY(f)) {
    Expr *e = parse_expression(I, &src);
    out = show_value(I, eval(I, e, NULL));
    err_pop(&f);
  } else {
    err_pop(&f);
    static char buf[1200];
    snprintf(buf, sizeof buf, "error: %s", err_info()->msg);
    out = buf;
    eval_restore(I, nforcing);
    I->ntrace = 0;
  }
  return out;
}

#define CHECK_EV(expr, want) do {                                        \
    const char *got_ = ev(expr);                                          \
    if (!strcmp(got_, want)) printf("ok eval: %s\n", expr);               \
    else { printf("FAIL eval: %s: got '%s' want '%s'\n", expr, got_, want); \
           check_failed_count++; }                                        \
  } while (0)

static void test_eval(void) {
  CHECK_EV("1 + 2 * 3", "7");
  CHECK_EV("(1 + 2) * 3", "9");
  CHECK_EV("2 ^ 3 ^ 2", "512");
  CHECK_EV("10 - 4 - 3", "3");
  CHECK_EV("-2 ^ 2", "-4");
  CHECK_EV("let f 0 = 1; f n = n * f (n - 1) in f 10", "3628800");
  CHECK_EV("take 3 (iterate (\\x -> x * 2) 1)", "[1, 2, 4]");
  CHECK_EV("[x \\\\ x <- [1..10] | mod x 3 == 0]", "[3, 6, 9]");
  CHECK_EV("[(x, y) | x <- [1, 2], y <- [\"ab\" == \"ab\"]]", "[(1, True), (2, True)]");
  CHECK_EV("[1.5, 2 .. 3]", "[1.5, 2, 2.5, 3]");
  CHECK_EV("[0, 0.1 .. 0.3]", "[0, 0.1, 0.2, 0.30000000000000004]");
  /* past the end by up to half a step, as Haskell: [10, 8 .. 1] ends at 0 */
  CHECK_EV("[10, 8 .. 1]", "[10, 8, 6, 4, 2, 0]");
  CHECK_EV("let xs = 1 : map (\\x -> x + 1) xs in take 4 xs", "[1, 2, 3, 4]");
  CHECK_EV("fst (1, error \"never\")", "1");
  CHECK_EV("length [1..100000]", "100000");
  CHECK_EV("foldr (+) 0 [1..300]", "45150");
  CHECK_EV("sum [1..1000000]", "500000500000");
  CHECK_EV("if 1 < 2 then \"a\" ++ \"b\" else \"c\"", "\"ab\"");
  CHECK_EV("(1, 2, 3) * 2 - (1, 1, 1)", "(1, 3, 5)");
  CHECK_EV("cross (1, 0, 0) (0, 1, 0)", "(0, 0, 1)");
  CHECK_EV("Shift (0, 1, 0) (Halfspace ((0, 2, 0), 1))",
           "Halfspace ((0, 2, 0), 3)");
  CHECK_EV("Rounded 0.07 (DensityHalfspace ((-1, 0, 0), -0.5))",
           "Rounded 0.07 (DensityHalfspace ((-1, 0, 0), -0.5))");
  CHECK_EV("let (a, [b : c]) = (1, [2, 3]) in (a, b, c)", "(1, 2, [3])");
  CHECK_EV("let x = x + 1 in x", "error: this value depends on itself (an "
                                 "infinite loop)");
  CHECK_EV("head []", "error: head of an empty list");
  CHECK_EV("undefinedName", "error: unknown name 'undefinedName'");
  CHECK_EV("1 2", "error: a Real is not a function, but it is applied to 1 "
                  "argument: 1");
  /* The failed thunk is retried, not reported as a loop: */
  CHECK_EV("let f x = x in f 2", "2");
}

/* Shortest round-trip printing, against strtod as the reference. */
static void test_print(void) {
  uint64_t s = 12111;
  int bad = 0, longer = 0;
  for (int i = 0; i < 200000; i++) {
    s ^= s << 13, s ^= s >> 7, s ^= s << 17;
    double x;
    uint64_t bits = s;
    memcpy(&x, &bits, sizeof x);
    if (!isfinite(x)) continue;
    char buf[32], ref[40];
    format_real(buf, x);
    if (strtod(buf, NULL) != x) bad++;
    /* No more significant digits than the shortest %.*e that reads back. */
    int p;
    for (p = 1; p <= 17; p++) {
      snprintf(ref, sizeof ref, "%.*e", p - 1, x);
      if (strtod(ref, NULL) == x) break;
    }
    int digits = 0, seen = 0, trailing = 0;
    for (const char *c = buf; *c && *c != 'e'; c++)
      if (*c >= '1' && *c <= '9') digits += trailing + 1, trailing = 0, seen = 1;
      else if (*c == '0' && seen) trailing++;
    if (digits > p) longer++;
  }
  CHECK("print: 200000 random doubles read back exactly", bad == 0);
  CHECK("print: with the fewest significant digits", longer == 0);
  /* Whole numbers below 2^53 (printed directly, not by the search):
     glibc's exact %.0f as the reference, and the shortest form by the
     search above (no fewer digits read back). */
  int wrong = 0, shorter = 0;
  for (int i = 0; i < 100000; i++) {
    s ^= s << 13, s ^= s >> 7, s ^= s << 17;
    double x = (double)(s >> (11 + s % 53)); /* 0 .. 2^53 - 1, all sizes */
    if (i & 1) x = -x;
    if (i % 1000 == 0) x = (i & 2 ? 1 : -1) * (9007199254740992.0 - (double)(s % 7 + 1));
    char buf[32], ref[40];
    format_real(buf, x);
    snprintf(ref, sizeof ref, "%.0f", x);
    if (x == 0) strcpy(ref, signbit(x) ? "-0" : "0");
    if (strcmp(buf, ref)) wrong++;
    int p;
    for (p = 1; p <= 17; p++) {
      snprintf(ref, sizeof ref, "%.*e", p - 1, x);
      if (strtod(ref, NULL) == x) break;
    }
    size_t sig = strlen(buf) - (x < 0);
    while (sig > 1 && buf[(x < 0) + sig - 1] == '0') sig--;
    if ((int)sig != p) shorter++;
  }
  CHECK("print: 100000 whole numbers below 2^53 as %.0f writes them", wrong == 0);
  CHECK("print: whole numbers with the fewest significant digits", shorter == 0);
  char buf[32];
  format_real(buf, 0.1);
  CHECK("print: 0.1", !strcmp(buf, "0.1"));
  format_real(buf, 100);
  CHECK("print: 100", !strcmp(buf, "100"));
  format_real(buf, 1e-12);
  CHECK("print: 1e-12", !strcmp(buf, "1e-12"));
  format_real(buf, -2.5);
  CHECK("print: -2.5", !strcmp(buf, "-2.5"));
}

static void count_file(const char *path, void *ud) {
  char *names = ud;
  const char *slash = strrchr(path, '/');
  strncat(names, slash ? slash + 1 : path, 200);
  strncat(names, " ", 2);
}

/* interp_files_read: every file the runs imported, once, a failed one too */
static void test_files_read(void) {
  char dir[] = "/tmp/qcs-test-files-XXXXXX";
  if (!mkdtemp(dir)) {
    CHECK("files read: a temporary folder", 0);
    return;
  }
  const char *files[][2] = {
      {"main.qcs", "import \"b.qcs\"\nimport \"c.qcs\"\nm = b + c;\n"},
      {"b.qcs", "import \"c.qcs\"\nb = c + 1;\n"},
      {"c.qcs", "c = 1;\n"},
      {"bad.qcs", "import \"d.qcs\"\n"},
      {"d.qcs", "d = 1 +;\n"}};
  char path[256];
  for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
    snprintf(path, sizeof path, "%s/%s", dir, files[i][0]);
    FILE *f = fopen(path, "w");
    if (f) {
      fputs(files[i][1], f);
      fclose(f);
    }
  }
  Interp *J = bind_interp_new();
  char probe;
  interp_set_stack(J, &probe, 4u << 20);
  snprintf(path, sizeof path, "%s/main.qcs", dir);
  RunStatus st = interp_run_file(J, path);
  char names[1024] = "";
  interp_files_read(J, count_file, names);
  CHECK("files read: the imports, each once, in order",
        st == RUN_OK && !strcmp(names, "b.qcs c.qcs "));
  Interp *K = bind_interp_new();
  interp_set_stack(K, &probe, 4u << 20);
  snprintf(path, sizeof path, "%s/bad.qcs", dir);
  FILE *saved = stderr;
  stderr = fopen("/dev/null", "w");
  st = interp_run_file(K, path);
  fclose(stderr);
  stderr = saved;
  names[0] = 0;
  interp_files_read(K, count_file, names);
  CHECK("files read: an import with an error is listed",
        st == RUN_ERROR && !strcmp(names, "d.qcs "));
  for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
    snprintf(path, sizeof path, "%s/%s", dir, files[i][0]);
    remove(path);
  }
  rmdir(dir);
}

/* The number a global holds (forced), or NAN. */
static double global_num(Interp *J, const char *name) {
  Sym *s = sym_intern(J, name, (int)strlen(name));
  double x = NAN;
  ErrFrame f;
  if (ERR_TRY(f)) {
    Value *v = s->global ? force(J, s->global) : NULL;
    if (v && v->kind == V_NUM) x = v->u.num;
    err_pop(&f);
  } else {
    err_pop(&f);
  }
  return x;
}

/* interp_param_list and interp_set_param (qcs view's sliders): the table,
   the checks, and only the dependents evaluated again */
static void test_set_param(void) {
  char path[] = "/tmp/qcs-test-param-XXXXXX";
  int fd = mkstemp(path);
  if (fd < 0) {
    CHECK("set param: a temporary file", 0);
    return;
  }
  const char *text = "param a = 2 in [0, 10] \"the a\"\nparam s = \"text\"\n"
                     "param u = 5\nb = a * 10;\nc = 7 + 1;\nd = b + u;\n";
  ssize_t w = write(fd, text, strlen(text));
  close(fd);
  Interp *J = bind_interp_new();
  char probe;
  interp_set_stack(J, &probe, 4u << 20);
  RunStatus st = w > 0 ? interp_run_file(J, path) : RUN_ERROR;
  remove(path);
  InterpParam p[8];
  int n = interp_param_list(J, p, 8);
  CHECK("set param: the table", st == RUN_OK && n == 3 &&
        !strcmp(p[0].name, "a") && p[0].has_range && p[0].lo == 0 &&
        p[0].hi == 10 && p[0].numeric && p[0].value == 2 &&
        !strcmp(p[0].doc, "the a") && !strcmp(p[0].text, "2") &&
        !strcmp(p[1].name, "s") && !p[1].numeric && !p[1].has_range &&
        !strcmp(p[2].name, "u") && p[2].numeric && !p[2].has_range);
  if (st != RUN_OK || n != 3) return;
  CHECK("set param: before", global_num(J, "d") == 25 &&
        global_num(J, "c") == 8);
  Value *c0 = sym_intern(J, "c", 1)->global, *b0 = sym_intern(J, "b", 1)->global;
  char err[300];
  st = interp_set_param(J, "a", 3.5, err, sizeof err);
  CHECK("set param: a = 3.5 re-binds what depends on a",
        st == RUN_OK && global_num(J, "d") == 40 && global_num(J, "b") == 35 &&
        sym_intern(J, "b", 1)->global != b0);
  CHECK("set param: what does not depend on a keeps its value",
        sym_intern(J, "c", 1)->global == c0 && global_num(J, "c") == 8);
  CHECK("set param: a number without a range",
        interp_set_param(J, "u", -1e9, err, sizeof err) == RUN_OK &&
        global_num(J, "d") == 35 - 1e9);
  CHECK("set param: out of range refused, nothing changed",
        interp_set_param(J, "a", 10.5, err, sizeof err) == RUN_ERROR &&
        strstr(err, "outside the range [0, 10]") && global_num(J, "b") == 35);
  CHECK("set param: NaN and infinity refused",
        interp_set_param(J, "a", NAN, err, sizeof err) == RUN_ERROR &&
        interp_set_param(J, "u", INFINITY, err, sizeof err) == RUN_ERROR &&
        global_num(J, "d") == 35 - 1e9);
  CHECK("set param: not a parameter",
        interp_set_param(J, "c", 1, err, sizeof err) == RUN_ERROR &&
        strstr(err, "no parameter c") &&
        interp_set_param(J, "nosuch", 1, err, sizeof err) == RUN_ERROR);
  CHECK("set param: a parameter whose value is not a number",
        interp_set_param(J, "s", 1, err, sizeof err) == RUN_ERROR &&
        strstr(err, "does not take a number"));
  interp_free(J);
}

/* The prelude and the kit read one definition at a time, as needed
   (interp.c), against both read whole at start-up (QCS_EAGER_PRELUDE=1,
   the way they were always loaded): every definition, once needed, is
   the same (where, arity, clauses, signature, doc, example), and so are
   :browse! and the prelude's own view of a name the user redefines. */
static char *browse_all(Interp *J) {
  char *buf = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&buf, &len);
  if (!f) return NULL;
  interp_browse(J, f, 1);
  fclose(f);
  return buf;
}

static int same_str(const char *a, const char *b) {
  return a == b || (a && b && !strcmp(a, b));
}

static void test_lazy_prelude(void) {
  setenv("QCS_EAGER_PRELUDE", "1", 1);
  Interp *E = bind_interp_new();
  unsetenv("QCS_EAGER_PRELUDE");
  Interp *L = bind_interp_new();
  int pending = 0, defs = 0, same = 0, cons = 0, same_cons = 0;
  for (size_t h = 0; h < L->symcap; h++)
    for (Sym *s = L->symtab[h]; s; s = s->next) pending += s->lazy != NULL;
  int eager_pending = 0;
  for (size_t h = 0; h < E->symcap; h++)
    for (Sym *s = E->symtab[h]; s; s = s->next) eager_pending += s->lazy != NULL;
  CHECK("lazy prelude: eager load reads everything at start-up",
        eager_pending == 0);
  for (size_t h = 0; h < E->symcap; h++)
    for (Sym *e = E->symtab[h]; e; e = e->next) {
      Sym *l = sym_intern(L, e->name, (int)strlen(e->name));
      if (e->con_arity >= 0) {
        cons++;
        same_cons += l->con_arity == e->con_arity && l->con_type &&
                     e->con_type && !strcmp(l->con_type->name, e->con_type->name);
        continue;
      }
      if (!e->def || e->user) continue;
      defs++;
      interp_materialize(L, l);
      same += l->def && !l->lazy && l->def->arity == e->def->arity &&
              l->def->nclauses == e->def->nclauses &&
              l->def_pos.line == e->def_pos.line &&
              l->def_pos.col == e->def_pos.col && l->def_pos.src &&
              !strcmp(l->def_pos.src->name, e->def_pos.src->name) &&
              l->def_pos.src->prelude && same_str(l->sig, e->sig) &&
              same_str(l->doc, e->doc) && same_str(l->example, e->example) &&
              l->prelude_def == l->def && l->prelude_value == l->global &&
              l->global && l->global->kind == e->global->kind && !l->user;
    }
  CHECK("lazy prelude: the prelude's and the kit's definitions", defs > 100);
  CHECK("lazy prelude: every one of them waited until needed",
        pending == defs);
  CHECK("lazy prelude: each read alike (position, arity, clauses, "
        "signature, doc, example)", same == defs);
  CHECK("lazy prelude: constructors installed at start-up", cons > 30 &&
        same_cons == cons);
  char *be = browse_all(E), *bl = browse_all(L);
  CHECK(":browse! the same either way", be && bl && strlen(be) > 5000 &&
        !strcmp(be, bl));
  free(be);
  free(bl);
  /* The user redefines Shift; the prelude's Box, read after, still
     moves with the prelude's (Box lo hi = Shift lo (Scale ...)). */
  Interp *U = bind_interp_new();
  char probe;
  interp_set_stack(U, &probe, 4u << 20);
  int ok = interp_run_string(U, "<test>", "Shift v x = 42;", MODE_SCRIPT) ==
           RUN_OK;
  Value *v = NULL, *w = NULL;
  ErrFrame f;
  if (ok && ERR_TRY(f)) {
    v = force(U, interp_eval_expr(U, "<test>", "Box (0, 0, 0) (1, 2, 3)"));
    w = force(U, interp_eval_expr(U, "<test>", "Shift (1, 0, 0) UnitCube"));
    err_pop(&f);
  } else if (ok) {
    err_pop(&f);
  }
  CHECK("lazy prelude: a user's Shift, the prelude's Box read after it",
        v && v->kind == V_CON && !strcmp(v->u.con.con->name, "Product") &&
        w && w->kind == V_NUM && w->u.num == 42);
  Sym *sh = sym_intern(U, "Shift", 5);
  CHECK("lazy prelude: the prelude's Shift kept for its own code",
        sh->prelude_def && sh->prelude_def != sh->def && sh->user &&
        sh->prelude_pos.src && sh->prelude_pos.src->prelude);
  interp_free(U);
  interp_free(L);
  interp_free(E);
}

/* The collector's own static data is not a root (interp_gc_init): an
   object referenced only from a word there is collected, while one
   referenced only from our own static data is kept. The word is the
   collector's own GC_is_visible_print_proc, looked up in its library
   (this binary does not use it, so it has no copy of it), which only
   GC_is_visible (never called here) reads; disappearing links,
   cleared by the collector when their object goes, tell which went. A
   collector that scanned its own data, as it did before, keeps both: the
   hint word for its next mmap pinned the first object of a heap section
   so, and with it every later cell of a list being consumed
   (suite-stream's stream-let-map failed about 1 run in 25). */
static GC_word gc_links[2];
static void *gc_ours;

static __attribute__((noinline)) void gc_roots_setup(void **word) {
  void *theirs = GC_MALLOC(64), *ours = GC_MALLOC(64);
  gc_links[0] = GC_HIDE_POINTER(theirs);
  gc_links[1] = GC_HIDE_POINTER(ours);
  GC_general_register_disappearing_link((void **)&gc_links[0], theirs);
  GC_general_register_disappearing_link((void **)&gc_links[1], ours);
  *word = theirs;
  gc_ours = ours;
}

static __attribute__((noinline)) void gc_scrub(void) {
  volatile char pad[16384];
  memset((char *)pad, 0, sizeof pad);
  __asm__ volatile("" : : "r"(pad) : "memory");
}

static void test_gc_roots(void) {
  Dl_info di;
  void *lib = NULL, **word = NULL;
  if (dladdr((void *)GC_get_push_other_roots(), &di) && di.dli_fname &&
      (lib = dlopen(di.dli_fname, RTLD_LAZY | RTLD_NOLOAD)))
    word = dlsym(lib, "GC_is_visible_print_proc");
  CHECK("gc: the collector's library and a word of its data found",
        word != NULL);
  if (!word) return;
  void *saved = *word;
  gc_roots_setup(word);
  gc_scrub();
  GC_gcollect();
  GC_gcollect();
  CHECK("gc: an object referenced only from the collector's own data is "
        "collected", gc_links[0] == 0);
  CHECK("gc: an object referenced from our static data is kept",
        gc_links[1] != 0 && gc_ours != NULL);
  *word = saved;
  dlclose(lib);
}

int main(void) {
  check_prefix = "lang";
  I = bind_interp_new();
  char probe;
  interp_set_stack(I, &probe, 4u << 20);
  test_lexer();
  test_parser();
  test_eval();
  test_print();
  test_files_read();
  test_set_param();
  test_lazy_prelude();
  test_gc_roots();
  CHECK_DONE();
}
