/* png.c: PNG. Written as 8-bit sRGB (the image clamped to [0, 1] and
 * encoded by img_srgb8_row) with an sRGB chunk: libpng writes the chunks
 * before the pixels, the IDATs are compressed here (below); read back by
 * libpng, decoding the sRGB curve into linear floats. libpng reports errors by longjmp to
 * png_jmpbuf, so everything a handler frees is allocated before setjmp or
 * kept in volatile pointers. */
#include "render/image.h"

#include <errno.h>
#include <png.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

typedef struct {
  FILE *f;
  int io_errno;   /* errno of a failed fwrite, 0 if none */
  char msg[200];  /* libpng's message */
} PngIo;

static void png_on_error(png_structp png, png_const_charp msg) {
  PngIo *io = png_get_error_ptr(png);
  if (io && !io->msg[0]) snprintf(io->msg, sizeof io->msg, "%s", msg);
  png_longjmp(png, 1);
}

static void png_on_warning(png_structp png, png_const_charp msg) {
  (void)png;
  (void)msg;  /* warnings change nothing we write or read */
}

static void png_write_data(png_structp png, png_bytep data, size_t len) {
  PngIo *io = png_get_io_ptr(png);
  if (fwrite(data, 1, len, io->f) != len) {
    io->io_errno = errno ? errno : EIO;
    png_error(png, "write failed");
  }
}

static void png_flush_data(png_structp png) {
  PngIo *io = png_get_io_ptr(png);
  if (fflush(io->f) != 0) {
    io->io_errno = errno;
    png_error(png, "write failed");
  }
}

/* ---- the image data: IDAT ------------------------------------------------
 *
 * The rows are cut into pieces of about PNG_PIECE_BYTES of filtered data,
 * a cut that depends on the image alone. Each piece is filtered and
 * compressed on its own (zlib, level 1) into raw deflate blocks ending on
 * a byte boundary (a full flush), the last
 * piece's block final: one after another they are one deflate stream, as
 * pigz joins its pieces. The Adler-32s of the pieces are joined with
 * zlib's adler32_combine. Threads take the pieces from a counter, and a
 * piece's bytes depend on the piece alone, so the file is the same bytes
 * on any number of threads. Each piece is one IDAT
 * chunk (the first with the zlib header, the last with the Adler-32).
 *
 * Until 2026-11-29 the pieces were compressed by ISA-L's igzip (level 1,
 * about 4 times faster), but igzip 2.30's stateless call gives other
 * (valid) bytes for the same piece depending on where its stream struct
 * lies in memory (one 64 KiB block of addresses in 16 MiB scanned, in 1
 * process in 50 to 150; besides a field its init leaves unset), so a
 * helper thread now and then wrote other bytes than the caller would:
 * files differed with the thread count, and merged parts from the single
 * render. zlib's deflate is a function of its input and settings alone. */

#ifndef PNG_PIECE_BYTES
#define PNG_PIECE_BYTES (128 * 1024)
#endif
#define PNG_MAX_THREADS 64

typedef struct {
  unsigned char *out;  /* the chunk's data */
  size_t len;          /* bytes of out in use, header and trailer included */
  size_t in_len;       /* filtered bytes compressed */
  uint32_t adler;      /* their Adler-32 */
} Piece;

/* The work shared by the calling thread and its helpers. The helpers are
 * detached: the caller never waits for one that the machine's load keeps
 * off a core. It takes pieces from the counter as they do, then does
 * itself every piece still unfinished (a helper's piece: whichever
 * finishes first publishes it, the other drops its copy, and a caller
 * working on a piece stops as soon as it is published). Before it
 * returns it raises `cancel` and takes `reading` for writing: a helper
 * reads the image only holding `reading` for reading, one row at a time,
 * and stops when it sees `cancel`, so none touches the image after. The
 * last thread out (refs) frees this. */
typedef struct {
  const float *rgba;  /* the image's pixels, read under `reading` */
  int width, height, alpha;
  size_t pix_bytes;   /* width * channels */
  int piece_rows, npieces;
  _Atomic(Piece *) *done; /* published pieces; `taken` once the caller
                             has them */
  atomic_int next;    /* the next piece to take */
  atomic_int cancel;  /* the caller has every piece: helpers stop */
  atomic_int refs;    /* the caller and the running helpers */
  pthread_rwlock_t reading;
} Idat;

static Piece taken; /* the mark of a piece the caller has taken over */

