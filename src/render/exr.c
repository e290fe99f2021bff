/* exr.c: OpenEXR writing and reading through the OpenEXR core C library
 * (3.1, openexr.h): one scanline part, channels in the sorted order the
 * format requires, pixels converted between our floats and the file's half
 * or float by the library's default pack/unpack routines. */
#include "render/image.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <openexr.h>

/* Where the library's messages and our I/O errors land (the context's user
 * data, reached from the error callback through exr_get_user_data). */
typedef struct {
  int fd;
  int io_errno;  /* errno of a failed write, 0 if none */
  char msg[256]; /* the library's first error message */
} ExrIo;

static void on_exr_error(exr_const_context_t ctxt, exr_result_t code,
                         const char *msg) {
  void *ud = NULL;
  if (exr_get_user_data(ctxt, &ud) != EXR_ERR_SUCCESS || !ud) return;
  ExrIo *io = ud;
  if (!io->msg[0]) snprintf(io->msg, sizeof io->msg, "%s", msg);
}

static int64_t write_fd(exr_const_context_t ctxt, void *ud, const void *buf,
                        uint64_t sz, uint64_t offset,
                        exr_stream_error_func_ptr_t error_cb) {
  ExrIo *io = ud;
  const char *p = buf;
  uint64_t done = 0;
  while (done < sz) {
    ssize_t n = pwrite(io->fd, p + done, (size_t)(sz - done),
                       (off_t)(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      io->io_errno = n < 0 ? errno : EIO;
      return -1;
    }
    done += (uint64_t)n;
  }
  return (int64_t)sz;
}

static void exr_fail(const ExrIo *io, exr_result_t rv, const char *verb,
                     const char *path, char *err, size_t errlen) {
  const char *why = io->io_errno ? strerror(io->io_errno)
                  : io->msg[0] ? io->msg : exr_get_default_error_message(rv);
  snprintf(err, errlen, "cannot %s %s: %s", verb, path, why);
}

/* A channel of ours: its EXR name, the plane and the float offset in it. */
typedef struct {
  const char *name;
  const float *base;
  int comps, offset;
  exr_pixel_type_t type;
} Chan;

/* The channels of im in strcmp order, as the format stores them. */
static int channels_of(const Image *im, const ImgWriteOptions *opt,
                       Chan *ch) {
  exr_pixel_type_t col = opt->float_pixels ? EXR_PIXEL_FLOAT : EXR_PIXEL_HALF;
  int n = 0;
  ch[n++] = (Chan){"A", im->rgba, 4, 3, col};
  ch[n++] = (Chan){"B", im->rgba, 4, 2, col};
  ch[n++] = (Chan){"G", im->rgba, 4, 1, col};
  if (im->n) {
    ch[n++] = (Chan){"N.X", im->n, 3, 0, EXR_PIXEL_FLOAT};
    ch[n++] = (Chan){"N.Y", im->n, 3, 1, EXR_PIXEL_FLOAT};
    ch[n++] = (Chan){"N.Z", im->n, 3, 2, EXR_PIXEL_FLOAT};
  }
  ch[n++] = (Chan){"R", im->rgba, 4, 0, col};
  if (im->z) ch[n++] = (Chan){"Z", im->z, 1, 0, EXR_PIXEL_FLOAT};
  if (im->cost)
    ch[n++] = (Chan){IMG_EXR_COST_CHANNEL, im->cost, 1, 0, EXR_PIXEL_FLOAT};
  return n;
}

static const Chan *find_chan(const Chan *ch, int n, const char *name) {
  for (int i = 0; i < n; i++)
    if (strcmp(ch[i].name, name) == 0) return &ch[i];
  return NULL;
}

/* Point the encoder at the rows of the chunk starting at row y. */
static int bind_encode(exr_encode_pipeline_t *enc, const Chan *ch, int nch,
                       const Image *im, int y) {
  for (int i = 0; i < enc->channel_count; i++) {
    exr_coding_channel_info_t *c = &enc->channels[i];
    const Chan *m = find_chan(ch, nch, c->channel_name);
    if (!m) return -1;
    c->user_bytes_per_element = 4;
    c->user_data_type = EXR_PIXEL_FLOAT;
    c->user_pixel_stride = (int32_t)((size_t)m->comps * sizeof(float));
    c->user_line_stride = c->user_pixel_stride * im->width;
    c->encode_from_ptr = (const uint8_t *)(m->base + (size_t)m->comps *
                                           img_index(im, 0, y) + m->offset);
  }
  return 0;
}

/* OpenEXR before 3.4.8 (Debian 12 has 3.1.5) keeps the zlib output of a
 * ZIP chunk when it is exactly as long as the raw data, and its reader
 * then takes those bytes for the raw data (upstream issue 2306): a small
 * chunk of float pixels could come back as garbage (found by fuzz_image:
 * a 1 x 1 float image of (1, 0, 0, 0)). The library's compressor is run
 * through this wrapper, which stores the raw data in that case, as the
 * format says and as fixed libraries do. */
typedef struct {
  exr_result_t (*compress)(exr_encode_pipeline_t *);
} CompressWrap;

static exr_result_t compress_raw_if_no_gain(exr_encode_pipeline_t *enc) {
  const CompressWrap *w = enc->encoding_user_data;
  exr_result_t rv = w->compress(enc);
  if (rv == EXR_ERR_SUCCESS && enc->compressed_bytes == enc->packed_bytes &&
      enc->compressed_buffer && enc->compressed_buffer != enc->packed_buffer)
    memcpy(enc->compressed_buffer, enc->packed_buffer, enc->packed_bytes);
  return rv;
}

static exr_result_t write_chunks(exr_context_t ctxt, const Image *im,
                                 const Chan *ch, int nch) {
  int32_t lines = 0;
  exr_result_t rv = exr_get_scanlines_per_chunk(ctxt, 0, &lines);
  if (rv != EXR_ERR_SUCCESS) return rv;
  exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
  CompressWrap wrap = {NULL};
  int started = 0;
  for (int y = 0; y < im->height && rv == EXR_ERR_SUCCESS; y += lines) {
    exr_chunk_info_t ci;
    rv = exr_write_scanline_chunk_info(ctxt, 0, im->y0 + y, &ci);
    if (rv != EXR_ERR_SUCCESS) break;
    rv = started ? exr_encoding_update(ctxt, 0, &ci, &enc)
                 : exr_encoding_initialize(ctxt, 0, &ci, &enc);
    if (rv != EXR_ERR_SUCCESS) break;
    started = 1;
    if (bind_encode(&enc, ch, nch, im, y) != 0) {
      rv = EXR_ERR_INVALID_ARGUMENT;
      break;
    }
    if (!enc.convert_and_pack_fn) {
      rv = exr_encoding_choose_default_routines(ctxt, 0, &enc);
      if (rv == EXR_ERR_SUCCESS && enc.compress_fn) {
        wrap.compress = enc.compress_fn;
        enc.encoding_user_data = &wrap;
        enc.compress_fn = compress_raw_if_no_gain;
      }
    }
    if (rv == EXR_ERR_SUCCESS) rv = exr_encoding_run(ctxt, 0, &enc);
  }
  if (started) exr_encoding_destroy(ctxt, &enc);
  return rv;
}

int img_write_exr(const Image *im, FILE *f, const ImgWriteOptions *opt,
                  const char *path, char *err, size_t errlen) {
  ExrIo io = {.fd = fileno(f)};
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = on_exr_error;
  init.user_data = &io;
  init.write_fn = write_fd;  /* our temporary file, not the library's */
  exr_context_t ctxt = NULL;
  exr_result_t rv = exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY,
                                    &init);
  if (rv != EXR_ERR_SUCCESS) {
    exr_fail(&io, rv, "write", path, err, errlen);
    return -1;
  }
  Chan ch[10];
  int nch = channels_of(im, opt, ch);
  int part = 0;
  rv = exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &part);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_initialize_required_attr_simple(
        ctxt, part, im->width, im->height,
        opt->no_compression ? EXR_COMPRESSION_NONE : EXR_COMPRESSION_ZIP);
  /* a part of a larger picture: its data window in the display window */
  if (rv == EXR_ERR_SUCCESS) {
    exr_attr_box2i_t disp, data;
    disp.min.x = disp.min.y = 0;
    disp.max.x = im->full_width - 1;
    disp.max.y = im->full_height - 1;
    data.min.x = im->x0;
    data.min.y = im->y0;
    data.max.x = im->x0 + im->width - 1;
    data.max.y = im->y0 + im->height - 1;
    rv = exr_set_display_window(ctxt, part, &disp);
    if (rv == EXR_ERR_SUCCESS) rv = exr_set_data_window(ctxt, part, &data);
  }
  if (rv == EXR_ERR_SUCCESS && im->has_camera) {
    exr_attr_m44f_t m;
    memcpy(m.m, im->world_to_camera, sizeof m.m);
    rv = exr_attr_set_m44f(ctxt, part, "worldToCamera", &m);
    memcpy(m.m, im->world_to_ndc, sizeof m.m);
    if (rv == EXR_ERR_SUCCESS)
      rv = exr_attr_set_m44f(ctxt, part, "worldToNDC", &m);
  }
  for (int i = 0; i < im->nattrs && rv == EXR_ERR_SUCCESS; i++)
    rv = exr_attr_set_string(ctxt, part, im->attr_name[i], im->attr_value[i]);
  for (int i = 0; i < nch && rv == EXR_ERR_SUCCESS; i++) {
    /* colour is perceptually logarithmic; data planes are not colours */
    int is_colour = ch[i].base == im->rgba;
    rv = exr_add_channel(ctxt, part, ch[i].name, ch[i].type,
                         is_colour ? EXR_PERCEPTUALLY_LOGARITHMIC
                                   : EXR_PERCEPTUALLY_LINEAR, 1, 1);
  }
  if (rv == EXR_ERR_SUCCESS) rv = exr_write_header(ctxt);
  if (rv == EXR_ERR_SUCCESS) rv = write_chunks(ctxt, im, ch, nch);
  /* exr_finish writes the chunk offset table; it must succeed too */
  exr_result_t fin = exr_finish(&ctxt);
  if (rv == EXR_ERR_SUCCESS) rv = fin;
  if (rv == EXR_ERR_SUCCESS && io.io_errno) rv = EXR_ERR_WRITE_IO;
  if (rv != EXR_ERR_SUCCESS) {
    exr_fail(&io, rv, "write", path, err, errlen);
    return -1;
  }
  return 0;
}

