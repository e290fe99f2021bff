/* image.c: the Image, the format switch, atomic writes, PPM, sRGB and
 * image comparison. The EXR and PNG codecs are in exr.c and png.c. */
#include "render/image.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

int img_check_size(long w, long h, char *err, size_t errlen) {
  if (w < 1 || h < 1) {
    snprintf(err, errlen, "image size %ldx%ld: width and height must be at "
             "least 1", w, h);
    return -1;
  }
  if (w > IMG_MAX_SIDE || h > IMG_MAX_SIDE || w > IMG_MAX_PIXELS / h) {
    snprintf(err, errlen, "image size %ldx%ld is too large (at most %ld "
             "pixels a side and %ld pixels in all)", w, h, IMG_MAX_SIDE,
             IMG_MAX_PIXELS);
    return -1;
  }
  return 0;
}

Image *img_new(int w, int h, int flags) {
  char err[160];
  if (img_check_size(w, h, err, sizeof err) != 0) return NULL;
  size_t np = (size_t)w * (size_t)h;
  Image *im = calloc(1, sizeof *im);
  if (!im) return NULL;
  im->width = w;
  im->height = h;
  im->flags = flags & (IMG_Z | IMG_N | IMG_COST);
  im->full_width = w;
  im->full_height = h;
  im->rgba = calloc(np * 4, sizeof(float));
  if (im->flags & IMG_Z) im->z = malloc(np * sizeof(float));
  if (im->flags & IMG_N) im->n = calloc(np * 3, sizeof(float));
  if (im->flags & IMG_COST) im->cost = calloc(np, sizeof(float));
  if (!im->rgba || ((im->flags & IMG_Z) && !im->z) ||
      ((im->flags & IMG_N) && !im->n) ||
      ((im->flags & IMG_COST) && !im->cost)) {
    img_free(im);
    return NULL;
  }
  for (size_t i = 0; im->z && i < np; i++) im->z[i] = INFINITY;
  return im;
}

void img_free(Image *im) {
  if (!im) return;
  free(im->rgba);
  free(im->z);
  free(im->n);
  free(im->cost);
  for (int i = 0; i < im->nattrs; i++) {
    free(im->attr_name[i]);
    free(im->attr_value[i]);
  }
  free(im);
}

int img_set_attr(Image *im, const char *name, const char *value) {
  char *v = strdup(value);
  if (!v) return -1;
  for (int i = 0; i < im->nattrs; i++)
    if (strcmp(im->attr_name[i], name) == 0) {
      free(im->attr_value[i]);
      im->attr_value[i] = v;
      return 0;
    }
  char *n = im->nattrs < IMG_MAX_ATTRS ? strdup(name) : NULL;
  if (!n) {
    free(v);
    return -1;
  }
  im->attr_name[im->nattrs] = n;
  im->attr_value[im->nattrs++] = v;
  return 0;
}

const char *img_get_attr(const Image *im, const char *name) {
  for (int i = 0; i < im->nattrs; i++)
    if (strcmp(im->attr_name[i], name) == 0) return im->attr_value[i];
  return NULL;
}

int img_copy_meta(Image *a, const Image *b) {
  for (int i = 0; i < a->nattrs; i++) {
    free(a->attr_name[i]);
    free(a->attr_value[i]);
  }
  a->nattrs = 0;
  for (int i = 0; i < b->nattrs; i++)
    if (img_set_attr(a, b->attr_name[i], b->attr_value[i])) return -1;
  a->has_camera = b->has_camera;
  memcpy(a->world_to_camera, b->world_to_camera, sizeof a->world_to_camera);
  memcpy(a->world_to_ndc, b->world_to_ndc, sizeof a->world_to_ndc);
  return 0;
}

int img_format(const char *path, char *err, size_t errlen) {
  const char *slash = strrchr(path, '/');
  const char *base = slash ? slash + 1 : path;
  const char *dot = strrchr(base, '.');
  if (dot && dot != base) {
    if (strcasecmp(dot, ".exr") == 0) return IMG_FMT_EXR;
    if (strcasecmp(dot, ".png") == 0) return IMG_FMT_PNG;
    if (strcasecmp(dot, ".ppm") == 0) return IMG_FMT_PPM;
    snprintf(err, errlen, "unknown image format '%s' (use .exr, .png or "
             ".ppm)", dot);
  } else {
    snprintf(err, errlen, "no image format in '%s' (use .exr, .png or "
             ".ppm)", path);
  }
  return -1;
}

/* The hidden temporary beside path: DIR/.BASE.tmp.PID, with a counter
 * appended after a collision (another thread, or a stale file of a dead
 * process that had the same id). Opened O_EXCL so nothing is clobbered. */