typedef struct {
  unsigned char *in, *prev, *cur;
  z_stream *z; /* raw deflate, level 1; reset for each piece */
} Scratch;

/* The Up filter on every row: each byte less the one above it (0 above
 * the first row), 16 bytes at a time (GCC's and Clang's vectors, plain
 * code where the machine has none); igzip compresses rendered pictures
 * filtered so better than after Sub (figure12: 53 KB against 54 KB at
 * 600x380, 225 KB against 244 KB at 1920x1080). */
typedef unsigned char Bytes16 __attribute__((vector_size(16)));

static void filter_up(unsigned char *restrict dst,
                      const unsigned char *restrict cur,
                      const unsigned char *restrict prev, size_t n) {
  dst[0] = 2; /* PNG filter type Up */
  size_t i = 0;
  for (; i + 16 <= n; i += 16) {
    Bytes16 a, b;
    memcpy(&a, cur + i, 16);
    memcpy(&b, prev + i, 16);
    a -= b;
    memcpy(dst + 1 + i, &a, 16);
  }
  for (; i < n; i++) dst[1 + i] = (unsigned char)(cur[i] - prev[i]);
}

/* Row y's codes into out; a helper holds `reading` while it reads the
 * image. 0, or -1 if the piece is no longer wanted (the caller cancelled,
 * or, for the caller, the piece was published meanwhile). */
static int encode_row(Idat *d, int k, int y, int helper, unsigned char *out) {
  if (helper) {
    pthread_rwlock_rdlock(&d->reading);
    if (atomic_load(&d->cancel)) {
      pthread_rwlock_unlock(&d->reading);
      return -1;
    }
  } else if (atomic_load(&d->done[k])) {
    return -1;
  }
  img_srgb8_row(d->rgba + 4 * (size_t)y * (size_t)d->width, d->width,
                d->alpha, out);
  if (helper) pthread_rwlock_unlock(&d->reading);
  return 0;
}

/* Piece k filtered and compressed, and published unless another thread
 * published it first. 0, 1 if not wanted any more, -1 out of memory. */
static int compress_piece(Idat *d, int k, int helper, Scratch *s) {
  int y0 = k * d->piece_rows;
  int y1 = y0 + d->piece_rows < d->height ? y0 + d->piece_rows : d->height;
  size_t rb = d->pix_bytes + 1;
  if (y0 == 0) memset(s->prev, 0, d->pix_bytes);
  else if (encode_row(d, k, y0 - 1, helper, s->prev)) return 1;
  for (int y = y0; y < y1; y++) {
    if (encode_row(d, k, y, helper, s->cur)) return 1;
    filter_up(s->in + rb * (size_t)(y - y0), s->cur, s->prev, d->pix_bytes);
    unsigned char *t = s->prev;
    s->prev = s->cur;
    s->cur = t;
  }
  size_t in_len = rb * (size_t)(y1 - y0);
  int first = k == 0, last = k == d->npieces - 1;
  size_t head = first ? 2 : 0, tail = last ? 4 : 0;
  /* zlib's bound for the input, and a full flush's empty stored block */
  size_t cap = deflateBound(s->z, (uLong)in_len) + 16 + head + tail;
  Piece *p = malloc(sizeof *p);
  unsigned char *out = p ? malloc(cap) : NULL;
  if (!out) {
    free(p);
    return -1;
  }
  z_stream *z = s->z;
  if (deflateReset(z) != Z_OK) {
    free(out);
    free(p);
    return -1;
  }
  z->next_in = s->in;
  z->avail_in = (uInt)in_len;
  z->next_out = out + head;
  z->avail_out = (uInt)(cap - head - tail);
  int rc = deflate(z, last ? Z_FINISH : Z_FULL_FLUSH); /* to a byte boundary */
  if (rc != (last ? Z_STREAM_END : Z_OK) || z->avail_in != 0) {
    free(out);
    free(p);
    return -1;
  }
  *p = (Piece){.out = out, .len = head + (size_t)z->total_out + tail,
               .in_len = in_len,
               .adler = (uint32_t)adler32(1, s->in, (uInt)in_len)};
  Piece *none = NULL;
  if (!atomic_compare_exchange_strong(&d->done[k], &none, p)) {
    free(out); /* another thread's copy came first: the same bytes */
    free(p);
  }
  return 0;
}

static void idat_release(Idat *d) {
  if (atomic_fetch_sub(&d->refs, 1) != 1) return;
  for (int k = 0; k < d->npieces; k++) {
    Piece *p = atomic_load(&d->done[k]);
    if (p && p != &taken) {
      free(p->out);
      free(p);
    }
  }
  pthread_rwlock_destroy(&d->reading);
  free(d->done);
  free(d);
}