/* ---- reading -------------------------------------------------------------- */

/* Where the channel called name goes in im, or NULL to skip it. */
static float *read_target(Image *im, const char *name, int *comps) {
  static const char *const rgba = "RGBA";
  if (name[0] && !name[1] && strchr(rgba, name[0])) {
    *comps = 4;
    return im->rgba + (strchr(rgba, name[0]) - rgba);
  }
  if (strcmp(name, "Z") == 0) { *comps = 1; return im->z; }
  if (strcmp(name, IMG_EXR_COST_CHANNEL) == 0) { *comps = 1; return im->cost; }
  if (im->n && strncmp(name, "N.", 2) == 0 && name[2] >= 'X' &&
      name[2] <= 'Z' && !name[3]) {
    *comps = 3;
    return im->n + (name[2] - 'X');
  }
  return NULL;
}

static int has_channel(const exr_attr_chlist_t *cl, const char *name) {
  for (int i = 0; i < cl->num_channels; i++)
    if (strcmp(cl->entries[i].name.str, name) == 0 &&
        cl->entries[i].x_sampling == 1 && cl->entries[i].y_sampling == 1)
      return 1;
  return 0;
}

/* Decoding goes through a planar scratch buffer (one run of floats per
 * channel per chunk), then is scattered into im: the library's fast path
 * for interleaved RGBA in OpenEXR 3.1 puts the channels in reverse order
 * when the destination pointers descend in name order (A B G R to offsets
 * 3 2 1 0), as ours do. */
