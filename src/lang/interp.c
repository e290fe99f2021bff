#define _GNU_SOURCE /* dladdr */
/* interp.c: running source text. See interp.h.
 *
 * A run parses the whole text first (a syntax error runs nothing), installs
 * its type declarations' constructors, resolves and checks every name it
 * uses (resolve.h: an unknown name is reported before anything is
 * evaluated, with a suggestion), installs the definitions, and then
 * evaluates the top-level expressions in order. */
#include "lang/interp.h"

#include <dlfcn.h>
#include <errno.h>
#include <gc.h>
#include <gc/gc_mark.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lang/builtins.h"
#include "lang/eval.h"
#include "lang/parse.h"
#include "lang/print.h"
#include "lang/resolve.h"

#include "prelude.inc"
#include "kit.inc"

#ifndef QCS_VERSION
#define QCS_VERSION "0.1"
#endif

static int run_counter;
static void materialize_all(Interp *I);

/* ---- error display ---- */

static int in_prelude(Interp *I, Pos p) {
  (void)I;
  return p.src && p.src->prelude;
}

/* A call made by the prelude's code to a prelude function or a built-in
   (not to a function of the user's, such as a lambda given to map). */
static int prelude_frame(Interp *I, const TraceEntry *t) {
  if (!in_prelude(I, t->pos) || t->name[0] == '%') return 0;
  Sym *s = sym_intern(I, t->name, (int)strlen(t->name));
  return !s->user && (s->def || s->builtin);
}

static void report_error(Interp *I) {
  ErrInfo *e = err_info();
  /* Found where no position was at hand (a lazy list's tail, printing):
     the top-level expression being run. */
  if (!e->pos.line && I->item_pos.line) e->pos = I->item_pos;
  I->item_pos = pos_none;
  /* Raised in the prelude: reported at the user's call that led there
     (Interp.origin), the prelude's line after it. */
  int from_prelude = in_prelude(I, e->pos);
  if (from_prelude && I->origin && I->origin->src && I->origin->line &&
      !in_prelude(I, *I->origin)) {
    err_report(stderr, "error", *I->origin, e->msg);
    fprintf(stderr, "  (raised inside the prelude, at %s:%d:%d)\n",
            e->pos.src->name, e->pos.line, e->pos.col);
  } else {
    err_report(stderr, "error", e->pos, e->msg);
  }
  I->origin = NULL;
  int n = I->ntrace < TRACE_MAX ? I->ntrace : TRACE_MAX;
  int lines = 0, i = n - 1;
  /* Innermost first; a run of identical entries (deep recursion) is
     shown once with its count; a run of calls made by the prelude's own
     code is one line naming them. */
  while (i >= 0 && lines < 8) {
    TraceEntry *t = &I->trace[i];
    if (prelude_frame(I, t) && i > 0 && prelude_frame(I, &I->trace[i - 1])) {
      fputs("  in the prelude:", stderr);
      int shown = 0, calls = 0;
      const char *prev = NULL;
      for (; i >= 0 && prelude_frame(I, &I->trace[i]); i--, calls++) {
        const char *nm = I->trace[i].name;
        if (prev && !strcmp(prev, nm)) continue;
        if (shown < 5) fprintf(stderr, "%s %s", shown ? "," : "", nm);
        else if (shown == 5) fputs(", ...", stderr);
        shown++;
        prev = nm;
      }
      fprintf(stderr, " (%d call%s)\n", calls, calls == 1 ? "" : "s");
      lines++;
      continue;
    }
    int same = 1;
    while (i - same >= 0 && I->trace[i - same].name == t->name &&
           I->trace[i - same].pos.line == t->pos.line &&
           I->trace[i - same].pos.col == t->pos.col &&
           I->trace[i - same].pos.src == t->pos.src)
      same++;
    const char *name = t->name[0] == '%' ? "a list comprehension" : t->name;
    if (t->pos.src && t->pos.line)
      fprintf(stderr, "  in %s, called at %s:%d:%d", name,
              t->pos.src->name, t->pos.line, t->pos.col);
    else
      fprintf(stderr, "  in %s", name);
    if (same > 1) fprintf(stderr, " (%d times)", same);
    fputc('\n', stderr);
    i -= same;
    lines++;
  }
  if (i >= 0) fprintf(stderr, "  ... and %d more calls\n", i + 1);
}

/* Put back every thunk that was being forced when the error struck, so
   a later evaluation retries it instead of seeing a false loop. */
static void unwind(Interp *I, int nforcing) {
  eval_restore(I, nforcing);
  I->ntrace = 0;
  I->origin = NULL;
  qcs_interrupted = 0;
}

/* ---- running ---- */

static void install_type(Interp *I, Item *it) {
  for (int i = 0; i < it->ncons; i++) {
    Sym *s = it->cons[i].name;
    s->con_arity = it->cons[i].arity;
    s->con_type = it->type;
    s->con_value = NULL;
    s->global = NULL;
    s->def = NULL;
    s->user = !I->loading_prelude;
    s->def_pos = it->cons[i].pos;
  }
}

/* Re-create every user-defined value from its definition, so that values
   computed from a definition the REPL has just replaced are computed
   again (a scene follows its parameters). */
static void refresh_values(Interp *I) {
  for (size_t h = 0; h < I->symcap; h++)
    for (Sym *s = I->symtab[h]; s; s = s->next)
      if (s->user && s->def && s->def->arity == 0 && !s->overridden)
        s->global = eval_global_value(I, s->def);
}

/* ---- doc comments ----
 *
 * The comment lines right above a definition (or above its signature) may
 * hold "// doc: TEXT", one line saying what it does, and "// e.g. EXPR",
 * an expression showing it; :doc and :info show them. */

static char *gc_strndup(const char *s, size_t n) {
  char *p = GC_MALLOC_ATOMIC(n + 1);
  memcpy(p, s, n);
  p[n] = 0;
  return p;
}

/* The start of each line of src: found once per source (and kept in it)
   instead of once per definition; the prelude's definitions, read one by
   one as they are needed, come from two sources in turn. */
static const char *line_at(const Src *src, int line) {
  if (!src->lines) {
    int n = 1;
    for (const char *p = src->text; *p; p++) n += *p == '\n';
    const char **at = GC_MALLOC(sizeof(char *) * (size_t)(n + 1));
    int k = 0;
    at[k++] = src->text;
    for (const char *p = src->text; *p; p++)
      if (*p == '\n') at[k++] = p + 1;
    Src *w = (Src *)src; /* a cache: the text it describes is unchanged */
    w->lines = at;
    w->nlines = k;
  }
  return line >= 1 && line <= src->nlines ? src->lines[line - 1] : NULL;
}

static void read_doc(Sym *s, Pos pos) {
  s->doc = s->example = NULL;
  if (!pos.src || !pos.src->text || pos.line < 2) return;
  const char *text = pos.src->text, *cur = line_at(pos.src, pos.line);
  if (!cur) return;
  size_t nlen = strlen(s->name);
  while (cur > text) {
    const char *end = cur - 1; /* the '\n' ending the line above */
    const char *start = end;
    while (start > text && start[-1] != '\n') start--;
    cur = start;
    const char *p = start;
    while (p < end && (*p == ' ' || *p == '\t')) p++;
    const char *q = end;
    while (q > p && (q[-1] == ' ' || q[-1] == '\t' || q[-1] == '\r')) q--;
    if (p == q) break; /* a blank line ends the block */
    if (q - p >= 2 && p[0] == '/' && p[1] == '/') {
      const char *c = p + 2;
      while (c < q && *c == ' ') c++;
      if (q - c > 4 && !strncmp(c, "doc:", 4)) {
        c += 4;
        while (c < q && *c == ' ') c++;
        if (!s->doc) s->doc = gc_strndup(c, (size_t)(q - c));
      } else if (q - c > 4 && !strncmp(c, "e.g.", 4)) {
        c += 4;
        while (c < q && *c == ' ') c++;
        if (!s->example) s->example = gc_strndup(c, (size_t)(q - c));
      }
      continue;
    }
    /* the name's signature: "name :: type" */
    if ((size_t)(q - p) > nlen && !strncmp(p, s->name, nlen)) {
      const char *c = p + nlen;
      while (c < q && (*c == ' ' || *c == '\t')) c++;
      if (q - c >= 2 && c[0] == ':' && c[1] == ':') continue;
    }
    break;
  }
}

/* A user definition of a name the built-ins or the prelude define: said
   once per name, as a warning (the prelude's own code keeps its own);
   only where asked (the REPL: the paper's scripts call their ground
   plane floor, and say so in their comments). */
static void warn_shadow(Interp *I, Sym *s, Pos pos) {
  if (!I->warn_shadow || I->loading_prelude || !s->prelude_value ||
      s->shadow_warned)
    return;
  s->shadow_warned = 1;
  qcs_warning(pos, "%s shadows the %s %s: your definition is used from now "
              "on (the prelude's own functions keep the original)", s->name,
              s->builtin ? "built-in" : "prelude's", s->name);
}
/* ---- growing arrays (GC heap) ---- */

static void *grow(void *a, int n, int *cap, size_t size) {
  if (n < *cap) return a;
  int nc = *cap ? 2 * *cap : 8;
  void *b = GC_MALLOC(size * (size_t)nc);
  if (n) memcpy(b, a, size * (size_t)n);
  *cap = nc;
  return b;
}

static char *gc_strdup(const char *t) {
  char *c = GC_MALLOC_ATOMIC(strlen(t) + 1);
  strcpy(c, t);
  return c;
}

/* ---- parameters ---- */