static void scratch_free(Scratch *s) {
  free(s->in);
  free(s->prev);
  free(s->cur);
  if (s->z) deflateEnd(s->z);
  free(s->z);
  *s = (Scratch){0};
}

static int scratch_new(Scratch *s, const Idat *d) {
  *s = (Scratch){.in = malloc((d->pix_bytes + 1) * (size_t)d->piece_rows),
                 .prev = malloc(d->pix_bytes),
                 .cur = malloc(d->pix_bytes),
                 .z = calloc(1, sizeof(z_stream))};
  if (s->z && deflateInit2(s->z, 1, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) !=
                  Z_OK) {
    free(s->z);
    s->z = NULL;
  }
  if (s->in && s->prev && s->cur && s->z) return 0;
  scratch_free(s);
  return -1;
}

static void *idat_helper(void *arg) {
  Idat *d = arg;
  Scratch s;
  if (scratch_new(&s, d) == 0)
    for (;;) { /* a helper out of memory leaves its pieces to the caller */
      int k = atomic_fetch_add(&d->next, 1);
      if (k >= d->npieces || atomic_load(&d->cancel) ||
          compress_piece(d, k, 1, &s) != 0)
        break;
    }
  scratch_free(&s);
  idat_release(d);
  return NULL;
}

static void free_pieces(Piece *pc, int n) {
  for (int i = 0; pc && i < n; i++) free(pc[i].out);
  free(pc);
}

/* The pieces of im's IDAT, compressed on up to `threads` threads (0: one
 * a core); NULL if memory runs out. Sets *npieces. */
static Piece *compress_idat(const Image *im, int alpha, int threads,
                            int *npieces) {
  Idat *d = calloc(1, sizeof *d);
  if (!d) return NULL;
  *d = (Idat){.rgba = im->rgba, .width = im->width, .height = im->height,
              .alpha = alpha};
  d->pix_bytes = (size_t)im->width * (alpha ? 4 : 3);
  size_t rows = PNG_PIECE_BYTES / (d->pix_bytes + 1);
  d->piece_rows = rows < 1 ? 1
                  : rows > (size_t)im->height ? im->height
                                              : (int)rows;
  d->npieces = (im->height + d->piece_rows - 1) / d->piece_rows;
  d->done = calloc((size_t)d->npieces, sizeof *d->done);
  Piece *pieces = calloc((size_t)d->npieces, sizeof *pieces);
  Scratch s;
  int ok = d->done && pieces && scratch_new(&s, d) == 0 &&
           pthread_rwlock_init(&d->reading, NULL) == 0;
  if (!ok) {
    if (d->done && pieces) scratch_free(&s);
    free(d->done);
    free(d);
    free(pieces);
    return NULL;
  }
  for (int k = 0; k < d->npieces; k++) atomic_init(&d->done[k], NULL);
  atomic_init(&d->next, 0);
  atomic_init(&d->cancel, 0);
  atomic_init(&d->refs, 1);
  if (threads <= 0) {
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    threads = n < 1 ? 1 : n > PNG_MAX_THREADS ? PNG_MAX_THREADS : (int)n;
  }
  if (threads > PNG_MAX_THREADS) threads = PNG_MAX_THREADS;
  if (threads > d->npieces) threads = d->npieces;
  pthread_attr_t attr;
  if (threads > 1 && pthread_attr_init(&attr) == 0) {
    pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
    for (int i = 1; i < threads; i++) {
      pthread_t t;
      atomic_fetch_add(&d->refs, 1);
      if (pthread_create(&t, &attr, idat_helper, d) != 0) {
        atomic_fetch_sub(&d->refs, 1); /* the caller does its share */
        break;
      }
    }
    pthread_attr_destroy(&attr);
  }
  /* the counter's pieces, then any still unpublished (a helper's) */
  for (int k; ok && (k = atomic_fetch_add(&d->next, 1)) < d->npieces;)
    ok = compress_piece(d, k, 0, &s) >= 0;
  for (int k = 0; ok && k < d->npieces; k++)
    if (!atomic_load(&d->done[k])) ok = compress_piece(d, k, 0, &s) >= 0;
  scratch_free(&s);
  atomic_store(&d->cancel, 1);
  pthread_rwlock_wrlock(&d->reading); /* no helper is reading a row now */
  pthread_rwlock_unlock(&d->reading);
  for (int k = 0; ok && k < d->npieces; k++) {
    Piece *p = atomic_exchange(&d->done[k], &taken);
    pieces[k] = *p;
    free(p);
  }
  int n = d->npieces;
  idat_release(d);
  if (!ok) {
    free_pieces(pieces, 0);
    return NULL;
  }
  *npieces = n;
  return pieces;
}

