/* repl.c: the interactive front end (see repl.h).
 *
 * One entry is what the interpreter runs at once: a line, or several lines
 * joined by '\n' while interp_run_string says RUN_INCOMPLETE, or a
 * ":{ ... :}" block. The same feed_line() serves the terminal loop and the
 * plain loop for piped input; only where lines come from differs.
 *
 * Signals: the handlers only set flags (for SIGINT also asking the
 * interpreter to stop) and write a byte to a pipe that the prompt loop
 * select()s on beside the terminal. So a Ctrl-C at the prompt is handled
 * between keys, never inside readline, whichever thread the kernel gave
 * the signal to (main runs the interpreter on a thread of its own, and the
 * collector has threads too: blocking signals in this thread and waiting
 * in pselect() would miss them). */
#include "app/repl.h"
#include "app/view.h"

#include "app/preview.h"
#include "bind/compile.h"
#include "bind/render_lang.h"
#include "bind/report.h"
#include "lang/eval.h"
#include "lang/print.h"
#include "study/tradeoff.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/select.h>
#include <termios.h>
#include <unistd.h>

#include <readline/history.h>
#include <readline/readline.h>

#include "app/dynlib.h"

/* GNU readline (and the terminfo library it brings) is loaded when the
   prompt first runs on a terminal (app/dynlib.h), not linked: scripts,
   -e and piped input, which never use it, do not pay for its dynamic
   linking at start-up (about 0.2 ms of CPU a run). The functions and
   variables this file uses, read through a table of pointers of their
   header's types; the names below stand for them. */
#define RL_FUNCS(X)                                                        \
  X(using_history) X(stifle_history) X(read_history) X(append_history)    \
  X(history_truncate_file) X(history_get) X(add_history)                  \
  X(rl_completion_matches) X(rl_filename_completion_function)             \
  X(rl_callback_handler_remove) X(rl_variable_value) X(rl_redisplay)      \
  X(rl_callback_sigcleanup) X(rl_free_line_state)                         \
  X(rl_callback_handler_install) X(rl_resize_terminal)                    \
  X(rl_deprep_terminal) X(rl_prep_terminal) X(rl_forced_update_display)   \
  X(rl_callback_read_char)
#define RL_ALL(X) RL_FUNCS(X) RL_VARS(X)
#define RL_VARS(X)                                                         \
  X(history_length) X(history_base) X(rl_line_buffer)                     \
  X(rl_attempted_completion_over) X(rl_outstream) X(rl_point) X(rl_end)   \
  X(rl_instream) X(rl_readline_name) X(rl_catch_signals)                  \
  X(rl_catch_sigwinch) X(rl_attempted_completion_function)                \
  X(rl_completion_word_break_hook) X(rl_basic_word_break_characters)      \
  X(rl_completer_quote_characters)

static struct {
#define X(f) __typeof__(f) *f;
  RL_FUNCS(X)
#undef X
#define X(v) __typeof__(v) *v;
  RL_VARS(X)
#undef X
} rl;

/* 0 once readline is loaded; -1 (said on stderr) if it cannot be. */
static int readline_load(void) {
  static const char *const sonames[] = {"libreadline.so.8", "libreadline.so",
                                        NULL};
  return DYNLIB_LOAD(rl, RL_ALL, sonames, "libreadline8", "no line editing");
}
#define using_history (rl.using_history)
#define stifle_history (rl.stifle_history)
#define read_history (rl.read_history)
#define append_history (rl.append_history)
#define history_truncate_file (rl.history_truncate_file)
#define history_get (rl.history_get)
#define add_history (rl.add_history)
#define rl_completion_matches (rl.rl_completion_matches)
#define rl_filename_completion_function (rl.rl_filename_completion_function)
#define rl_callback_handler_remove (rl.rl_callback_handler_remove)
#define rl_variable_value (rl.rl_variable_value)
#define rl_redisplay (rl.rl_redisplay)
#define rl_callback_sigcleanup (rl.rl_callback_sigcleanup)
#define rl_free_line_state (rl.rl_free_line_state)
#define rl_callback_handler_install (rl.rl_callback_handler_install)
#define rl_resize_terminal (rl.rl_resize_terminal)
#define rl_deprep_terminal (rl.rl_deprep_terminal)
#define rl_prep_terminal (rl.rl_prep_terminal)
#define rl_forced_update_display (rl.rl_forced_update_display)
#define rl_callback_read_char (rl.rl_callback_read_char)
#define history_length (*rl.history_length)
#define history_base (*rl.history_base)
#define rl_line_buffer (*rl.rl_line_buffer)
#define rl_attempted_completion_over (*rl.rl_attempted_completion_over)
#define rl_outstream (*rl.rl_outstream)
#define rl_point (*rl.rl_point)
#define rl_end (*rl.rl_end)
#define rl_instream (*rl.rl_instream)
#define rl_readline_name (*rl.rl_readline_name)
#define rl_catch_signals (*rl.rl_catch_signals)
#define rl_catch_sigwinch (*rl.rl_catch_sigwinch)
#define rl_attempted_completion_function (*rl.rl_attempted_completion_function)
#define rl_completion_word_break_hook (*rl.rl_completion_word_break_hook)
#define rl_basic_word_break_characters (*rl.rl_basic_word_break_characters)
#define rl_completer_quote_characters (*rl.rl_completer_quote_characters)

#define PROMPT      "qcs> "
#define PROMPT_MORE "...> "
#define HISTORY_FILE "/.qcs_history"
#define HISTORY_MAX 1000
#define SOURCE_NAME "<stdin>"

/* Word breaks for name completion: what cannot be part of a name (a name
   may hold a quote after its first letter: x'). File names after :load
   break only at blanks and quotes. Not const: readline's word-break hook
   returns a plain char *. */
static char name_breaks[] = " \t\n\"\\`@$><=;|&{}()[],.+-*/^%!~#?:";
static char file_breaks[] = " \t\n\"'";

/* ---- signals ---- */

/* Set by the handlers, which run on whichever thread the kernel picks (the
   interpreter's, the collector's, main's), and read by the prompt loop on
   the interpreter's thread: lock-free atomics, so that both a handler may
   store to them and another thread may read them without a data race. */
_Static_assert(ATOMIC_INT_LOCK_FREE == 2, "signal flags must be lock-free");
static atomic_int got_sigint, got_sigwinch, got_sigcont;
static atomic_int at_prompt;    /* waiting for a key */
static atomic_int sigint_count; /* Ctrl-Cs during one entry */
static int stderr_is_tty; /* set before the handler is installed */
static int wake_pipe[2] = {-1, -1}; /* handlers -> prompt loop */

static void wake(void) {
  if (wake_pipe[1] >= 0 && write(wake_pipe[1], "", 1) < 0) {
    /* full: the loop has a byte to wake on already */
  }
}