static void bind_decode(exr_decode_pipeline_t *dec, float *scratch,
                        size_t plane) {
  for (int i = 0; i < dec->channel_count; i++) {
    exr_coding_channel_info_t *c = &dec->channels[i];
    c->user_bytes_per_element = 4;
    c->user_data_type = EXR_PIXEL_FLOAT;
    c->user_pixel_stride = (int32_t)sizeof(float);
    c->user_line_stride = (int32_t)sizeof(float) * c->width;
    c->decode_to_ptr =
        c->x_samples == 1 && c->y_samples == 1
            ? (uint8_t *)(scratch + plane * (size_t)i) : NULL;
  }
}

static void scatter(const exr_decode_pipeline_t *dec, const float *scratch,
                    size_t plane, Image *im, int row) {
  for (int i = 0; i < dec->channel_count; i++) {
    const exr_coding_channel_info_t *c = &dec->channels[i];
    int comps = 1;
    float *base = c->decode_to_ptr ? read_target(im, c->channel_name, &comps)
                                   : NULL;
    if (!base) continue;
    const float *src = scratch + plane * (size_t)i;
    float *dst = base + (size_t)comps * img_index(im, 0, row);
    size_t n = (size_t)c->width * (size_t)c->height;
    for (size_t k = 0; k < n; k++) dst[(size_t)comps * k] = src[k];
  }
}

