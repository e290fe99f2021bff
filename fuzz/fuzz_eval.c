/* fuzz_eval: parse and run arbitrary scripts with the resource limits of
 * fuzz.h, each in a new interpreter (so that every crash reproduces from
 * its input alone). Renders do not write files: a capture hook renders the
 * compiled scene at 12 x 8, one sample, one thread, and throws the image
 * away. Probes and values print to stdout (make fuzz closes it). */
#include "fuzz.h"

#include "render.h"
#include "render_lang.h"

static int tiny_render(void *ctx, const struct Scene *s,
                       const struct RenderSettings *rs, const char *path,
                       char *err, size_t errlen) {
  (void)ctx; (void)path;
  RenderSettings small = *rs;
  small.width = 12;
  small.height = 8;
  small.spp = 1;
  small.threads = 1;
  small.progress = 0;
  RenderReport rep;
  Image *im = render_scene(s, &small, &rep, NULL, err, errlen);
  if (!im) return -1;
  img_free(im);
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static RenderOverrides ov;
  ov.capture = tiny_render;
  Interp *I = interp_new();
  render_set_overrides(I, &ov);
  fuzz_limits(I);
  FUZZ_STACK(I);
  char *text = fuzz_text(data, size);
  interp_run_string(I, "<fuzz>", text, MODE_SCRIPT);
  free(text);
  return 0;
}