static int same_kind(Value *a, Value *b) {
  int la = a->kind == V_NIL || a->kind == V_CONS;
  int lb = b->kind == V_NIL || b->kind == V_CONS;
  if (la || lb) return la && lb;
  int fa = a->kind == V_FUNC || a->kind == V_PAP;
  int fb = b->kind == V_FUNC || b->kind == V_PAP;
  if (fa || fb) return fa && fb;
  if (a->kind != b->kind) return 0;
  if (a->kind == V_TUPLE) return a->u.tup.n == b->u.tup.n;
  if (a->kind == V_CON) return a->u.con.con->con_type == b->u.con.con->con_type;
  return 1;
}

/* The range of a parameter, evaluated: lo and hi. */
static void param_range(Interp *I, const Param *pm, double *lo, double *hi) {
  *lo = force_num(I, eval(I, pm->lo, NULL), pm->lo->pos,
                  "the low end of a parameter's range");
  *hi = force_num(I, eval(I, pm->hi, NULL), pm->hi->pos,
                  "the high end of a parameter's range");
  if (!(*lo <= *hi))
    qcs_error(pm->lo->pos, "a parameter's range [LOW, HIGH] needs LOW <= "
              "HIGH, not [%g, %g]", *lo, *hi);
}

static void record_param(Interp *I, Sym *s, const Param *pm) {
  int known = s->param != NULL;
  s->param = pm;
  if (known) return;
  I->params = grow(I->params, I->nparams, &I->capparams, sizeof(Sym *));
  I->params[I->nparams++] = s;
}

/* A declared parameter's default must lie in its range. */
static void check_default(Interp *I, Sym *s, Def *d) {
  const Param *pm = s->param;
  if (!pm->lo) return;
  double lo, hi;
  param_range(I, pm, &lo, &hi);
  Value *v = force(I, eval_global_value(I, d));
  if (v->kind != V_NUM)
    qcs_error(d->clauses[0]->bodies[0]->pos, "parameter %s has a range, so "
              "its default must be a number, not %s", s->name,
              val_describe(v));
  if (!(v->u.num >= lo && v->u.num <= hi))
    qcs_error(d->clauses[0]->bodies[0]->pos, "the default %g of parameter %s "
              "is outside its range [%g, %g]", v->u.num, s->name, lo, hi);
}

/* Every --set must name a declared parameter, with a value of the
   default's kind, within its range; checked once the first script's
   definitions are in, before any of its expressions run. */
static void check_sets(Interp *I, const char *runname) {
  I->sets_pending = 0;
  for (int i = 0; i < I->nset_syms; i++) {
    Sym *s = I->set_syms[i];
    if (s->set_checked) continue;
    const char *best = NULL;
    int bestd = (int)strlen(s->name) / 2 + 1;
    if (bestd > 4) bestd = 4;
    for (int j = 0; j < I->nparams; j++) {
      int d = edit_distance(s->name, I->params[j]->name);
      if (d < bestd) bestd = d, best = I->params[j]->name;
    }
    if (best)
      qcs_error(pos_none, "--set %s: %s declares no parameter %s (did you "
                "mean %s?)", s->name, runname, s->name, best);
    if (I->nparams == 0)
      qcs_error(pos_none, "--set %s: %s declares no parameters (declare one "
                "with `param %s = DEFAULT`)", s->name, runname, s->name);
    char names[400];
    size_t k = 0;
    names[0] = 0;
    for (int j = 0; j < I->nparams && k < sizeof names - 40; j++)
      k += (size_t)snprintf(names + k, sizeof names - k, "%s%s",
                            j ? ", " : "", I->params[j]->name);
    qcs_error(pos_none, "--set %s: %s declares no parameter %s (its "
              "parameters: %s)", s->name, runname, s->name, names);
  }
  for (int i = 0; i < I->nset_syms; i++) {
    Sym *s = I->set_syms[i];
    const Param *pm = s->param;
    Value *v = force(I, s->global);
    Value *dv = force(I, eval_global_value(I, s->def));
    Pos at = s->set_expr->pos;
    if (pm->lo) {
      double lo, hi;
      param_range(I, pm, &lo, &hi);
      if (v->kind != V_NUM)
        qcs_error(at, "parameter %s (%s:%d) takes a number in [%g, %g], not "
                  "%s", s->name, s->def_pos.src->name, s->def_pos.line, lo, hi,
                  val_describe(v));
      if (!(v->u.num >= lo && v->u.num <= hi))
        qcs_error(at, "%g is outside the range [%g, %g] of parameter %s "
                  "(%s:%d)", v->u.num, lo, hi, s->name, s->def_pos.src->name,
                  s->def_pos.line);
    } else if (!same_kind(v, dv)) {
      qcs_error(at, "parameter %s (%s:%d) takes %s like its default %s, not "
                "%s", s->name, s->def_pos.src->name, s->def_pos.line,
                val_describe(dv), pm->text, val_describe(v));
    }
  }
}

/* ---- imports ---- */

static RunStatus run_items(Interp *I, Item **items, int n, RunMode mode,
                           const char *runname, int imported);

#ifndef QCS_LIBDIR
#define QCS_LIBDIR "/usr/local/share/qcs"
#endif

/* Where `import "NAME"` finds NAME: beside the importing file, then in
   each folder of QCS_PATH (':'-separated), then in QCS_LIBDIR (where make
   install puts the prelude and the example parts). NULL if nowhere; the
   folders tried are listed in tried. */
static char *find_import(const char *importer, const char *name, char *tried,
                         size_t tn) {
  size_t k = 0;
  tried[0] = 0;
  if (name[0] == '/') {
    snprintf(tried, tn, "%s", name);
    return access(name, R_OK) == 0 ? gc_strdup(name) : NULL;
  }
  char dir[PATH_MAX];
  const char *slash = importer[0] == '<' ? NULL : strrchr(importer, '/');
  if (slash) snprintf(dir, sizeof dir, "%.*s", (int)(slash - importer),
                      importer);
  else snprintf(dir, sizeof dir, ".");
  const char *env = getenv("QCS_PATH");
  char list[4 * PATH_MAX];
  snprintf(list, sizeof list, "%s:%s:%s", dir, env ? env : "", QCS_LIBDIR);
  for (char *d = list, *e; d; d = e) {
    e = strchr(d, ':');
    if (e) *e++ = 0;
    if (!*d) continue;
    size_t pl = strlen(d) + strlen(name) + 2;
    char *path = GC_MALLOC_ATOMIC(pl);
    if (d == list && !slash) snprintf(path, pl, "%s", name);
    else snprintf(path, pl, "%s/%s", d, name);
    if (access(path, R_OK) == 0) return path;
    if (k < tn)
      k += (size_t)snprintf(tried + k, tn - k, "%s%s", k ? ", " : "", d);
  }
  return NULL;
}

static char *read_file(const char *path, size_t *len);

static void push_file(Interp *I, const char *real, const char *shown) {
  int cap = I->capfiles;
  I->files = grow(I->files, I->nfiles, &cap, sizeof(char *));
  I->shown = grow(I->shown, I->nfiles, &I->capfiles, sizeof(char *));
  I->files[I->nfiles] = gc_strdup(real);
  I->shown[I->nfiles++] = gc_strdup(shown);
}

/* The Syms an imported file's definitions hold (its own names, or the
   qualified ones it was given where another import had the name). */
struct ImportedDefs {
  const char *path;   /* as found (what Sym.imported holds) */
  Sym *qual;          /* its first qualifier, or NULL */
  Sym **syms;
  int n, cap;
};

/* The qualifier of an import: `as Name`, else the file's stem with a
   capital (parts.qcs: Parts), or NULL if the stem is not a name
   (soft-cloud.qcs). */
static Sym *import_qualifier(Interp *I, const Item *it) {
  if (it->import_as) return it->import_as;
  const char *b = strrchr(it->import, '/');
  b = b ? b + 1 : it->import;
  size_t n = strlen(b);
  if (n > 4 && !strcmp(b + n - 4, ".qcs")) n -= 4;
  if (n == 0 || n > 200 || !((b[0] >= 'a' && b[0] <= 'z') ||
                              (b[0] >= 'A' && b[0] <= 'Z')))
    return NULL;
  char name[208];
  for (size_t i = 0; i < n; i++) {
    char c = b[i];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
          (c >= '0' && c <= '9') || c == '_'))
      return NULL;
    name[i] = c;
  }
  if (name[0] >= 'a' && name[0] <= 'z') name[0] = (char)(name[0] - 'a' + 'A');
  return sym_intern(I, name, (int)n);
}

/* Q.x for the plain name of t (t may itself be qualified). */
static Sym *qualified_sym(Interp *I, Sym *q, const Sym *t) {
  const char *plain = strchr(t->name, '.');
  plain = plain ? plain + 1 : t->name;
  char buf[512];
  int n = snprintf(buf, sizeof buf, "%s.%s", q->name, plain);
  if (n < 0 || n >= (int)sizeof buf) return NULL;
  return sym_intern(I, buf, n);
}

/* Make Q.x name each definition x of the imported file k. */
static void alias_defs(Interp *I, Sym *q, int k, Pos pos) {
  struct ImportedDefs *d = &I->importdefs[k];
  for (int i = 0; i < d->n; i++) {
    Sym *t = d->syms[i];
    Sym *a = qualified_sym(I, q, t);
    if (!a || a == t) continue;
    if (a->global && a->imported && a->imported != t->imported)
      qcs_error(pos, "%s names two imports (%s is also from %s)", q->name,
                a->name, a->imported);
    a->global = t->global;
    a->def = t->def;
    a->sig = t->sig;
    a->doc = t->doc;
    a->example = t->example;
    a->def_pos = t->def_pos;
    a->def_file = t->def_file;
    a->imported = t->imported;
    a->user = 1;
    a->alias_of = t;
  }
}

