/* lex.c: the qcs lexer. See lex.h. */
#include "lang/lex.h"

#include <errno.h>
#include <gc.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const kind_names[] = {
#define X(name, text) text,
    TOKENS(X)
#undef X
};

const char *tok_kind_name(TokKind k) { return kind_names[k]; }

typedef struct Lexer {
  const Src *src;
  const char *p;
  int line, col;
  int bol;
  Token *toks;
  int n, cap;
  const char *end; /* no token starts here or after (NULL: the text's end) */
} Lexer;

static Pos here(Lexer *L) { return (Pos){L->src, L->line, L->col}; }

static void advance(Lexer *L) {
  if (*L->p == '\n') {
    L->line++;
    L->col = 1;
    L->bol = 1;
  } else if (*L->p == '\t') {
    L->col = ((L->col - 1) / 8 + 1) * 8 + 1;
  } else if (((unsigned char)*L->p & 0xC0) != 0x80) {
    L->col++; /* count UTF-8 sequences as one column */
  }
  L->p++;
}

static Token *push(Lexer *L, TokKind k, Pos pos, const char *start) {
  if (L->n == L->cap) {
    L->cap = L->cap ? 2 * L->cap : 256;
    Token *t = GC_MALLOC(sizeof(Token) * (size_t)L->cap);
    if (L->n) memcpy(t, L->toks, sizeof(Token) * (size_t)L->n);
    /* the old array goes back to the collector at once: its pages are
       used again instead of new ones (the prelude's arrays grow to 4096
       tokens) */
    if (L->toks) GC_FREE(L->toks);
    L->toks = t;
  }
  Token *t = &L->toks[L->n++];
  memset(t, 0, sizeof *t);
  t->kind = k;
  t->pos = pos;
  t->start = start;
  t->len = (int)(L->p - start);
  t->bol = L->bol;
  L->bol = 0;
  return t;
}

/* Checks a UTF-8 sequence at p; returns its length or 0 if malformed. */
static int utf8_len(const unsigned char *p) {
  int n;
  if (p[0] < 0x80) return 1;
  if ((p[0] & 0xE0) == 0xC0) n = 2;
  else if ((p[0] & 0xF0) == 0xE0) n = 3;
  else if ((p[0] & 0xF8) == 0xF0) n = 4;
  else return 0;
  if (n == 2 && p[0] < 0xC2) return 0;
  for (int i = 1; i < n; i++)
    if ((p[i] & 0xC0) != 0x80) return 0;
  return n;
}

static void skip_space(Lexer *L) {
  for (;;) {
    char c = *L->p;
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f') {
      advance(L);
    } else if (c == '/' && L->p[1] == '/') {
      while (*L->p && *L->p != '\n') advance(L);
    } else if (c == '/' && L->p[1] == '*') {
      /* Block comments nest, as in Clean. */
      Pos open = here(L);
      int depth = 0;
      do {
        if (!*L->p)
          qcs_error_incomplete(open, "unterminated comment (opened here)");
        if (L->p[0] == '/' && L->p[1] == '*') {
          depth++;
          advance(L);
        } else if (L->p[0] == '*' && L->p[1] == '/') {
          depth--;
          advance(L);
        }
        advance(L);
      } while (depth > 0);
    } else {
      return;
    }
  }
}

static int is_ident(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
         (c >= '0' && c <= '9') || c == '_' || c == '\'';
}