static void put32(unsigned char *b, uint32_t v) {
  b[0] = (unsigned char)(v >> 24);
  b[1] = (unsigned char)(v >> 16);
  b[2] = (unsigned char)(v >> 8);
  b[3] = (unsigned char)v;
}

/* One chunk: length, type, data, and the CRC-32 of type and data. */
static int write_chunk(FILE *f, const char *type, const unsigned char *data,
                       size_t len) {
  unsigned char head[8], crc[4];
  put32(head, (uint32_t)len);
  memcpy(head + 4, type, 4);
  uLong c = crc32(0L, head + 4, 4);
  if (len) c = crc32(c, data, (uInt)len);
  put32(crc, (uint32_t)c);
  int ok = fwrite(head, 1, 8, f) == 8 &&
           (!len || fwrite(data, 1, len, f) == len) &&
           fwrite(crc, 1, 4, f) == 4;
  return ok ? 0 : -1;
}

/* The zlib header and Adler-32 put around the pieces, and the IDAT
 * chunks and IEND written. */
static int write_idat(FILE *f, Piece *pc, int n) {
  pc[0].out[0] = 0x78; /* deflate, 32 KB window */
  pc[0].out[1] = 0x01; /* fastest; (0x78 << 8 | 0x01) % 31 == 0 */
  uLong adler = pc[0].adler;
  for (int i = 1; i < n; i++)
    adler = adler32_combine(adler, pc[i].adler, (z_off_t)pc[i].in_len);
  put32(pc[n - 1].out + pc[n - 1].len - 4, (uint32_t)adler);
  for (int i = 0; i < n; i++)
    if (write_chunk(f, "IDAT", pc[i].out, pc[i].len) != 0) return -1;
  return write_chunk(f, "IEND", NULL, 0);
}

/* The signature and the chunks before the image data, by libpng as when
 * it wrote the rows too: IHDR, sRGB with gAMA and cHRM, tEXt. */
static int write_head(const Image *im, FILE *f, int alpha, const char *path,
                      char *err, size_t errlen) {
  PngIo io = {.f = f};
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &io,
                                            png_on_error, png_on_warning);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  if (!info) {
    png_destroy_write_struct(&png, NULL);
    snprintf(err, errlen, "cannot write %s: out of memory", path);
    return -1;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    snprintf(err, errlen, "cannot write %s: %s", path,
             io.io_errno ? strerror(io.io_errno) : io.msg);
    return -1;
  }
  png_set_write_fn(png, &io, png_write_data, png_flush_data);
  png_set_IHDR(png, info, (png_uint_32)im->width, (png_uint_32)im->height, 8,
               alpha ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  /* sRGB, plus the gAMA and cHRM that describe it to older readers */
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  /* qcs's attributes as tEXt chunks; a part of a larger picture says
     where it lies in "qcs.window" (x0 y0 full_width full_height) */
  png_text text[IMG_MAX_ATTRS + 1];
  char window[64];
  int nt = 0;
  for (int i = 0; i < im->nattrs; i++)
    text[nt++] = (png_text){.compression = PNG_TEXT_COMPRESSION_NONE,
                            .key = im->attr_name[i],
                            .text = im->attr_value[i]};
  if (im->x0 || im->y0 || im->full_width != im->width ||
      im->full_height != im->height) {
    snprintf(window, sizeof window, "%d %d %d %d", im->x0, im->y0,
             im->full_width, im->full_height);
    text[nt++] = (png_text){.compression = PNG_TEXT_COMPRESSION_NONE,
                            .key = "qcs.window", .text = window};
  }
  if (nt) png_set_text(png, info, text, nt);
  png_write_info(png, info);
  png_destroy_write_struct(&png, &info);
  return 0;
}

