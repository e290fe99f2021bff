/* test_image.c: the image output layer (image.c, exr.c, png.c).
 *
 * EXR files are read back through the OpenEXR C library itself (header,
 * channel list, types) and through img_read_exr (values): float channels
 * must come back exactly, half channels within relative 2^-11 (round to
 * nearest half, normal range; the test values stay above 2^-14). The PNG
 * and PPM bytes are checked against an sRGB encoder written here in long
 * double (powl), not the code under test, and the PNG bytes are read with
 * libpng directly. The atomic-write tests make writes fail for real (no
 * permission, no directory, a file size limit, a directory in the way) and
 * check that no temporary is left and an existing target is untouched.
 * Everything happens in a mkdtemp directory that is removed at the end. */
#include "check.h"
#include "render/image.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <openexr.h>
#include <png.h>
#include <setjmp.h>
#include <signal.h>
#include <stdint.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

static char dir[64];

static const char *in_dir(const char *name, char *buf, size_t n) {
  snprintf(buf, n, "%s/%s", dir, name);
  return buf;
}

/* Remove path and, for a directory, everything under it. */
static void rm_rf(const char *path) {
  DIR *d = opendir(path);
  if (d) {
    struct dirent *e;
    while ((e = readdir(d))) {
      if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
      char sub[1024];
      snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
      rm_rf(sub);
    }
    closedir(d);
    chmod(path, 0700);
    rmdir(path);
  } else {
    unlink(path);
  }
}

/* Names in directory d containing ".tmp." (leftover temporaries). */
static int temps_in(const char *d) {
  DIR *dd = opendir(d);
  int n = 0;
  struct dirent *e;
  while (dd && (e = readdir(dd)))
    if (strstr(e->d_name, ".tmp.")) n++;
  if (dd) closedir(dd);
  return n;
}

static int entries_in(const char *d) {
  DIR *dd = opendir(d);
  int n = 0;
  struct dirent *e;
  while (dd && (e = readdir(dd)))
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
  if (dd) closedir(dd);
  return n;
}

static unsigned char *slurp(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 1 << 16, n = 0;
  unsigned char *buf = malloc(cap);
  size_t got;
  while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0) {
    n += got;
    if (n == cap) buf = realloc(buf, cap *= 2);
  }
  fclose(f);
  *len = n;
  return buf;
}

static int exists(const char *path) {
  struct stat st;
  return lstat(path, &st) == 0;
}

/* ---- independent sRGB reference (long double) ---------------------------- */

static long double ref_encode(long double x) {
  return x <= 0.0031308L ? 12.92L * x : 1.055L * powl(x, 1.0L / 2.4L) - 0.055L;
}

static long double ref_decode(long double s) {
  return s <= 0.04045L ? s / 12.92L : powl((s + 0.055L) / 1.055L, 2.4L);
}

/* The 8-bit code of linear v; *tie set when 255 * encode(v) is within
 * 1e-9 of a rounding boundary (where float rounding may legitimately go
 * either way). */
static int ref_code(float v, int *tie) {
  *tie = 0;
  if (!(v > 0)) return 0;
  if (v >= 1) return 255;
  long double t = ref_encode(v) * 255.0L;
  *tie = fabsl(t - floorl(t) - 0.5L) < 1e-9L;
  return (int)floorl(t + 0.5L);
}

/* ---- size limits and format names ---------------------------------------- */

static void test_sizes(void) {
  char err[200] = "";
  CHECK("1x1 allowed", img_check_size(1, 1, err, sizeof err) == 0);
  CHECK("8192x8192 allowed", img_check_size(8192, 8192, err, sizeof err) == 0);
  CHECK("65536x1 allowed", img_check_size(65536, 1, err, sizeof err) == 0);
  CHECK("0 wide refused", img_check_size(0, 10, err, sizeof err) == -1 &&
                              strstr(err, "at least 1"));
  CHECK("negative refused", img_check_size(10, -3, err, sizeof err) == -1);
  CHECK("too many pixels", img_check_size(8193, 8192, err, sizeof err) == -1 &&
                               strstr(err, "too large"));
  CHECK("too wide", img_check_size(65537, 1, err, sizeof err) == -1);
  CHECK("huge sides, no overflow",
        img_check_size(0x7fffffffL, 0x7fffffffL, err, sizeof err) == -1);
  CHECK("img_new refuses 0x5", img_new(0, 5, 0) == NULL);
  Image *im = img_new(3, 2, IMG_Z | IMG_N | IMG_COST);
  CHECK("img_new planes", im && im->rgba && im->z && im->n && im->cost &&
                              im->width == 3 && im->height == 2);
  CHECK("img_new Z is +inf, rest 0",
        im && isinf(im->z[5]) && im->z[5] > 0 && im->n[17] == 0 &&
            im->cost[5] == 0 && im->rgba[23] == 0);
  img_free(im);
  im = img_new(2, 2, 0);
  CHECK("img_new without planes", im && !im->z && !im->n && !im->cost);
  img_free(im);
  img_free(NULL);

  CHECK("format .exr", img_format("a/b.exr", err, sizeof err) == IMG_FMT_EXR);
  CHECK("format .PNG", img_format("B.PNG", err, sizeof err) == IMG_FMT_PNG);
  CHECK("format .Ppm", img_format("x.y.Ppm", err, sizeof err) == IMG_FMT_PPM);
  CHECK("format .jpg refused",
        img_format("out.jpg", err, sizeof err) == -1 &&
            !strcmp(err, "unknown image format '.jpg' (use .exr, .png or .ppm)"));
  CHECK("no extension refused",
        img_format("dir.png/out", err, sizeof err) == -1 &&
            strstr(err, "use .exr, .png or .ppm"));
  CHECK("dot file is no extension", img_format(".png", err, sizeof err) == -1);
}

/* ---- EXR ------------------------------------------------------------------ */

