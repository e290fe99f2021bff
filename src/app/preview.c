/* preview.c: pictures in the terminal with libchafa. See preview.h. */
#include "app/preview.h"

#include <chafa.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <poll.h>
#include <sys/select.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "render/progressive.h"
#include "app/dynlib.h"

/* libchafa (and glib, which it brings) is loaded the first time a picture
   is drawn or a terminal asked about (app/dynlib.h): the functions this
   file calls, through a table of their own types. */
#define CHAFA_FUNCS(X) \
  X(chafa_term_db_get_default) X(chafa_term_db_detect) \
  X(chafa_term_db_get_fallback_info) X(chafa_term_info_have_seq) \
  X(chafa_term_info_unref) X(chafa_set_n_threads) X(chafa_canvas_config_new) \
  X(chafa_canvas_config_unref) X(chafa_canvas_config_set_geometry) \
  X(chafa_canvas_config_set_canvas_mode) \
  X(chafa_canvas_config_set_pixel_mode) \
  X(chafa_canvas_config_set_cell_geometry) \
  X(chafa_canvas_config_set_symbol_map) X(chafa_symbol_map_new) \
  X(chafa_symbol_map_add_by_tags) X(chafa_symbol_map_remove_by_tags) \
  X(chafa_symbol_map_unref) X(chafa_canvas_new) X(chafa_canvas_unref) \
  X(chafa_canvas_draw_all_pixels) X(chafa_canvas_print) X(g_string_free)
static struct {
#define X(f) __typeof__(f) *f;
  CHAFA_FUNCS(X)
#undef X
} cf;
static int cf_state; /* 0: not tried, 1: loaded, -1: failed */

/* 0 once chafa is loaded; -1 (said once on stderr) if it cannot be. */
static int chafa_load(void) {
  if (cf_state) return cf_state > 0 ? 0 : -1;
  static const char *const sonames[] = {"libchafa.so.0", "libchafa.so", NULL};
  if (DYNLIB_LOAD(cf, CHAFA_FUNCS, sonames, "libchafa0", "no pictures")) {
    cf_state = -1;
    return -1;
  }
  cf_state = 1;
  return 0;
}
#define chafa_term_db_get_default (cf.chafa_term_db_get_default)
#define chafa_term_db_detect (cf.chafa_term_db_detect)
#define chafa_term_db_get_fallback_info (cf.chafa_term_db_get_fallback_info)
#define chafa_term_info_have_seq (cf.chafa_term_info_have_seq)
#define chafa_term_info_unref (cf.chafa_term_info_unref)
#define chafa_set_n_threads (cf.chafa_set_n_threads)
#define chafa_canvas_config_new (cf.chafa_canvas_config_new)
#define chafa_canvas_config_unref (cf.chafa_canvas_config_unref)
#define chafa_canvas_config_set_geometry (cf.chafa_canvas_config_set_geometry)
#define chafa_canvas_config_set_canvas_mode (cf.chafa_canvas_config_set_canvas_mode)
#define chafa_canvas_config_set_pixel_mode (cf.chafa_canvas_config_set_pixel_mode)
#define chafa_canvas_config_set_cell_geometry (cf.chafa_canvas_config_set_cell_geometry)
#define chafa_canvas_config_set_symbol_map (cf.chafa_canvas_config_set_symbol_map)
#define chafa_symbol_map_new (cf.chafa_symbol_map_new)
#define chafa_symbol_map_add_by_tags (cf.chafa_symbol_map_add_by_tags)
#define chafa_symbol_map_remove_by_tags (cf.chafa_symbol_map_remove_by_tags)
#define chafa_symbol_map_unref (cf.chafa_symbol_map_unref)
#define chafa_canvas_new (cf.chafa_canvas_new)
#define chafa_canvas_unref (cf.chafa_canvas_unref)
#define chafa_canvas_draw_all_pixels (cf.chafa_canvas_draw_all_pixels)
#define chafa_canvas_print (cf.chafa_canvas_print)
#define g_string_free (cf.g_string_free)

