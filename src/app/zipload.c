/* zipload.c: libzip, loaded the first time a 3MF mesh is written.
 *
 * render/mesh.c writes 3MF files (zips) with libzip. Linked at start-up,
 * libzip and what it needs (libcrypto, libbz2) cost every run of qcs about
 * 0.8 ms of dynamic loading, for a format few runs write. The qcs binary
 * is therefore linked without -lzip (see the Makefile): the functions
 * mesh.c calls are defined here, each loading libzip on its first call
 * (app/dynlib.h) and passing its arguments on. The unit tests and fuzz
 * replays, which link the layers without app/, link libzip itself.
 *
 * If libzip cannot be loaded, the reason is said once on stderr,
 * zip_source_buffer_create returns NULL (mesh.c then writes nothing and
 * reports the failure) and the error-struct functions, which mesh.c calls
 * around it, do nothing more than keep the struct zeroed.
 *
 * A function mesh.c starts to call must be added to ZIP_FNS and given a
 * forwarder below: the link of qcs fails until it is. */
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <zip.h>

#include "app/dynlib.h"

#define ZIP_FNS(X)                                                         \
  X(zip_close) X(zip_discard) X(zip_error_fini) X(zip_error_init)          \
  X(zip_file_add) X(zip_open_from_source) X(zip_source_buffer)             \
  X(zip_source_buffer_create) X(zip_source_close) X(zip_source_free)       \
  X(zip_source_keep) X(zip_source_open) X(zip_source_read)                 \
  X(zip_source_stat)

static struct {
#define X(f) __typeof__(f) *f;
  ZIP_FNS(X)
#undef X
} zf;

static int zip_loaded; /* 1 once loaded, -1 if it cannot be */

static void zip_load_once(void) {
  static const char *const sonames[] = {"libzip.so.4", "libzip.so.5",
                                        "libzip.so", NULL};
  zip_loaded = DYNLIB_LOAD(zf, ZIP_FNS, sonames, "libzip4", "error") ? -1 : 1;
}

static int zip_load(void) {
  static pthread_once_t once = PTHREAD_ONCE_INIT;
  pthread_once(&once, zip_load_once);
  return zip_loaded > 0;
}

void zip_error_init(zip_error_t *e) {
  if (zip_load()) zf.zip_error_init(e);
  else memset(e, 0, sizeof *e);
}

void zip_error_fini(zip_error_t *e) {
  if (zip_load()) zf.zip_error_fini(e);
}

zip_source_t *zip_source_buffer_create(const void *data, zip_uint64_t len,
                                       int freep, zip_error_t *e) {
  return zip_load() ? zf.zip_source_buffer_create(data, len, freep, e) : NULL;
}

/* The rest take what only the functions above can have made, so libzip
   is loaded when they are called. */
int zip_close(zip_t *za) { return zf.zip_close(za); }
void zip_discard(zip_t *za) { zf.zip_discard(za); }
zip_int64_t zip_file_add(zip_t *za, const char *name, zip_source_t *s,
                         zip_flags_t flags) {
  return zf.zip_file_add(za, name, s, flags);
}
zip_t *zip_open_from_source(zip_source_t *s, int flags, zip_error_t *e) {
  return zf.zip_open_from_source(s, flags, e);
}
zip_source_t *zip_source_buffer(zip_t *za, const void *data, zip_uint64_t len,
                                int freep) {
  return zf.zip_source_buffer(za, data, len, freep);
}
int zip_source_close(zip_source_t *s) { return zf.zip_source_close(s); }
void zip_source_free(zip_source_t *s) {
  if (s) zf.zip_source_free(s);
}
void zip_source_keep(zip_source_t *s) { zf.zip_source_keep(s); }
int zip_source_open(zip_source_t *s) { return zf.zip_source_open(s); }
zip_int64_t zip_source_read(zip_source_t *s, void *buf, zip_uint64_t len) {
  return zf.zip_source_read(s, buf, len);
}
int zip_source_stat(zip_source_t *s, zip_stat_t *st) {
  return zf.zip_source_stat(s, st);
}