/* 37 x 21: two full ZIP chunks of 16 lines and a short one. */
static Image *test_pattern(int w, int h) {
  Image *im = img_new(w, h, IMG_Z | IMG_N | IMG_COST);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      size_t i = img_index(im, x, y);
      float *p = im->rgba + 4 * i;
      p[0] = 0.001f + (float)x / 7.0f;              /* up to ~5.1 */
      p[1] = 1.0f / (1.0f + (float)(x * y));       /* (0, 1] */
      p[2] = (float)(y + 1) * 3.3333f;             /* up to 70 */
      p[3] = (x + y) % 3 ? 1.0f : 0.5f;
      im->z[i] = (x + 2 * y) % 5 == 0 ? INFINITY : 0.125f + 1.37f * (float)x;
      double a = 0.3 * x + 0.1 * y;
      im->n[3 * i + 0] = (float)(cos(a) * 0.6);
      im->n[3 * i + 1] = (float)(sin(a) * 0.6);
      im->n[3 * i + 2] = 0.8f;
      im->cost[i] = (float)(x * 31 + y * 7);
    }
  return im;
}

/* Header of an EXR file as the OpenEXR library itself reads it. */
static void check_exr_header(const char *path, const char *what,
                             int w, int h, int aovs, exr_pixel_type_t col,
                             exr_compression_t comp) {
  char name[160];
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  exr_context_t ctxt = NULL;
  int ok = exr_start_read(&ctxt, path, &init) == EXR_ERR_SUCCESS;
  snprintf(name, sizeof name, "%s: OpenEXR opens it", what);
  CHECK(name, ok);
  if (!ok) return;
  int parts = 0;
  exr_storage_t st;
  exr_attr_box2i_t dw;
  exr_compression_t c;
  exr_get_count(ctxt, &parts);
  exr_get_storage(ctxt, 0, &st);
  exr_get_data_window(ctxt, 0, &dw);
  exr_get_compression(ctxt, 0, &c);
  snprintf(name, sizeof name, "%s: one scanline part, %dx%d", what, w, h);
  CHECK(name, parts == 1 && st == EXR_STORAGE_SCANLINE && dw.min.x == 0 &&
                  dw.min.y == 0 && dw.max.x == w - 1 && dw.max.y == h - 1);
  snprintf(name, sizeof name, "%s: compression", what);
  CHECK(name, c == comp);
  static const char *const all[] = {"A", "B", "G", "N.X", "N.Y", "N.Z",
                                    "R", "Z", IMG_EXR_COST_CHANNEL};
  static const char *const rgba[] = {"A", "B", "G", "R"};
  const char *const *want = aovs ? all : rgba;
  int nwant = aovs ? 9 : 4;
  const exr_attr_chlist_t *cl = NULL;
  exr_get_channels(ctxt, 0, &cl);
  int names_ok = cl && cl->num_channels == nwant, types_ok = names_ok;
  for (int i = 0; names_ok && i < nwant; i++) {
    names_ok = !strcmp(cl->entries[i].name.str, want[i]);
    int colour = strlen(want[i]) == 1 && strchr("RGBA", want[i][0]);
    types_ok = types_ok && cl->entries[i].pixel_type ==
                               (colour ? col : EXR_PIXEL_FLOAT) &&
               cl->entries[i].x_sampling == 1;
  }
  snprintf(name, sizeof name, "%s: channels %s in sorted order", what,
           aovs ? "A B G N.X N.Y N.Z R Z qcs.steps" : "A B G R");
  CHECK(name, names_ok);
  snprintf(name, sizeof name, "%s: channel types", what);
  CHECK(name, types_ok);
  exr_finish(&ctxt);
}

/* |got - want| within relative 2^-11 (half) or exactly (float). */
static int close_to(float got, float want, int half) {
  if (isinf(want)) return got == want;
  if (!half) return got == want;
  return fabs((double)got - want) <= ldexp(fabs(want), -11);
}

static void test_exr(void) {
  char path[256], err[300], name[160];
  Image *im = test_pattern(37, 21);
  for (int mode = 0; mode < 4; mode++) {
    ImgWriteOptions opt = {.float_pixels = mode & 1,
                           .no_compression = (mode & 2) != 0};
    const char *what = (const char *[]){"EXR half zip", "EXR float zip",
                                        "EXR half raw", "EXR float raw"}[mode];
    in_dir(mode & 2 ? "all.EXR" : "all.exr", path, sizeof path);
    int rc = img_write(im, path, &opt, err, sizeof err);
    snprintf(name, sizeof name, "%s: written", what);
    CHECK(name, rc == 0);
    if (rc != 0) { printf("  %s\n", err); continue; }
    check_exr_header(path, what, 37, 21, 1,
                     opt.float_pixels ? EXR_PIXEL_FLOAT : EXR_PIXEL_HALF,
                     opt.no_compression ? EXR_COMPRESSION_NONE
                                        : EXR_COMPRESSION_ZIP);
    Image *back = img_read_exr(path, err, sizeof err);
    snprintf(name, sizeof name, "%s: read back with every plane", what);
    CHECK(name, back && back->width == 37 && back->height == 21 &&
                    back->flags == (IMG_Z | IMG_N | IMG_COST));
    if (!back) { printf("  %s\n", err); continue; }
    size_t np = 37 * 21;
    int rgba_ok = 1, z_ok = 1, n_ok = 1, cost_ok = 1;
    for (size_t i = 0; i < 4 * np; i++)
      rgba_ok &= close_to(back->rgba[i], im->rgba[i], !opt.float_pixels);
    for (size_t i = 0; i < np; i++) {
      z_ok &= back->z[i] == im->z[i];
      cost_ok &= back->cost[i] == im->cost[i];
    }
    for (size_t i = 0; i < 3 * np; i++) n_ok &= back->n[i] == im->n[i];
    snprintf(name, sizeof name, "%s: RGBA values (%s)", what,
             opt.float_pixels ? "exact" : "relative 2^-11");
    CHECK(name, rgba_ok);
    snprintf(name, sizeof name, "%s: Z exact, +inf kept", what);
    CHECK(name, z_ok && isinf(back->z[0]));
    snprintf(name, sizeof name, "%s: N exact", what);
    CHECK(name, n_ok);
    snprintf(name, sizeof name, "%s: cost exact", what);
    CHECK(name, cost_ok);
    img_free(back);
  }
  img_free(im);

  /* no AOV planes: only the colour channels */
  im = img_new(5, 40, 0);
  for (size_t i = 0; i < 4 * 200; i++) im->rgba[i] = (float)(i % 17) * 0.25f;
  in_dir("plain.exr", path, sizeof path);
  CHECK("EXR RGBA only: written", img_write(im, path, NULL, err, sizeof err) == 0);
  check_exr_header(path, "EXR RGBA only", 5, 40, 0, EXR_PIXEL_HALF,
                   EXR_COMPRESSION_ZIP);
  Image *back = img_read_exr(path, err, sizeof err);
  int same = back && back->flags == 0 && !back->z && !back->n;
  for (size_t i = 0; same && i < 800; i++) same = back->rgba[i] == im->rgba[i];
  CHECK("EXR RGBA only: values (exact: quarters are halves)", same);
  img_free(back);
  img_free(im);

  CHECK("EXR read of a missing file",
        !img_read_exr(in_dir("none.exr", path, sizeof path), err, sizeof err) &&
            strstr(err, "cannot read") && strstr(err, "No such file"));
  FILE *f = fopen(in_dir("junk.exr", path, sizeof path), "wb");
  fputs("this is not an OpenEXR file at all, not even close", f);
  fclose(f);
  CHECK("EXR read of a non-EXR file fails cleanly",
        !img_read_exr(path, err, sizeof err) && strstr(err, "cannot read"));
  unlink(path);
}