static void on_sigint(int sig) {
  int saved = errno;
  got_sigint = 1;
  interp_request_interrupt();
  wake();
  /* An evaluation stuck where the interpreter does not look at the flag
     must not hold the user hostage. */
  if (!at_prompt && stderr_is_tty) { /* the tty echoed "^C"; end its line */
    if (write(STDERR_FILENO, "\n", 1) < 0) { /* nothing to do */ }
  }
  if (!at_prompt && ++sigint_count >= 3) {
    static const char msg[] = "\nqcs: interrupted three times, quitting\n";
    if (write(STDERR_FILENO, msg, sizeof msg - 1) < 0) { /* nothing to do */ }
    _exit(128 + SIGINT);
  }
  errno = saved;
}

static void on_sigwinch(int sig) {
  int saved = errno;
  got_sigwinch = 1;
  wake();
  errno = saved;
}

static void on_sigcont(int sig) {
  int saved = errno;
  got_sigcont = 1;
  wake();
  errno = saved;
}

static int open_wake_pipe(void) {
  if (wake_pipe[0] >= 0) return 0;
  if (pipe(wake_pipe) < 0) return -1;
  for (int i = 0; i < 2; i++) {
    fcntl(wake_pipe[i], F_SETFL, fcntl(wake_pipe[i], F_GETFL) | O_NONBLOCK);
    fcntl(wake_pipe[i], F_SETFD, FD_CLOEXEC);
  }
  return 0;
}

static void drain_wake_pipe(void) {
  char buf[64];
  while (read(wake_pipe[0], buf, sizeof buf) > 0) continue;
}

static void set_handler(int sig, void (*fn)(int)) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = fn;
  sigemptyset(&sa.sa_mask);
  /* SA_RESTART keeps the interpreter's stdio from failing with EINTR; the
     prompt loop learns of signals through the pipe. */
  sa.sa_flags = SA_RESTART;
  sigaction(sig, &sa, NULL);
}

void repl_install_sigint(void) {
  stderr_is_tty = isatty(STDERR_FILENO);
  set_handler(SIGINT, on_sigint);
}

/* ---- growing strings ---- */

typedef struct {
  char *s;
  size_t len, cap;
} Buf;

static void buf_add(Buf *b, const char *s, size_t n) {
  if (b->len + n + 1 > b->cap) {
    size_t cap = b->cap ? b->cap : 256;
    while (b->len + n + 1 > cap) cap *= 2;
    char *p = realloc(b->s, cap);
    if (!p) {
      fputs("qcs: out of memory\n", stderr);
      exit(1);
    }
    b->s = p;
    b->cap = cap;
  }
  memcpy(b->s + b->len, s, n);
  b->len += n;
  b->s[b->len] = '\0';
}

static void buf_clear(Buf *b) {
  b->len = 0;
  if (b->s) b->s[0] = '\0';
}

/* ---- REPL state ---- */

typedef struct {
  Interp *I;
  int interactive;   /* stdin is a terminal */
  Buf pending;       /* the unfinished entry, lines joined by '\n' */
  Buf last;          /* the last entry run, if it was a definition: an
                        indented line after it continues it (layout) */
  int in_block;      /* between ":{" and ":}" */
  long block_line;   /* input line of the ":{", for messages */
  long line_no;      /* input lines read so far */
  int had_error;
  int quit;
  char **files;      /* what :load ran, for :reload */
  size_t nfiles;
  char *histfile;    /* NULL: no history file */
  /* Pictures at the prompt (:set preview, :set preview-size, :show). */
  PreviewMode preview;   /* as set; resolved against stdout when used */
  int preview_cols, preview_rows; /* 0: from the terminal */
  int show_forced;       /* the entry is a :show: show it, or say why not */
  const char *show_settings; /* :show ... with SETTINGS: their text */
  int reload_renders;    /* :set reload-renders on: :reload renders too */
  int joined;            /* the pending entry continues the last one */
} Repl;

static Interp *completion_interp; /* readline's callbacks take no user data */

static const char *skip_blanks(const char *s) {
  while (*s == ' ' || *s == '\t') s++;
  return s;
}

static int is_blank(const char *s) { return *skip_blanks(s) == '\0'; }

static int is_blank_text(const char *s) {
  if (s)
    for (; *s; s++)
      if (*s != ' ' && *s != '\t' && *s != '\n' && *s != '\r') return 0;
  return 1;
}

/* The line without surrounding blanks is exactly word. */
static int line_is(const char *line, const char *word) {
  const char *s = skip_blanks(line);
  size_t n = strlen(word);
  return strncmp(s, word, n) == 0 && is_blank(s + n);
}

/* Run one interpreter call with Ctrl-C armed for it. */
#define RUN_GUARDED(st, call)                                                  \
  do {                                                                         \
    interp_clear_interrupt();                                                  \
    sigint_count = 0;                                                          \
    got_sigint = 0;                                                            \
    (st) = (call);                                                             \
    got_sigint = 0;                                                            \
    fflush(stdout);                                                            \
  } while (0)

static void note_status(Repl *R, RunStatus st) {
  if (st == RUN_ERROR) R->had_error = 1;
}

/* ---- commands ---- */

typedef enum { ARG_NONE, ARG_FILE, ARG_ANY, ARG_NAME } ArgKind;

typedef struct {
  const char *name;
  ArgKind arg;
  int bang;  /* accepts a trailing '!' */
  void (*run)(Repl *R, const char *arg, int bang);
  const char *usage, *help;
} Command;

static void cmd_help(Repl *R, const char *arg, int bang);
static void cmd_load(Repl *R, const char *arg, int bang);
static void cmd_reload(Repl *R, const char *arg, int bang);
static void cmd_unload(Repl *R, const char *arg, int bang);
static void cmd_browse(Repl *R, const char *arg, int bang);
static void cmd_quit(Repl *R, const char *arg, int bang);
static void cmd_tradeoff(Repl *R, const char *arg, int bang);
static void cmd_set(Repl *R, const char *arg, int bang);
static void cmd_show(Repl *R, const char *arg, int bang);
static void cmd_view(Repl *R, const char *arg, int bang);
static void cmd_type(Repl *R, const char *arg, int bang);
static void cmd_info(Repl *R, const char *arg, int bang);
static void cmd_doc(Repl *R, const char *arg, int bang);