static exr_result_t read_chunks(exr_context_t ctxt, Image *im,
                                const exr_attr_box2i_t *dw, int nch) {
  int32_t lines = 0;
  exr_result_t rv = exr_get_scanlines_per_chunk(ctxt, 0, &lines);
  if (rv != EXR_ERR_SUCCESS) return rv;
  if (lines < 1 || lines > 4096) return EXR_ERR_CORRUPT_CHUNK;
  size_t plane = (size_t)im->width * (size_t)lines;
  float *scratch = malloc(plane * (size_t)(nch > 0 ? nch : 1) * sizeof *scratch);
  if (!scratch) return EXR_ERR_OUT_OF_MEMORY;
  exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
  int started = 0;
  /* chunks are aligned to multiples of lines counted from the window top */
  for (int y = dw->min.y; y <= dw->max.y && rv == EXR_ERR_SUCCESS;
       y += lines) {
    exr_chunk_info_t ci;
    rv = exr_read_scanline_chunk_info(ctxt, 0, y, &ci);
    if (rv != EXR_ERR_SUCCESS) break;
    rv = started ? exr_decoding_update(ctxt, 0, &ci, &dec)
                 : exr_decoding_initialize(ctxt, 0, &ci, &dec);
    if (rv != EXR_ERR_SUCCESS) break;
    started = 1;
    if (dec.channel_count != nch || ci.width != im->width ||
        ci.height > lines || ci.start_y < dw->min.y ||
        ci.start_y - dw->min.y + ci.height > im->height) {
      rv = EXR_ERR_CORRUPT_CHUNK;
      break;
    }
    bind_decode(&dec, scratch, plane);
    if (!dec.unpack_and_convert_fn)
      rv = exr_decoding_choose_default_routines(ctxt, 0, &dec);
    if (rv == EXR_ERR_SUCCESS) rv = exr_decoding_run(ctxt, 0, &dec);
    if (rv == EXR_ERR_SUCCESS)
      scatter(&dec, scratch, plane, im, ci.start_y - dw->min.y);
  }
  if (started) exr_decoding_destroy(ctxt, &dec);
  free(scratch);
  return rv;
}

/* The windows, qcs's string attributes ("qcs." names), the camera
   matrices and the colour's pixel type, into im. 0, or -1 (memory). */