/* ---- PNG and PPM ------------------------------------------------------------ */

static void png_strict_warning(png_structp png, png_const_charp msg) {
  printf("  libpng warning: %s\n", msg);
  png_error(png, msg);
}

/* A PNG's 8-bit rows as libpng decodes them, read with libpng directly,
 * warnings failing too: w * h * channels bytes; *srgb (unless NULL) says
 * whether it has an sRGB chunk. */
static unsigned char *png_decode_strict(const unsigned char *data, size_t len,
                                        int *w, int *h, int *nc, int *srgb) {
  FILE *f = fmemopen((void *)data, len, "rb");
  if (!f) return NULL;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL,
                                           png_strict_warning);
  png_infop info = png_create_info_struct(png);
  unsigned char *volatile out = NULL;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    free(out);
    return NULL;
  }
  png_init_io(png, f);
  png_read_info(png, info);
  *w = (int)png_get_image_width(png, info);
  *h = (int)png_get_image_height(png, info);
  *nc = png_get_channels(png, info);
  int srgb_intent = -1;
  if (srgb) *srgb = png_get_sRGB(png, info, &srgb_intent) != 0;
  if (png_get_bit_depth(png, info) != 8) png_error(png, "not 8 bits");
  size_t rb = png_get_rowbytes(png, info);
  out = malloc(rb * (size_t)*h);
  for (int y = 0; y < *h; y++) png_read_row(png, out + rb * (size_t)y, NULL);
  png_read_end(png, info);
  png_destroy_read_struct(&png, &info, NULL);
  fclose(f);
  return out;
}

/* The same of a file. */
static unsigned char *png_bytes(const char *path, int *w, int *h, int *nc,
                                int *srgb) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  long len = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
  unsigned char *data = len > 0 ? malloc((size_t)len) : NULL;
  int read = data && fseek(f, 0, SEEK_SET) == 0 &&
             fread(data, 1, (size_t)len, f) == (size_t)len;
  fclose(f);
  unsigned char *out =
      read ? png_decode_strict(data, (size_t)len, w, h, nc, srgb) : NULL;
  free(data);
  return out;
}

/* Linear values that probe the encoder: an even sweep, both sides of every
 * rounding boundary (relative 1e-5 away from it), the linear segment's end,
 * and the out-of-range ones (clamped) and NaN. */
static int probe_values(float *v, int cap) {
  int n = 0;
  for (int i = 0; i < 2048; i++) v[n++] = (float)i / 2047.0f;
  for (int k = 0; k < 255; k++) {
    long double b = ref_decode((k + 0.5L) / 255.0L);
    v[n++] = (float)(b * (1 - 1e-5L));
    v[n++] = (float)(b * (1 + 1e-5L));
  }
  float special[] = {0.0031308f, 0.0031307f, 0.0031309f, -0.5f, -0.0f, 1.5f,
                     1e30f, INFINITY, -INFINITY, NAN, 1e-30f, 0.99999f};
  for (size_t i = 0; i < sizeof special / sizeof *special; i++)
    v[n++] = special[i];
  (void)cap;
  return n;
}