/* 1 if q already names the import of r; an error if it names another. */
static int check_qualifier(Interp *I, Sym *q, const char *r, Pos pos) {
  for (int i = 0; q && i < I->nquals; i++)
    if (I->quals[i] == q) {
      if (strcmp(I->qual_files[i], r))
        qcs_error(pos, "%s already names the import of %s (give this one "
                  "another: import \"...\" as Name)", q->name,
                  I->qual_files[i]);
      return 1;
    }
  return 0;
}

/* Register qualifier q for the imported file k (real path r). */
static void add_qualifier(Interp *I, Sym *q, const char *r, int k, Pos pos) {
  if (!q || check_qualifier(I, q, r, pos)) return;
  int cap = I->capquals;
  I->quals = grow(I->quals, I->nquals, &cap, sizeof(Sym *));
  I->qual_files = grow(I->qual_files, I->nquals, &I->capquals, sizeof(char *));
  I->quals[I->nquals] = q;
  I->qual_files[I->nquals++] = r;
  alias_defs(I, q, k, pos);
}

/* import "NAME": runs the file once (its definitions, types and
   parameters; its top-level expressions are checked, not run). */
static void run_import(Interp *I, Item *it, const char *runname) {
  char tried[1024];
  char *path = find_import(runname, it->import, tried, sizeof tried);
  if (!path)
    qcs_error(it->pos, "cannot find \"%s\" to import (looked in %s)",
              it->import, tried);
  char *real = realpath(path, NULL);
  if (!real)
    qcs_error(it->pos, "cannot import %s: %s", path, strerror(errno));
  char *r = gc_strdup(real);
  free(real);
  for (int i = 0; i < I->nfiles; i++)
    if (!strcmp(I->files[i], r)) {
      char chain[2048];
      size_t k = 0;
      chain[0] = 0;
      for (int j = i; j < I->nfiles && k < sizeof chain; j++)
        k += (size_t)snprintf(chain + k, sizeof chain - k, "%s -> ",
                              I->shown[j]);
      if (k < sizeof chain) snprintf(chain + k, sizeof chain - k, "%s", path);
      qcs_error(it->pos, "import cycle: %s", chain);
    }
  Sym *qual = import_qualifier(I, it);
  check_qualifier(I, qual, r, it->pos);
  for (int i = 0; i < I->nimported; i++)
    if (!strcmp(I->imported[i], r)) {
      add_qualifier(I, qual, r, i, it->pos);
      return;
    }
  int seen = 0;
  for (int i = 0; i < I->nreadfiles; i++)
    if (!strcmp(I->readfiles[i], path)) seen = 1;
  if (!seen) {
    I->readfiles = grow(I->readfiles, I->nreadfiles, &I->capreadfiles,
                        sizeof(char *));
    I->readfiles[I->nreadfiles++] = gc_strdup(path);
  }
  size_t len;
  char *text = read_file(path, &len);
  if (!text) qcs_error(it->pos, "cannot read %s: %s", path, strerror(errno));
  Src *src = GC_MALLOC(sizeof *src);
  src->name = path;
  char *tx = GC_MALLOC_ATOMIC(len + 1);
  memcpy(tx, text, len + 1);
  free(text);
  if (strlen(tx) < len)
    qcs_error(it->pos, "cannot import %s: it holds a NUL byte", path);
  src->text = tx;
  push_file(I, r, path);
  int n;
  Item **items = parse_program(I, src, MODE_SCRIPT, &n);
  Sym *saved = I->cur_qual;
  I->cur_qual = qual;
  run_items(I, items, n, MODE_SCRIPT, path, 1);
  I->cur_qual = saved;
  I->nfiles--;
  int cap = I->capimported;
  I->imported = grow(I->imported, I->nimported, &I->capimported,
                     sizeof(char *));
  I->importdefs = grow(I->importdefs, I->nimported, &cap,
                       sizeof(struct ImportedDefs));
  struct ImportedDefs *d = &I->importdefs[I->nimported];
  memset(d, 0, sizeof *d);
  d->path = path;
  d->qual = qual;
  for (int i = 0; i < n; i++)
    if (items[i]->kind == ITEM_DEF) {
      d->syms = grow(d->syms, d->n, &d->cap, sizeof(Sym *));
      d->syms[d->n++] = items[i]->def->name;
    }
  I->imported[I->nimported++] = r;
  add_qualifier(I, qual, r, I->nimported - 1, it->pos);
}

/* ---- running items ---- */

static RunStatus run_items(Interp *I, Item **items, int n, RunMode mode,
                           const char *runname, int imported) {
  int runid = ++run_counter;
  for (int i = 0; i < n; i++)
    if (items[i]->kind == ITEM_IMPORT) run_import(I, items[i], runname);
  /* A name the user defines, declares or signs that the prelude defines
     too: the prelude's definition is read first (its code keeps it). */
  if (!I->loading_prelude)
    for (int i = 0; i < n; i++) {
      Item *it = items[i];
      if (it->kind == ITEM_DEF && it->def->name)
        interp_materialize(I, it->def->name);
      else if (it->kind == ITEM_SIG)
        interp_materialize(I, it->signame);
      else if (it->kind == ITEM_TYPE)
        for (int k = 0; k < it->ncons; k++)
          interp_materialize(I, it->cons[k].name);
    }
  /* Duplicate definitions within one script are mistakes. */
  for (int i = 0; i < n; i++) {
    if (items[i]->kind != ITEM_DEF) continue;
    Def *d = items[i]->def;
    for (int j = 0; j < i; j++)
      if (items[j]->kind == ITEM_DEF && items[j]->def->name == d->name)
        qcs_error(d->pos, "%s is already defined at %d:%d (the clauses of a "
                  "function must be together)", d->name->name,
                  items[j]->def->pos.line, items[j]->def->pos.col);
  }
  for (int i = 0; i < n; i++)
    if (items[i]->kind == ITEM_TYPE) install_type(I, items[i]);
  for (int i = 0; i < n; i++)
    if (items[i]->kind == ITEM_DEF && items[i]->def->name->con_arity >= 0)
      qcs_error(items[i]->def->pos, "'%s' is a constructor; a function needs "
                "another name", items[i]->def->name->name);
  for (int i = 0; i < n; i++)
    if (items[i]->kind == ITEM_DEF && strchr(items[i]->def->name->name, '.'))
      qcs_error(items[i]->def->pos, "%s is a qualified name (an import's "
                "definition): it cannot be defined", items[i]->def->name->name);
  /* A definition may not clash with another file's, but for two imports:
     the later one's takes its qualified name (Parts.x), inside that file
     its own name still means it, and the bare name, used anywhere else,
     is an error that lists both. The importer's own definitions and
     parameters may clash with none. */
  int nrename0 = I->nrename;
  if (mode == MODE_SCRIPT && !I->loading_prelude)
    for (int i = 0; i < n; i++) {
      if (items[i]->kind != ITEM_DEF) continue;
      Def *d = items[i]->def;
      Sym *s = d->name;
      if (!s->def || !s->user || s->overridden) continue;
      if ((s->imported && s->imported != runname) ||
          (imported && s->def_file != runname)) {
        Sym *q = imported && s->imported && !items[i]->param &&
                         !s->param && I->cur_qual
                     ? qualified_sym(I, I->cur_qual, s)
                     : NULL;
        if (!q || q->global)
          qcs_error(d->pos, "%s is defined here and at %s:%d:%d%s; rename "
                    "one of them%s", s->name, s->def_pos.src ?
                    s->def_pos.src->name : "?", s->def_pos.line,
                    s->def_pos.col, s->imported ? " (imported)" : "",
                    imported && s->imported && !items[i]->param && !s->param
                        ? ", or import this file with `as Name`"
                        : "");
        /* what to write instead: the first import's Q.x, then this one's */
        char both[1000];
        if (!s->ambiguous) {
          Sym *fq = NULL;
          for (int k = 0; k < I->nimported; k++)
            if (I->importdefs[k].path == s->imported) fq = I->importdefs[k].qual;
          Sym *f = fq ? qualified_sym(I, fq, s) : NULL;
          snprintf(both, sizeof both, "%s (%s:%d:%d) and %s (%s:%d:%d)",
                   f ? f->name : s->name,
                   s->def_pos.src ? s->def_pos.src->name : "?",
                   s->def_pos.line, s->def_pos.col, q->name,
                   d->pos.src ? d->pos.src->name : "?", d->pos.line,
                   d->pos.col);
        } else {
          snprintf(both, sizeof both, "%s and %s (%s:%d:%d)", s->ambiguous,
                   q->name, d->pos.src ? d->pos.src->name : "?", d->pos.line,
                   d->pos.col);
        }
        s->ambiguous = gc_strdup(both);
        int cap = I->caprename;
        I->rename_from = grow(I->rename_from, I->nrename, &cap, sizeof(Sym *));
        I->rename_to = grow(I->rename_to, I->nrename, &I->caprename,
                            sizeof(Sym *));
        I->rename_from[I->nrename] = s;
        I->rename_to[I->nrename++] = q;
        d->name = q;
      }
    }
  resolve_items(I, items, n);
  I->nrename = nrename0;
  int redefined = 0;
  for (int i = 0; i < n; i++) {
    Item *it = items[i];
    if (it->kind == ITEM_SIG) {
      it->signame->sig = it->sigtext;
    } else if (it->kind == ITEM_DEF) {
      Sym *s = it->def->name;
      if (s->overridden) {
        if (!it->param)
          qcs_error(it->def->pos, "--set %s: %s is defined here but is not "
                    "a parameter (declare it with `param %s = ...`)", s->name,
                    s->name, s->name);
        s->def = it->def;
        s->def_pos = it->def->pos;
        s->def_file = runname;
        s->set_checked = 1;
        record_param(I, s, it->param);
        continue;
      }
      if (s->def && s->user) redefined = 1;
      warn_shadow(I, s, it->def->pos);
      s->def = it->def;
      s->global = eval_global_value(I, it->def);
      s->user = !I->loading_prelude;
      s->def_pos = it->def->pos;
      s->def_file = runname;
      read_doc(s, it->def->pos);
      s->imported = imported ? runname : NULL;
      if (it->param) {
        record_param(I, s, it->param);
        check_default(I, s, it->def);
      } else {
        s->param = NULL;
      }
      (void)runid;
    }
  }
  if (redefined && mode == MODE_REPL) refresh_values(I);
  if (I->sets_pending && !imported && !I->loading_prelude)
    check_sets(I, runname);
  if (imported || I->declare_only) return RUN_OK;
  for (int i = 0; i < n; i++) {
    /* :set digits N applies from its line on; --digits N overrides it.
       An animation's later frames replay it in order too. */
    if (items[i]->kind == ITEM_SET) {
      if (!I->digits_fixed) I->digits = items[i]->digits;
      if (mode == MODE_SCRIPT) {
        I->anim = grow(I->anim, I->nanim, &I->capanim, sizeof(Item *));
        I->anim[I->nanim++] = items[i];
      }
    }
    if (items[i]->kind != ITEM_EXPR) continue;
    if (mode == MODE_SCRIPT) {
      I->anim = grow(I->anim, I->nanim, &I->capanim, sizeof(Item *));
      I->anim[I->nanim++] = items[i];
    }
    /* max-steps counts per top-level expression */
    I->steps = 0;
    I->item_pos = items[i]->expr->pos;
    Value *v = eval(I, items[i]->expr, NULL);
    if (mode == MODE_REPL && I->show &&
        I->show(I, v, items[i]->expr->pos, I->show_ud))
      continue;
    print_value(I, stdout, v);
    fputc('\n', stdout);
    fflush(stdout);
  }
  return RUN_OK;
}

