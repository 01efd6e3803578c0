// docs/snippets/c_effect.c: built as C and run by tests/c_api
#include <flurry.h>
#include <stdio.h>

// Every call returns a status; flurry_last_error() says what went wrong, naming the field.
#define TRY(call)                                                               \
  do {                                                                          \
    flurry_status s_ = (call);                                                  \
    if (s_ != FLURRY_OK) {                                                      \
      fprintf(stderr, "%s: %s\n", flurry_status_name(s_), flurry_last_error()); \
      return 1;                                                                 \
    }                                                                           \
  } while (0)

int main(void) {
  flurry_effect* fx = NULL;
  flurry_context_options options;
  flurry_context* ctx = NULL;
  flurry_group* flames = NULL;
  size_t alive = 0;
  int frames = 0, step;

  TRY(flurry_effect_load("campfire.json", &fx));  // FLURRY_ERROR_EFFECT: "FILE: PATH: why"
  TRY(flurry_context_options_init(&options));
  TRY(flurry_effect_context_options(fx, &options));  // the effect's seed and dt
  TRY(flurry_context_create(&options, &ctx));
  TRY(flurry_effect_build(fx, ctx, 0));
  TRY(flurry_effect_frames(fx, &frames));
  for (step = 0; step < frames; ++step) TRY(flurry_context_step(ctx));

  TRY(flurry_context_group(ctx, "flames", &flames));
  TRY(flurry_group_size(flames, &alive));
  printf("flames: %zu particles\n", alive);
  TRY(flurry_context_destroy(ctx));
  TRY(flurry_effect_destroy(fx));
  return alive > 0 ? 0 : 1;
}