static void test_png(void) {
  char path[256], err[300];
  float v[4096];
  int n = probe_values(v, 4096);
  /* 3 rows: R G B carry the probe values in three different orders */
  Image *im = img_new(n, 3, 0);
  for (int y = 0; y < 3; y++)
    for (int x = 0; x < n; x++) {
      float *p = im->rgba + 4 * img_index(im, x, y);
      p[0] = v[(x + y) % n];
      p[1] = v[(x + 7 * y + 1) % n];
      p[2] = v[(n - 1 - x + y) % n];
      p[3] = 1.0f;
    }
  in_dir("probe.png", path, sizeof path);
  CHECK("PNG written", img_write(im, path, NULL, err, sizeof err) == 0);
  int w = 0, h = 0, nc = 0, srgb = 0;
  unsigned char *b = png_bytes(path, &w, &h, &nc, &srgb);
  CHECK("PNG size and RGB", b && w == n && h == 3 && nc == 3);
  CHECK("PNG has an sRGB chunk", b && srgb);
  int wrong = 0, ties = 0;
  for (int i = 0; b && i < 3 * n; i++)
    for (int c = 0; c < 3; c++) {
      int tie, want = ref_code(im->rgba[4 * i + c], &tie);
      if (tie) ties++;
      else if (b[3 * i + c] != want) {
        if (wrong++ < 5)
          printf("  value %.9g: code %d, reference %d\n",
                 (double)im->rgba[4 * i + c], b[3 * i + c], want);
      }
    }
  CHECK("PNG codes equal the long double sRGB reference, rounded to nearest",
        b && wrong == 0);
  CHECK("no probe value sits on a rounding tie", ties == 0);
  free(b);

  /* read back: linear values from the codes, by the reference decoder */
  Image *back = img_read_png(path, err, sizeof err);
  CHECK("PNG read back", back && back->width == n && back->height == 3);
  int far = 0, tie;
  for (int i = 0; back && i < 3 * n; i++)
    for (int c = 0; c < 3; c++) {
      long double want =
          ref_decode(ref_code(im->rgba[4 * i + c], &tie) / 255.0L);
      if (fabsl(back->rgba[4 * i + c] - want) > 1e-6L * want + 1e-9L) far++;
    }
  CHECK("PNG read decodes sRGB to linear (relative 1e-6)", back && far == 0);
  CHECK("PNG without alpha reads as A = 1", back && back->rgba[3] == 1.0f);
  img_free(back);
  img_free(im);

  int round_trip = 1;
  for (int k = 0; k < 256; k++)
    round_trip &= img_srgb8((float)img_srgb_decode(k / 255.0)) == k;
  CHECK("every code survives decode then encode", round_trip);

  /* alpha: premultiplied colour is divided out, alpha written linearly */
  im = img_new(2, 1, 0);
  float px[8] = {0.25f, 0.1f, 0.0f, 0.5f, 0.8f, 0.2f, 0.05f, 1.0f};
  memcpy(im->rgba, px, sizeof px);
  ImgWriteOptions opt = {.alpha = 1};
  in_dir("alpha.png", path, sizeof path);
  CHECK("PNG RGBA written", img_write(im, path, &opt, err, sizeof err) == 0);
  b = png_bytes(path, &w, &h, &nc, &srgb);
  CHECK("PNG RGBA has 4 channels", b && nc == 4 && w == 2 && h == 1);
  CHECK("PNG RGBA unpremultiplied",
        b && b[0] == ref_code(0.5f, &tie) && b[1] == ref_code(0.2f, &tie) &&
            b[2] == 0 && b[3] == 128 && b[4] == ref_code(0.8f, &tie) &&
            b[7] == 255);
  free(b);
  back = img_read_png(path, err, sizeof err);
  CHECK("PNG RGBA read back premultiplied",
        back && fabs(back->rgba[3] - 128 / 255.0) < 1e-7 &&
            fabsl(back->rgba[0] - ref_decode(ref_code(0.5f, &tie) / 255.0L) *
                                      (128 / 255.0L)) < 1e-6L);
  img_free(back);
  img_free(im);

  CHECK("PNG read of a missing file",
        !img_read_png(in_dir("none.png", path, sizeof path), err, sizeof err) &&
            strstr(err, "No such file"));
  FILE *f = fopen(in_dir("junk.png", path, sizeof path), "wb");
  fputs("GIF89a not a png", f);
  fclose(f);
  CHECK("PNG read of a non-PNG fails cleanly",
        !img_read_png(path, err, sizeof err) && strstr(err, "cannot read"));
  unlink(path);
}

static void test_ppm(void) {
  char path[256], err[300];
  Image *im = img_new(3, 2, 0);
  float vals[6][3] = {{0, 0.5f, 1}, {0.2f, 2.0f, -1}, {0.0031308f, 0.04f, 0.7f},
                      {1, 1, 1},    {0.001f, 0.01f, 0.1f}, {NAN, 0.3f, 0.9f}};
  for (int i = 0; i < 6; i++) {
    memcpy(im->rgba + 4 * i, vals[i], sizeof vals[i]);
    im->rgba[4 * i + 3] = 1;
  }
  in_dir("small.ppm", path, sizeof path);
  CHECK("PPM written", img_write(im, path, NULL, err, sizeof err) == 0);
  size_t len = 0;
  unsigned char *b = slurp(path, &len);
  const char *hdr = "P6\n3 2\n255\n";
  size_t hl = strlen(hdr);
  CHECK("PPM header P6 3 2 255", b && len == hl + 18 && !memcmp(b, hdr, hl));
  int same = b && len == hl + 18, tie;
  for (int i = 0; same && i < 18; i++)
    same = b[hl + i] == ref_code(vals[i / 3][i % 3], &tie);
  CHECK("PPM bytes are the reference sRGB codes, row by row", same);
  free(b);
  img_free(im);
}

/* ---- atomic writes -------------------------------------------------------- */

/* Run img_write in a child process (so a resource limit or a changed user
 * stays there); its return code and message come back through a pipe. */
typedef struct {
  const Image *im;
  const char *path;
  int as_nobody;   /* drop root to uid/gid 65534 first */
  long fsize_max;  /* RLIMIT_FSIZE in the child if > 0 */
} ChildWrite;

static int write_in_child(const ChildWrite *cw, char *err, size_t errlen) {
  int fds[2];
  if (pipe(fds) != 0) return -2;
  fflush(stdout);
  pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    char msg[300] = "";
    int rc;
    if (cw->as_nobody && (setgid(65534) != 0 || setuid(65534) != 0)) {
      rc = -3;
    } else {
      if (cw->fsize_max > 0) {
        signal(SIGXFSZ, SIG_IGN);  /* let write() fail with EFBIG instead */
        struct rlimit rl;
        getrlimit(RLIMIT_FSIZE, &rl);
        rl.rlim_cur = (rlim_t)cw->fsize_max;
        setrlimit(RLIMIT_FSIZE, &rl);
      }
      rc = img_write(cw->im, cw->path, NULL, msg, sizeof msg);
    }
    if (write(fds[1], msg, strlen(msg) + 1) < 0) rc = -4;
    _exit(rc == 0 ? 0 : rc == -1 ? 1 : rc == -3 ? 3 : 4);
  }
  close(fds[1]);
  size_t got = 0;
  ssize_t r;
  while (got + 1 < errlen && (r = read(fds[0], err + got, errlen - 1 - got)) > 0)
    got += (size_t)r;
  err[got] = 0;
  close(fds[0]);
  int st = 0;
  waitpid(pid, &st, 0);
  if (!WIFEXITED(st)) return -2;
  int code = WEXITSTATUS(st);
  return code == 0 ? 0 : code == 1 ? -1 : -code;
}