RunStatus interp_run_string(Interp *I, const char *name, const char *text,
                            RunMode mode) {
  Src *src = GC_MALLOC(sizeof *src);
  char *nm = GC_MALLOC_ATOMIC(strlen(name) + 1);
  strcpy(nm, name);
  size_t len = strlen(text);
  char *tx = GC_MALLOC_ATOMIC(len + 1);
  memcpy(tx, text, len + 1);
  src->name = nm;
  src->text = tx;
  src->prelude = I->loading_prelude;
  I->item_pos = pos_none;
  int nforcing = I->nforcing, nfiles = I->nfiles;
  ErrFrame f;
  if (ERR_TRY(f)) {
    int n;
    Item **items = parse_program(I, src, mode, &n);
    RunStatus st = run_items(I, items, n, mode, nm, 0);
    err_pop(&f);
    return st;
  }
  err_pop(&f);
  I->nfiles = nfiles;
  fflush(stdout);
  if (err_info()->incomplete && mode == MODE_REPL) {
    unwind(I, nforcing);
    return RUN_INCOMPLETE;
  }
  report_error(I);
  unwind(I, nforcing);
  return RUN_ERROR;
}

/* Reads a whole file; NULL with errno set on failure. */
static char *read_file(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 4096, n = 0;
  char *buf = malloc(cap);
  for (;;) {
    if (n + 1 >= cap) {
      char *nb = realloc(buf, cap *= 2);
      if (!nb) {
        free(buf);
        fclose(f);
        errno = ENOMEM;
        return NULL;
      }
      buf = nb;
    }
    size_t r = fread(buf + n, 1, cap - n - 1, f);
    n += r;
    if (r == 0) break;
  }
  int err = ferror(f);
  fclose(f);
  if (err) {
    free(buf);
    errno = EIO;
    return NULL;
  }
  buf[n] = 0;
  *len = n;
  return buf;
}

RunStatus interp_run_file(Interp *I, const char *path) {
  size_t len;
  char *text = read_file(path, &len);
  if (!text) {
    fprintf(stderr, "qcs: error: cannot read %s: %s\n", path, strerror(errno));
    return RUN_ERROR;
  }
  /* A NUL byte would silently end the text: say where it is. */
  size_t nul = strlen(text);
  if (nul < len) {
    int line = 1, col = 1;
    for (size_t i = 0; i < nul; i++) {
      if (text[i] == '\n') line++, col = 1;
      else col++;
    }
    fprintf(stderr, "%s:%d:%d: error: NUL byte in source\n", path, line, col);
    free(text);
    return RUN_ERROR;
  }
  char *real = realpath(path, NULL);
  int nfiles = I->nfiles;
  push_file(I, real ? real : path, path);
  free(real);
  RunStatus st = interp_run_string(I, path, text, MODE_SCRIPT);
  I->nfiles = nfiles;
  free(text);
  return st;
}

RunStatus interp_eval_print(Interp *I, const char *text) {
  Src *src = GC_MALLOC(sizeof *src);
  src->name = "<-e>";
  char *tx = GC_MALLOC_ATOMIC(strlen(text) + 1);
  strcpy(tx, text);
  src->text = tx;
  I->item_pos = pos_none;
  int nforcing = I->nforcing;
  ErrFrame f;
  if (ERR_TRY(f)) {
    int n;
    Item **items = parse_program(I, src, MODE_REPL, &n);
    RunStatus st = run_items(I, items, n, MODE_REPL, "<-e>", 0);
    err_pop(&f);
    return st;
  }
  err_pop(&f);
  fflush(stdout);
  report_error(I);
  unwind(I, nforcing);
  return RUN_ERROR;
}

void interp_set_show(Interp *I,
                     int (*show)(Interp *I, struct Value *v, Pos pos, void *ud),
                     void *ud) {
  I->show = show;
  I->show_ud = ud;
}

Value *interp_eval_expr(Interp *I, const char *name, const char *text) {
  Src *src = GC_MALLOC(sizeof *src);
  char *nm = GC_MALLOC_ATOMIC(strlen(name) + 1);
  strcpy(nm, name);
  char *tx = GC_MALLOC_ATOMIC(strlen(text) + 1);
  strcpy(tx, text);
  src->name = nm;
  src->text = tx;
  Expr *e = parse_expression(I, src);
  resolve_expr(I, e);
  return eval(I, e, NULL);
}

RunStatus interp_run_item(Interp *I, Pos pos,
                          Value *(*fn)(Interp *I, void *ud), void *ud) {
  int nforcing = I->nforcing;
  I->steps = 0;
  I->item_pos = pos;
  ErrFrame f;
  if (ERR_TRY(f)) {
    Value *v = fn(I, ud);
    if (v) {
      print_value(I, stdout, v);
      fputc('\n', stdout);
    }
    fflush(stdout);
    err_pop(&f);
    return RUN_OK;
  }
  err_pop(&f);
  fflush(stdout);
  report_error(I);
  unwind(I, nforcing);
  return RUN_ERROR;
}

