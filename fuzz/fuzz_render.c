/* fuzz_render: the input is a qcs program; every scene it renders goes
 * through a capture hook that renders it at 16 x 12, one sample, on 3
 * threads (the tile scheduler, per-thread span stacks and the out-of-
 * memory stop under a sanitizer) and throws the image away, so nothing is
 * written. Whatever the program, the run must end in a value or a clean
 * error; a render that fails must say why (err), never crash. The seed
 * corpus (fuzz/corpus/render) holds the examples and deep-CSG programs. */
#include "fuzz.h"

#include <stdio.h>
#include <string.h>

#include "render/render.h"
#include "bind/render_lang.h"

static int render_small(void *ctx, const struct Scene *s,
                        const struct RenderSettings *rs, const char *path,
                        char *err, size_t errlen) {
  (void)ctx; (void)path;
  RenderSettings small = *rs;
  small.width = 16;
  small.height = 12;
  small.spp = 1;
  small.threads = 3;
  small.progress = NULL;
  RenderReport rep;
  err[0] = 0;
  Image *im = render_scene(s, &small, &rep, NULL, err, errlen);
  /* QCS_FUZZ_SHOW=1: say how each render went. */
  if (getenv("QCS_FUZZ_SHOW"))
    fprintf(stderr, "render: %s\n", im ? "ok" : err);
  if (!im) {
    if (!err[0]) abort(); /* a failure must be explained */
    return -1;
  }
  img_free(im);
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static Interp *I;
  static RenderOverrides ov;
  if (!I) {
    I = bind_interp_new();
    ov.capture = render_small;
    render_set_overrides(I, &ov);
    fuzz_limits(I);
  }
  FUZZ_STACK(I);
  char *src = malloc(size + 1);
  if (!src) abort();
  memcpy(src, data, size);
  src[size] = 0;
  RunStatus st = interp_run_string(I, "<fuzz>", src, MODE_SCRIPT);
  if (getenv("QCS_FUZZ_SHOW")) fprintf(stderr, "run: status %d\n", (int)st);
  free(src);
  return 0;
}
