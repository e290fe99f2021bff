/* image.h: the renderer's picture and its way to disk. An Image holds
 * linear floating-point RGBA (premultiplied by alpha, as OpenEXR expects)
 * and optional AOV planes (distance Z, normal N, root-finder cost); the
 * writers turn it into OpenEXR (OpenEXR C library), PNG (libpng's chunks,
 * the pixels compressed by zlib in pieces on threads) or PPM, chosen by the
 * file name's extension, and the readers bring EXR and PNG back for tests
 * and reference-image comparison.
 *
 * Every write goes to a temporary file in the target's directory (created
 * with O_EXCL), is flushed and fsync'ed, and is renamed over the target
 * only when complete; on any failure the temporary is removed, so a failed
 * or interrupted write never leaves a truncated image (a process killed
 * outright may leave a hidden ".NAME.tmp.PID" file, never a bad NAME).
 *
 * Memory: img_new and the readers malloc an Image (never GC memory); the
 * caller owns it and releases it with img_free. Writers and img_compare
 * only read the Image. Errors go to a caller-provided buffer; there is no
 * global state, so different threads may write different images at once. */
#ifndef QCS_IMAGE_H
#define QCS_IMAGE_H

#include <stddef.h>
#include <stdio.h>

/* Optional planes (flags of img_new). */
enum {
  IMG_Z    = 1,  /* distance along the primary ray, +inf where nothing hit */
  IMG_N    = 2,  /* surface normal, 3 floats, 0 where nothing hit */
  IMG_COST = 4   /* root-finder steps per pixel, a float count */
};

/* Size limits of img_check_size: each side at most IMG_MAX_SIDE, and at
 * most IMG_MAX_PIXELS pixels in all (8192 x 8192; with every plane that is
 * 36 bytes a pixel, about 2.4 GB). */
#define IMG_MAX_SIDE   65536L
#define IMG_MAX_PIXELS (8192L * 8192L)

/* The EXR name of the IMG_COST plane (sorted after the upper-case names). */
#define IMG_EXR_COST_CHANNEL "qcs.steps"

/* Metadata carried to the file: string attributes (EXR string attributes,
 * PNG tEXt chunks), in order, and the camera matrices (EXR's standard
 * worldToCamera and worldToNDC, m44f, row vectors: p' = p M). */
#define IMG_MAX_ATTRS 24

/* Pixel (x, y) is at index y * width + x; row 0 is the top of the picture.
 * rgba holds 4 floats a pixel, n 3, z and cost 1; absent planes are NULL.
 *
 * A part of a larger picture (a crop, a tile): the image's pixels are the
 * full picture's [x0, x0 + width) x [y0, y0 + height) of a full_width x
 * full_height picture (EXR: the data window inside the display window;
 * PNG: a "qcs.window" tEXt chunk). A whole picture has x0 = y0 = 0 and
 * full_* = width, height (img_new's defaults). */
typedef struct {
  int width, height;
  int flags;         /* IMG_Z | IMG_N | IMG_COST: the planes present */
  float *rgba;
  float *z;
  float *n;
  float *cost;
  int x0, y0, full_width, full_height;
  int nattrs;
  char *attr_name[IMG_MAX_ATTRS], *attr_value[IMG_MAX_ATTRS]; /* malloc'd */
  int has_camera;
  float world_to_camera[16], world_to_ndc[16];
  int float_pixels;  /* set by img_read_exr: RGBA was stored as float */
} Image;

/* Set (add or replace) a string attribute; -1 if full or out of memory. */
int img_set_attr(Image *im, const char *name, const char *value);
/* The value of an attribute, or NULL. */
const char *img_get_attr(const Image *im, const char *name);
/* Copy b's metadata (attributes, camera) to a, replacing a's. 0 or -1. */
int img_copy_meta(Image *a, const Image *b);

/* Options of img_write; a NULL pointer means all zero (the defaults). */
typedef struct {
  int float_pixels;    /* EXR: RGBA as 32-bit float (default half) */
  int no_compression;  /* EXR: no compression (default ZIP) */
  int alpha;           /* PNG: write RGBA (default RGB) */
  int threads;         /* PNG: threads that compress (0: all cores); the
                          file is the same on any number */
} ImgWriteOptions;