/* Sorted by name; a command may be abbreviated to any unique prefix. */
static const Command commands[] = {
  {"browse", ARG_NONE, 1, cmd_browse, ":browse[!]",
   "list your definitions (! adds the prelude and built-ins)"},
  {"doc", ARG_NAME, 0, cmd_doc, ":doc NAME",
   "what NAME does, in one line, and an example"},
  {"help", ARG_NONE, 0, cmd_help, ":help", "this text"},
  {"info", ARG_NAME, 0, cmd_info, ":info NAME",
   "kind, arity, where defined, signature, doc (also :i)"},
  {"load", ARG_FILE, 0, cmd_load, ":load FILE",
   "run a qcs file and remember it for :reload"},
  {"quit", ARG_NONE, 0, cmd_quit, ":quit", "leave qcs (so does Ctrl-D)"},
  {"reload", ARG_NONE, 1, cmd_reload, ":reload[!]",
   "run the loaded files again, but not their renders (! renders too)"},
  {"set", ARG_ANY, 0, cmd_set, ":set [NAME VALUE]",
   "list the settings and limits, or change one (:set digits 6)"},
  {"show", ARG_ANY, 0, cmd_show, ":show EXPR [with S]",
   "draw a scene object as a picture (S: render settings, [Size 600 380])"},
  {"tradeoff", ARG_FILE, 0, cmd_tradeoff, ":tradeoff FILE",
   "error against run time over root tolerances (writes tradeoff.svg)"},
  {"type", ARG_ANY, 0, cmd_type, ":type EXPR",
   "what kind of value EXPR is (also :t); a scene object is summarised"},
  {"unload", ARG_FILE, 0, cmd_unload, ":unload FILE",
   "forget a loaded file and the definitions it made"},
  {"view", ARG_ANY, 0, cmd_view, ":view [EXPR]",
   "serve EXPR (default scene) in the browser until Enter (qcs view)"},
};
#define NCOMMANDS (sizeof commands / sizeof commands[0])

static void cmd_help(Repl *R, const char *arg, int bang) {
  puts("Commands (any unique prefix will do, e.g. :b for :browse):");
  for (size_t i = 0; i < NCOMMANDS; i++)
    printf("  %-16s %s\n", commands[i].usage, commands[i].help);
  puts("  :{ ... :}        lines in between are one block, run as a script\n"
       "\n"
       "Type a definition to add it, or an expression to see its value:\n"
       "  qcs> f x = x * 2\n"
       "  qcs> f 21\n"
       "  42\n"
       "  qcs> Density 0.1 (0,0,0) UnitCube\n"
       "An unfinished entry (open bracket, trailing operator, \"g x =\")\n"
       "continues at the ...> prompt; an indented line (or one starting\n"
       "with | = or where) after a definition continues it, which then\n"
       "runs again whole. Ctrl-C stops a running evaluation or\n"
       "abandons the line being typed; an error never loses earlier\n"
       "definitions. Tab completes names, commands and file names after\n"
       ":load. History is kept in ~/.qcs_history.\n"
       "The language is described in lang/ of the qcs sources; the command\n"
       "line in qcs(1).\n"
       "\n"
       "Limits: an evaluation or render that passes one stops with an error\n"
       "naming it. :set lists them; :set NAME VALUE changes one:\n"
       "  max-stack SIZE   stack for nested calls, i.e. recursion depth (256M)\n"
       "  max-steps N      evaluation steps of one entry (0: no limit)\n"
       "  max-list N       elements of one list (0: no limit)\n"
       "  max-memory SIZE  memory for values and a mesh's, e.g. 512M or 2G (0: none)\n"
       "  max-pixels N     pixels of one image, N or WxH (at most 8192x8192)\n"
       "  max-spp N        samples per pixel of a render (at most 256)\n"
       "The same limits are options of the command line: --max-steps N, ...");
}

/* :set lists the limits; :set NAME VALUE changes one. */
static int set_preview(Repl *R, const char *name, const char *val);

static void cmd_set(Repl *R, const char *arg, int bang) {
  if (!*arg) {
    printf("preview       %-12s pictures of scene objects at the prompt "
           "(off, auto, kitty, iterm, sixel, symbols)\n",
           preview_mode_name(R->preview));
    if (R->preview_cols || R->preview_rows)
      printf("preview-size  %dx%-9d the picture's size in character cells\n",
             R->preview_cols, R->preview_rows);
    else
      printf("preview-size  %-12s the picture's size in character cells\n",
             "auto");
    printf("digits        %-12d significant digits of printed Reals "
           "(0: shortest that reads back)\n", R->I->digits);
    printf("reload-renders %-11s whether :reload runs the files' renders "
           "again (on, off)\n", R->reload_renders ? "on" : "off");
    interp_list_limits(R->I, stdout);
    fflush(stdout);
    return;
  }
  char name[64];
  size_t n = strcspn(arg, " \t=");
  const char *val = arg + n;
  while (*val == ' ' || *val == '\t' || *val == '=') val++;
  if (n >= sizeof name) n = sizeof name - 1;
  memcpy(name, arg, n);
  name[n] = 0;
  char err[300];
  if (!strcmp(name, "reload-renders")) {
    if (!strcmp(val, "on") || !strcmp(val, "off")) {
      R->reload_renders = !strcmp(val, "on");
    } else {
      fprintf(stderr, "error: :set reload-renders needs on or off, not "
              "'%s'\n", val);
      R->had_error = 1;
    }
    return;
  }
  if (!strcmp(name, "preview") || !strcmp(name, "preview-size")) {
    if (set_preview(R, name, val)) R->had_error = 1;
    return;
  }
  if (!strcmp(name, "digits")) { /* printing, not a limit: Reals, probes */
    char *end;
    long d = strtol(val, &end, 10);
    if (!*val || *end || d < 0 || d > 17) {
      fprintf(stderr, "error: :set digits needs 0 (shortest that reads "
              "back) to 17, not '%s'\n", val);
      R->had_error = 1;
    } else {
      R->I->digits = (int)d;
    }
    return;
  }
  if (!*val) {
    unsigned long long v;
    if (interp_limit_parse(name, "0", &v, err, sizeof err) &&
        !strncmp(err, "unknown", 7))
      fprintf(stderr, "error: %s; :set alone lists the limits\n", err);
    else
      fprintf(stderr, "error: :set %s needs a value (usage: :set %s VALUE)\n",
              name, name);
    R->had_error = 1;
    return;
  }
  if (interp_set_limit(R->I, name, val, err, sizeof err)) {
    fprintf(stderr, "error: %s%s\n", err,
            strncmp(err, "unknown", 7) ? "" : "; :set alone lists the limits");
    R->had_error = 1;
  }
}

/* :set preview MODE, :set preview-size WxH | auto. 0, or -1 after an
   error message. */
