/* Two builds of libflurry in one process, stepping the same game scene in turn.
 *
 * On a shared machine two benchmark runs minutes apart differ by more than most changes do
 * (scripts/compare_libraries.py alternates whole runs: its same-library ratios still swing
 * by 10 %). This loads each library, with the C API over it, into a link-map namespace of
 * its own (dlmopen), builds the same scene in each (bench_runtime's: `instances` copies of a
 * 100-particle puff of sparks falling on a floor, each placed and turned its own way), and
 * steps them in alternating slices of a few milliseconds: both see the same load. It prints
 * each one's time per instance-step and the median (and quartiles) of the slices' ratios.
 *
 *   build/release/bench/ab_instances OLD/libflurry.so.0.1.0 build/release/sdk/libflurry.so.0.1.0 \
 *       --instances 1000 --threads 1 --slices 40 --steps 20
 *
 * (one command line; OLD built as scripts/compare_libraries.py says). The same library
 * against itself gives ratios of 1 within a few percent: what a difference must beat.
 * `--bounds 1` also reads every instance's box after each step, as a game culling them does;
 * `--move 1` moves every instance before each step (a little along x, turned a little more
 * about y), as a game moves the effects it attaches to what moves; `--move 2` sets every
 * instance's transform again, unchanged, as a game does for those standing still.
 * Where the public headers changed between the two, give the old one the C API built with
 * it (`--old-capi OLD/libflurry_c.so`).
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <link.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "flurry.h"

#ifndef FLURRY_C_LIBRARY
#define FLURRY_C_LIBRARY "libflurry_c.so"
#endif

typedef struct {
  flurry_status (*options_init)(flurry_context_options*);
  flurry_status (*create)(const flurry_context_options*, flurry_context**);
  flurry_status (*step)(flurry_context*);
  flurry_status (*run)(flurry_context*, uint64_t);
  flurry_status (*parse)(const char*, const char*, flurry_effect**);
  flurry_status (*instantiate)(const flurry_effect*, flurry_context*, const char*, size_t,
                               flurry_instance**);
  flurry_status (*place)(flurry_instance*, const float*, const float*, float);
  flurry_status (*bounds)(const flurry_instance*, float[3], float[3], int*);
  flurry_context* ctx;
  flurry_instance** instances;
} Library;

static void* symbol(void* lib, const char* name) {
  void* p = dlsym(lib, name);
  if (!p) {
    fprintf(stderr, "ab_instances: %s\n", dlerror());
    exit(1);
  }
  return p;
}

/* The library at `core` and the C API over it, in a namespace of their own: the C API's
 * libflurry is the one loaded there first. */
static void load(Library* L, const char* core, const char* capi) {
  void* first = dlmopen(LM_ID_NEWLM, core, RTLD_NOW | RTLD_LOCAL);
  if (!first) {
    fprintf(stderr, "ab_instances: %s\n", dlerror());
    exit(1);
  }
  Lmid_t id;
  dlinfo(first, RTLD_DI_LMID, &id);
  void* lib = dlmopen(id, capi, RTLD_NOW | RTLD_LOCAL);
  if (!lib) {
    fprintf(stderr, "ab_instances: %s\n", dlerror());
    exit(1);
  }
  L->options_init = symbol(lib, "flurry_context_options_init");
  L->create = symbol(lib, "flurry_context_create");
  L->step = symbol(lib, "flurry_context_step");
  L->run = symbol(lib, "flurry_context_run");
  L->parse = symbol(lib, "flurry_effect_parse");
  L->instantiate = symbol(lib, "flurry_effect_instantiate");
  L->place = symbol(lib, "flurry_instance_set_transform");
  L->bounds = symbol(lib, "flurry_instance_bounds");
}

static double seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int ascending(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return x < y ? -1 : x > y;
}

static void check(flurry_status s, const char* what) {
  if (s != FLURRY_OK) {
    fprintf(stderr, "ab_instances: %s failed (status %d)\n", what, (int)s);
    exit(1);
  }
}

/* Instance k on a grid of `side` a row, turned by 0.37 k about y; `moved` steps later a
 * hundredth of a unit further along x and turned a hundredth of a radian more each step. */
static void place(Library* L, long k, long side, long moved) {
  const float at[3] = {(float)(k % side) * 4.0f + 0.01f * (float)moved, 0.0f,
                       (float)(k / side) * 4.0f};
  const float half = ((float)k * 0.37f + 0.01f * (float)moved) * 0.5f; /* (x, y, z, w) */
  const float turn[4] = {0.0f, sinf(half), 0.0f, cosf(half)};
  check(L->place(L->instances[k], at, turn, 1.0f), "flurry_instance_set_transform");
}