static void lex_number(Lexer *L) {
  Pos pos = here(L);
  const char *start = L->p;
  int nonzero = 0, whole = 1;
  while (*L->p >= '0' && *L->p <= '9') nonzero |= *L->p != '0', advance(L);
  if (L->p[0] == '.' && L->p[1] >= '0' && L->p[1] <= '9') {
    whole = 0;
    advance(L);
    while (*L->p >= '0' && *L->p <= '9') nonzero |= *L->p != '0', advance(L);
  }
  if (*L->p == 'e' || *L->p == 'E') {
    whole = 0;
    const char *q = L->p + 1;
    if (*q == '+' || *q == '-') q++;
    if (*q >= '0' && *q <= '9') {
      while (L->p < q) advance(L);
      while (*L->p >= '0' && *L->p <= '9') advance(L);
    } else {
      qcs_error(here(L), "malformed number: exponent has no digits");
    }
  }
  if (is_ident(*L->p))
    qcs_error(here(L), "malformed number: unexpected '%c' after '%.*s'",
              *L->p, (int)(L->p - start), start);
  char buf[400];
  int len = (int)(L->p - start);
  if (len >= (int)sizeof buf)
    qcs_error(pos, "number literal is too long (%d characters)", len);
  memcpy(buf, start, (size_t)len);
  buf[len] = 0;
  errno = 0;
  double v = strtod(buf, NULL);
  if (isinf(v))
    qcs_error(pos, "number %s is too large for a Real (largest is about "
              "1.8e308)", buf);
  if (v == 0 && nonzero)
    qcs_error(pos, "number %s is too small for a Real: it would be 0 "
              "(smallest is about 4.9e-324)", buf);
  /* A whole number written out in digits is meant exactly: one that a
     Real would round is refused (write 1e23 or N.0 to accept rounding). */
  if (whole && v >= 9007199254740992.0) {
    char back[400];
    const char *digits = buf;
    while (digits[0] == '0' && digits[1]) digits++;
    snprintf(back, sizeof back, "%.0f", v);
    if (strcmp(back, digits))
      qcs_error(pos, "number %s cannot be held exactly by a Real (whole "
                "numbers are exact up to 9007199254740992); write %s.0 if the "
                "nearest Real will do", buf, buf);
  }
  Token *t = push(L, T_NUM, pos, start);
  t->num = v;
}

static void lex_string(Lexer *L) {
  Pos pos = here(L);
  const char *start = L->p;
  advance(L);
  size_t cap = 32, n = 0;
  char *buf = GC_MALLOC_ATOMIC(cap);
  for (;;) {
    char c = *L->p;
    if (c == 0 || c == '\n')
      qcs_error(pos, "unterminated string (a string ends on its own line)");
    if (c == '"') {
      advance(L);
      break;
    }
    if (c == '\\') {
      Pos epos = here(L);
      advance(L);
      switch (*L->p) {
      case 'n': c = '\n'; break;
      case 't': c = '\t'; break;
      case '\\': c = '\\'; break;
      case '"': c = '"'; break;
      case '0': c = 0; break;
      default:
        qcs_error(epos, "unknown escape '\\%c' in string (use \\n \\t \\\\ \\\")",
                  *L->p ? *L->p : ' ');
      }
      if (c == 0) qcs_error(epos, "a string may not contain a NUL byte");
    }
    if (n + 2 > cap) {
      char *nb = GC_MALLOC_ATOMIC(cap * 2);
      memcpy(nb, buf, n);
      buf = nb;
      cap *= 2;
    }
    buf[n++] = c;
    advance(L);
  }
  buf[n] = 0;
  Token *t = push(L, T_STR, pos, start);
  t->str = buf;
}

static const struct {
  const char *text;
  TokKind kind;
} keywords[] = {
    {"where", T_WHERE}, {"let", T_LET},   {"in", T_IN},     {"if", T_IF},
    {"then", T_THEN},   {"else", T_ELSE}, {"True", T_TRUE}, {"False", T_FALSE},
    {"and", T_KAND},    {"or", T_KOR},    {"case", T_CASE}, {"of", T_OF},
    {"param", T_PARAM}, {"import", T_IMPORT},
};

