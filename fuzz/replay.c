/* replay.c: run a fuzz target's LLVMFuzzerTestOneInput over files without
 * libFuzzer, so that `make test` (and `make sanitize`) replays the
 * committed corpora of fuzz/corpus/ with any compiler. Arguments are files
 * or directories (read recursively, in name order); prints
 * "ok fuzz-replay TARGET: N inputs" at the end. An input that crashes the
 * target kills the process: the test runner reports the signal. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fuzz.h"

static long ninputs;

static int by_name(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

static int replay_file(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) { perror(path); return -1; }
  size_t cap = 4096, n = 0;
  unsigned char *buf = malloc(cap);
  size_t k;
  while (buf && (k = fread(buf + n, 1, cap - n, f)) > 0) {
    n += k;
    if (n == cap) buf = realloc(buf, cap *= 2);
  }
  fclose(f);
  if (!buf) { fprintf(stderr, "replay: out of memory\n"); return -1; }
  if (getenv("QCS_REPLAY_VERBOSE")) fprintf(stderr, "replay: %s\n", path);
  LLVMFuzzerTestOneInput(buf, n);
  free(buf);
  ninputs++;
  return 0;
}

static int replay(const char *path) {
  struct stat st;
  if (stat(path, &st) != 0) { perror(path); return -1; }
  if (!S_ISDIR(st.st_mode)) return replay_file(path);
  DIR *d = opendir(path);
  if (!d) { perror(path); return -1; }
  char **names = NULL;
  size_t nn = 0, cap = 0;
  struct dirent *e;
  while ((e = readdir(d))) {
    if (e->d_name[0] == '.') continue;
    if (nn == cap) names = realloc(names, (cap = cap ? 2 * cap : 64) * sizeof *names);
    size_t len = strlen(path) + strlen(e->d_name) + 2;
    names[nn] = malloc(len);
    snprintf(names[nn++], len, "%s/%s", path, e->d_name);
  }
  closedir(d);
  if (nn) qsort(names, nn, sizeof *names, by_name);
  int rc = 0;
  for (size_t i = 0; i < nn; i++) {
    if (replay(names[i]) != 0) rc = -1;
    free(names[i]);
  }
  free(names);
  return rc;
}

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: %s TARGET-NAME FILE-OR-DIR...\n", argv[0]);
    return 2;
  }
  int rc = 0;
  for (int i = 2; i < argc; i++)
    if (replay(argv[i]) != 0) rc = 1;
  if (rc) printf("FAIL fuzz-replay %s: unreadable input\n", argv[1]);
  else printf("ok fuzz-replay %s: %ld inputs\n", argv[1], ninputs);
  return rc;
}