RunStatus interp_set_override(Interp *I, const char *name, const char *expr) {
  Src *src = GC_MALLOC(sizeof *src);
  char *nm = GC_MALLOC_ATOMIC(strlen(name) + 16);
  snprintf(nm, strlen(name) + 16, "--set %s", name);
  src->name = nm;
  char *tx = GC_MALLOC_ATOMIC(strlen(expr) + 1);
  strcpy(tx, expr);
  src->text = tx;
  ErrFrame f;
  if (ERR_TRY(f)) {
    const char *p = name;
    int ok = *p && ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z'));
    for (; *p && ok; p++)
      ok = (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') ||
           (*p >= '0' && *p <= '9') || *p == '_' || *p == '\'';
    if (!ok) qcs_error(pos_none, "--set needs NAME=VALUE with a plain name, "
                       "not '%s'", name);
    Expr *e = parse_expression(I, src);
    resolve_expr(I, e);
    Sym *s = sym_intern(I, name, (int)strlen(name));
    interp_materialize(I, s);
    if (s->con_arity >= 0)
      qcs_error(pos_none, "--set cannot replace the constructor %s", name);
    if (!s->overridden) {
      if (I->nset_syms == 64) qcs_error(pos_none, "too many --set options");
      I->set_syms[I->nset_syms++] = s;
    }
    s->global = delay(I, e, NULL);
    s->overridden = 1;
    s->user = 1;
    s->set_expr = e;
    I->sets_pending = 1;
    err_pop(&f);
    return RUN_OK;
  }
  err_pop(&f);
  report_error(I);
  return RUN_ERROR;
}

/* ---- qcs params ---- */

static void range_text(Interp *I, const Param *pm, char *buf, size_t n) {
  buf[0] = 0;
  if (!pm->lo) return;
  double lo, hi;
  param_range(I, pm, &lo, &hi);
  snprintf(buf, n, "[%.15g, %.15g]", lo, hi);
}

RunStatus interp_params(Interp *I, const char *path, FILE *out) {
  I->declare_only = 1;
  RunStatus st = interp_run_file(I, path);
  I->declare_only = 0;
  if (st != RUN_OK) return st;
  int wn = 4, wd = 7, wr = 5;
  char range[128];
  ErrFrame f;
  if (ERR_TRY(f)) {
    for (int i = 0; i < I->nparams; i++) {
      Sym *s = I->params[i];
      if (!s->param) continue;
      range_text(I, s->param, range, sizeof range);
      if ((int)strlen(s->name) > wn) wn = (int)strlen(s->name);
      if ((int)strlen(s->param->text) > wd) wd = (int)strlen(s->param->text);
      if ((int)strlen(range) > wr) wr = (int)strlen(range);
    }
    if (wd > 40) wd = 40;
    fprintf(out, "%-*s  %-*s  %-*s  %s\n", wn, "name", wd, "default", wr,
            "range", "doc");
    for (int i = 0; i < I->nparams; i++) {
      Sym *s = I->params[i];
      if (!s->param) continue;
      range_text(I, s->param, range, sizeof range);
      fprintf(out, "%-*s  %-*s  %-*s  %s\n", wn, s->name, wd, s->param->text,
              wr, range, s->param->doc ? s->param->doc : "");
    }
    err_pop(&f);
    return RUN_OK;
  }
  err_pop(&f);
  report_error(I);
  unwind(I, I->nforcing);
  return RUN_ERROR;
}

/* ---- animation ---- */

/* Re-evaluates the user's top-level definitions that depend on any of the
   symbols seeds (through any chain of globals; the seeds themselves are
   left as they are): marked by passes until nothing changes (cycles
   among globals are fine). */
static void rebind_dependents(Interp *I, Sym **seeds, int nseeds) {
  int epoch = ++I->anim_epoch, changed = 1;
  for (int i = 0; i < nseeds; i++) seeds[i]->anim_mark = epoch * 2 + 1;
  while (changed) {
    changed = 0;
    for (size_t h = 0; h < I->symcap; h++)
      for (Sym *s = I->symtab[h]; s; s = s->next) {
        if (!s->def || !s->user || s->anim_mark == epoch * 2 + 1) continue;
        for (int i = 0; i < s->def->nuses; i++)
          if (s->def->uses[i]->anim_mark == epoch * 2 + 1) {
            s->anim_mark = epoch * 2 + 1;
            changed = 1;
            break;
          }
      }
  }
  for (size_t h = 0; h < I->symcap; h++)
    for (Sym *s = I->symtab[h]; s; s = s->next) {
      int seed = 0;
      for (int i = 0; i < nseeds; i++) seed |= s == seeds[i];
      if (s->anim_mark == epoch * 2 + 1 && s->def && s->def->arity == 0 &&
          !s->overridden && !seed)
        s->global = eval_global_value(I, s->def);
    }
}

void interp_set_frame(Interp *I, double frame, double clock) {
  Sym *sf = sym_intern(I, "frame", 5), *sc = sym_intern(I, "clock", 5);
  if (!sf->user) sf->global = val_num(frame);
  if (!sc->user) sc->global = val_num(clock);
  Sym *seeds[2] = {sf, sc};
  rebind_dependents(I, seeds, 2);
}

int interp_param_list(Interp *I, InterpParam *out, int max) {
  int nforcing = I->nforcing;
  volatile int n = 0;
  ErrFrame f;
  if (ERR_TRY(f)) {
    for (int i = 0; i < I->nparams; i++) {
      Sym *s = I->params[i];
      if (!s->param) continue;
      if (n < max) {
        InterpParam *p = &out[n];
        memset(p, 0, sizeof *p);
        p->name = s->name;
        p->text = s->param->text;
        p->doc = s->param->doc;
        if (s->param->lo) {
          p->has_range = 1;
          param_range(I, s->param, &p->lo, &p->hi);
        }
        Value *v = force(I, s->global);
        p->numeric = v->kind == V_NUM;
        p->value = p->numeric ? v->u.num : NAN;
      }
      n++;
    }
    err_pop(&f);
    return n;
  }
  err_pop(&f);
  report_error(I);
  unwind(I, nforcing);
  return -1;
}

RunStatus interp_set_param(Interp *I, const char *name, double x, char *err,
                           size_t errlen) {
  Sym *s = NULL;
  for (int i = 0; i < I->nparams && !s; i++)
    if (I->params[i]->param && !strcmp(I->params[i]->name, name))
      s = I->params[i];
  if (!s) {
    snprintf(err, errlen, "no parameter %s is declared", name);
    return RUN_ERROR;
  }
  if (!isfinite(x)) {
    snprintf(err, errlen, "parameter %s takes a finite number", name);
    return RUN_ERROR;
  }
  InterpParam p;
  int nforcing = I->nforcing;
  ErrFrame f;
  if (ERR_TRY(f)) {
    p.has_range = s->param->lo != NULL;
    if (p.has_range) param_range(I, s->param, &p.lo, &p.hi);
    Value *v = force(I, s->global);
    p.numeric = v->kind == V_NUM;
    err_pop(&f);
  } else {
    err_pop(&f);
    report_error(I);
    unwind(I, nforcing);
    snprintf(err, errlen, "parameter %s: its range or value is in error",
             name);
    return RUN_ERROR;
  }
  if (!p.numeric) {
    snprintf(err, errlen, "parameter %s does not take a number", name);
    return RUN_ERROR;
  }
  if (p.has_range && !(x >= p.lo && x <= p.hi)) {
    snprintf(err, errlen, "%.17g is outside the range [%.17g, %.17g] of "
             "parameter %s", x, p.lo, p.hi, name);
    return RUN_ERROR;
  }
  s->global = val_num(x);
  rebind_dependents(I, &s, 1);
  return RUN_OK;
}

void interp_free(Interp *I) { GC_FREE(I); }

RunStatus interp_rerun(Interp *I) {
  int nforcing = I->nforcing;
  ErrFrame f;
  if (ERR_TRY(f)) {
    for (int i = 0; i < I->nanim; i++) {
      if (I->anim[i]->kind == ITEM_SET) {
        if (!I->digits_fixed) I->digits = I->anim[i]->digits;
        continue;
      }
      I->steps = 0;
      I->item_pos = I->anim[i]->expr->pos;
      Value *v = eval(I, I->anim[i]->expr, NULL);
      print_value(I, stdout, v);
      fputc('\n', stdout);
      fflush(stdout);
    }
    err_pop(&f);
    return RUN_OK;
  }
  err_pop(&f);
  fflush(stdout);
  report_error(I);
  unwind(I, nforcing);
  return RUN_ERROR;
}

/* ---- completion and browsing ---- */

void interp_complete(Interp *I, const char *prefix,
                     void (*emit)(const char *name, void *ud), void *ud) {
  size_t len = strlen(prefix);
  for (size_t h = 0; h < I->symcap; h++)
    for (Sym *s = I->symtab[h]; s; s = s->next)
      if ((s->global || s->lazy || s->con_arity >= 0) && s->name[0] != '%' &&
          !strncmp(s->name, prefix, len))
        emit(s->name, ud);
}

static int cmp_sym(const void *a, const void *b) {
  return strcmp((*(Sym *const *)a)->name, (*(Sym *const *)b)->name);
}

void interp_browse(Interp *I, FILE *out, int all) {
  if (all) materialize_all(I);
  Sym **list = GC_MALLOC(sizeof(Sym *) * (I->nsyms + 1));
  size_t n = 0;
  for (size_t h = 0; h < I->symcap; h++)
    for (Sym *s = I->symtab[h]; s; s = s->next)
      if ((s->global || s->con_arity >= 0) && s->name[0] != '%' &&
          (all || s->user))
        list[n++] = s;
  qsort(list, n, sizeof *list, cmp_sym);
  for (size_t i = 0; i < n; i++) {
    Sym *s = list[i];
    if (s->user && s->prelude_value) {
      fprintf(out, "%s  -- yours, shadows the %s %s", s->name,
              s->builtin ? "built-in" : "prelude's", s->name);
      if (s->sig) fprintf(out, "; %s :: %s", s->name, s->sig);
      fputc('\n', out);
    } else if (s->builtin) {
      fprintf(out, "%s  -- built-in: %s\n", s->name, s->doc ? s->doc : "");
    } else if (s->con_arity >= 0) {
      fprintf(out, "%s  -- constructor of %s, %d argument%s\n", s->name,
              s->con_type ? s->con_type->name : "?", s->con_arity,
              s->con_arity == 1 ? "" : "s");
    } else if (s->sig) {
      fprintf(out, "%s :: %s\n", s->name, s->sig);
    } else if (s->def) {
      fprintf(out, "%s  -- %d argument%s, defined at %s:%d\n", s->name,
              s->def->arity, s->def->arity == 1 ? "" : "s",
              s->def_pos.src ? s->def_pos.src->name : "?", s->def_pos.line);
    } else {
      fprintf(out, "%s\n", s->name);
    }
  }
}

int interp_unload(Interp *I, const char *file) {
  int n = 0;
  for (size_t h = 0; h < I->symcap; h++)
    for (Sym *s = I->symtab[h]; s; s = s->next) {
      if (!s->user || s->overridden || s->con_arity >= 0 || !s->def_file ||
          strcmp(s->def_file, file))
        continue;
      s->global = s->prelude_value;
      s->def = s->prelude_def;
      s->sig = s->prelude_sig;
      s->doc = s->prelude_doc;
      s->example = s->prelude_example;
      s->def_pos = s->prelude_pos;
      s->def_file = NULL;
      s->user = 0;
      n++;
    }
  if (n) refresh_values(I);
  return n;
}

/* ---- :info, :doc, :type ---- */

/* The symbol of a global or constructor called name, or NULL. */
static Sym *known_sym(Interp *I, const char *name) {
  Sym *s = sym_intern(I, name, (int)strlen(name));
  interp_materialize(I, s);
  return s->global || s->con_arity >= 0 ? s : NULL;
}

static void where_defined(FILE *out, Pos pos) {
  if (!pos.src || !pos.line) return;
  if (!strcmp(pos.src->name, "<stdin>"))
    fputs(", defined at the prompt", out);
  else
    fprintf(out, ", defined at %s:%d", pos.src->name, pos.line);
}

static void no_such_name(Interp *I, const char *name) {
  fprintf(stderr, "error: '%s' is not defined", name);
  const char *best = NULL;
  int best_d = 3;
  for (size_t h = 0; h < I->symcap; h++)
    for (Sym *s = I->symtab[h]; s; s = s->next)
      if ((s->global || s->lazy || s->con_arity >= 0) && s->name[0] != '%') {
        int d = edit_distance(name, s->name);
        if (d < best_d && (size_t)d < strlen(name)) best = s->name, best_d = d;
      }
  if (best) fprintf(stderr, " (did you mean '%s'?)", best);
  fputc('\n', stderr);
}

int interp_info(Interp *I, FILE *out, const char *name) {
  Sym *s = known_sym(I, name);
  if (!s) {
    no_such_name(I, name);
    return -1;
  }
  if (s->con_arity >= 0) {
    fprintf(out, "%s  -- constructor of %s, %d argument%s", s->name,
            s->con_type ? s->con_type->name : "?", s->con_arity,
            s->con_arity == 1 ? "" : "s");
    where_defined(out, s->def_pos);
    fputc('\n', out);
  } else {
    const char *kind = s->user ? "your definition"
                       : s->builtin ? "built-in"
                       : s->def ? "prelude function" : "value";
    int arity = -1;
    if (s->def) arity = s->def->arity;
    else if (s->global && s->global->kind == V_FUNC)
      arity = s->global->u.fn.arity;
    else if (s->builtin) arity = 0;
    if (arity == 0 && !s->builtin)
      kind = s->user ? "your definition, a value" : "prelude value";
    fprintf(out, "%s  -- %s", s->name, kind);
    if (arity > 0 || (arity == 0 && s->builtin))
      fprintf(out, ", %d argument%s", arity, arity == 1 ? "" : "s");
    if (s->overridden) fputs(", set by --set", out);
    else if (!s->builtin || s->user) where_defined(out, s->def_pos);
    fputc('\n', out);
    if (s->user && s->prelude_value)
      fprintf(out, "  (shadows the %s %s; the prelude's own functions keep "
              "the original)\n", s->builtin ? "built-in" : "prelude's",
              s->name);
  }
  if (s->sig) fprintf(out, "%s :: %s\n", s->name, s->sig);
  if (s->doc) fprintf(out, "  %s\n", s->doc);
  if (s->example) fprintf(out, "  e.g. %s\n", s->example);
  return 0;
}

int interp_doc(Interp *I, FILE *out, const char *name) {
  Sym *s = known_sym(I, name);
  if (!s) {
    no_such_name(I, name);
    return -1;
  }
  if (s->sig) fprintf(out, "%s :: %s\n", s->name, s->sig);
  if (s->doc) fprintf(out, "%s\n", s->doc);
  if (s->example) fprintf(out, "e.g. %s\n", s->example);
  if (!s->doc && !s->example) {
    if (s->con_arity >= 0)
      fprintf(out, "%s: a constructor of %s with %d argument%s (no doc)\n",
              s->name, s->con_type ? s->con_type->name : "?", s->con_arity,
              s->con_arity == 1 ? "" : "s");
    else
      fprintf(out, "%s has no doc (a \"// doc: TEXT\" line above its "
              "definition gives it one)\n", s->name);
  }
  return 0;
}

const char *interp_signature(Interp *I, const char *name) {
  Sym *s = known_sym(I, name);
  return s ? s->sig : NULL;
}

static const char *plural(int n) { return n == 1 ? "" : "s"; }

void interp_describe(Interp *I, Value *v, char *buf, size_t n) {
  v = force(I, v);
  switch (v->kind) {
  case V_TUPLE:
    snprintf(buf, n, "a %d-tuple", v->u.tup.n);
    return;
  case V_NIL:
    snprintf(buf, n, "a list, empty");
    return;
  case V_CONS: {
    Value *h = force(I, v->u.cons.head);
    char hd[200];
    interp_describe(I, h, hd, sizeof hd);
    snprintf(buf, n, "a list whose first element is %s", hd);
    return;
  }
  case V_CON: {
    Sym *c = v->u.con.con;
    snprintf(buf, n, "a %s, made by the constructor %s",
             c->con_type ? c->con_type->name : "value", c->name);
    return;
  }
  case V_FUNC:
    switch (v->u.fn.kind) {
    case F_CON:
      snprintf(buf, n, "the constructor %s of %s: a function of %d "
               "argument%s", v->u.fn.u.con->name,
               v->u.fn.u.con->con_type ? v->u.fn.u.con->con_type->name : "?",
               v->u.fn.arity, plural(v->u.fn.arity));
      return;
    case F_BUILTIN:
      snprintf(buf, n, "a built-in function of %d argument%s (%s)",
               v->u.fn.arity, plural(v->u.fn.arity), v->u.fn.u.bi->name);
      return;
    case F_DEF:
      if (v->u.fn.u.def->name)
        snprintf(buf, n, "a function of %d argument%s (%s)", v->u.fn.arity,
                 plural(v->u.fn.arity), v->u.fn.u.def->name->name);
      else
        snprintf(buf, n, "a function of %d argument%s", v->u.fn.arity,
                 plural(v->u.fn.arity));
      return;
    }
    break;
  case V_PAP: {
    Value *f = force(I, v->u.pap.fn);
    int arity = f->kind == V_FUNC ? f->u.fn.arity : v->u.pap.n;
    int left = arity - v->u.pap.n;
    const char *fname = NULL;
    if (f->kind == V_FUNC) {
      if (f->u.fn.kind == F_CON) fname = f->u.fn.u.con->name;
      else if (f->u.fn.kind == F_BUILTIN) fname = f->u.fn.u.bi->name;
      else if (f->u.fn.u.def->name) fname = f->u.fn.u.def->name->name;
    }
    if (fname)
      snprintf(buf, n, "a function of %d more argument%s (%s given %d of %d)",
               left, plural(left), fname, v->u.pap.n, arity);
    else
      snprintf(buf, n, "a function of %d more argument%s", left,
               plural(left));
    return;
  }
  default:
    break;
  }
  snprintf(buf, n, "%s", val_describe(v));
}

void interp_set_warn_shadow(Interp *I, int on) { I->warn_shadow = on; }

int interp_has_global(Interp *I, const char *name) {
  Sym *s = sym_intern(I, name, (int)strlen(name));
  interp_materialize(I, s);
  return s->global != NULL;
}

void interp_request_interrupt(void) { qcs_interrupted = 1; }
void interp_clear_interrupt(void) { qcs_interrupted = 0; }

/* ---- the prelude, read a definition at a time ----
 *
 * The prelude and the kit are 900 lines; a scene uses a few dozen of
 * their definitions. At start-up a scan finds where each of their items
 * begins: a line whose first character (column 1), outside comments and
 * strings, starts a name or `::`. Type declarations are read and
 * installed at once (every pattern may need their constructors); each
 * definition, its signature and clauses (adjacent lines starting with
 * its name), is only noted in its Sym (Sym.lazy, the text it is in).
 * interp_materialize reads and installs it as loading the whole source
 * would have (the prelude's code, its doc comments, Sym.prelude_*) when
 * the name is first needed: when code naming it is resolved, before a
 * user's definition, type, signature or --set of the name is installed,
 * and for the commands that show names (:info, :doc, :browse!). A source
 * with an item of another form (an expression, a pattern binding, an
 * import, :set) is read whole at start-up, as is everything when
 * QCS_EAGER_PRELUDE=1 is set (to compare the two). */
typedef struct LazyDef {
  const Src *src;
  size_t start, end;     /* the bytes of the text it is read from */
  int line;              /* the line start begins */
  struct LazyDef *next;  /* another range of the same source naming it */
  int busy;              /* being read */
} LazyDef;

int interp_lazy_pending(const Sym *s) { return s->lazy != NULL; }

typedef struct LazyState {
  Interp *I;
  LazyDef *z;
  int loading, nrename;
  const Pos *origin;
  Sym *qual;
} LazyState;

static void lazy_restore(void *arg) {
  LazyState *st = arg;
  st->I->loading_prelude = st->loading;
  st->I->nrename = st->nrename;
  st->I->origin = st->origin;
  st->I->cur_qual = st->qual;
  st->z->busy = 0;
}

static void snapshot_prelude(Sym *s) {
  s->prelude_value = s->global;
  s->prelude_def = s->def;
  s->prelude_sig = s->sig;
  s->prelude_doc = s->doc;
  s->prelude_example = s->example;
  s->prelude_pos = s->def_pos;
}

void interp_materialize(Interp *I, Sym *s) {
  LazyDef *z = s->lazy;
  if (!z || z->busy) return;
  z->busy = 1;
  LazyState st = {I, z, I->loading_prelude, I->nrename, I->origin,
                  I->cur_qual};
  ErrCleanup c;
  err_defer(&c, lazy_restore, &st);
  /* as the prelude's own run: no import's renaming, no user's call */
  I->loading_prelude = 1;
  I->nrename = 0;
  I->origin = NULL;
  I->cur_qual = NULL;
  Item **items = NULL;
  int n = 0;
  for (LazyDef *r = z; r; r = r->next) {
    int k;
    Item **part = parse_range(I, r->src, r->start, r->end, r->line, &k);
    if (!items) {
      items = part;
    } else if (k) {
      Item **all = GC_MALLOC(sizeof(Item *) * (size_t)(n + k));
      memcpy(all, items, sizeof(Item *) * (size_t)n);
      memcpy(all + n, part, sizeof(Item *) * (size_t)k);
      items = all;
    }
    n += k;
  }
  run_items(I, items, n, MODE_SCRIPT, z->src->name, 0);
  err_release(&c);
  lazy_restore(&st);
  s->lazy = NULL;
  for (int i = 0; i < n; i++)
    if (items[i]->kind == ITEM_DEF) snapshot_prelude(items[i]->def->name);
}

/* Every definition not read yet, read (:browse! lists them all). Reading
   one may intern names and so grow and rehash the table being walked:
   walked again until a walk reads nothing. */
static void materialize_all(Interp *I) {
  for (int again = 1; again;) {
    again = 0;
    for (size_t h = 0; h < I->symcap; h++)
      for (Sym *s = I->symtab[h]; s; s = s->next)
        if (s->lazy && !s->lazy->busy) {
          interp_materialize(I, s);
          again = 1;
        }
  }
}

static int name_start(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}

/* One item found by the scan: a type declaration, or a name's lines. */
typedef struct ScanItem {
  int type;            /* `::` (else a definition) */
  const char *name;    /* into the text */
  int nlen;
  size_t start;
  int line;
} ScanItem;

/* The items of text, in order, into *out (malloc'd); their number, or
   -1 if one has a form the scan does not take (read the text whole). */
static __attribute__((noinline)) int scan_items(const char *text,
                                                ScanItem **out) {
  static const char *const cont[] = {"where", NULL};
  static const char *const whole[] = {"let", "in", "if", "then", "else",
                                      "case", "of", "and", "or", "True",
                                      "False", "param", "import", NULL};
  ScanItem *items = NULL;
  int n = 0, cap = 0, depth = 0, line = 1;
  for (const char *p = text; *p; line++) {
    if (depth == 0) {
      char c = *p;
      int begins = 0, type = 0, nlen = 0;
      if (name_start(c)) {
        while (name_start(p[nlen]) || (p[nlen] >= '0' && p[nlen] <= '9') ||
               p[nlen] == '\'')
          nlen++;
        if (p[nlen] == '.') goto fail; /* a qualified name */
        int kw = 0;
        for (int k = 0; cont[k]; k++)
          if ((int)strlen(cont[k]) == nlen && !strncmp(p, cont[k], (size_t)nlen))
            kw = 1;
        for (int k = 0; whole[k]; k++)
          if ((int)strlen(whole[k]) == nlen && !strncmp(p, whole[k], (size_t)nlen))
            goto fail;
        begins = !kw;
      } else if (c == ':' && p[1] == ':') {
        begins = type = 1;
      } else if (!(c == ' ' || c == '\t' || c == '\r' || c == '\n' ||
                   c == '\f' || c == '|' || c == '=' ||
                   (c == '/' && (p[1] == '/' || p[1] == '*')))) {
        goto fail; /* an expression, a pattern binding, :set */
      }
      if (begins &&
          (type || !n || items[n - 1].type || items[n - 1].nlen != nlen ||
           strncmp(items[n - 1].name, p, (size_t)nlen))) {
        if (n == cap) {
          cap = cap ? 2 * cap : 256;
          ScanItem *m = realloc(items, sizeof *items * (size_t)cap);
          if (!m) goto fail;
          items = m;
        }
        items[n++] = (ScanItem){type, p, nlen, (size_t)(p - text), line};
      }
    }
    /* the rest of the line: comments (nested) and strings, looked into
       only if the line holds a '/' (or, outside comments, a '"') */
    const char *nl = strchr(p, '\n');
    if (!nl) nl = p + strlen(p);
    if (!memchr(p, '/', (size_t)(nl - p)) &&
        (depth > 0 || !memchr(p, '"', (size_t)(nl - p))))
      p = nl;
    while (p < nl) {
      if (depth > 0) {
        if (p[0] == '/' && p[1] == '*') depth++, p += 2;
        else if (p[0] == '*' && p[1] == '/') depth--, p += 2;
        else p++;
      } else if (p[0] == '/' && p[1] == '/') {
        p = nl;
      } else if (p[0] == '/' && p[1] == '*') {
        depth++, p += 2;
      } else if (*p == '"') {
        for (p++; p < nl && *p != '"'; p++)
          if (*p == '\\' && p + 1 < nl) p++;
        if (p < nl) p++;
      } else {
        p++;
      }
    }
    if (*p == '\n') p++;
  }
  *out = items;
  return n;
fail:
  free(items);
  return -1;
}

/* Loads one of the prelude's sources: its type declarations now, its
   definitions when needed (see above); 0, or -1 if it must be read whole. */
static RunStatus load_lazily(Interp *I, const char *name, const char *text) {
  ScanItem *found;
  int nfound = getenv("QCS_EAGER_PRELUDE") ? -1 : scan_items(text, &found);
  if (nfound < 0) return interp_run_string(I, name, text, MODE_SCRIPT);
  ScanItem *volatile it = found; /* (kept over the error handler's setjmp) */
  volatile int n = nfound;
  Src *src = GC_MALLOC(sizeof *src);
  src->name = name;
  src->text = text; /* the binary's own copy: it outlives every run */
  src->prelude = 1;
  size_t len = strlen(text);
  RunStatus st = RUN_OK;
  ErrFrame f;
  if (ERR_TRY(f)) {
    for (int i = 0; i < n; i++) {
      size_t end = i + 1 < n ? it[i + 1].start : len;
      if (it[i].type) {
        int k;
        Item **items = parse_range(I, src, it[i].start, end, it[i].line, &k);
        run_items(I, items, k, MODE_SCRIPT, name, 0);
        continue;
      }
      Sym *s = sym_intern(I, it[i].name, it[i].nlen);
      LazyDef *z = GC_MALLOC(sizeof *z);
      *z = (LazyDef){src, it[i].start, end, it[i].line, NULL, 0};
      if (s->lazy && s->lazy->src == src) { /* the name's lines again */
        LazyDef *r = s->lazy;
        while (r->next) r = r->next;
        r->next = z;
      } else {
        s->lazy = z; /* a later source's definition replaces it */
      }
    }
    err_pop(&f);
  } else {
    err_pop(&f);
    report_error(I);
    unwind(I, I->nforcing);
    st = RUN_ERROR;
  }
  free(it);
  return st;
}

/* ---- start-up ---- */

/* The collector scans the writable data of every loaded object for
   pointers, its own included (all but its main tables). One word there,
   the hint for its next mmap (the end of its newest heap section), is not
   a pointer to anything of ours, but when the kernel places the newest
   section just below an older one it equals the older section's start:
   the address of whatever object was made first there. When that object
   is a cell of a list being consumed as it is made (`sum (map f [1 ..
   n])`), the cell and every cell made after it stay alive: the stream
   test found it in about 1 run of 25 (1 of 8 with one marker thread),
   by address-space layout, holding hundreds of MB. So the collector's own
   data is left out of the roots (it pushes the structures of its own that
   hold our objects, its thread table and finalizers, itself once the
   roots have been cleared: GC_clear_roots below), and every other
   object's data is scanned as before. */
static const void *gc_own_base;

/* The base of the shared object holding the collector, found from a
   function of its own that our binary cannot have a stub for (the default
   root pusher; GC_malloc's address may be a PLT entry of ours), or NULL
   when the collector is linked into our binary. */
static const void *gc_library_base(void) {
  Dl_info gc, self;
  void *own = (void *)GC_get_push_other_roots();
  if (!own) own = (void *)GC_malloc;
  if (!dladdr(own, &gc) || !gc.dli_fbase ||
      !dladdr((void *)interp_gc_init, &self))
    return NULL;
  return gc.dli_fbase != self.dli_fbase ? gc.dli_fbase : NULL;
}

static int gc_scan_data(const char *name, void *start, size_t size) {
  Dl_info di;
  (void)name, (void)size;
  return !(gc_own_base && dladdr(start, &di) && di.dli_fbase == gc_own_base);
}

void interp_gc_init(void) {
  static int gc_ready;
  if (gc_ready) return;
  gc_own_base = gc_library_base();
  if (gc_own_base) GC_register_has_static_roots_callback(gc_scan_data);
  GC_INIT();
  /* The collector's own warnings ("repeated allocation of very large
     block") mean nothing to a user; limits say what went wrong. */
  GC_set_warn_proc(GC_ignore_warn_proc);
  /* Start with a heap of 16 MB and let it grow to about three times
     the live values (free-space divisor 1; Boehm's default, 3, keeps it
     near 1.7 times and collects more often). A stream (`length
     [1 .. 10000000]`) then runs in a heap that stays near 16 MB, since
     whatever touches the heap's pages keeps them in the resident set
     (the 256 MB start this replaces made every script that allocated
     much hold 288 MB), while a scene that builds a big structure is
     not collected over and over as it grows: 100,000 soft keys take
     11% more instructions than with 256 MB at the start, 37% fewer
     than with 16 MB and the default divisor (callgrind). */
  GC_set_free_space_divisor(1);
  GC_expand_hp((size_t)16 << 20);
  /* the roots are made again, through gc_scan_data, at each collection */
  if (gc_own_base) GC_clear_roots();
  gc_ready = 1;
}

Interp *interp_new(void (*install)(Interp *I)) {
  interp_gc_init();
  Interp *I = GC_MALLOC_UNCOLLECTABLE(sizeof *I);
  char probe;
  I->stack_base = &probe;
  I->stack_limit = I->stack_reserved = 6u << 20;
  /* 8 GB of values unless told otherwise, or half the machine's memory
     when it has less than 16 GB (the limit must come before the
     system's out-of-memory killer). */
  I->max_memory = (size_t)8 << 30;
  long pages = sysconf(_SC_PHYS_PAGES), pagesize = sysconf(_SC_PAGESIZE);
  if (pages > 0 && pagesize > 0 &&
      (unsigned long long)pages * (unsigned long long)pagesize / 2 <
          I->max_memory)
    I->max_memory = (size_t)((unsigned long long)pages *
                             (unsigned long long)pagesize / 2 >> 20 << 20);
  I->max_steps = QCS_DEFAULT_MAX_STEPS;
  I->max_list = QCS_DEFAULT_MAX_LIST;
  I->max_pixels = QCS_DEFAULT_MAX_PIXELS;
  I->max_spp = QCS_DEFAULT_MAX_SPP;
  I->v_true = GC_MALLOC(sizeof(Value));
  I->v_true->kind = V_BOOL;
  I->v_true->u.b = 1;
  I->v_false = GC_MALLOC(sizeof(Value));
  I->v_false->kind = V_BOOL;
  I->v_nil = GC_MALLOC(sizeof(Value));
  I->v_nil->kind = V_NIL;
  builtins_install(I);
  /* The animation's frame and clock (0 outside one): globals the
     interpreter re-binds per frame (interp_set_frame), documented like
     the built-ins. */
  Sym *sf = sym_intern(I, "frame", 5), *sc = sym_intern(I, "clock", 5);
  sf->global = val_num(0);
  sf->builtin = 1;
  sf->doc = "frame: the number of the animation frame being rendered "
            "(--frames A-B), 0 outside an animation";
  sf->example = "frame + 1";
  sc->global = val_num(0);
  sc->builtin = 1;
  sc->doc = "clock: 0 at the animation's first frame to 1 at its last "
            "(--animation F-L), 0 outside an animation";
  sc->example = "360 * clock";
  if (install) install(I);
  I->loading_prelude = 1;
  /* The prelude proper, then the modeller's kit (stdlib/kit.qcs) written
     on it: both are the prelude's code, reported at the user's calls. */
  RunStatus st = load_lazily(I, "<prelude>", qcs_prelude_source);
  if (st == RUN_OK) st = load_lazily(I, "<kit>", qcs_kit_source);
  I->loading_prelude = 0;
  if (st != RUN_OK) {
    fprintf(stderr, "qcs: internal error: the prelude does not load\n");
    exit(2);
  }
  for (size_t h = 0; h < I->symcap; h++)
    for (Sym *s = I->symtab[h]; s; s = s->next) snapshot_prelude(s);
  return I;
}

void interp_set_stack(Interp *I, char *base, size_t limit) {
  I->stack_base = base;
  I->stack_limit = limit;
  I->stack_reserved = limit;
}

void interp_set_stack_reserved(Interp *I, size_t reserved) {
  if (reserved > I->stack_reserved) I->stack_reserved = reserved;
}

void interp_set_max_memory(Interp *I, size_t bytes) { I->max_memory = bytes; }

void interp_set_max_steps(Interp *I, unsigned long long steps) {
  I->max_steps = steps;
  I->steps = 0;
}

/* ---- resource limits ---- */

typedef enum { LIM_SIZE, LIM_COUNT, LIM_PIXELS, LIM_SPP } LimitKind;

static const struct {
  const char *name;
  LimitKind kind;
  int zero_ok;          /* 0 switches the limit off */
  unsigned long long min, max;
  const char *what;
} limits[] = {
  {"max-stack", LIM_SIZE, 0, 1ULL << 20, 1ULL << 40,
   "C stack for nested calls and parsing (recursion depth)"},
  {"max-steps", LIM_COUNT, 1, 1, ~0ULL,
   "evaluation steps of one top-level expression"},
  {"max-list", LIM_COUNT, 1, 1, ~0ULL,
   "elements of one list (ranges, length, sum, printing, ...)"},
  {"max-memory", LIM_SIZE, 1, 1ULL << 20, 1ULL << 50, "memory for values, and a mesh's"},
  {"max-pixels", LIM_PIXELS, 0, 1, QCS_MAX_PIXELS_CAP,
   "pixels of one rendered image"},
  {"max-spp", LIM_SPP, 0, 1, 256, "samples per pixel of a render"},
};
#define NLIMITS (sizeof limits / sizeof limits[0])

const char *const interp_limit_names[] = {
  "max-stack", "max-steps", "max-list", "max-memory", "max-pixels", "max-spp",
  NULL};

/* "256M", "8G", or bytes when not a whole number of K. */
void interp_format_size(char *buf, size_t n, unsigned long long bytes) {
  static const char units[] = "KMGT";
  int u = -1;
  while (u < 3 && bytes >= 1024 && bytes % 1024 == 0) bytes /= 1024, u++;
  if (u < 0) snprintf(buf, n, "%llu", bytes);
  else snprintf(buf, n, "%llu%c", bytes, units[u]);
}

static int limit_index(const char *name) {
  for (size_t i = 0; i < NLIMITS; i++)
    if (!strcmp(limits[i].name, name)) return (int)i;
  return -1;
}

/* A whole number of decimal digits (no sign, no blanks); 0 on success. */
static int parse_whole(const char **p, unsigned long long *out) {
  const char *s = *p;
  unsigned long long v = 0;
  if (*s < '0' || *s > '9') return -1;
  for (; *s >= '0' && *s <= '9'; s++) {
    if (v > (~0ULL - 9) / 10) return -1;
    v = v * 10 + (unsigned long long)(*s - '0');
  }
  *p = s;
  *out = v;
  return 0;
}

int interp_limit_parse(const char *name, const char *text,
                       unsigned long long *out, char *err, size_t errlen) {
  int i = limit_index(name);
  if (i < 0) {
    const char *best = NULL;
    int bestd = 4;
    for (size_t j = 0; j < NLIMITS; j++) {
      int d = edit_distance(name, limits[j].name);
      if (d < bestd) bestd = d, best = limits[j].name;
    }
    if (best)
      snprintf(err, errlen, "unknown limit '%s' (did you mean %s?)", name,
               best);
    else
      snprintf(err, errlen, "unknown limit '%s'; the limits are max-stack, "
               "max-steps, max-list, max-memory, max-pixels and max-spp",
               name);
    return -1;
  }
  const char *p = text;
  unsigned long long v = 0, h;
  int ok = parse_whole(&p, &v) == 0;
  const char *want = "a whole number";
  switch (limits[i].kind) {
  case LIM_SIZE: {
    want = "a size such as 512M or 2G (a bare number is megabytes)";
    unsigned shift = 20;
    if (ok && *p) {
      const char *u = strchr("KkMmGgTt", *p);
      if (u && *p) {
        shift = 10 * (unsigned)((u - "KkMmGgTt") / 2 + 1);
        p++;
        if (*p == 'B' || *p == 'b') p++;
      } else {
        ok = 0;
      }
    }
    if (ok && v > (~0ULL >> shift)) ok = 0;
    v <<= shift;
    break;
  }
  case LIM_PIXELS:
    want = "a number of pixels, or WxH such as 4096x4096";
    if (ok && (*p == 'x' || *p == 'X')) {
      p++;
      if (parse_whole(&p, &h) || (h && v > ~0ULL / h)) ok = 0;
      else v *= h;
    }
    break;
  case LIM_COUNT:
    want = "a whole number (0 for no limit)";
    break;
  case LIM_SPP:
    break;
  }
  if (!ok || *p) {
    snprintf(err, errlen, "%s needs %s, not '%s'", name, want, text);
    return -1;
  }
  if (v == 0 && limits[i].zero_ok) {
    *out = 0;
    return 0;
  }
  if (v < limits[i].min || v > limits[i].max) {
    char lo[32], hi[32];
    if (limits[i].kind == LIM_SIZE) {
      interp_format_size(lo, sizeof lo, limits[i].min);
      interp_format_size(hi, sizeof hi, limits[i].max);
    } else {
      snprintf(lo, sizeof lo, "%llu", limits[i].min);
      snprintf(hi, sizeof hi, "%llu", limits[i].max);
    }
    snprintf(err, errlen, "%s must be from %s to %s%s, not '%s'", name, lo, hi,
             limits[i].zero_ok ? " (or 0 for no limit)" : "", text);
    return -1;
  }
  *out = v;
  return 0;
}

/* The most max-stack may be: the thread's stack, less a quarter kept for
   what runs below the checks (scene compilation, the C library). */
static size_t stack_cap(Interp *I) {
  size_t cap = I->stack_reserved / 4 * 3;
  return cap > I->stack_limit ? cap : I->stack_limit;
}

int interp_set_limit(Interp *I, const char *name, const char *text,
                     char *err, size_t errlen) {
  unsigned long long v;
  if (interp_limit_parse(name, text, &v, err, errlen)) return -1;
  switch (limit_index(name)) {
  case 0:
    if (v > stack_cap(I)) {
      char cap[32];
      interp_format_size(cap, sizeof cap, stack_cap(I));
      snprintf(err, errlen, "max-stack can be at most %s here (the stack "
               "reserved at start-up); start qcs with --max-stack SIZE for "
               "more", cap);
      return -1;
    }
    I->stack_limit = (size_t)v;
    break;
  case 1: I->max_steps = v; break;
  case 2: I->max_list = v; break;
  case 3: I->max_memory = (size_t)v; break;
  case 4: I->max_pixels = v; break;
  case 5: I->max_spp = (int)v; break;
  }
  return 0;
}

void interp_list_limits(Interp *I, FILE *out) {
  for (size_t i = 0; i < NLIMITS; i++) {
    unsigned long long v = 0;
    switch (i) {
    case 0: v = I->stack_limit; break;
    case 1: v = I->max_steps; break;
    case 2: v = I->max_list; break;
    case 3: v = I->max_memory; break;
    case 4: v = I->max_pixels; break;
    case 5: v = (unsigned long long)I->max_spp; break;
    }
    char buf[40];
    if (v == 0) snprintf(buf, sizeof buf, "none");
    else if (limits[i].kind == LIM_SIZE) interp_format_size(buf, sizeof buf, v);
    else snprintf(buf, sizeof buf, "%llu", v);
    fprintf(out, "%-11s %-12s %s\n", limits[i].name, buf, limits[i].what);
  }
}

const char *interp_version(void) { return QCS_VERSION; }

void interp_files_read(Interp *I, void (*emit)(const char *path, void *ud),
                       void *ud) {
  for (int i = 0; i < I->nreadfiles; i++) emit(I->readfiles[i], ud);
}
