/* bench_soft.c: rays per second of soft_roots on the soft-cloud N scene
 * (examples/soft-cloud.qcs): N keys, R = 0.6, w = 1, magic 0.5, on the R2
 * sequence; 600 x 380 primary rays from the scene's camera, plus one shadow
 * ray towards the light from every hit. Not part of the test suite (it is
 * not named test_*). Build and run:
 *   make build/libqcscore.a
 *   cc -std=c11 -D_DEFAULT_SOURCE -O2 -Isrc tests/unit/bench_soft.c \
 *      build/libqcscore.a -lm -lpthread -o /tmp/bench && /tmp/bench [N...]
 * Options: -t THREADS (default 2), -m MAXOUT for primary rays (default 1;
 * 0 = all crossings, 64). */
#include "core/soft.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define W 600
#define H 380

typedef struct {
  const soft_obj *obj;
  double eye[3], fw[3], rt[3], up[3], light[3], tanh_;
  int y0, y1, maxout;
  long hits, shadow, nroots;
  soft_stats st;
} job_t;

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static double fract(double x) { return x - floor(x); }

static void norm(double v[3])
{
  double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int i = 0; i < 3; i++) v[i] /= l;
}

static void cross(const double a[3], const double b[3], double c[3])
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

static void *run(void *arg)
{
  job_t *j = arg;
  soft_scratch *s = soft_scratch_new(soft_nkeys(j->obj));
  double out[64];
  double aspect = (double)W / H;
  for (int y = j->y0; y < j->y1; y++)
    for (int x = 0; x < W; x++) {
      double sx = (2 * (x + 0.5) / W - 1) * j->tanh_ * aspect;
      double sy = (1 - 2 * (y + 0.5) / H) * j->tanh_;
      double d[3];
      for (int i = 0; i < 3; i++) d[i] = j->fw[i] + sx * j->rt[i] + sy * j->up[i];
      int n = soft_roots(j->obj, j->eye, d, 0, INFINITY, out, j->maxout, s, &j->st);
      if (n <= 0) continue;
      j->hits++;
      j->nroots += n;
      double p[3], l[3];
      for (int i = 0; i < 3; i++) p[i] = j->eye[i] + out[0] * d[i];
      for (int i = 0; i < 3; i++) l[i] = j->light[i] - p[i];
      /* the shadow ray starts just off the surface (1e-4 of its length) */
      soft_roots(j->obj, p, l, 1e-4 / sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]),
                 1, out, 1, s, &j->st);
      j->shadow++;
    }
  soft_scratch_free(s);
  return NULL;
}

int main(int argc, char **argv)
{
  int threads = 2, maxout = 1, ns[16], nn = 0;
  for (int a = 1; a < argc; a++) {
    if (!strcmp(argv[a], "-t") && a + 1 < argc) threads = atoi(argv[++a]);
    else if (!strcmp(argv[a], "-m") && a + 1 < argc) { maxout = atoi(argv[++a]); if (maxout <= 0) maxout = 64; }
    else if (nn < 16) ns[nn++] = atoi(argv[a]);
  }
  if (nn == 0) { ns[0] = 100; ns[1] = 1000; ns[2] = 10000; ns[3] = 100000; nn = 4; }
  for (int q = 0; q < nn; q++) {
    int N = ns[q];
    double L = 0.5 * cbrt((double)N);
    soft_key *keys = calloc(N, sizeof *keys);
    for (int k = 0; k < N; k++) {
      keys[k].kind = SOFT_SPHERE;
      keys[k].c[0] = L * fract(0.5 + k * 0.8191725134);
      keys[k].c[1] = L * fract(0.5 + k * 0.6710436067);
      keys[k].c[2] = L * fract(0.5 + k * 0.5497004779);
      keys[k].R = 0.6;
      keys[k].w = 1;
    }
    double t = now();
    soft_obj *obj;
    size_t bad;
    if (soft_build(keys, N, 0.5, &obj, &bad)) { fprintf(stderr, "build failed\n"); return 1; }
    double tbuild = now() - t;
    job_t jobs[64];
    double eye[3] = {1.6 * L + 1, 1.2 * L + 1, 2.2 * L + 2}, at[3] = {L / 2, L / 2, L / 2};
    double fw[3], rt[3], up[3], wup[3] = {0, 1, 0};
    for (int i = 0; i < 3; i++) fw[i] = at[i] - eye[i];
    norm(fw);
    cross(fw, wup, rt); norm(rt);
    cross(rt, fw, up);
    pthread_t th[64];
    if (threads > 64) threads = 64;
    t = now();
    for (int i = 0; i < threads; i++) {
      job_t *j = &jobs[i];
      memset(j, 0, sizeof *j);
      j->obj = obj;
      memcpy(j->eye, eye, sizeof eye); memcpy(j->fw, fw, sizeof fw);
      memcpy(j->rt, rt, sizeof rt); memcpy(j->up, up, sizeof up);
      j->light[0] = -L; j->light[1] = 4 * L; j->light[2] = 3 * L;
      j->tanh_ = tan(20 * M_PI / 180);
      j->y0 = H * i / threads; j->y1 = H * (i + 1) / threads;
      j->maxout = maxout;
      pthread_create(&th[i], NULL, run, j);
    }
    long hits = 0, shadow = 0, nroots = 0;
    soft_stats st;
    memset(&st, 0, sizeof st);
    for (int i = 0; i < threads; i++) {
      pthread_join(th[i], NULL);
      hits += jobs[i].hits; shadow += jobs[i].shadow; nroots += jobs[i].nroots;
      st.rays += jobs[i].st.rays; st.nodes += jobs[i].st.nodes; st.keys += jobs[i].st.keys;
      st.intervals += jobs[i].st.intervals; st.skipped += jobs[i].st.skipped;
      st.poly.solves += jobs[i].st.poly.solves; st.poly.quick += jobs[i].st.poly.quick;
      st.poly.laguerre += jobs[i].st.poly.laguerre; st.poly.fallbacks += jobs[i].st.poly.fallbacks;
    }
    double tt = now() - t;
    long rays = (long)W * H + shadow;
    printf("N=%-7d build %.3fs  trace %.3fs (%d threads, maxout %d)  %ld rays (%ld hits, %.2f crossings/hit)  %.0f rays/s"
           "  per ray: nodes %.1f keys %.1f intervals %.1f skipped %.1f solves %.2f (quick %.2f lag %.2f fb %.3f)\n",
           N, tbuild, tt, threads, maxout, rays, hits, hits ? (double)nroots / hits : 0, rays / tt,
           (double)st.nodes / st.rays, (double)st.keys / st.rays, (double)st.intervals / st.rays,
           (double)st.skipped / st.rays, (double)st.poly.solves / st.rays,
           (double)st.poly.quick / st.rays, (double)st.poly.laguerre / st.rays,
           (double)st.poly.fallbacks / st.rays);
    soft_free(obj);
    free(keys);
  }
  return 0;
}