static int set_preview(Repl *R, const char *name, const char *val) {
  if (!strcmp(name, "preview")) {
    PreviewMode m;
    if (preview_mode_parse(val, &m)) {
      fprintf(stderr, "error: :set preview needs off, auto, kitty, iterm, "
              "sixel or symbols, not '%s'\n", val);
      return -1;
    }
    R->preview = m;
    const char *term = getenv("TERM");
    if ((m == PREVIEW_KITTY || m == PREVIEW_ITERM || m == PREVIEW_SIXEL) &&
        (getenv("TMUX") || getenv("STY") ||
         (term && (!strncmp(term, "screen", 6) || !strncmp(term, "tmux", 4)))))
      fprintf(stderr, "note: tmux and screen do not pass %s graphics through "
              "to the terminal unless told to (tmux: allow-passthrough); if "
              "no picture appears, :set preview symbols\n",
              preview_mode_name(m));
    return 0;
  }
  if (!strcmp(val, "auto")) {
    R->preview_cols = R->preview_rows = 0;
    return 0;
  }
  char *end;
  long w = strtol(val, &end, 10), h = -1;
  if (end != val && (*end == 'x' || *end == 'X')) {
    const char *hs = end + 1;
    h = strtol(hs, &end, 10);
    if (end == hs) h = -1;
  }
  if (h < 1 || w < 1 || *skip_blanks(end)) {
    fprintf(stderr, "error: :set preview-size needs COLUMNSxROWS (e.g. "
            "80x25) or auto, not '%s'\n", val);
    return -1;
  }
  if (w > PREVIEW_MAX_COLS || h > PREVIEW_MAX_ROWS) {
    fprintf(stderr, "error: :set preview-size %ldx%ld is too large: at most "
            "%dx%d character cells\n", w, h, PREVIEW_MAX_COLS,
            PREVIEW_MAX_ROWS);
    return -1;
  }
  R->preview_cols = (int)w;
  R->preview_rows = (int)h;
  return 0;
}

/* The last " with " of text outside brackets and strings, or NULL. */
static const char *find_with(const char *text) {
  const char *found = NULL;
  int depth = 0, in_str = 0;
  for (const char *p = text; *p; p++) {
    if (in_str) {
      if (*p == '\\' && p[1]) p++;
      else if (*p == '"') in_str = 0;
      continue;
    }
    if (*p == '"') in_str = 1;
    else if (*p == '(' || *p == '[' || *p == '{') depth++;
    else if ((*p == ')' || *p == ']' || *p == '}') && depth > 0) depth--;
    else if (depth == 0 && !strncmp(p, "with", 4) && p > text &&
             (p[-1] == ' ' || p[-1] == '\t') &&
             (p[4] == ' ' || p[4] == '\t' || p[4] == '['))
      found = p;
  }
  return found;
}

/* :show EXPR [with SETTINGS]: the value of EXPR as a picture, whatever
   the preview setting (a pipe gets the summary and no picture). */
/* :view [EXPR]: the browser viewer (app/view.h) for EXPR or `scene`. */
static void cmd_view(Repl *R, const char *arg, int bang) {
  ViewOptions vo = {0};
  if (view_expr(R->I, *arg ? arg : "scene", &vo)) R->had_error = 1;
}

static void cmd_show(Repl *R, const char *arg, int bang) {
  if (!*arg) {
    fputs("error: :show needs an expression (usage: :show EXPR [with "
          "SETTINGS])\n", stderr);
    R->had_error = 1;
    return;
  }
  char *expr = strdup(arg), *settings = NULL;
  if (!expr) return;
  const char *w = find_with(expr);
  if (w) {
    settings = strdup(skip_blanks(w + 4));
    expr[w - expr] = 0;
  }
  R->show_forced = 1;
  R->show_settings = settings;
  RunStatus st;
  RUN_GUARDED(st, interp_run_string(R->I, SOURCE_NAME, expr, MODE_REPL));
  if (st == RUN_INCOMPLETE) {
    fputs("error: :show needs the whole expression on one line\n", stderr);
    st = RUN_ERROR;
  }
  note_status(R, st);
  R->show_forced = 0;
  R->show_settings = NULL;
  free(settings);
  free(expr);
}

/* The terminal's input in non-canonical mode without echo while a picture
   is drawn, so a key stops it at once (and stays unread for the prompt). */
typedef struct { int fd, saved; struct termios t; } RawInput;

static void raw_input_begin(RawInput *r, int fd) {
  r->fd = fd;
  r->saved = fd >= 0 && isatty(fd) && tcgetattr(fd, &r->t) == 0;
  if (r->saved) {
    struct termios t = r->t;
    t.c_lflag &= ~(tcflag_t)(ICANON | ECHO);
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    tcsetattr(fd, TCSANOW, &t);
  }
}

static void raw_input_end(RawInput *r) {
  if (r->saved) tcsetattr(r->fd, TCSANOW, &r->t);
}

static void free_scene_cb(void *s) { scene_free(s); }

/* The interpreter's show hook: a scene object (or a list of them) at the
   prompt becomes a one-line summary and a picture. */
static int repl_show(Interp *I, Value *v, Pos pos, void *ud) {
  Repl *R = ud;
  PreviewMode mode = preview_resolve(R->preview, STDOUT_FILENO);
  if (mode == PREVIEW_OFF && !R->show_forced) return 0;
  if (!compile_is_object(I, v)) {
    if (!R->show_forced) return 0;
    char buf[160];
    val_brief(v, buf, sizeof buf);
    qcs_error(pos, ":show draws scene objects (or lists of them), not %s: %s",
              val_describe(v), buf);
  }
  Scene *s = compile_scene_any(I, v, pos);
  ErrCleanup cu;
  err_defer(&cu, free_scene_cb, s);
  RenderSettings rs;
  Value *sv = R->show_settings
                  ? interp_eval_expr(I, "<:show settings>", R->show_settings)
                  : NULL;
  render_lang_settings(I, sv, pos, &rs);
  char brief[200], line[512];
  val_brief(v, brief, sizeof brief);
  if (strlen(brief) > 40) { /* the head of a long tree: "Rounded 0.1 (...)" */
    char *cut = brief + 36;
    while (cut > brief && *cut != ' ') cut--;
    strcpy(cut > brief ? cut : brief + 36, " ...");
  }
  report_scene(line, sizeof line, s, brief);
  printf("%s\n", line);
  fflush(stdout);
  if (mode == PREVIEW_OFF) {
    printf("(no picture: %s)\n", R->preview == PREVIEW_OFF
                                    ? "preview is off; :set preview auto"
                                    : "standard output is not a terminal");
  } else {
    PreviewOptions o = {mode, R->preview_cols, R->preview_rows,
                        STDOUT_FILENO, R->interactive ? STDIN_FILENO : -1,
                        &qcs_interrupted};
    PreviewResult res;
    char err[300];
    RawInput raw;
    raw_input_begin(&raw, o.input_fd);
    int rc = preview_show(stdout, s, &rs, &o, &res, err, sizeof err);
    raw_input_end(&raw);
    if (atomic_load(&qcs_interrupted)) {
      interp_clear_interrupt();
      printf("(picture stopped)\n");
    } else if (rc) {
      fprintf(stderr, "error: %s\n", err);
    } else if (res.rungs && !res.stopped && res.rep.primary > 0 &&
               res.rep.hits == 0) {
      printf("nothing hit: 0 of %ld primary rays met a surface\n",
             res.rep.primary);
    }
  }
  fflush(stdout);
  err_release(&cu);
  scene_free(s);
  return 1;
}

static void remember_file(Repl *R, const char *path) {
  for (size_t i = 0; i < R->nfiles; i++)
    if (strcmp(R->files[i], path) == 0) return;
  char **files = realloc(R->files, (R->nfiles + 1) * sizeof *files);
  char *copy = strdup(path);
  if (!files || !copy) {
    fputs("qcs: out of memory\n", stderr);
    exit(1);
  }
  files[R->nfiles++] = copy;
  R->files = files;
}