extern char **environ;

static const char *const mode_names[] = {"off", "auto", "kitty", "iterm",
                                         "sixel", "symbols"};

const char *preview_mode_name(PreviewMode m) {
  return m >= PREVIEW_OFF && m <= PREVIEW_SYMBOLS ? mode_names[m] : "?";
}

int preview_mode_parse(const char *s, PreviewMode *m) {
  for (int i = 0; i <= PREVIEW_SYMBOLS; i++)
    if (!strcmp(s, mode_names[i])) {
      *m = (PreviewMode)i;
      return 0;
    }
  return -1;
}

/* What chafa's terminal database makes of the environment. */
static ChafaTermInfo *term_info(void) {
  if (chafa_load()) return NULL;
  return chafa_term_db_detect(chafa_term_db_get_default(), environ);
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* What the terminal said of itself when asked (preview_query_terminal):
   0 not asked or no answer, 1 answered without sixels, 2 with sixels. */
static int queried;

/* The reply to DA1 (ESC [ c), "ESC [ ? P1 ; P2 ; ... c", in buf: 1 if
   found, with *sixel set when one of its attributes is 4 (sixel graphics,
   as xterm, mlterm, foot, WezTerm and contour report it). */
int preview_parse_da1(const char *buf, size_t n, int *sixel) {
  for (size_t i = 0; i + 2 < n; i++) {
    if (buf[i] != '\033' || buf[i + 1] != '[' || buf[i + 2] != '?') continue;
    size_t j = i + 3;
    long v = -1;
    int four = 0;
    for (; j < n; j++) {
      char c = buf[j];
      if (c >= '0' && c <= '9') {
        v = (v < 0 ? 0 : v * 10) + (c - '0');
        if (v > 100000) break;
      } else if (c == ';' || c == 'c') {
        if (v == 4) four = 1;
        v = -1;
        if (c == 'c') {
          *sixel = four;
          return 1;
        }
      } else {
        break;
      }
    }
  }
  return 0;
}

int preview_query_terminal(int in_fd, int out_fd, int timeout_ms) {
  if (!isatty(in_fd) || !isatty(out_fd)) return 0;
  const char *term = getenv("TERM");
  /* Only where the question is safe and useful: a terminal that answers
     DA1, not one the environment already names (tmux and screen answer
     for themselves, and draw symbols anyway), not a dumb one. */
  if (!term || !*term || !strcmp(term, "dumb") || getenv("TMUX") ||
      getenv("STY") || !strncmp(term, "screen", 6) || !strncmp(term, "tmux", 4))
    return 0;
  struct termios old, raw;
  if (tcgetattr(in_fd, &old)) return 0;
  raw = old;
  raw.c_lflag &= (tcflag_t) ~(ICANON | ECHO);
  raw.c_cc[VMIN] = 0;
  raw.c_cc[VTIME] = 0;
  if (tcsetattr(in_fd, TCSANOW, &raw)) return 0;
  static const char q[] = "\033[c";
  char buf[256];
  size_t n = 0;
  int sixel = 0, got = 0;
  if (write(out_fd, q, sizeof q - 1) == (ssize_t)(sizeof q - 1)) {
    double end = now() + timeout_ms * 1e-3;
    while (!got && n < sizeof buf) {
      int left = (int)((end - now()) * 1e3);
      if (left <= 0) break;
      struct pollfd pf = {in_fd, POLLIN, 0};
      if (poll(&pf, 1, left) <= 0) break;
      ssize_t k = read(in_fd, buf + n, sizeof buf - n);
      if (k <= 0) break;
      n += (size_t)k;
      got = preview_parse_da1(buf, n, &sixel);
    }
  }
  tcsetattr(in_fd, TCSANOW, &old);
  queried = got ? 1 + sixel : 0;
  return queried;
}

PreviewMode preview_resolve(PreviewMode m, int fd) {
  if (m != PREVIEW_AUTO) return m; /* asked for by name: as chafa -f does */
  if (!isatty(fd)) return PREVIEW_OFF;
  /* tmux and screen swallow graphics unless told to pass them through */
  const char *term = getenv("TERM");
  if (getenv("TMUX") || getenv("STY") ||
      (term && (!strncmp(term, "screen", 6) || !strncmp(term, "tmux", 4))))
    return PREVIEW_SYMBOLS;
  if (term && !strcmp(term, "dumb")) return PREVIEW_OFF;
  ChafaTermInfo *ti = term_info();
  if (!ti) return PREVIEW_OFF; /* no libchafa: values are printed */
  PreviewMode r = PREVIEW_SYMBOLS;
  if (chafa_term_info_have_seq(ti, CHAFA_TERM_SEQ_BEGIN_KITTY_IMMEDIATE_IMAGE_V1))
    r = PREVIEW_KITTY;
  else if (chafa_term_info_have_seq(ti, CHAFA_TERM_SEQ_BEGIN_ITERM2_IMAGE))
    r = PREVIEW_ITERM;
  else if (chafa_term_info_have_seq(ti, CHAFA_TERM_SEQ_BEGIN_SIXELS))
    r = PREVIEW_SIXEL;
  else if (queried == 2) /* not in the database, but it said so itself */
    r = PREVIEW_SIXEL;
  chafa_term_info_unref(ti);
  return r;
}

void preview_geometry(PreviewMode m, int out_fd, int cols, int rows,
                      double aspect, int *out_cols, int *out_rows, int *px_w,
                      int *px_h) {
  struct winsize ws;
  memset(&ws, 0, sizeof ws);
  int tcols = 80, trows = 24, cw = 0, ch = 0;
  if (ioctl(out_fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 && ws.ws_row > 0) {
    tcols = ws.ws_col;
    trows = ws.ws_row;
    if (ws.ws_xpixel > 0 && ws.ws_ypixel > 0) {
      cw = ws.ws_xpixel / ws.ws_col;
      ch = ws.ws_ypixel / ws.ws_row;
    }
  }
  if (cw <= 0 || ch <= 0) cw = 10, ch = 20; /* a common cell, 1:2 */
  if (!(aspect > 0) || !isfinite(aspect)) aspect = 600.0 / 380.0;
  double cell = (double)cw / ch; /* a cell's width over its height */
  if (cols <= 0 && rows <= 0) {
    /* As wide as the terminal, at most 100 columns, and leaving room for
       the prompt and a few lines of what came before. */
    cols = tcols < 100 ? tcols : 100;
    rows = (int)lround(cols * cell / aspect);
    if (rows > trows - 4 && trows > 8) {
      rows = trows - 4;
      cols = (int)lround(rows * aspect / cell);
    }
  } else if (cols <= 0) {
    cols = (int)lround(rows * aspect / cell);
  } else if (rows <= 0) {
    rows = (int)lround(cols * cell / aspect);
  }
  if (cols < 1) cols = 1;
  if (rows < 1) rows = 1;
  if (cols > PREVIEW_MAX_COLS) cols = PREVIEW_MAX_COLS;
  if (rows > PREVIEW_MAX_ROWS) rows = PREVIEW_MAX_ROWS;
  *out_cols = cols;
  *out_rows = rows;
  /* Symbols show about 4 x 8 dots a cell (chafa matches a cell against
     8 x 8 glyph dots, two rows of a cell each); graphics the
     terminal's own pixels. Either way the picture keeps the aspect. */
  int pw = m == PREVIEW_SYMBOLS ? 4 : cw;
  /* Capped at 800 x 600 pixels: a full picture within about 0.3 s of a
     figure12-like scene on 2 cores; the terminal scales it to the cells. */
  int w = cols * pw;
  if (w > 800) w = 800;
  int h = (int)lround(w / aspect);
  if (h > 600) {
    h = 600;
    w = (int)lround(h * aspect);
  }
  if (w < 8) w = 8;
  if (h < 8) h = 8;
  *px_w = w;
  *px_h = h;
}

/* The picture as 8-bit sRGB RGBA, unassociated, alpha opaque. */
static unsigned char *to_rgba8(const Image *im) {
  size_t n = (size_t)im->width * (size_t)im->height;
  unsigned char *px = malloc(n * 4);
  if (!px) return NULL;
  for (size_t i = 0; i < n; i++) {
    const float *p = im->rgba + 4 * i;
    float a = p[3];
    float k = a > 0 ? 1 / a : 0;
    /* Background pixels may carry alpha 0 with colour: show them as is. */
    if (a <= 0) k = 1;
    for (size_t c = 0; c < 3; c++) px[4 * i + c] = img_srgb8(p[c] * k);
    px[4 * i + 3] = 255;
  }
  return px;
}

typedef struct Drawer {
  FILE *out;
  ChafaCanvasConfig *cfg;
  ChafaTermInfo *ti;
  int cols, rows;
} Drawer;

static int drawer_init(Drawer *d, FILE *out, PreviewMode m, int cols,
                       int rows, int out_fd) {
  memset(d, 0, sizeof *d);
  if (chafa_load()) return -1;
  d->out = out;
  d->cols = cols;
  d->rows = rows;
  /* chafa draws on the caller's thread: the render's workers have the
     cores, and glib's thread pool (uninstrumented, synchronised by futexes
     ThreadSanitizer cannot see) stays out of make tsan's way. */
  chafa_set_n_threads(1);
  d->cfg = chafa_canvas_config_new();
  d->ti = term_info();
  if (!d->cfg || !d->ti) return -1;
  chafa_canvas_config_set_geometry(d->cfg, cols, rows);
  chafa_canvas_config_set_canvas_mode(d->cfg, CHAFA_CANVAS_MODE_TRUECOLOR);
  ChafaPixelMode pm = CHAFA_PIXEL_MODE_SYMBOLS;
  if (m == PREVIEW_KITTY) pm = CHAFA_PIXEL_MODE_KITTY;
  else if (m == PREVIEW_ITERM) pm = CHAFA_PIXEL_MODE_ITERM2;
  else if (m == PREVIEW_SIXEL) pm = CHAFA_PIXEL_MODE_SIXELS;
  chafa_canvas_config_set_pixel_mode(d->cfg, pm);
  struct winsize ws;
  if (ioctl(out_fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col && ws.ws_row &&
      ws.ws_xpixel && ws.ws_ypixel)
    chafa_canvas_config_set_cell_geometry(d->cfg, ws.ws_xpixel / ws.ws_col,
                                          ws.ws_ypixel / ws.ws_row);
  else
    chafa_canvas_config_set_cell_geometry(d->cfg, 10, 20);
  /* The sequences the mode needs: a terminal the database does not credit
     with them (tmux's "screen", a bare xterm asked for sixels by name) gets
     chafa's fallback, which has them all, as `chafa -f MODE` does. For
     symbols that is 24-bit colour, which such terminals understand or
     approximate. */
  ChafaTermSeq need = pm == CHAFA_PIXEL_MODE_KITTY
                          ? CHAFA_TERM_SEQ_BEGIN_KITTY_IMMEDIATE_IMAGE_V1
                      : pm == CHAFA_PIXEL_MODE_ITERM2
                          ? CHAFA_TERM_SEQ_BEGIN_ITERM2_IMAGE
                      : pm == CHAFA_PIXEL_MODE_SIXELS
                          ? CHAFA_TERM_SEQ_BEGIN_SIXELS
                          : CHAFA_TERM_SEQ_SET_COLOR_FGBG_DIRECT;
  if (!chafa_term_info_have_seq(d->ti, need)) {
    chafa_term_info_unref(d->ti);
    d->ti = chafa_term_db_get_fallback_info(chafa_term_db_get_default());
    if (!d->ti) return -1;
  }
  if (pm == CHAFA_PIXEL_MODE_SYMBOLS) {
    ChafaSymbolMap *sm = chafa_symbol_map_new();
    chafa_symbol_map_add_by_tags(sm, CHAFA_SYMBOL_TAG_BLOCK |
                                 CHAFA_SYMBOL_TAG_BORDER |
                                 CHAFA_SYMBOL_TAG_SPACE);
    chafa_symbol_map_remove_by_tags(sm, CHAFA_SYMBOL_TAG_BAD);
    chafa_canvas_config_set_symbol_map(d->cfg, sm);
    chafa_symbol_map_unref(sm);
  }
  /* Reserve the picture's lines (scrolling now, not mid-picture), then
     remember where it starts. */
  for (int i = 0; i < rows; i++) fputc('\n', out);
  fprintf(out, "\x1b[%dA\r\x1b" "7", rows);
  fflush(out);
  return 0;
}

static int drawer_draw(Drawer *d, const Image *im) {
  unsigned char *px = to_rgba8(im);
  if (!px) return -1;
  ChafaCanvas *cv = chafa_canvas_new(d->cfg);
  if (!cv) {
    free(px);
    return -1;
  }
  chafa_canvas_draw_all_pixels(cv, CHAFA_PIXEL_RGBA8_UNASSOCIATED, px,
                               im->width, im->height, im->width * 4);
  GString *gs = chafa_canvas_print(cv, d->ti);
  fputs("\x1b" "8", d->out);
  fwrite(gs->str, 1, gs->len, d->out);
  fputs("\x1b[0m", d->out);
  fflush(d->out);
  g_string_free(gs, TRUE);
  chafa_canvas_unref(cv);
  free(px);
  return 0;
}

/* Leave the cursor at the start of the line after the picture, with the
   attributes reset, whatever happened. */
static void drawer_end(Drawer *d) {
  if (d->out) {
    fprintf(d->out, "\x1b[0m\x1b" "8\x1b[%dB\r", d->rows);
    fflush(d->out);
  }
  if (d->cfg) chafa_canvas_config_unref(d->cfg);
  if (d->ti) chafa_term_info_unref(d->ti);
}

static int key_waiting(int fd) {
  if (fd < 0) return 0;
  fd_set rd;
  FD_ZERO(&rd);
  FD_SET(fd, &rd);
  struct timeval tv = {0, 0};
  return select(fd + 1, &rd, NULL, NULL, &tv) > 0;
}

int preview_show(FILE *out, const Scene *s, const RenderSettings *base,
                 const PreviewOptions *o, PreviewResult *res, char *err,
                 size_t errlen) {
  double t0 = now();
  PreviewResult r;
  memset(&r, 0, sizeof r);
  RenderSettings rs = *base;
  double aspect = (double)base->width / base->height;
  int cols, rows, pw, ph;
  preview_geometry(o->mode, o->out_fd, o->cols, o->rows, aspect, &cols, &rows,
                   &pw, &ph);
  prog_size(pw, ph, &rs.width, &rs.height);
  rs.progress = NULL;
  r.width = rs.width;
  r.height = rs.height;
  Progressive *p = prog_start(s, &rs, err, errlen);
  if (!p) return -1;
  Drawer d;
  int status = 0;
  if (drawer_init(&d, out, o->mode, cols, rows, o->out_fd)) {
    snprintf(err, errlen, "out of memory for the picture");
    status = -1;
    goto done;
  }
  for (;;) {
    if ((o->stop && atomic_load(o->stop)) || key_waiting(o->input_fd)) {
      r.stopped = 1;
      break;
    }
    const Image *im;
    int step;
    RenderReport rep;
    int w = prog_wait(p, 20, &im, &step, &rep, err, errlen);
    if (w == PROG_TIMEOUT) continue;
    if (w == PROG_DONE) break;
    if (w == PROG_FAILED) {
      status = -1;
      break;
    }
    if (drawer_draw(&d, im)) {
      snprintf(err, errlen, "out of memory for the picture");
      status = -1;
      break;
    }
    double t = now() - t0;
    if (!r.rungs) r.t_first = t;
    if (step == 1) r.t_full = t;
    r.rungs++;
    r.finest = step;
    r.rep = rep;
  }
done:
  prog_stop(p);
  drawer_end(&d);
  if (res) *res = r;
  return status;
}