enum { IMG_FMT_EXR = 1, IMG_FMT_PNG, IMG_FMT_PPM };

/* 0 if a w x h image is allowed (1 <= w, h <= IMG_MAX_SIDE and
 * w * h <= IMG_MAX_PIXELS), else -1 with a message in err. */
int img_check_size(long w, long h, char *err, size_t errlen);

/* A new image, RGBA all 0, Z +inf, N and COST 0; NULL if the size fails
 * img_check_size or memory runs out. */
Image *img_new(int w, int h, int flags);
void img_free(Image *im);

static inline size_t img_index(const Image *im, int x, int y) {
  return (size_t)y * (size_t)im->width + (size_t)x;
}

/* The format named by path's extension (.exr, .png, .ppm, any case), or -1
 * with a message naming the three. Lets a caller reject a bad output name
 * before a long render. */
int img_format(const char *path, char *err, size_t errlen);

/* Write len bytes (an SVG, a report) to path atomically, as img_write
   writes an image: whole or not at all. 0, or -1 with err set. */
int img_write_bytes(const char *path, const void *data, size_t len,
                    char *err, size_t errlen);

/* Write im to path in the format of its extension, atomically (see above).
 * 0, or -1 with a message like "cannot write out.png: Permission denied". */
int img_write(const Image *im, const char *path, const ImgWriteOptions *opt,
              char *err, size_t errlen);

/* Read an OpenEXR file (single-part scanline, first part): R G B A into
 * rgba (A = 1 where the file has none), and the planes Z, N.X N.Y N.Z and
 * IMG_EXR_COST_CHANNEL when present (flags says which). NULL with a message
 * on failure. */
Image *img_read_exr(const char *path, char *err, size_t errlen);

/* Read a PNG: code values decoded with the sRGB curve into linear RGBA
 * (premultiplied; A = 1 without an alpha channel). NULL with a message. */
Image *img_read_png(const char *path, char *err, size_t errlen);

/* Compare the RGB of two images of the same size: *rms is the root mean
 * square difference over all RGB values, *share_differing the fraction of
 * pixels where some channel differs by more than threshold. Values equal
 * as floats (including equal infinities, or NaN against NaN) count as no
 * difference; any other non-finite difference makes *rms infinite.
 * -1 (outputs untouched) if the sizes differ, else 0. */
int img_compare(const Image *a, const Image *b, double *rms,
                double *share_differing, double threshold);

/* sRGB transfer (IEC 61966-2-1, the exact piecewise curve): linear value
 * to an 8-bit code, clamped to [0, 1] (NaN to 0) and rounded to nearest;
 * and a code value in [0, 1] back to linear. */
unsigned char img_srgb8(float v);
/* A row of n pixels of RGBA to 8-bit sRGB codes: RGB (3 bytes a pixel), or
 * with alpha RGBA (4 bytes), the colour divided by alpha (PNG's is not
 * premultiplied) and alpha clamped to [0, 1] (NaN to 0) and rounded. */
void img_srgb8_row(const float *rgba, int n, int alpha, unsigned char *out);
/* The same by its formula (a pow per call), for the test of img_srgb8. */
unsigned char img_srgb8_exact(float v);
double img_srgb_decode(double s);

/* The parts of one picture (crops or farm tiles, .exr or .png, each
 * knowing where it lies: image.h's window) assembled into the whole: the
 * parts must be of the same render (same full size, channels, pixel type,
 * attributes and camera), may not overlap, and must cover the picture.
 * NULL with a message naming the file at fault otherwise. The result has
 * the parts' metadata; written with img_write (float_pixels as the
 * parts', PNG alpha when its "qcs.alpha" is "on") it is the single
 * render's file. */
Image *img_merge(const char *const *paths, int n, char *err, size_t errlen);

/* The per-format writers under img_write, which owns the temporary file:
 * each writes im to f (a fresh, empty file; the EXR writer uses its file
 * descriptor directly) and reports failures against path, the target. */
int img_write_exr(const Image *im, FILE *f, const ImgWriteOptions *opt,
                  const char *path, char *err, size_t errlen);
int img_write_png(const Image *im, FILE *f, const ImgWriteOptions *opt,
                  const char *path, char *err, size_t errlen);
int img_write_ppm(const Image *im, FILE *f, const char *path, char *err,
                  size_t errlen);

#endif
