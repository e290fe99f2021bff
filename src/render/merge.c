/* merge.c: assemble the parts of one picture (crops, farm tiles) into the
 * whole, as qcs merge does. Every pixel comes from exactly one part, as
 * the part's file stored it, so the result written by img_write is the
 * single render's file bit for bit (render.h: a crop's pixels are the
 * whole picture's). */
#include "render/image.h"

#include <stdlib.h>
#include <string.h>

static Image *read_any(const char *path, char *err, size_t errlen) {
  int fmt = img_format(path, err, errlen);
  if (fmt == IMG_FMT_EXR) return img_read_exr(path, err, errlen);
  if (fmt == IMG_FMT_PNG) return img_read_png(path, err, errlen);
  if (fmt == IMG_FMT_PPM)
    snprintf(err, errlen, "%s: a PPM carries no window; render the parts "
             "as .exr or .png", path);
  return NULL;
}

/* The first way b is not a part of the same render as a, or NULL. */
static const char *differs(const Image *a, const Image *b, char *why,
                           size_t n) {
  if (a->full_width != b->full_width || a->full_height != b->full_height) {
    snprintf(why, n, "a part of a %dx%d picture, not %dx%d", b->full_width,
             b->full_height, a->full_width, a->full_height);
    return why;
  }
  if (a->flags != b->flags) return "other channels (Z, N, cost)";
  if (a->float_pixels != b->float_pixels) return "another pixel type";
  if (a->nattrs != b->nattrs) return "other render attributes";
  for (int i = 0; i < a->nattrs; i++) {
    const char *v = img_get_attr(b, a->attr_name[i]);
    if (!v || strcmp(v, a->attr_value[i])) {
      snprintf(why, n, "another render (its %s differs)", a->attr_name[i]);
      return why;
    }
  }
  if (a->has_camera != b->has_camera ||
      memcmp(a->world_to_camera, b->world_to_camera,
             sizeof a->world_to_camera) ||
      memcmp(a->world_to_ndc, b->world_to_ndc, sizeof a->world_to_ndc))
    return "another camera";
  return NULL;
}

static void copy_rows(Image *dst, const Image *src) {
  for (int y = 0; y < src->height; y++) {
    size_t d = img_index(dst, src->x0, src->y0 + y), s = img_index(src, 0, y);
    size_t w = (size_t)src->width;
    memcpy(dst->rgba + 4 * d, src->rgba + 4 * s, 4 * w * sizeof(float));
    if (dst->z) memcpy(dst->z + d, src->z + s, w * sizeof(float));
    if (dst->n) memcpy(dst->n + 3 * d, src->n + 3 * s, 3 * w * sizeof(float));
    if (dst->cost) memcpy(dst->cost + d, src->cost + s, w * sizeof(float));
  }
}

Image *img_merge(const char *const *paths, int n, char *err, size_t errlen) {
  Image *first = NULL, *out = NULL;
  int *owner = NULL;
  char why[160];
  if (n < 1) {
    snprintf(err, errlen, "no parts to merge");
    return NULL;
  }
  for (int i = 0; i < n; i++) {
    Image *t = read_any(paths[i], err, errlen);
    if (!t) goto fail;
    if (!first) {
      first = t;
      out = img_new(t->full_width, t->full_height, t->flags);
      owner = out ? malloc(sizeof *owner * (size_t)t->full_width *
                           (size_t)t->full_height) : NULL;
      if (!owner || img_copy_meta(out, t)) {
        snprintf(err, errlen, "out of memory for the merged picture");
        goto fail;
      }
      for (size_t k = 0; k < (size_t)t->full_width * (size_t)t->full_height;
           k++)
        owner[k] = -1;
      out->float_pixels = t->float_pixels;
    } else {
      const char *d = differs(first, t, why, sizeof why);
      if (d) {
        snprintf(err, errlen, "%s is not a part of the render %s is a part "
                 "of: %s", paths[i], paths[0], d);
        img_free(t);
        goto fail;
      }
    }
    for (int y = 0; y < t->height; y++)
      for (int x = 0; x < t->width; x++) {
        size_t k = img_index(out, t->x0 + x, t->y0 + y);
        if (owner[k] >= 0) {
          snprintf(err, errlen, "%s and %s overlap (pixel %d,%d)",
                   paths[owner[k]], paths[i], t->x0 + x, t->y0 + y);
          if (t != first) img_free(t);
          goto fail;
        }
        owner[k] = i;
      }
    copy_rows(out, t);
    if (t != first) img_free(t);
  }
  size_t missing = 0, at = 0;
  for (size_t k = (size_t)out->width * (size_t)out->height; k-- > 0;)
    if (owner[k] < 0) missing++, at = k;
  if (missing) {
    snprintf(err, errlen, "a part is missing: %zu pixel%s of the %dx%d "
             "picture in no part, the first at %zu,%zu", missing,
             missing == 1 ? "" : "s", out->width, out->height,
             at % (size_t)out->width, at / (size_t)out->width);
    goto fail;
  }
  free(owner);
  img_free(first);
  return out;
fail:
  free(owner);
  img_free(first);
  img_free(out);
  return NULL;
}