static void cmd_load(Repl *R, const char *arg, int bang) {
  Buf path = {0};
  size_t n = strlen(arg);
  if (n >= 2 && arg[0] == '"' && arg[n - 1] == '"') { /* :load "a b.qcs" */
    arg++;
    n -= 2;
  }
  if (arg[0] == '~' && (n == 1 || arg[1] == '/') && getenv("HOME")) {
    buf_add(&path, getenv("HOME"), strlen(getenv("HOME")));
    arg++;
    n--;
  }
  buf_add(&path, arg, n);
  /* A file that cannot be read is not remembered; one with an error in it
     is, so that it can be mended and reloaded. */
  int readable = access(path.s, R_OK) == 0;
  RunStatus st;
  RUN_GUARDED(st, interp_run_file(R->I, path.s));
  note_status(R, st);
  if (readable) {
    remember_file(R, path.s);
    if (st == RUN_OK && R->interactive) printf("loaded %s\n", path.s);
  }
  free(path.s);
}

/* :tradeoff FILE (issue 6): the file's render captured and measured over
   the tolerance ladder; see tradeoff.h. */
static void cmd_tradeoff(Repl *R, const char *arg, int bang) {
  TradeoffOptions o;
  memset(&o, 0, sizeof o);
  int st;
  interp_clear_interrupt();
  st = tradeoff_file(R->I, arg, &o);
  fflush(stdout);
  if (st) R->had_error = 1;
}

/* :reload runs the files' definitions and expressions again, but not
   their renders (a file that renders at its end would redraw it on every
   edit): those are counted and said. :reload! (or :set reload-renders
   on) runs them too. */
static void cmd_reload(Repl *R, const char *arg, int bang) {
  if (R->nfiles == 0) {
    fputs("error: no files to reload; use :load FILE first\n", stderr);
    R->had_error = 1;
    return;
  }
  RenderOverrides *old = render_get_overrides(R->I);
  RenderOverrides skip = old ? *old : (RenderOverrides){0};
  skip.skip = !bang && !R->reload_renders;
  for (size_t i = 0; i < R->nfiles; i++) { /* all, as :load ran them */
    RunStatus st;
    skip.skipped = 0;
    render_set_overrides(R->I, &skip);
    RUN_GUARDED(st, interp_run_file(R->I, R->files[i]));
    render_set_overrides(R->I, old);
    if (old) old->renders = skip.renders;
    note_status(R, st);
    if (st == RUN_OK && R->interactive) printf("reloaded %s\n", R->files[i]);
    if (skip.skipped)
      printf("(%d render%s in %s not run again; :reload! runs them)\n",
             skip.skipped, skip.skipped == 1 ? "" : "s", R->files[i]);
    fflush(stdout);
  }
}

/* :unload FILE: forget a loaded file and the definitions it made. */
static void cmd_unload(Repl *R, const char *arg, int bang) {
  size_t i = 0;
  while (i < R->nfiles && strcmp(R->files[i], arg)) i++;
  if (i == R->nfiles) {
    fprintf(stderr, "error: %s is not loaded (:unload takes a file as "
            ":load was given it:", arg);
    for (size_t k = 0; k < R->nfiles; k++) fprintf(stderr, " %s", R->files[k]);
    fputs(R->nfiles ? ")\n" : " none is loaded)\n", stderr);
    R->had_error = 1;
    return;
  }
  int n = interp_unload(R->I, R->files[i]);
  printf("unloaded %s: %d definition%s removed\n", R->files[i], n,
         n == 1 ? "" : "s");
  fflush(stdout);
  free(R->files[i]);
  memmove(R->files + i, R->files + i + 1,
          (R->nfiles - i - 1) * sizeof *R->files);
  R->nfiles--;
}

static void cmd_browse(Repl *R, const char *arg, int bang) {
  interp_browse(R->I, stdout, bang);
  fflush(stdout);
}

static void cmd_quit(Repl *R, const char *arg, int bang) { R->quit = 1; }

static void cmd_info(Repl *R, const char *arg, int bang) {
  if (interp_info(R->I, stdout, arg)) R->had_error = 1;
  fflush(stdout);
}

static void cmd_doc(Repl *R, const char *arg, int bang) {
  if (interp_doc(R->I, stdout, arg)) R->had_error = 1;
  fflush(stdout);
}

/* :type EXPR runs as an item, so that an error in EXPR is reported as
   one; the value is described, not printed. */
static Value *type_item(Interp *I, void *ud) {
  const char *text = ud;
  Value *v = interp_eval_expr(I, SOURCE_NAME, text);
  char desc[400];
  interp_describe(I, v, desc, sizeof desc);
  const char *t = skip_blanks(text);
  const char *sig = interp_signature(I, t);
  if (sig) printf("%s :: %s\n", t, sig);
  printf("%s\n", desc);
  if (compile_is_object(I, v)) { /* a scene object: what it compiles to */
    Scene *s = compile_scene_any(I, v, pos_none);
    char line[512];
    report_scene(line, sizeof line, s, "a scene object");
    scene_free(s);
    printf("%s\n", line);
  }
  return NULL;
}

static void cmd_type(Repl *R, const char *arg, int bang) {
  if (!*arg) {
    fputs("error: :type needs an expression (usage: :type EXPR)\n", stderr);
    R->had_error = 1;
    return;
  }
  RunStatus st;
  RUN_GUARDED(st, interp_run_item(R->I, pos_none, type_item, (void *)arg));
  note_status(R, st);
}

static void unknown_command(Repl *R, const char *word) {
  const char *best = NULL;
  int best_d = 3; /* suggest only close names (lang/error.h's distance) */
  for (size_t i = 0; i < NCOMMANDS; i++) {
    int d = edit_distance(word, commands[i].name);
    if (d < best_d && (size_t)d < strlen(word)) {
      best = commands[i].name;
      best_d = d;
    }
  }
  if (best)
    fprintf(stderr, "error: unknown command ':%s'; did you mean ':%s'?\n",
            word, best);
  else
    fprintf(stderr, "error: unknown command ':%s'; :help lists them\n", word);
  R->had_error = 1;
}

/* An exact name wins; otherwise a unique prefix. */
static const Command *find_command(Repl *R, const char *word) {
  const Command *found = NULL;
  size_t n = strlen(word), matches = 0;
  for (size_t i = 0; i < NCOMMANDS; i++) {
    if (strcmp(commands[i].name, word) == 0) return &commands[i];
    if (n > 0 && strncmp(commands[i].name, word, n) == 0) {
      found = &commands[i];
      matches++;
    }
  }
  if (matches == 1) return found;
  if (matches == 0) {
    unknown_command(R, word);
    return NULL;
  }
  fprintf(stderr, "error: ambiguous command ':%s'; it could be", word);
  for (size_t i = 0; i < NCOMMANDS; i++)
    if (strncmp(commands[i].name, word, n) == 0)
      fprintf(stderr, " :%s", commands[i].name);
  fputc('\n', stderr);
  R->had_error = 1;
  return NULL;
}

