/* Built outside CMake against the installed C API (tests/c_api/pkg_config.cmake). */
#include <flurry.h>
#include <stdio.h>
#include <string.h>

int main(void) {
  flurry_effect* fx = NULL;
  flurry_context* ctx = NULL;
  flurry_group* g = NULL;
  size_t n = 0;
  if (flurry_abi_version() != FLURRY_C_ABI_VERSION) return 1;
  if (flurry_effect_parse(
          "{\"groups\": [{\"name\": \"g\", \"capacity\": 100, \"emitters\": "
          "[{\"bursts\": [{\"count\": 7}]}], \"actions\": [{\"type\": \"Move\"}]}]}",
          "consumer", &fx) != FLURRY_OK ||
      flurry_context_create(NULL, &ctx) != FLURRY_OK || flurry_effect_build(fx, ctx, 0) ||
      flurry_context_step(ctx) || flurry_context_group(ctx, "g", &g) || flurry_group_size(g, &n)) {
    fprintf(stderr, "consumer: %s\n", flurry_last_error());
    return 1;
  }
  printf("flurry %s: %zu particles\n", flurry_version(), n);
  flurry_context_destroy(ctx);
  flurry_effect_destroy(fx);
  return n == 7 ? 0 : 1;
}