static int open_temp(const char *path, char **tmp_out) {
  const char *slash = strrchr(path, '/');
  size_t dirlen = slash ? (size_t)(slash - path) + 1 : 0;
  size_t cap = strlen(path) + 64;
  char *tmp = malloc(cap);
  if (!tmp) { errno = ENOMEM; return -1; }
  for (int k = 0; k < 100; k++) {
    int n = snprintf(tmp, cap, "%.*s.%s.tmp.%ld", (int)dirlen, path,
                     path + dirlen, (long)getpid());
    if (k > 0) snprintf(tmp + n, cap - (size_t)n, ".%d", k);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) { *tmp_out = tmp; return fd; }
    if (errno != EEXIST) break;
  }
  int e = errno;
  free(tmp);
  errno = e;
  return -1;
}

static int check_image(const Image *im, const char *path, char *err,
                       size_t errlen) {
  char why[160];
  if (!im || !im->rgba) {
    snprintf(err, errlen, "cannot write %s: no image", path);
    return -1;
  }
  if (img_check_size(im->width, im->height, why, sizeof why) != 0) {
    snprintf(err, errlen, "cannot write %s: %s", path, why);
    return -1;
  }
  return 0;
}

int img_write(const Image *im, const char *path, const ImgWriteOptions *opt,
              char *err, size_t errlen) {
  static const ImgWriteOptions defaults;
  if (!opt) opt = &defaults;
  int fmt = img_format(path, err, errlen);
  if (fmt < 0 || check_image(im, path, err, errlen) != 0) return -1;
  char *tmp = NULL;
  int fd = open_temp(path, &tmp);
  if (fd < 0) {
    snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
    return -1;
  }
  FILE *f = fdopen(fd, "wb");
  if (!f) {
    snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
    close(fd);
    unlink(tmp);
    free(tmp);
    return -1;
  }
  int rc = fmt == IMG_FMT_EXR ? img_write_exr(im, f, opt, path, err, errlen)
         : fmt == IMG_FMT_PNG ? img_write_png(im, f, opt, path, err, errlen)
         : img_write_ppm(im, f, path, err, errlen);
  /* Complete and on disk before the rename makes it visible; fsync may be
   * refused (EINVAL) by file systems that cannot sync, which is no error. */
  if (rc == 0 && (fflush(f) != 0 ||
                  (fsync(fileno(f)) != 0 && errno != EINVAL))) {
    snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
    rc = -1;
  }
  if (fclose(f) != 0 && rc == 0) {
    snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
    rc = -1;
  }
  if (rc == 0 && rename(tmp, path) != 0) {
    snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
    rc = -1;
  }
  if (rc != 0) unlink(tmp);
  free(tmp);
  return rc;
}

int img_write_bytes(const char *path, const void *data, size_t len,
                    char *err, size_t errlen) {
  char *tmp = NULL;
  int fd = open_temp(path, &tmp);
  if (fd < 0) {
    snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
    return -1;
  }
  int rc = 0;
  const char *p = data;
  while (len > 0) {
    ssize_t w = write(fd, p, len);
    if (w < 0) {
      if (errno == EINTR) continue;
      rc = -1;
      break;
    }
    p += w;
    len -= (size_t)w;
  }
  if (rc == 0 && fsync(fd) != 0 && errno != EINVAL) rc = -1;
  if (rc != 0) snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
  if (close(fd) != 0 && rc == 0) {
    snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
    rc = -1;
  }
  if (rc == 0 && rename(tmp, path) != 0) {
    snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
    rc = -1;
  }
  if (rc != 0) unlink(tmp);
  free(tmp);
  return rc;
}

/* ---- sRGB ---------------------------------------------------------------- */

/* The definition: linear v in [0, 1] to the nearest 8-bit sRGB code. */
static unsigned char srgb8_exact(float v) {
  if (!(v > 0.0f)) return 0;  /* also NaN */
  if (v >= 1.0f) return 255;
  double x = v;
  double s = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
  return (unsigned char)floor(s * 255.0 + 0.5);
}

/* srgb8_exact is nondecreasing in v, so it is fixed by the least float at
   which each code starts: found once for each code from the curve's
   inverse at the code's lower edge, then moved by single floats (a float
   a step: positive floats order as their bits do) to the least float
   whose code it is; a bisection on the bits found the same floats with
   six times as many pow calls (1.2M instructions, a start-up cost of
   every process that writes a picture). An encode is then a look-up
   instead of a pow (the PNG writer spent 8% of figure12's instructions in
   pow): [0, 1] is cut into SRGB8_BUCKETS equal buckets (v * SRGB8_BUCKETS
   is exact, a power of two), each knowing the code at its lower end; the
   encoding is steepest at 0, 255 * 12.92 = 3295 codes per unit, under one
   code per bucket, so a code is its bucket's or the next: one comparison,
   no branch. It replaced a bisection of 8 comparisons per channel, 3% of
   figure12's instructions. The same code as srgb8_exact for every float:
   test_image checks every float in (0, 1). */