/* line -> ':' word ['!'] [blanks arg] */
static void run_command(Repl *R, const char *line) {
  const char *s = skip_blanks(line) + 1;
  const char *end = s;
  while (*end && *end != ' ' && *end != '\t') end++;
  char word[64];
  size_t n = (size_t)(end - s);
  if (n >= sizeof word) n = sizeof word - 1;
  memcpy(word, s, n);
  word[n] = '\0';
  int bang = n > 0 && word[n - 1] == '!';
  if (bang) word[n - 1] = '\0';
  if (strcmp(word, "?") == 0) strcpy(word, "help");
  if (strcmp(word, "t") == 0) strcpy(word, "type"); /* as in GHCi */
  if (strcmp(word, "i") == 0) strcpy(word, "info");

  /* the argument, without surrounding blanks */
  const char *arg = skip_blanks(end);
  size_t alen = strlen(arg);
  while (alen > 0 && (arg[alen - 1] == ' ' || arg[alen - 1] == '\t')) alen--;
  char *argcopy = strndup(arg, alen);
  if (!argcopy) {
    fputs("qcs: out of memory\n", stderr);
    exit(1);
  }

  const Command *c = word[0] ? find_command(R, word) : NULL;
  if (!word[0]) {
    fputs("error: a ':' with no command; :help lists them\n", stderr);
    R->had_error = 1;
  } else if (!c) {
    /* reported */
  } else if (bang && !c->bang) {
    fprintf(stderr, "error: ':%s' takes no '!'\n", c->name);
    R->had_error = 1;
  } else if (c->arg == ARG_NONE && alen > 0) {
    fprintf(stderr, "error: ':%s' takes no argument (usage: %s)\n", c->name,
            c->usage);
    R->had_error = 1;
  } else if (c->arg == ARG_NAME && (alen == 0 || strpbrk(argcopy, " \t"))) {
    fprintf(stderr, "error: ':%s' needs one name (usage: %s)\n", c->name,
            c->usage);
    R->had_error = 1;
  } else if (c->arg == ARG_FILE && alen == 0) {
    fprintf(stderr, "error: ':%s' needs a file name (usage: %s)\n", c->name,
            c->usage);
    R->had_error = 1;
  } else {
    c->run(R, argcopy, bang);
  }
  free(argcopy);
}

/* ---- entries ---- */

static void reset_entry(Repl *R) {
  buf_clear(&R->pending);
  R->in_block = 0;
  R->joined = 0;
}

/* Does text start with a definition, "name args = ..." or "name args |"
   (a '=' or '|' outside brackets and strings, not part of an operator)? */
static int looks_like_definition(const char *text) {
  const char *p = skip_blanks(text);
  if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || *p == '_'))
    return 0;
  static const char *const keywords[] = {"let", "if", "case", NULL};
  for (int k = 0; keywords[k]; k++) {
    size_t n = strlen(keywords[k]);
    if (!strncmp(p, keywords[k], n) &&
        !strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                "0123456789_'", p[n] ? p[n] : 'a'))
      return 0;
  }
  int depth = 0, in_str = 0;
  for (; *p; p++) {
    if (in_str) {
      if (*p == '\\' && p[1]) p++;
      else if (*p == '"') in_str = 0;
      continue;
    }
    if (*p == '"') in_str = 1;
    else if (*p == '(' || *p == '[') depth++;
    else if ((*p == ')' || *p == ']') && depth > 0) depth--;
    else if (*p == '/' && p[1] == '/') { /* a comment, to the end of its line */
      while (p[1] && p[1] != '\n') p++;
    }
    else if (depth == 0 && (*p == '=' || *p == '|')) {
      char a = p[1], b = p[-1];
      if (*p == '=' && (a == '=' || b == '=' || b == '<' || b == '>' ||
                        b == '/' || b == '!'))
        continue;
      if (*p == '|' && (a == '|' || b == '|')) continue;
      return 1;
    }
  }
  return 0;
}

/* "g x (a, b)": one line of names, numbers and brackets, which an
   error (unknown name g) may have met because guards follow. */
static int looks_like_head(const char *text) {
  const char *p = skip_blanks(text);
  if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || *p == '_'))
    return 0;
  for (; *p; p++)
    if (!strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                "0123456789_' \t()[],:.", *p))
      return 0;
  return 1;
}

/* A line that continues the definition before it, as the layout rule
   has it: indented, or starting with '|', '=' or "where". */
static int continues_definition(const char *line) {
  const char *p = skip_blanks(line);
  if (!*p || (p[0] == '/' && p[1] == '/')) return 0;
  return p != line || *p == '|' || *p == '=' ||
         (!strncmp(p, "where", 5) &&
          (p[5] == 0 || p[5] == ' ' || p[5] == '\t'));
}

/* Give the pending text to the interpreter; keep it if it is unfinished. */
static void submit(Repl *R, RunMode mode) {
  RunStatus st;
  RUN_GUARDED(st, interp_run_string(R->I, SOURCE_NAME, R->pending.s, mode));
  if (st == RUN_INCOMPLETE) return;
  note_status(R, st);
  /* On a terminal the line before has run already: say that it was run
     again with this one (an indent typed by mistake shows here). */
  if (R->joined && st == RUN_OK && R->interactive)
    printf("(joined to the definition above, which runs again)\n");
  R->joined = 0;
  buf_clear(&R->last);
  if (mode == MODE_REPL && (looks_like_definition(R->pending.s) ||
                            (st == RUN_ERROR && looks_like_head(R->pending.s))))
    buf_add(&R->last, R->pending.s, R->pending.len);
  reset_entry(R);
}

/* One input line, without its newline. */
static void feed_line(Repl *R, const char *line) {
  R->line_no++;
  if (R->in_block) {
    /* A block is pasted text: run as a script, items start in column 1. */
    if (line_is(line, ":}")) {
      if (!is_blank_text(R->pending.s)) submit(R, MODE_SCRIPT);
      reset_entry(R);
      return;
    }
    buf_add(&R->pending, line, strlen(line));
    buf_add(&R->pending, "\n", 1);
    return;
  }
  if (R->pending.len == 0) {
    if (is_blank(line)) return;
    if (line_is(line, ":{")) {
      R->in_block = 1;
      R->block_line = R->line_no;
      return;
    }
    if (line_is(line, ":}")) {
      fputs("error: ':}' without an opening ':{'\n", stderr);
      R->had_error = 1;
      return;
    }
    if (*skip_blanks(line) == ':') {
      buf_clear(&R->last);
      run_command(R, line);
      return;
    }
    /* "f x = y" then "  where y = ...": the definition is run again with
       the new line (a definition replaces the one before it) */
    if ((R->last.len > 0 || *skip_blanks(line) == '|') &&
        continues_definition(line)) {
      if (R->last.len > 0) {
        buf_add(&R->pending, R->last.s, R->last.len);
        buf_add(&R->pending, "\n", 1);
        R->joined = 1;
      }
    }
  } else {
    buf_add(&R->pending, "\n", 1);
  }
  buf_add(&R->pending, line, strlen(line));
  submit(R, MODE_REPL);
}