int main(int argc, char** argv) {
  if (argc < 3) {
    fprintf(stderr,
            "usage: ab_instances OLD.so NEW.so [--instances N] [--threads T] [--slices S]\n"
            "       [--steps K] [--rate R] [--bounds 0|1] [--move 0|1|2] [--capi libflurry_c.so]\n"
            "       [--old-capi libflurry_c.so]\n");
    return 2;
  }
  long instances = 1000, threads = 1, slices = 40, steps = 20, rate = 100, bounds = 0, move = 0;
  const char* capi = FLURRY_C_LIBRARY;
  const char* oldCapi = NULL;
  for (int i = 3; i + 1 < argc; i += 2) {
    const char* k = argv[i];
    if (!strcmp(k, "--capi") || !strcmp(k, "--old-capi")) {
      *(!strcmp(k, "--capi") ? &capi : &oldCapi) = argv[i + 1];
      continue;
    }
    const long v = strtol(argv[i + 1], NULL, 10);
    if (!strcmp(k, "--bounds") && (v == 0 || v == 1)) {
      bounds = v;
      continue;
    }
    if (!strcmp(k, "--move") && v >= 0 && v <= 2) {
      move = v;
      continue;
    }
    if (v <= 0) {
      fprintf(stderr, "ab_instances: %s must be a positive integer\n", k);
      return 2;
    }
    if (!strcmp(k, "--instances"))
      instances = v;
    else if (!strcmp(k, "--threads"))
      threads = v;
    else if (!strcmp(k, "--slices"))
      slices = v;
    else if (!strcmp(k, "--steps"))
      steps = v;
    else if (!strcmp(k, "--rate"))
      rate = v;
    else {
      fprintf(stderr, "ab_instances: unknown option %s\n", k);
      return 2;
    }
  }
  char json[2048];
  snprintf(json, sizeof json,
           "{\"version\": 1, \"name\": \"sparks\", \"dt\": 0.0333333333333, \"seed\": 7, "
           "\"groups\": [{\"name\": \"sparks\", \"capacity\": %ld, \"emitters\": [{\"shape\": "
           "{\"type\": \"sphere\", \"center\": [0, 1, 0], \"outerRadius\": 0.1}, \"rate\": %ld, "
           "\"types\": [{\"velocity\": {\"type\": \"sphere\", \"center\": [0, 2, 0], "
           "\"outerRadius\": 1}, \"lifetime\": 1}]}], \"actions\": [{\"type\": \"Gravity\", "
           "\"acceleration\": [0, -9.81, 0]}, {\"type\": \"Bounce\", \"surface\": {\"type\": "
           "\"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0]}, \"restitution\": 0.5}, "
           "{\"type\": \"Move\"}, {\"type\": \"KillOld\"}]}]}",
           rate * 5 / 4 + 16, rate);
  Library L[2];
  const long side = (long)ceil(sqrt((double)instances));
  for (int l = 0; l < 2; ++l) {
    load(&L[l], argv[1 + l], l == 0 && oldCapi ? oldCapi : capi);
    L[l].instances = malloc(sizeof(flurry_instance*) * (size_t)instances);
    flurry_context_options o;
    check(L[l].options_init(&o), "flurry_context_options_init");
    o.threads = (unsigned)threads;
    check(L[l].create(&o, &L[l].ctx), "flurry_context_create");
    flurry_effect* effect;
    check(L[l].parse(json, "sparks", &effect), "flurry_effect_parse");
    for (long k = 0; k < instances; ++k) {
      char name[32];
      snprintf(name, sizeof name, "%ld", k);
      flurry_instance* instance;
      check(L[l].instantiate(effect, L[l].ctx, name, 0, &instance), "flurry_effect_instantiate");
      L[l].instances[k] = instance;
      place(&L[l], k, side, 0);
    }
    check(L[l].run(L[l].ctx, 45), "flurry_context_run"); /* births and deaths balance */
  }
  double* ratio = malloc(sizeof(double) * (size_t)slices);
  double total[2] = {0.0, 0.0};
  volatile float sink = 0.0f; /* the boxes read, kept */
  for (long s = 0; s < slices; ++s) {
    double t[2];
    for (int j = 0; j < 2; ++j) {
      const int l = (s & 1) ? 1 - j : j; /* each goes first in turn */
      const double t0 = seconds();
      for (long k = 0; k < steps; ++k) {
        for (long i = 0; move && i < instances; ++i)
          place(&L[l], i, side, move == 1 ? s * steps + k + 1 : 0);
        check(L[l].step(L[l].ctx), "flurry_context_step");
        for (long i = 0; bounds && i < instances; ++i) {
          float lo[3], hi[3];
          int empty;
          check(L[l].bounds(L[l].instances[i], lo, hi, &empty), "flurry_instance_bounds");
          sink += hi[1];
        }
      }
      t[l] = seconds() - t0;
      total[l] += t[l];
    }
    ratio[s] = t[0] / t[1];
  }
  qsort(ratio, (size_t)slices, sizeof(double), ascending);
  const double per = 1e6 / (double)(slices * steps * instances);
  printf("%ld instances, %ld thread(s): old %.3f us an instance-step, new %.3f\n", instances,
         threads, total[0] * per, total[1] * per);
  printf("new faster by %.3fx (median of %ld slices; quartiles %.3f, %.3f)\n", ratio[slices / 2],
         slices, ratio[slices / 4], ratio[(3 * slices) / 4]);
  free(ratio);
  for (int l = 0; l < 2; ++l) free(L[l].instances);
  return 0;
}