static int read_meta(exr_const_context_t ctxt, Image *im,
                     const exr_attr_chlist_t *cl) {
  exr_attr_box2i_t dw, disp;
  if (exr_get_data_window(ctxt, 0, &dw) == EXR_ERR_SUCCESS &&
      exr_get_display_window(ctxt, 0, &disp) == EXR_ERR_SUCCESS) {
    im->x0 = dw.min.x - disp.min.x;
    im->y0 = dw.min.y - disp.min.y;
    im->full_width = disp.max.x - disp.min.x + 1;
    im->full_height = disp.max.y - disp.min.y + 1;
  }
  int32_t n = 0;
  if (exr_get_attribute_count(ctxt, 0, &n) != EXR_ERR_SUCCESS) n = 0;
  for (int32_t i = 0; i < n; i++) {
    const exr_attribute_t *a = NULL;
    if (exr_get_attribute_by_index(ctxt, 0, EXR_ATTR_LIST_FILE_ORDER, i,
                                   &a) != EXR_ERR_SUCCESS || !a)
      continue;
    if (a->type == EXR_ATTR_STRING && strncmp(a->name, "qcs.", 4) == 0 &&
        a->string && im->nattrs < IMG_MAX_ATTRS) {
      char *v = strndup(a->string->str, (size_t)a->string->length);
      int bad = !v || img_set_attr(im, a->name, v);
      free(v);
      if (bad) return -1;
    }
  }
  exr_attr_m44f_t c, ndc;
  if (exr_attr_get_m44f(ctxt, 0, "worldToCamera", &c) == EXR_ERR_SUCCESS &&
      exr_attr_get_m44f(ctxt, 0, "worldToNDC", &ndc) == EXR_ERR_SUCCESS) {
    im->has_camera = 1;
    memcpy(im->world_to_camera, c.m, sizeof c.m);
    memcpy(im->world_to_ndc, ndc.m, sizeof ndc.m);
  }
  for (int i = 0; i < cl->num_channels; i++)
    if (strcmp(cl->entries[i].name.str, "R") == 0)
      im->float_pixels = cl->entries[i].pixel_type == EXR_PIXEL_FLOAT;
  return 0;
}

Image *img_read_exr(const char *path, char *err, size_t errlen) {
  /* a missing or unreadable file gets the system's words for it */
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno));
    return NULL;
  }
  close(fd);
  ExrIo io = {.fd = -1};
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = on_exr_error;
  init.user_data = &io;
  exr_context_t ctxt = NULL;
  exr_result_t rv = exr_start_read(&ctxt, path, &init);
  if (rv != EXR_ERR_SUCCESS) {
    exr_fail(&io, rv, "read", path, err, errlen);
    exr_finish(&ctxt);
    return NULL;
  }
  Image *im = NULL;
  exr_storage_t storage;
  exr_attr_box2i_t dw;
  const exr_attr_chlist_t *cl = NULL;
  char why[160];
  rv = exr_get_storage(ctxt, 0, &storage);
  if (rv == EXR_ERR_SUCCESS) rv = exr_get_data_window(ctxt, 0, &dw);
  if (rv == EXR_ERR_SUCCESS) rv = exr_get_channels(ctxt, 0, &cl);
  if (rv != EXR_ERR_SUCCESS) {
    exr_fail(&io, rv, "read", path, err, errlen);
  } else if (storage != EXR_STORAGE_SCANLINE) {
    snprintf(err, errlen, "cannot read %s: only scanline OpenEXR images are "
             "supported", path);
  } else if (img_check_size((long)dw.max.x - dw.min.x + 1,
                            (long)dw.max.y - dw.min.y + 1, why,
                            sizeof why) != 0) {
    snprintf(err, errlen, "cannot read %s: %s", path, why);
  } else {
    int flags = (has_channel(cl, "Z") ? IMG_Z : 0) |
                (has_channel(cl, IMG_EXR_COST_CHANNEL) ? IMG_COST : 0) |
                (has_channel(cl, "N.X") && has_channel(cl, "N.Y") &&
                         has_channel(cl, "N.Z") ? IMG_N : 0);
    im = img_new(dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1, flags);
    if (!im) {
      snprintf(err, errlen, "cannot read %s: out of memory", path);
    } else {
      if (!has_channel(cl, "A")) {
        size_t np = (size_t)im->width * (size_t)im->height;
        for (size_t i = 0; i < np; i++) im->rgba[4 * i + 3] = 1.0f;
      }
      rv = read_chunks(ctxt, im, &dw, cl->num_channels);
      if (rv != EXR_ERR_SUCCESS) {
        exr_fail(&io, rv, "read", path, err, errlen);
        img_free(im);
        im = NULL;
      }
    }
  }
  if (im && read_meta(ctxt, im, cl) != 0) {
    snprintf(err, errlen, "cannot read %s: out of memory", path);
    img_free(im);
    im = NULL;
  }
  exr_finish(&ctxt);
  return im;
}