/* Does any line of text start with ':' (a command) in column 1? */
static int has_command_line(const char *text) {
  for (const char *s = text;; s++) {
    if (*s == ':') return 1;
    if ((s = strchr(s, '\n')) == NULL) return 0;
  }
}

/* What readline returns: one line, or several when text was pasted (with
   bracketed paste the newlines stay in the line). A paste of plain code
   at the top level is run as a script, like a ':{ ... :}' block, so that
   it means what it meant in the file it came from; otherwise its lines
   are fed one by one, as if typed. */
static void feed_text(Repl *R, const char *text) {
  if (!strchr(text, '\n')) {
    feed_line(R, text);
    return;
  }
  if (!R->in_block && R->pending.len == 0 && !has_command_line(text)) {
    for (const char *s = text; (s = strchr(s, '\n')) != NULL; s++)
      R->line_no++;
    R->line_no++;
    if (!is_blank_text(text)) {
      buf_add(&R->pending, text, strlen(text));
      submit(R, MODE_SCRIPT);
    }
    reset_entry(R);
    return;
  }
  Buf line = {0};
  for (const char *s = text; s;) {
    const char *nl = strchr(s, '\n');
    size_t n = nl ? (size_t)(nl - s) : strlen(s);
    buf_clear(&line);
    buf_add(&line, s, n);
    feed_line(R, line.s);
    s = nl ? nl + 1 : NULL;
  }
  free(line.s);
}

/* End of input with an entry still open. */
static void feed_eof(Repl *R) {
  if (R->in_block) {
    fprintf(stderr,
            SOURCE_NAME ":%ld: error: end of input inside the ':{' block "
            "opened at line %ld\n", R->line_no, R->block_line);
    R->had_error = 1;
  } else if (R->pending.len > 0) {
    fprintf(stderr, SOURCE_NAME ":%ld: error: end of input inside an "
            "unfinished entry\n", R->line_no);
    R->had_error = 1;
  }
  reset_entry(R);
}

/* ---- plain loop: stdin is not a terminal ---- */

/* Reads one line without its end; 0 at end of input. */
static int plain_line(char **line, size_t *cap) {
  ssize_t n = getline(line, cap, stdin);
  if (n < 0) return 0;
  while (n > 0 && ((*line)[n - 1] == '\n' || (*line)[n - 1] == '\r'))
    (*line)[--n] = 0;
  return 1;
}

/* Piped input can look ahead: lines that continue a definition (the
   layout rule: indented, or starting with '|', '=' or where) join it
   before it runs, so "f x = y" is not run without its "  where y = ...". */
static int run_plain(Repl *R) {
  char *line = NULL, *next = NULL;
  size_t cap = 0, ncap = 0;
  int have = plain_line(&line, &cap);
  Buf entry = {0};
  while (!R->quit && have) {
    buf_clear(&entry);
    buf_add(&entry, line, strlen(line));
    int joined = 0;
    int have_next;
    while ((have_next = plain_line(&next, &ncap)) != 0 &&
           R->pending.len == 0 && !R->in_block &&
           *skip_blanks(line) != ':' && continues_definition(next) &&
           (looks_like_definition(entry.s) || looks_like_head(entry.s))) {
      buf_add(&entry, "\n", 1);
      buf_add(&entry, next, strlen(next));
      joined++;
    }
    R->line_no += joined;
    feed_line(R, entry.s);
    char *t = line;
    size_t tc = cap;
    line = next, cap = ncap;
    next = t, ncap = tc;
    have = have_next;
  }
  free(entry.s);
  free(line);
  free(next);
  if (!R->quit) feed_eof(R);
  fflush(stdout);
  return R->had_error ? 1 : 0;
}

/* ---- history ---- */

static void history_open(Repl *R) {
  const char *home = getenv("HOME");
  if (!home || !*home) return;
  Buf path = {0};
  buf_add(&path, home, strlen(home));
  buf_add(&path, HISTORY_FILE, strlen(HISTORY_FILE));
  R->histfile = path.s;
  using_history();
  stifle_history(HISTORY_MAX);
  read_history(R->histfile);
  /* append_history() does not create the file */
  int fd = open(R->histfile, O_WRONLY | O_CREAT | O_APPEND, 0600);
  if (fd >= 0) close(fd);
  history_truncate_file(R->histfile, HISTORY_MAX);
}

/* Written line by line, so that a crash loses nothing. */
static void history_note(Repl *R, const char *line) {
  if (is_blank(line)) return;
  HIST_ENTRY *last = history_length > 0 ? history_get(history_base +
                                                      history_length - 1)
                                        : NULL;
  if (last && strcmp(last->line, line) == 0) return;
  add_history(line);
  if (R->histfile) append_history(1, R->histfile);
}

static void history_close(Repl *R) {
  if (R->histfile) history_truncate_file(R->histfile, HISTORY_MAX);
  free(R->histfile);
  R->histfile = NULL;
}

/* ---- completion ---- */

static char *dup_or_die(const char *s) {
  char *p = strdup(s); /* readline frees matches with free() */
  if (!p) {
    fputs("qcs: out of memory\n", stderr);
    exit(1);
  }
  return p;
}

static char *command_generator(const char *text, int state) {
  static size_t i, n;
  if (state == 0) {
    i = 0;
    n = strlen(text);
  }
  while (i < NCOMMANDS) {
    const char *name = commands[i++].name;
    if (strncmp(name, text, n) == 0) return dup_or_die(name);
  }
  return NULL;
}

/* Names from interp_complete, copied with malloc; names[next..n) are not
   yet handed to readline, which frees the ones it gets. */
typedef struct {
  char **names;
  size_t n, cap, next;
} NameList;

static NameList name_matches;

static void collect_name(const char *name, void *ud) {
  NameList *l = ud;
  if (l->n == l->cap) {
    size_t cap = l->cap ? 2 * l->cap : 64;
    char **p = realloc(l->names, cap * sizeof *p);
    if (!p) return;
    l->names = p;
    l->cap = cap;
  }
  l->names[l->n++] = dup_or_die(name);
}

static void names_clear(NameList *l) {
  for (size_t k = l->next; k < l->n; k++) free(l->names[k]);
  l->n = l->next = 0;
}

static char *name_generator(const char *text, int state) {
  NameList *l = &name_matches;
  if (state == 0) {
    names_clear(l);
    interp_complete(completion_interp, text, collect_name, l);
  }
  return l->next < l->n ? l->names[l->next++] : NULL;
}

/* If line is ":CMD ..." with CMD naming :load or :unload, where its
   argument (a file name) starts. */