static void test_atomic(void) {
  char path[320], sub[256], err[400], want[600];
  Image *im = test_pattern(37, 21);

  CHECK("no temporary left by the successful writes",
        temps_in(dir) == 0 && entries_in(dir) == 6);

  /* unknown extension: nothing created */
  int before = entries_in(dir);
  CHECK("unknown extension refused",
        img_write(im, in_dir("out.jpg", path, sizeof path), NULL, err,
                  sizeof err) == -1 &&
            !strcmp(err, "unknown image format '.jpg' (use .exr, .png or .ppm)"));
  CHECK("unknown extension creates nothing", entries_in(dir) == before);

  /* a directory that does not exist */
  in_dir("nowhere/out.png", path, sizeof path);
  snprintf(want, sizeof want, "cannot write %s: No such file or directory",
           path);
  CHECK("missing directory: clear message",
        img_write(im, path, NULL, err, sizeof err) == -1 && !strcmp(err, want));

  /* a read-only directory (as root, permissions bind only another user) */
  in_dir("ro", sub, sizeof sub);
  mkdir(sub, 0755);
  chmod(dir, 0755);
  chmod(sub, 0555);
  snprintf(path, sizeof path, "%s/out.png", sub);
  ChildWrite cw = {im, path, geteuid() == 0, 0};
  int rc = write_in_child(&cw, err, sizeof err);
  if (rc == -3) {
    printf("skip image: read-only directory (cannot drop root)\n");
  } else {
    snprintf(want, sizeof want, "cannot write %s: Permission denied", path);
    CHECK("read-only directory: fails", rc == -1);
    CHECK("read-only directory: 'cannot write PATH: Permission denied'",
          !strcmp(err, want));
    if (strcmp(err, want)) printf("  got: %s\n", err);
    CHECK("read-only directory: left empty", entries_in(sub) == 0);
  }
  chmod(dir, 0700);

  /* a failing write (file size limit) leaves the existing target as it was
   * and no temporary, in every format */
  Image *big = test_pattern(300, 200);
  uint32_t seed = 12111;  /* noise, so that no format compresses it small */
  for (size_t i = 0; i < 4 * 300 * 200; i++) {
    seed = seed * 1664525u + 1013904223u;
    big->rgba[i] = (float)(seed >> 8) * 0x1p-24f;
  }
  static const char *const names[] = {"keep.exr", "keep.png", "keep.ppm"};
  for (int k = 0; k < 3; k++) {
    char name[160];
    in_dir(names[k], path, sizeof path);
    FILE *f = fopen(path, "wb");
    fputs("the previous image", f);
    fclose(f);
    ChildWrite fw = {big, path, 0, 4096};
    rc = write_in_child(&fw, err, sizeof err);
    snprintf(want, sizeof want, "cannot write %s: File too large", path);
    snprintf(name, sizeof name, "%s: write past the size limit fails", names[k]);
    CHECK(name, rc == -1 && !strcmp(err, want));
    if (strcmp(err, want)) printf("  got: %s\n", err);
    size_t len = 0;
    unsigned char *b = slurp(path, &len);
    snprintf(name, sizeof name, "%s: existing target untouched", names[k]);
    CHECK(name, b && len == 18 && !memcmp(b, "the previous image", 18));
    free(b);
    snprintf(name, sizeof name, "%s: temporary removed", names[k]);
    CHECK(name, temps_in(dir) == 0);
    /* and without the limit the same write replaces it */
    fw.fsize_max = 0;
    snprintf(name, sizeof name, "%s: replaced when the write succeeds",
             names[k]);
    CHECK(name, write_in_child(&fw, err, sizeof err) == 0 &&
                    (b = slurp(path, &len)) && len > 18 &&
                    memcmp(b, "the previous image", 18));
    free(b);
  }
  img_free(big);

  /* a directory where the file should go: rename fails, temporary goes */
  in_dir("adir.ppm", path, sizeof path);
  mkdir(path, 0755);
  snprintf(want, sizeof want, "cannot write %s: Is a directory", path);
  CHECK("directory in the way: fails with its reason",
        img_write(im, path, NULL, err, sizeof err) == -1 && !strcmp(err, want));
  CHECK("directory in the way: temporary removed", temps_in(dir) == 0);

  /* a stale temporary with our very name is not clobbered */
  char stale[300];
  snprintf(stale, sizeof stale, "%s/.fresh.ppm.tmp.%ld", dir, (long)getpid());
  FILE *f = fopen(stale, "wb");
  fputs("stale", f);
  fclose(f);
  in_dir("fresh.ppm", path, sizeof path);
  CHECK("stale temporary: write succeeds beside it",
        img_write(im, path, NULL, err, sizeof err) == 0 && exists(path));
  size_t len = 0;
  unsigned char *b = slurp(stale, &len);
  CHECK("stale temporary: left as it was", b && len == 5 && !memcmp(b, "stale", 5));
  free(b);
  unlink(stale);
  CHECK("stale temporary: no other temporary left", temps_in(dir) == 0);

  CHECK("NULL image refused",
        img_write(NULL, in_dir("n.png", path, sizeof path), NULL, err,
                  sizeof err) == -1 && strstr(err, "no image"));
  img_free(im);
}

/* ---- comparison ------------------------------------------------------------ */

