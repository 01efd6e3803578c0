// docs/snippets/c_api.c: built as C and run by tests/c_api
#include <flurry.h>
#include <stdio.h>

// Prints the failing call's message and returns 1 from main.
#define TRY(call)                                                               \
  do {                                                                          \
    flurry_status s_ = (call);                                                  \
    if (s_ != FLURRY_OK) {                                                      \
      fprintf(stderr, "%s: %s\n", flurry_status_name(s_), flurry_last_error()); \
      return 1;                                                                 \
    }                                                                           \
  } while (0)

int main(void) {
  flurry_context_options options;
  flurry_context* ctx = NULL;
  flurry_group* water = NULL;
  flurry_emitter* nozzle = NULL;
  flurry_action_list* actions = NULL;
  const float* y = NULL;
  size_t count = 0, stride = 0, i;
  float lowest = 0.0f;

  TRY(flurry_context_options_init(&options));
  options.seed = 7;
  options.dt = 1.0 / 60;
  TRY(flurry_context_create(&options, &ctx));
  TRY(flurry_context_create_group(ctx, "water", 100000, &water));

  // An emitter and actions by name and field, as an effect file names them.
  TRY(flurry_emitter_create(&nozzle));
  TRY(flurry_emitter_set_domain(nozzle, "shape", "disc"));
  TRY(flurry_emitter_set_vec3(nozzle, "shape.normal", 0, 1, 0));
  TRY(flurry_emitter_set_float(nozzle, "shape.outerRadius", 0.1));
  TRY(flurry_emitter_set_vec3(nozzle, "position", 0, 0.01f, 0));  // above the floor
  TRY(flurry_emitter_set_float(nozzle, "rate", 2000));
  TRY(flurry_emitter_set_json(nozzle, "types[0].velocity",
                              "{\"type\": \"cone\", \"base\": [0, 8, 0], \"outerRadius\": 1.5}"));
  TRY(flurry_emitter_set_float(nozzle, "types[0].lifetime", 3));
  TRY(flurry_group_add_emitter(water, nozzle));
  TRY(flurry_emitter_destroy(nozzle));

  TRY(flurry_action_list_create(&actions));
  TRY(flurry_action_list_add(actions, "Gravity", NULL));
  TRY(flurry_action_set_vec3(actions, 0, "acceleration", 0, -9.81f, 0));
  TRY(flurry_action_list_add(actions, "Bounce", NULL));
  TRY(flurry_action_set_domain(actions, 1, "surface", "plane"));
  TRY(flurry_action_set_vec3(actions, 1, "surface.normal", 0, 1, 0));
  TRY(flurry_action_set_float(actions, 1, "restitution", -0.5));  // refused when used:
  if (flurry_group_set_actions(water, actions) != FLURRY_ERROR_EFFECT) return 1;
  printf("%s\n", flurry_last_error());  // actions[1].restitution: must be finite and >= 0
  TRY(flurry_action_set_float(actions, 1, "restitution", 0.4));
  TRY(flurry_action_list_add(actions, "Move", NULL));
  TRY(flurry_action_list_add(actions, "KillOld", NULL));
  TRY(flurry_group_set_actions(water, actions));
  TRY(flurry_action_list_destroy(actions));

  TRY(flurry_context_run(ctx, 300));
  // One component of an attribute: valid until the next step.
  TRY(flurry_group_lane(water, FLURRY_ATTR_POSITION, 1, &y, &count, &stride));
  for (i = 0; i < count; ++i) {
    const float v = *(const float*)((const char*)y + i * stride);
    if (i == 0 || v < lowest) lowest = v;
  }
  printf("%zu particles alive, lowest y %g\n", count, lowest);
  TRY(flurry_context_destroy(ctx));  // and with it its groups
  return count > 0 && lowest >= 0 ? 0 : 1;
}