static const char *load_argument(const char *line) {
  const char *s = skip_blanks(line);
  if (*s++ != ':') return NULL;
  const char *end = s;
  while (*end && *end != ' ' && *end != '\t') end++;
  size_t n = (size_t)(end - s);
  if (n == 0 || *end == '\0') return NULL;
  if ((n <= strlen("load") && strncmp(s, "load", n) == 0) ||
      (n <= strlen("unload") && strncmp(s, "unload", n) == 0))
    return end;
  return NULL;
}

static char *word_breaks(void) {
  return load_argument(rl_line_buffer) ? file_breaks : name_breaks;
}

static char **complete(const char *text, int start, int end) {
  rl_attempted_completion_over = 1; /* no file names unless asked for */
  const char *line = rl_line_buffer;
  const char *first = skip_blanks(line);
  const char *arg = load_argument(line);
  if (arg && start >= (int)(arg - line))
    return rl_completion_matches(text, rl_filename_completion_function);
  if (*first == ':' && start == (int)(first - line) + 1)
    return rl_completion_matches(text, command_generator);
  if (*first == ':') return NULL;
  return rl_completion_matches(text, name_generator);
}

/* ---- terminal loop ---- */

typedef enum { READ_LINE, READ_EOF, READ_INTERRUPTED } ReadResult;

static char *read_got;
static int read_done;

static void on_line(char *line) {
  read_got = line;
  read_done = 1;
  rl_callback_handler_remove(); /* the entry runs outside readline */
}

/* Whether leaving readline ends the line itself: with bracketed paste on,
   rl_deprep_terminal() writes "\r", and at end of file also "\n". */
static int bracketed_paste(void) {
  const char *v = rl_variable_value("enable-bracketed-paste");
  return v && strcmp(v, "on") == 0;
}

/* Ctrl-C at the prompt: show it, drop the line, leave readline. */
static void abandon_line(void) {
  FILE *out = rl_outstream ? rl_outstream : stdout;
  rl_point = rl_end;
  rl_redisplay();
  fputs("^C", out);
  fflush(out);
  rl_callback_sigcleanup();
  rl_free_line_state();
  rl_callback_handler_remove();
  fputs("\n", out);
  fflush(out);
}

static ReadResult read_line(const char *prompt, char **out) {
  fflush(stdout);
  drain_wake_pipe();
  got_sigint = 0;
  read_done = 0;
  read_got = NULL;
  at_prompt = 1;
  rl_callback_handler_install(prompt, on_line);
  int fd = fileno(rl_instream ? rl_instream : stdin);
  int maxfd = fd > wake_pipe[0] ? fd : wake_pipe[0];
  ReadResult r;
  for (;;) {
    if (got_sigint) {
      got_sigint = 0;
      abandon_line();
      r = READ_INTERRUPTED;
      break;
    }
    if (got_sigwinch) {
      got_sigwinch = 0;
      rl_resize_terminal();
    }
    if (got_sigcont) { /* after Ctrl-Z the shell may have reset the tty */
      got_sigcont = 0;
      rl_deprep_terminal();
      rl_prep_terminal(1);
      rl_forced_update_display();
    }
    if (read_done) {
      r = read_got ? READ_LINE : READ_EOF;
      break;
    }
    fd_set fds;
    FD_ZERO(&fds);
    FD_SET(fd, &fds);
    FD_SET(wake_pipe[0], &fds);
    int n = select(maxfd + 1, &fds, NULL, NULL, NULL);
    if (n < 0) {
      if (errno == EINTR) continue;
      rl_callback_handler_remove();
      r = READ_EOF;
      break;
    }
    if (FD_ISSET(wake_pipe[0], &fds)) drain_wake_pipe();
    /* a signal first: a key waiting behind a Ctrl-C is for the new line */
    else if (FD_ISSET(fd, &fds)) rl_callback_read_char();
  }
  at_prompt = 0;
  interp_clear_interrupt(); /* a Ctrl-C at the prompt stops nothing later */
  *out = read_got;
  return r;
}

static int run_terminal(Repl *R) {
  rl_readline_name = "qcs";
  rl_catch_signals = 0;
  rl_catch_sigwinch = 0;
  rl_attempted_completion_function = complete;
  rl_completion_word_break_hook = word_breaks;
  rl_basic_word_break_characters = name_breaks;
  rl_completer_quote_characters = "\"";
  completion_interp = R->I;
  if (open_wake_pipe() < 0) {
    perror("qcs: pipe");
    return 1;
  }
  /* With the output redirected (qcs > file), the prompt, the echo of what
     is typed and readline's escape codes belong on the terminal, not in
     the file: only values go to standard output. */
  FILE *tty_out = NULL;
  if (!isatty(STDOUT_FILENO)) {
    tty_out = isatty(STDERR_FILENO) ? NULL : fopen("/dev/tty", "w");
    rl_outstream = tty_out ? tty_out : stderr;
  }
  history_open(R);
  repl_install_sigint();
  set_handler(SIGWINCH, on_sigwinch);
  set_handler(SIGCONT, on_sigcont);
  /* One line, on a terminal only (run_terminal runs only on one). */
  if (isatty(STDOUT_FILENO)) {
    /* what the terminal is, where its name does not say (sixels) */
    if (R->preview == PREVIEW_AUTO)
      preview_query_terminal(STDIN_FILENO, STDOUT_FILENO, 150);
    printf("qcs %s: type an expression or a definition; :help for help, "
           ":quit to leave\n", interp_version());
    fflush(stdout);
  }

  while (!R->quit) {
    int more = R->in_block || R->pending.len > 0;
    char *line;
    ReadResult r = read_line(more ? PROMPT_MORE : PROMPT, &line);
    if (r == READ_INTERRUPTED) {
      reset_entry(R);
      continue;
    }
    if (r == READ_EOF) {
      if (!bracketed_paste()) fputc('\n', rl_outstream ? rl_outstream : stdout);
      break;
    }
    history_note(R, line);
    feed_text(R, line);
    free(line);
  }
  feed_eof(R);
  history_close(R);
  if (rl_outstream) fflush(rl_outstream);
  if (tty_out) fclose(tty_out);
  rl_outstream = NULL;
  names_clear(&name_matches);
  free(name_matches.names);
  name_matches = (NameList){0};
  fflush(stdout);
  return 0;
}

int repl_run(Interp *I) {
  Repl R = {0};
  R.I = I;
  R.interactive = isatty(STDIN_FILENO);
  R.preview = PREVIEW_AUTO;
  interp_set_show(I, repl_show, &R);
  interp_set_warn_shadow(I, 1);
  /* without readline, a terminal is read as piped input is */
  int status = R.interactive && readline_load() == 0 ? run_terminal(&R)
                                                      : run_plain(&R);
  interp_set_show(I, NULL, NULL);
  interp_set_warn_shadow(I, 0);
  for (size_t i = 0; i < R.nfiles; i++) free(R.files[i]);
  free(R.files);
  free(R.pending.s);
  free(R.last.s);
  return status;
}
