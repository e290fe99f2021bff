/* progressive.c: the coarse-to-fine ladder. See progressive.h. */
#include "render/progressive.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

struct Progressive {
  const Scene *s;
  RenderSettings rs;
  pthread_t thread;
  pthread_mutex_t lock;
  pthread_cond_t cond;
  atomic_int cancel;
  /* Under the lock: rungs finished (images[i] for i < finished), rungs
     handed out, and the end of the ladder. */
  Image *images[PROG_RUNGS];
  RenderReport reports[PROG_RUNGS];
  int finished, handed, ended, failed;
  char err[256];
};

static const int steps[PROG_RUNGS] = {8, 4, 2, 1};

void prog_size(int w, int h, int *fw, int *fh) {
  *fw = w < 8 ? 8 : w / 8 * 8;
  *fh = h < 8 ? 8 : h / 8 * 8;
}

static void *ladder(void *arg) {
  Progressive *p = arg;
  for (int i = 0; i < PROG_RUNGS; i++) {
    if (atomic_load(&p->cancel)) break;
    RenderSettings rs = p->rs;
    rs.width = p->rs.width / steps[i];
    rs.height = p->rs.height / steps[i];
    rs.progress = NULL;
    RenderReport rep;
    char err[256] = "";
    Image *im = render_scene(p->s, &rs, &rep, &p->cancel, err, sizeof err);
    pthread_mutex_lock(&p->lock);
    if (!im) {
      if (!rep.interrupted) {
        p->failed = 1;
        memcpy(p->err, err, sizeof p->err);
      }
      pthread_mutex_unlock(&p->lock);
      break;
    }
    p->images[i] = im;
    p->reports[i] = rep;
    p->finished = i + 1;
    pthread_cond_signal(&p->cond);
    pthread_mutex_unlock(&p->lock);
  }
  pthread_mutex_lock(&p->lock);
  p->ended = 1;
  pthread_cond_signal(&p->cond);
  pthread_mutex_unlock(&p->lock);
  return NULL;
}

Progressive *prog_start(const Scene *s, const RenderSettings *rs, char *err,
                        size_t errlen) {
  Progressive *p = calloc(1, sizeof *p);
  if (!p) {
    snprintf(err, errlen, "out of memory for the picture");
    return NULL;
  }
  p->s = s;
  p->rs = *rs;
  atomic_init(&p->cancel, 0);
  pthread_mutex_init(&p->lock, NULL);
  pthread_condattr_t ca;
  pthread_condattr_init(&ca);
  pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
  pthread_cond_init(&p->cond, &ca);
  pthread_condattr_destroy(&ca);
  if (pthread_create(&p->thread, NULL, ladder, p)) {
    snprintf(err, errlen, "cannot start a render thread: %s", strerror(errno));
    pthread_cond_destroy(&p->cond);
    pthread_mutex_destroy(&p->lock);
    free(p);
    return NULL;
  }
  return p;
}

int prog_wait(Progressive *p, int timeout_ms, const Image **im, int *step,
              RenderReport *rep, char *err, size_t errlen) {
  struct timespec until;
  clock_gettime(CLOCK_MONOTONIC, &until);
  if (timeout_ms > 0) {
    until.tv_sec += timeout_ms / 1000;
    until.tv_nsec += (long)(timeout_ms % 1000) * 1000000L;
    if (until.tv_nsec >= 1000000000L) {
      until.tv_sec++;
      until.tv_nsec -= 1000000000L;
    }
  }
  pthread_mutex_lock(&p->lock);
  while (p->handed == p->finished && !p->ended && timeout_ms != 0) {
    if (timeout_ms < 0) pthread_cond_wait(&p->cond, &p->lock);
    else if (pthread_cond_timedwait(&p->cond, &p->lock, &until) == ETIMEDOUT)
      break;
  }
  int r;
  if (p->handed < p->finished) {
    /* Hand out the finest finished rung; coarser ones not yet shown are
       skipped (and freed), as a finer picture makes them pointless. */
    int i = p->finished - 1;
    for (int j = p->handed; j < i; j++) {
      img_free(p->images[j]);
      p->images[j] = NULL;
    }
    if (p->handed > 0) {
      img_free(p->images[p->handed - 1]);
      p->images[p->handed - 1] = NULL;
    }
    *im = p->images[i];
    *step = steps[i];
    if (rep) *rep = p->reports[i];
    p->handed = i + 1;
    r = PROG_RUNG;
  } else if (p->ended) {
    r = p->failed ? PROG_FAILED : PROG_DONE;
    if (p->failed) snprintf(err, errlen, "%s", p->err);
  } else {
    r = PROG_TIMEOUT;
  }
  pthread_mutex_unlock(&p->lock);
  return r;
}

void prog_stop(Progressive *p) {
  if (!p) return;
  atomic_store(&p->cancel, 1);
  pthread_join(p->thread, NULL);
  for (int i = 0; i < PROG_RUNGS; i++) img_free(p->images[i]);
  pthread_cond_destroy(&p->cond);
  pthread_mutex_destroy(&p->lock);
  free(p);
}