static void test_compare(void) {
  Image *a = test_pattern(10, 8), *b = test_pattern(10, 8);
  Image *c = img_new(8, 10, 0);
  double rms = -1, share = -1;
  CHECK("identical images", img_compare(a, b, &rms, &share, 0) == 0 &&
                                rms == 0 && share == 0);
  b->rgba[4 * img_index(b, 3, 4) + 1] += 0.1f;
  b->rgba[4 * img_index(b, 5, 5) + 2] += 0.001f;
  img_compare(a, b, &rms, &share, 0.01);
  double d1 = (double)b->rgba[4 * img_index(b, 3, 4) + 1] -
              a->rgba[4 * img_index(a, 3, 4) + 1];
  double d2 = (double)b->rgba[4 * img_index(b, 5, 5) + 2] -
              a->rgba[4 * img_index(a, 5, 5) + 2];
  CHECK_NEAR("rms over the 240 RGB values", rms,
             sqrt((d1 * d1 + d2 * d2) / 240), 1e-15);
  CHECK_NEAR("share above threshold 0.01: 1 pixel of 80", share, 1.0 / 80, 0);
  img_compare(a, b, &rms, &share, 0.0001);
  CHECK_NEAR("share above threshold 0.0001: 2 of 80", share, 2.0 / 80, 0);
  b->rgba[0] = a->rgba[0] = INFINITY;
  img_compare(a, b, &rms, &share, 0.01);
  CHECK("equal infinities do not differ", isfinite(rms) && share == 1.0 / 80);
  b->rgba[0] = NAN;
  img_compare(a, b, &rms, &share, 0.01);
  CHECK("NaN against a number differs infinitely", isinf(rms) &&
                                                       share == 2.0 / 80);
  rms = 7;
  CHECK("size mismatch refused", img_compare(a, c, &rms, &share, 0) == -1 &&
                                     rms == 7);
  img_free(a);
  img_free(b);
  img_free(c);
}

/* Small ZIP-compressed float images whose zlib output is exactly as long
 * as the raw chunk (OpenEXR issue 2306, in Debian's 3.1.5): they must come
 * back bit for bit (found by fuzz_image). Every 1 x 1 to 3 x 2 image of
 * one non-zero value among zeros, in each of the four RGBA places. */
static void test_exr_zip_no_gain(void) {
  static const float vals[] = {1.0f, 3.8236443e15f, -2.5f, 1e-30f, 65504.0f};
  int bad = 0, total = 0;
  char path[600];
  snprintf(path, sizeof path, "%s/zip-no-gain.exr", dir);
  for (int w = 1; w <= 3; w++)
    for (int h = 1; h <= 2; h++)
      for (size_t v = 0; v < sizeof vals / sizeof *vals; v++)
        for (int place = 0; place < 4; place++) {
          Image *im = img_new(w, h, 0);
          im->rgba[place] = vals[v];
          ImgWriteOptions opt = {.float_pixels = 1};
          char err[300];
          Image *back = NULL;
          if (img_write(im, path, &opt, err, sizeof err) == 0)
            back = img_read_exr(path, err, sizeof err);
          total++;
          if (!back || memcmp(back->rgba, im->rgba,
                              sizeof(float) * 4 * (size_t)(w * h)))
            bad++;
          img_free(back);
          img_free(im);
        }
  unlink(path);
  printf("# zip no-gain: %d of %d images differ after a round trip\n", bad, total);
  CHECK("EXR: small ZIP float images come back bit for bit", bad == 0);
}

/* ---- the PNG writer against libpng's own --------------------------------
 *
 * img_write_png compresses the rows itself (zlib, in pieces on threads)
 * and has libpng write only the chunks before them. The reference here is
 * the writer it replaced: libpng writing every row (its own filters and
 * zlib), the codes from img_srgb8_exact (the formula, not the table). The
 * two files must decode, by libpng with every warning an error, to the
 * same bytes, and carry the same chunks but IDAT, byte for byte; the
 * IDATs joined must be one zlib stream (zlib inflates it to its end, with
 * nothing left over, into exactly the filtered rows); and the bytes must
 * not depend on the number of threads. */

typedef struct {
  unsigned char *p;
  size_t n;
} Buf;

static void ref_png_data(png_structp png, png_bytep d, size_t n) {
  Buf *b = png_get_io_ptr(png);
  b->p = realloc(b->p, b->n + n);
  memcpy(b->p + b->n, d, n);
  b->n += n;
}

/* One tEXt chunk more. */
static void ref_text(png_structp png, png_infop info, char *key, char *text) {
  png_text t = {.compression = PNG_TEXT_COMPRESSION_NONE, .key = key,
                .text = text};
  png_set_text(png, info, &t, 1);
}

/* The replaced writer: libpng from signature to IEND. */
static Buf ref_png_write(const Image *im, int alpha) {
  Buf b = {0};
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL,
                                            NULL, NULL);
  png_infop info = png_create_info_struct(png);
  int nc = alpha ? 4 : 3;
  unsigned char *row = malloc((size_t)im->width * 4);
  png_set_write_fn(png, &b, ref_png_data, NULL);
  int type = alpha ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB;
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_set_IHDR(png, info, (png_uint_32)im->width, (png_uint_32)im->height, 8,
               type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  for (int i = 0; i < im->nattrs; i++)
    ref_text(png, info, im->attr_name[i], im->attr_value[i]);
  int whole = !im->x0 && !im->y0 && im->full_width == im->width &&
              im->full_height == im->height;
  char window[64];
  snprintf(window, sizeof window, "%d %d %d %d", im->x0, im->y0,
           im->full_width, im->full_height);
  if (!whole) ref_text(png, info, "qcs.window", window);
  png_write_info(png, info);
  for (int y = 0; y < im->height; y++) {
    const float *p = im->rgba + 4 * img_index(im, 0, y);
    for (int x = 0; x < im->width; x++, p += 4) {
      float a = p[3], k = 1.0f;
      if (alpha && a > 0.0f && a < 1.0f) k = 1.0f / a;
      for (int c = 0; c < 3; c++)
        row[nc * x + c] = img_srgb8_exact(p[c] * k);
      if (alpha) {
        float ac = a > 0.0f ? (a < 1.0f ? a : 1.0f) : 0.0f;
        row[nc * x + 3] = (unsigned char)(ac * 255.0f + 0.5f);
      }
    }
    png_write_row(png, row);
  }
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  free(row);
  return b;
}

