/* lex.h: source text to tokens.
 *
 * The whole text is tokenised at once into an array (the parser looks ahead
 * freely and the layout rule needs each token's column and whether it
 * starts a line). Token texts point into the source, which the caller keeps
 * alive; the token array is allocated in the GC heap. Lexical errors
 * (unterminated string or comment, stray bytes, NUL, out-of-range numbers)
 * are raised with qcs_error at their position (an unterminated comment
 * with qcs_error_incomplete, so the REPL reads on; a string must end on
 * its line). The lexer keeps no state between calls and touches no
 * Interp. */
#ifndef QCS_LEX_H
#define QCS_LEX_H

#include <stddef.h>

#include "lang/error.h"

#define TOKENS(X)                                                      \
  X(EOF, "end of input") X(NUM, "number") X(STR, "string")             \
  X(NAME, "name") X(CNAME, "capitalised name") X(WILD, "'_'")          \
  X(LPAREN, "'('") X(RPAREN, "')'") X(LBRACK, "'['") X(RBRACK, "']'")  \
  X(COMMA, "','") X(SEMI, "';'") X(LAMBDA, "'\\'")                     \
  X(BACKSLASH2, "'\\\\'") X(ARROW, "'->'") X(LARROW, "'<-'")           \
  X(EQUALS, "'='") X(BAR, "'|'") X(COLONCOLON, "'::'")                 \
  X(DOTDOT, "'..'") X(COLON, "':'") X(BANG, "'!'")                     \
  X(SYNONYM, "':=='")                                                  \
  X(PLUS, "'+'") X(MINUS, "'-'") X(STAR, "'*'") X(SLASH, "'/'")        \
  X(CARET, "'^'") X(APPEND, "'++'") X(EQ, "'=='") X(NE, "'<>'")        \
  X(LT, "'<'") X(LE, "'<='") X(GT, "'>'") X(GE, "'>='")                \
  X(AND, "'&&'") X(OR, "'||'") X(INDEX, "'!!'") X(COMPOSE, "'.'")      \
  X(WHERE, "'where'") X(LET, "'let'") X(IN, "'in'") X(IF, "'if'")      \
  X(THEN, "'then'") X(ELSE, "'else'") X(TRUE, "'True'")                \
  X(FALSE, "'False'") X(KAND, "'and'") X(KOR, "'or'")                  \
  X(CASE, "'case'") X(OF, "'of'")                                     \
  X(PARAM, "'param'") X(IMPORT, "'import'")                            \
  X(VSEP, "end of definition") X(VEND, "end of block")

typedef enum {
#define X(name, text) T_##name,
  TOKENS(X)
#undef X
  T_COUNT
} TokKind;

typedef struct Token {
  TokKind kind;
  int bol;           /* first token on its line */
  Pos pos;
  const char *start; /* into the source text */
  int len;
  union {
    double num;      /* T_NUM */
    const char *str; /* T_STR: the decoded string (NUL-terminated) */
  };
} Token;             /* 48 bytes: the prelude and the kit are 6500 */

/* Tokenise src->text. Returns the array, ending with a T_EOF token; the
   caller may hand it back with lex_free once nothing points into it. */
Token *lex_all(const Src *src, int *ntokens);
/* The tokens of src->text from byte start_at, which begins line `line`
   (column 1), to byte end_at (0: the text's end), which must be where a
   line begins outside any comment or string: the prelude's definitions,
   each read when first used (interp.c). */
Token *lex_range(const Src *src, size_t start_at, size_t end_at, int line,
                 int *ntokens);
void lex_free(Token *toks);

/* "'('", "name", ... for error messages. */
const char *tok_kind_name(TokKind k);
#endif
