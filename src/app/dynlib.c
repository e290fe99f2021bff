/* dynlib.c: loading a library on first use. See dynlib.h. */
#include "app/dynlib.h"

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int dynlib_load(const char *const *sonames, const char *package,
                const char *const *names, void **fns, size_t n, char *err,
                size_t errlen) {
  void *h = NULL;
  const char *why = "not found";
  for (size_t i = 0; sonames[i] && !h; i++) {
    h = dlopen(sonames[i], RTLD_NOW | RTLD_LOCAL);
    if (!h && dlerror()) why = "cannot be loaded";
  }
  if (!h) {
    snprintf(err, errlen, "%s %s (install the Debian package %s)",
             sonames[0], why, package);
    return -1;
  }
  for (size_t i = 0; i < n; i++) {
    fns[i] = dlsym(h, names[i]);
    if (!fns[i]) {
      snprintf(err, errlen, "%s has no %s (install a newer %s)", sonames[0],
               names[i], package);
      return -1;
    }
  }
  return 0;
}

int dynlib_load_table(const char *const *sonames, const char *package,
                      const char *const *names, size_t n, void *table,
                      size_t table_size, const char *what) {
  char err[300];
  void **fns = NULL;
  int rc = -1;
  if (table_size != n * sizeof *fns)
    snprintf(err, sizeof err, "the table for %s is not %zu pointers",
             sonames[0], n);
  else if (!(fns = malloc(n * sizeof *fns)))
    snprintf(err, sizeof err, "out of memory loading %s", sonames[0]);
  else
    rc = dynlib_load(sonames, package, names, fns, n, err, sizeof err);
  if (rc == 0) memcpy(table, fns, n * sizeof *fns);
  else fprintf(stderr, "qcs: %s: %s\n", what, err);
  free(fns);
  return rc;
}