/* The chunks but IDAT, concatenated whole (length, type, data, CRC), and
 * the IDATs' data joined; -1 if the framing is broken or a CRC wrong. */
static int png_split(const Buf *b, Buf *meta, Buf *idat) {
  static const unsigned char sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
  if (b->n < 8 || memcmp(b->p, sig, 8)) return -1;
  size_t i = 8;
  int ended = 0;
  while (i + 12 <= b->n && !ended) {
    const unsigned char *c = b->p + i;
    size_t len = (size_t)c[0] << 24 | (size_t)c[1] << 16 | (size_t)c[2] << 8 |
                 c[3];
    if (i + 12 + len > b->n) return -1;
    uLong crc = crc32(0L, c + 4, (uInt)(4 + len));
    if ((((uLong)c[8 + len] << 24) | ((uLong)c[9 + len] << 16) |
         ((uLong)c[10 + len] << 8) | c[11 + len]) != crc)
      return -1;
    Buf *to = memcmp(c + 4, "IDAT", 4) ? meta : idat;
    const unsigned char *from = to == idat ? c + 8 : c;
    size_t n = to == idat ? len : len + 12;
    to->p = realloc(to->p, to->n + n + 1);
    memcpy(to->p + to->n, from, n);
    to->n += n;
    ended = !memcmp(c + 4, "IEND", 4);
    i += 12 + len;
  }
  return ended && i == b->n ? 0 : -1;
}

/* zlib inflates the joined IDATs to Z_STREAM_END using all of them, into
 * exactly `want` bytes. */
static int zlib_stream_ok(const Buf *idat, size_t want) {
  z_stream z = {0};
  if (inflateInit(&z) != Z_OK) return 0;
  unsigned char *out = malloc(want + 16);
  z.next_in = idat->p;
  z.avail_in = (uInt)idat->n;
  z.next_out = out;
  z.avail_out = (uInt)(want + 16);
  int rc = inflate(&z, Z_FINISH);
  int ok = rc == Z_STREAM_END && z.avail_in == 0 && z.total_out == want;
  inflateEnd(&z);
  free(out);
  return ok;
}

static Buf png_in_memory(const Image *im, int alpha, int threads) {
  Buf b = {0};
  FILE *f = open_memstream((char **)&b.p, &b.n);
  ImgWriteOptions opt = {.alpha = alpha, .threads = threads};
  char err[200];
  int rc = img_write_png(im, f, &opt, "mem.png", err, sizeof err);
  fclose(f);
  if (rc) {
    free(b.p);
    b.p = NULL;
    b.n = 0;
  }
  return b;
}

static uint64_t rng_state = 0x9e3779b97f4a7c15u;
static double rng01(void) { /* xorshift64* */
  rng_state ^= rng_state >> 12;
  rng_state ^= rng_state << 25;
  rng_state ^= rng_state >> 27;
  return (double)((rng_state * 2685821657736338717u) >> 11) * 0x1p-53;
}

/* A picture to compress: smooth shading (long matches), noise (none),
   flat runs, out-of-range values and NaN, and alpha 0, 1 and between. */
static Image *writer_picture(int w, int h) {
  Image *im = img_new(w, h, 0);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      float *p = im->rgba + 4 * img_index(im, x, y);
      int kind = (x / 37 + y / 23) % 4;
      double r = rng01();
      for (int c = 0; c < 3; c++)
        p[c] = kind == 0   ? (float)((x + 3 * y + 50 * c) % 400) / 399.0f
               : kind == 1 ? (float)(rng01() * 1.3 - 0.15)
               : kind == 2 ? 0.2f * (float)c
                           : (float)(0.5 + 0.5 * sin(0.01 * x * (c + 1) + y));
      if (r < 0.002) p[(x + y) % 3] = NAN;
      else if (r < 0.004) p[(x + y) % 3] = INFINITY;
      p[3] = kind == 1 ? (float)rng01() : kind == 2 ? 0.0f : 1.0f;
      if (p[3] < 1.0f)
        for (int c = 0; c < 3; c++) p[c] *= p[3];
    }
  return im;
}

/* Fills the stack below the caller with 16-bit tens, then returns. A
 * compressor that reads a field its init left unset (ISA-L igzip 2.30's
 * hist_bits, which qcs used until 2026-11-29: a window of 2^10 instead of
 * 32 KB, so other matches and other bytes) sees the tens where its frame
 * lands next. */
static __attribute__((noinline)) void dirty_stack(void) {
  uint16_t junk[256 * 1024];
  for (size_t i = 0; i < sizeof junk / sizeof *junk; i++) junk[i] = 10;
  __asm__ volatile("" : : "r"(junk) : "memory");
}

/* The PNG's bytes depend on the picture alone: the same after the stack
 * was filled with junk (with igzip they differed: on 1 test run in about
 * 100 a helper thread's stack gave another window). */
static void test_png_stack_independent(void) {
  Image *im = writer_picture(1021, 129);
  Buf clean = png_in_memory(im, 1, 1);
  dirty_stack();
  Buf dirty = png_in_memory(im, 1, 1);
  CHECK("PNG bytes the same after the stack was filled with junk",
        clean.p && dirty.p && clean.n == dirty.n &&
            !memcmp(clean.p, dirty.p, clean.n));
  free(clean.p);
  free(dirty.p);
  img_free(im);
}