#define SRGB8_BUCKETS 4096
static float srgb8_start[257];
static unsigned char srgb8_bucket[SRGB8_BUCKETS + 1];
static pthread_once_t srgb8_once = PTHREAD_ONCE_INIT;
static atomic_int srgb8_ready;

static void srgb8_init(void) {
  for (int c = 1; c < 256; c++) {
    float f = (float)img_srgb_decode((c - 0.5) / 255.0);
    while (f > 0.0f && srgb8_exact(f) >= c) f = nextafterf(f, 0.0f);
    while (srgb8_exact(f) < c) f = nextafterf(f, 1.0f);
    srgb8_start[c] = f;
  }
  srgb8_start[256] = INFINITY; /* never reached */
  for (int b = 0, c = 0; b <= SRGB8_BUCKETS; b++) {
    float lo = (float)b / (float)SRGB8_BUCKETS;
    while (c < 255 && lo >= srgb8_start[c + 1]) c++;
    srgb8_bucket[b] = (unsigned char)c;
  }
  atomic_store_explicit(&srgb8_ready, 1, memory_order_release);
}

/* img_srgb8 once the tables are made. */
static inline unsigned char srgb8_lookup(float v) {
  float x = v > 0.0f ? v : 0.0f; /* NaN to 0 too */
  x = x < 1.0f ? x : 1.0f;       /* 1 is the last bucket's, code 255 */
  unsigned c = srgb8_bucket[(int)(x * (float)SRGB8_BUCKETS)];
  return (unsigned char)(c + (x >= srgb8_start[c + 1]));
}

static void srgb8_ensure(void) {
  if (!atomic_load_explicit(&srgb8_ready, memory_order_acquire))
    pthread_once(&srgb8_once, srgb8_init);
}

unsigned char img_srgb8(float v) {
  srgb8_ensure();
  return srgb8_lookup(v);
}

void img_srgb8_row(const float *rgba, int n, int alpha, unsigned char *out) {
  srgb8_ensure();
  if (!alpha) {
    for (int x = 0; x < n; x++, rgba += 4, out += 3) {
      out[0] = srgb8_lookup(rgba[0]);
      out[1] = srgb8_lookup(rgba[1]);
      out[2] = srgb8_lookup(rgba[2]);
    }
    return;
  }
  /* The colour is premultiplied by alpha and PNG's is not: divide it out. */
  for (int x = 0; x < n; x++, rgba += 4, out += 4) {
    float a = rgba[3], k = 1.0f;
    if (a > 0.0f && a < 1.0f) k = 1.0f / a;
    for (int c = 0; c < 3; c++) out[c] = srgb8_lookup(rgba[c] * k);
    float ac = a > 0.0f ? (a < 1.0f ? a : 1.0f) : 0.0f;  /* NaN to 0 */
    out[3] = (unsigned char)(ac * 255.0f + 0.5f);
  }
}

unsigned char img_srgb8_exact(float v) { return srgb8_exact(v); }

double img_srgb_decode(double s) {
  return s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4);
}

/* ---- PPM ------------------------------------------------------------------ */

/* P6, 8 bits, the sRGB encoding of PNG; alpha is dropped (the colour is
 * premultiplied, so that is the image over black). */
int img_write_ppm(const Image *im, FILE *f, const char *path, char *err,
                  size_t errlen) {
  size_t w = (size_t)im->width;
  unsigned char *row = malloc(3 * w);
  if (!row) {
    snprintf(err, errlen, "cannot write %s: out of memory", path);
    return -1;
  }
  int ok = fprintf(f, "P6\n%d %d\n255\n", im->width, im->height) > 0;
  for (int y = 0; ok && y < im->height; y++) {
    img_srgb8_row(im->rgba + 4 * img_index(im, 0, y), im->width, 0, row);
    ok = fwrite(row, 1, 3 * w, f) == 3 * w;
  }
  free(row);
  if (!ok) {
    snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno));
    return -1;
  }
  return 0;
}

/* ---- comparison ----------------------------------------------------------- */

int img_compare(const Image *a, const Image *b, double *rms,
                double *share_differing, double threshold) {
  if (a->width != b->width || a->height != b->height) return -1;
  size_t np = (size_t)a->width * (size_t)a->height;
  double sum = 0;
  size_t differing = 0;
  for (size_t i = 0; i < np; i++) {
    double worst = 0;
    for (int c = 0; c < 3; c++) {
      float x = a->rgba[4 * i + (size_t)c], y = b->rgba[4 * i + (size_t)c];
      if (x == y || (isnan(x) && isnan(y))) continue;
      double d = fabs((double)x - (double)y);
      if (isnan(d)) d = INFINITY;
      sum += d * d;
      if (d > worst) worst = d;
    }
    if (worst > threshold) differing++;
  }
  *rms = sqrt(sum / (double)(3 * np));
  *share_differing = (double)differing / (double)np;
  return 0;
}