/* Punctuation, longest first. */
static const struct {
  const char *text;
  TokKind kind;
} puncts[] = {
    {":==", T_SYNONYM}, {"\\\\", T_BACKSLASH2}, {"->", T_ARROW},
    {"<-", T_LARROW},   {"::", T_COLONCOLON},   {"..", T_DOTDOT},
    {"++", T_APPEND},   {"==", T_EQ},           {"<>", T_NE},
    {"/=", T_NE},       {"!=", T_NE},           {"<=", T_LE},
    {">=", T_GE},       {"&&", T_AND},          {"||", T_OR},
    {"!!", T_INDEX},    {"(", T_LPAREN},        {")", T_RPAREN},
    {"[", T_LBRACK},    {"]", T_RBRACK},        {",", T_COMMA},
    {";", T_SEMI},      {"\\", T_LAMBDA},       {"=", T_EQUALS},
    {"|", T_BAR},       {":", T_COLON},         {"!", T_BANG},
    {"+", T_PLUS},      {"-", T_MINUS},         {"*", T_STAR},
    {"/", T_SLASH},     {"^", T_CARET},         {"<", T_LT},
    {">", T_GT},        {".", T_COMPOSE},
};

Token *lex_all(const Src *src, int *ntokens) {
  return lex_range(src, 0, 0, 1, ntokens);
}

Token *lex_range(const Src *src, size_t start_at, size_t end_at, int line,
                 int *ntokens) {
  Lexer L = {src, src->text + start_at, line, 1, 1, NULL, 0, 0,
             end_at ? src->text + end_at : NULL};
  /* about one token per 6 bytes of qcs: an array that rarely grows, and
     no 256-token one for a 200-byte definition */
  size_t bytes = end_at ? end_at - start_at : strlen(L.p);
  L.cap = bytes / 5 + 8 < 1 << 20 ? (int)(bytes / 5 + 8) : 1 << 20;
  L.toks = GC_MALLOC(sizeof(Token) * (size_t)L.cap);
  for (;;) {
    skip_space(&L);
    Pos pos = here(&L);
    const char *start = L.p;
    unsigned char c = (unsigned char)*L.p;
    if (c == 0 || (L.end && L.p >= L.end)) {
      push(&L, T_EOF, pos, start);
      break;
    }
    if (c >= '0' && c <= '9') {
      lex_number(&L);
      continue;
    }
    if (c == '"') {
      lex_string(&L);
      continue;
    }
    if (is_ident((char)c) && c != '\'') {
      while (is_ident(*L.p)) advance(&L);
      int len = (int)(L.p - start);
      TokKind k = (c >= 'A' && c <= 'Z') ? T_CNAME : T_NAME;
      if (len == 1 && c == '_') k = T_WILD;
      /* (the first character first: the prelude and the kit are lexed
         at every start) */
      for (size_t i = 0; i < sizeof keywords / sizeof *keywords; i++)
        if (keywords[i].text[0] == (char)c &&
            (int)strlen(keywords[i].text) == len &&
            !memcmp(keywords[i].text, start, (size_t)len))
          k = keywords[i].kind;
      /* A qualified name, Parts.bolt (no spaces): a definition of the
         import named Parts (interp.c). `F . g`, with spaces, composes. */
      if (k == T_CNAME && L.p[0] == '.' &&
          ((L.p[1] >= 'a' && L.p[1] <= 'z') || L.p[1] == '_')) {
        advance(&L);
        while (is_ident(*L.p)) advance(&L);
        k = T_NAME;
      }
      push(&L, k, pos, start);
      continue;
    }
    int matched = 0;
    for (size_t i = 0; i < sizeof puncts / sizeof *puncts; i++) {
      if (puncts[i].text[0] != (char)c) continue;
      size_t n = strlen(puncts[i].text);
      if (!strncmp(L.p, puncts[i].text, n)) {
        for (size_t j = 0; j < n; j++) advance(&L);
        push(&L, puncts[i].kind, pos, start);
        matched = 1;
        break;
      }
    }
    if (matched) continue;
    if (c >= 0x80) {
      int n = utf8_len((const unsigned char *)L.p);
      if (n == 0)
        qcs_error(pos, "invalid UTF-8 byte 0x%02X in source", c);
      qcs_error(pos, "unexpected character '%.*s' (qcs names and operators "
                "are ASCII)", n, L.p);
    }
    if (c < 0x20 || c == 0x7f)
      qcs_error(pos, "unexpected control character 0x%02X in source", c);
    qcs_error(pos, "unexpected character '%c'", c);
  }
  *ntokens = L.n;
  return L.toks;
}

void lex_free(Token *toks) { GC_FREE(toks); }
