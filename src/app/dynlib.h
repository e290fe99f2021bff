/* dynlib.h: libraries a feature loads when it is first used.
 *
 * qcs links at start-up only what every run needs (the interpreter, the
 * tracer, the image writers). The terminal pictures (libchafa, with glib)
 * and the viewer's web server (libmicrohttpd, with GnuTLS and its
 * friends) are loaded by dlopen the first time a picture is drawn or a
 * viewer starts: a script, a farm task or an animation frame does not pay
 * for their thirteen libraries (about 4 million instructions of dynamic
 * linking a process). So are libzip (3MF meshes, app/zipload.c: with
 * libcrypto and libbz2, about 0.8 ms a process) and GNU readline (the
 * prompt on a terminal, app/repl.c: with libtinfo, 3600 relocations).
 *
 * A module that uses such a library lists the functions (and variables)
 * it uses in an X-macro and declares, after the library's own header, a
 * table of pointers of their own types (__typeof__), so every call keeps
 * the header's prototype. DYNLIB_LOAD fills the table.
 *
 * Threads: load from one thread before others use the table (the REPL's
 * thread, the viewer's start; zipload.c loads under pthread_once). */
#ifndef QCS_DYNLIB_H
#define QCS_DYNLIB_H

#include <stddef.h>

/* Open the first of the sonames that loads (NULL-terminated) and look up
   each of the n names into fns[0..n). 0, or -1 with a message in err
   naming the library and the Debian package that has it. */
int dynlib_load(const char *const *sonames, const char *package,
                const char *const *names, void **fns, size_t n, char *err,
                size_t errlen);

/* A table of pointers named by an X-macro LIST (X(f) for each name),
   declared as a struct of `__typeof__(f) *f;` (functions in the types of
   the library's header, pointers to its variables), filled from the
   first of sonames that loads: DYNLIB_LOAD(tab, LIST, sonames, package,
   what) is 0, or -1 after "qcs: WHAT: why" on stderr. The pointers are
   copied in as bytes, so each member keeps its declared type; a table
   that is not one pointer per name is refused. */
#define DYNLIB_NAME(f) #f,
#define DYNLIB_LOAD(tab, LIST, sonames, package, what)                      \
  dynlib_load_table(sonames, package,                                       \
                    (const char *const[]){LIST(DYNLIB_NAME)},               \
                    sizeof((const char *const[]){LIST(DYNLIB_NAME)}) /      \
                        sizeof(const char *),                               \
                    &(tab), sizeof(tab), what)
int dynlib_load_table(const char *const *sonames, const char *package,
                      const char *const *names, size_t n, void *table,
                      size_t table_size, const char *what);
#endif
