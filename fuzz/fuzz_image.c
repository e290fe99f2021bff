/* fuzz_image: the image writers and readers. The input gives a size (1 to
 * 64 on a side), the planes present, writer options and the pixel values
 * as raw floats (NaN, infinities, denormals, negatives included); the
 * image is written as OpenEXR, PNG and PPM into memory files (memfd), and
 * the EXR and PNG are read back: the size and the planes must survive,
 * and EXR float pixels must come back bit for bit. */
#define _GNU_SOURCE
#include "fuzz.h"

#include <math.h>
#include <stdio.h>
#include <sys/mman.h>
#include <unistd.h>

#include "render/image.h"

typedef int (*Writer)(const Image *, FILE *, const ImgWriteOptions *,
                      const char *, char *, size_t);

static int ppm_writer(const Image *im, FILE *f, const ImgWriteOptions *o,
                      const char *path, char *err, size_t errlen) {
  (void)o;
  return img_write_ppm(im, f, path, err, errlen);
}

/* Write im with w into a memory file; read it back with rd (may be NULL).
   Returns the image read, or NULL. */
static Image *roundtrip(const Image *im, Writer w, const ImgWriteOptions *o,
                        Image *(*rd)(const char *, char *, size_t)) {
  char err[512];
  int fd = memfd_create("qcs-fuzz", 0);
  if (fd < 0) abort();
  FILE *f = fdopen(fd, "w+b");
  if (!f) abort();
  Image *back = NULL;
  if (w(im, f, o, "fuzz", err, sizeof err) != 0 || fflush(f) != 0) {
    fprintf(stderr, "write failed: %s\n", err);
    abort();
  }
  if (rd) {
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    back = rd(path, err, sizeof err);
    if (!back) {
      fprintf(stderr, "read back failed: %s\n", err);
      abort();
    }
  }
  fclose(f);
  return back;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 4) return 0;
  int w = data[0] % 64 + 1, h = data[1] % 64 + 1, flags = data[2] & 7;
  ImgWriteOptions o = {.float_pixels = data[3] & 1,
                       .no_compression = (data[3] >> 1) & 1,
                       .alpha = (data[3] >> 2) & 1,
                       .threads = 1 + ((data[3] >> 3) & 3)};
  data += 4;
  size -= 4;
  Image *im = img_new(w, h, flags);
  if (!im) abort();
  size_t np = (size_t)w * (size_t)h;
  float *planes[4] = {im->rgba, im->z, im->n, im->cost};
  size_t counts[4] = {4 * np, np, 3 * np, np};
  size_t at = 0;
  for (int k = 0; k < 4; k++) {
    if (!planes[k]) continue;
    for (size_t i = 0; i < counts[k]; i++, at += 4)
      if (at + 4 <= size) memcpy(&planes[k][i], data + at, 4);
  }
  Image *e = roundtrip(im, img_write_exr, &o, img_read_exr);
  if (e->width != w || e->height != h || (e->flags & flags) != flags) abort();
  if (o.float_pixels)
    for (size_t i = 0; i < 4 * np; i++)
      if (memcmp(&e->rgba[i], &im->rgba[i], 4) &&
          !(isnan(e->rgba[i]) && isnan(im->rgba[i])))
        abort();
  img_free(e);
  Image *p = roundtrip(im, img_write_png, &o, img_read_png);
  if (p->width != w || p->height != h) abort();
  img_free(p);
  Image *q = roundtrip(im, ppm_writer, &o, NULL);
  (void)q;
  img_free(im);
  return 0;
}