static void test_png_writer(void) {
  static const int sizes[][2] = {{1, 1},    {2, 1},    {1, 2},   {3, 7},
                                 {31, 17},  {257, 300}, {600, 380},
                                 {4000, 1}, {4000, 40}, {1, 3000},
                                 {1021, 129}};
  int n = (int)(sizeof sizes / sizeof *sizes), decoded = 0, meta = 0,
      stream = 0, threads_same = 0, cases = 0;
  for (int s = 0; s < n; s++)
    for (int alpha = 0; alpha < 2; alpha++) {
      int w = sizes[s][0], h = sizes[s][1];
      Image *im = writer_picture(w, h);
      img_set_attr(im, "qcs.render", "1");
      img_set_attr(im, "qcs.size", "a b  c");
      if (s % 3 == 1) {  /* a part of a larger picture: qcs.window */
        im->x0 = 5;
        im->full_width = w + 9;
        im->full_height = h + 2;
      }
      cases++;
      Buf ours = png_in_memory(im, alpha, 1), ref = ref_png_write(im, alpha);
      int wa = 0, ha = 0, na = 0, wb = 0, hb = 0, nb = 0;
      unsigned char *a = ours.p ? png_decode_strict(ours.p, ours.n, &wa, &ha,
                                                    &na, NULL)
                                : NULL;
      unsigned char *b = png_decode_strict(ref.p, ref.n, &wb, &hb, &nb, NULL);
      size_t bytes = (size_t)w * (size_t)h * (alpha ? 4 : 3);
      if (a && b && wa == w && ha == h && wb == w && hb == h && na == nb &&
          na == (alpha ? 4 : 3) && !memcmp(a, b, bytes))
        decoded++;
      else
        printf("  %dx%d alpha %d: decoded pixels differ\n", w, h, alpha);
      Buf ma = {0}, ia = {0}, mb = {0}, ib = {0};
      if (ours.p && png_split(&ours, &ma, &ia) == 0 &&
          png_split(&ref, &mb, &ib) == 0 && ma.n == mb.n &&
          !memcmp(ma.p, mb.p, ma.n))
        meta++;
      else
        printf("  %dx%d alpha %d: chunks other than IDAT differ\n", w, h,
               alpha);
      if (ia.p && zlib_stream_ok(&ia, (size_t)h * (1 + (size_t)w *
                                                       (alpha ? 4 : 3))))
        stream++;
      else
        printf("  %dx%d alpha %d: IDAT is not one zlib stream of the rows\n",
               w, h, alpha);
      int same = 1;
      static const int tc[] = {2, 3, 7, 64, 0};
      for (int t = 0; t < 5; t++) {
        Buf other = png_in_memory(im, alpha, tc[t]);
        same &= other.n == ours.n && ours.p && !memcmp(other.p, ours.p, ours.n);
        free(other.p);
      }
      if (same) threads_same++;
      else printf("  %dx%d alpha %d: bytes depend on threads\n", w, h, alpha);
      free(a);
      free(b);
      free(ours.p);
      free(ref.p);
      free(ma.p);
      free(ia.p);
      free(mb.p);
      free(ib.p);
      img_free(im);
    }
  printf("# PNG writer: %d pictures, 1x1 to 4000 wide, RGB and RGBA\n", cases);
  CHECK("PNG decodes (libpng, warnings as errors) to the pixels libpng's "
        "own writer wrote", decoded == cases);
  CHECK("PNG chunks but IDAT byte for byte as libpng wrote them", meta == cases);
  CHECK("PNG IDATs are one zlib stream of exactly the filtered rows",
        stream == cases);
  CHECK("PNG bytes the same on 1, 2, 3, 7, 64 and all cores' threads",
        threads_same == cases);
}

/* img_srgb8 (a table of where each code starts) against img_srgb8_exact
   (the formula, a pow per call): every 61st float of (0, 1), the 8 floats
   each side of every code's start, and the edges. (Every float of (0, 1),
   1.07e9 of them, was checked once when the table came in, and again
   when the bucket look-up replaced the bisection: all equal.) */
static void test_srgb8_table(void) {
  unsigned long bad = 0, n = 0;
  for (uint32_t b = 1; b < 0x3f800000u; b += 61, n++) {
    float f;
    memcpy(&f, &b, sizeof f);
    if (img_srgb8(f) != img_srgb8_exact(f)) bad++;
  }
  int edges_ok = 1;
  for (uint32_t b = 1; b < 0x3f800000u;) { /* walk code starts by bisection */
    float f;
    memcpy(&f, &b, sizeof f);
    unsigned c = img_srgb8_exact(f);
    if (c == 255) break;
    uint32_t lo = b, hi = 0x3f800000u; /* code(lo) <= c < code(hi) */
    while (hi - lo > 1) {
      uint32_t mid = lo + (hi - lo) / 2;
      float g;
      memcpy(&g, &mid, sizeof g);
      if (img_srgb8_exact(g) > c) hi = mid;
      else lo = mid;
    }
    for (uint32_t k = hi - 8; k <= hi + 8; k++) {
      float g;
      memcpy(&g, &k, sizeof g);
      if (img_srgb8(g) != img_srgb8_exact(g)) edges_ok = 0;
      n++;
    }
    b = hi;
  }
  CHECK("srgb8 table = formula on sampled floats", bad == 0);
  CHECK("srgb8 table = formula at every code's start", edges_ok);
  float nan = NAN;
  CHECK("srgb8 edges", img_srgb8(0.0f) == 0 && img_srgb8(-1.0f) == 0 &&
                           img_srgb8(nan) == 0 && img_srgb8(1.0f) == 255 &&
                           img_srgb8(2.0f) == 255 &&
                           img_srgb8(INFINITY) == 255 &&
                           img_srgb8(0x1p-149f) == 0 &&
                           img_srgb8(0.99999994f) == 255);
  (void)n;
}

int main(void) {
  check_prefix = "image";
  test_srgb8_table();
  test_png_writer();
  test_png_stack_independent();
  snprintf(dir, sizeof dir, "/tmp/qcs-image-XXXXXX");
  if (!mkdtemp(dir)) {
    printf("FAIL image: mkdtemp: %s\n", strerror(errno));
    return 1;
  }
  test_sizes();
  test_exr();
  test_exr_zip_no_gain();
  test_png();
  test_ppm();
  test_atomic();
  test_compare();
  rm_rf(dir);
  CHECK("test directory removed", !exists(dir));
  CHECK_DONE();
}