int img_write_png(const Image *im, FILE *f, const ImgWriteOptions *opt,
                  const char *path, char *err, size_t errlen) {
  int alpha = opt->alpha != 0, npieces = 0;
  Piece *pieces = compress_idat(im, alpha, opt->threads, &npieces);
  if (!pieces) {
    snprintf(err, errlen, "cannot write %s: out of memory", path);
    return -1;
  }
  if (write_head(im, f, alpha, path, err, errlen) != 0) {
    free_pieces(pieces, npieces);
    return -1;
  }
  errno = 0;
  int rc = write_idat(f, pieces, npieces);
  free_pieces(pieces, npieces);
  if (rc != 0) {
    snprintf(err, errlen, "cannot write %s: %s", path,
             strerror(errno ? errno : EIO));
    return -1;
  }
  return 0;
}

/* Decode png's rows (8 or 16 bits, RGB or RGBA after the transforms set
 * in img_read_png) into im's linear premultiplied RGBA. */
static void decode_row(Image *im, int y, png_const_bytep row, int nc,
                       int depth) {
  float *p = im->rgba + 4 * img_index(im, 0, y);
  double full = depth == 16 ? 65535.0 : 255.0;
  for (int x = 0; x < im->width; x++, p += 4) {
    double v[4] = {0, 0, 0, 1};
    for (int c = 0; c < nc; c++) {
      size_t i = (size_t)nc * (size_t)x + (size_t)c;
      unsigned code = depth == 16 ? (unsigned)row[2 * i] << 8 | row[2 * i + 1]
                                  : row[i];
      v[c] = code / full;
    }
    for (int c = 0; c < 3; c++) p[c] = (float)(img_srgb_decode(v[c]) * v[3]);
    p[3] = (float)v[3];
  }
}

Image *img_read_png(const char *path, char *err, size_t errlen) {
  FILE *f = fopen(path, "rb");
  if (!f) {
    snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno));
    return NULL;
  }
  PngIo io = {.f = f};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &io,
                                           png_on_error, png_on_warning);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  Image *volatile im = NULL;
  png_bytep volatile row = NULL;
  if (!info) {
    png_destroy_read_struct(&png, NULL, NULL);
    fclose(f);
    snprintf(err, errlen, "cannot read %s: out of memory", path);
    return NULL;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    free(row);
    img_free(im);
    snprintf(err, errlen, "cannot read %s: %s", path,
             io.msg[0] ? io.msg : "not a PNG file");
    return NULL;
  }
  png_init_io(png, f);
  png_read_info(png, info);
  png_uint_32 w = png_get_image_width(png, info);
  png_uint_32 h = png_get_image_height(png, info);
  char why[160];
  if (img_check_size((long)w, (long)h, why, sizeof why) != 0) {
    snprintf(io.msg, sizeof io.msg, "%s", why);
    png_error(png, why);
  }
  /* everything becomes RGB or RGBA of 8 or 16 bits */
  png_set_expand(png);  /* palette to RGB, gray to 8 bits, tRNS to alpha */
  png_set_gray_to_rgb(png);
  png_read_update_info(png, info);
  int nc = png_get_channels(png, info);
  int depth = png_get_bit_depth(png, info);
  if ((nc != 3 && nc != 4) || (depth != 8 && depth != 16))
    png_error(png, "unsupported PNG layout");
  if (png_get_interlace_type(png, info) != PNG_INTERLACE_NONE)
    png_error(png, "interlaced PNG images are not supported");
  im = img_new((int)w, (int)h, 0);
  row = malloc(png_get_rowbytes(png, info));
  if (!im || !row) png_error(png, "out of memory");
  for (int y = 0; y < (int)h; y++) {
    png_read_row(png, row, NULL);
    decode_row(im, y, row, nc, depth);
  }
  png_read_end(png, info);
  png_textp text = NULL;
  int nt = png_get_text(png, info, &text, NULL);
  for (int i = 0; i < nt; i++) {
    int x0, y0, fw, fh;
    char c;
    if (strcmp(text[i].key, "qcs.window") == 0) {
      if (sscanf(text[i].text, "%d %d %d %d%c", &x0, &y0, &fw, &fh, &c) == 4 &&
          x0 >= 0 && y0 >= 0 && fw >= 1 && fh >= 1 &&
          (long)x0 + im->width <= fw && (long)y0 + im->height <= fh) {
        im->x0 = x0;
        im->y0 = y0;
        im->full_width = fw;
        im->full_height = fh;
      }
    } else if (strncmp(text[i].key, "qcs.", 4) == 0 &&
               img_set_attr(im, text[i].key, text[i].text)) {
      png_error(png, "out of memory");
    }
  }
  png_destroy_read_struct(&png, &info, NULL);
  fclose(f);
  free(row);
  return im;
}
