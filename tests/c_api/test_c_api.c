/* The C API, compiled as C99: every call, its results and its error paths (NULL handles,
 * wrong types, unknown names, invalid fields, bad files, a missing OpenCL device). Run as
 *   test_c_api FOUNTAIN_JSON OUT_DIR
 * It prints each failed check and exits non-zero if any failed. */
#include <flurry.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures = 0;

#define CHECK(cond)                                                            \
  do {                                                                         \
    if (!(cond)) {                                                             \
      fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
      ++failures;                                                              \
    }                                                                          \
  } while (0)

/* A call that must succeed. */
#define OK(call)                                                                                  \
  do {                                                                                            \
    flurry_status s_ = (call);                                                                    \
    if (s_ != FLURRY_OK) {                                                                        \
      fprintf(stderr, "%s:%d: %s -> %s: %s\n", __FILE__, __LINE__, #call, flurry_status_name(s_), \
              flurry_last_error());                                                               \
      ++failures;                                                                                 \
    }                                                                                             \
  } while (0)

/* A call that must fail with `status` and a message containing `text`. */
#define FAILS(call, status, text) expect_failure((call), (status), (text), #call, __LINE__)

static void expect_failure(flurry_status got, flurry_status want, const char* text,
                           const char* call, int line) {
  if (got != want) {
    fprintf(stderr, "%s:%d: %s -> %s (%s), expected %s\n", __FILE__, line, call,
            flurry_status_name(got), flurry_last_error(), flurry_status_name(want));
    ++failures;
  } else if (!strstr(flurry_last_error(), text)) {
    fprintf(stderr, "%s:%d: %s: message \"%s\" lacks \"%s\"\n", __FILE__, line, call,
            flurry_last_error(), text);
    ++failures;
  }
}

static void test_version_and_errors(void) {
  CHECK(flurry_abi_version() == FLURRY_C_ABI_VERSION);
  CHECK(strlen(flurry_version()) >= 5 && strchr(flurry_version(), '.'));
  CHECK(strcmp(flurry_status_name(FLURRY_OK), "FLURRY_OK") == 0);
  CHECK(strcmp(flurry_status_name(FLURRY_ERROR_EFFECT), "FLURRY_ERROR_EFFECT") == 0);
  CHECK(strcmp(flurry_status_name((flurry_status)999), "unknown flurry_status") == 0);
  /* Destroying NULL is allowed, as free(NULL). */
  OK(flurry_context_destroy(NULL));
  OK(flurry_effect_destroy(NULL));
  OK(flurry_action_list_destroy(NULL));
  OK(flurry_emitter_destroy(NULL));
}

static void test_context(void) {
  flurry_context_options o;
  flurry_context* ctx = NULL;
  double t = -1, dt = 0;
  uint64_t steps = 99;
  flurry_backend b = FLURRY_BACKEND_OPENCL;
  const char* why = NULL;
  size_t n = 99;
  flurry_group* g = NULL;
  flurry_group* g2 = NULL;
  const char* name = NULL;

  FAILS(flurry_context_options_init(NULL), FLURRY_ERROR_NULL_ARGUMENT, "options");
  OK(flurry_context_options_init(&o));
  CHECK(o.seed == 1 && o.backend == FLURRY_BACKEND_CPU && o.device == NULL && o.threads == 0);
  CHECK(fabs(o.dt - 1.0 / 30.0) < 1e-12);
  FAILS(flurry_context_create(&o, NULL), FLURRY_ERROR_NULL_ARGUMENT, "out");
  o.dt = -1;
  FAILS(flurry_context_create(&o, &ctx), FLURRY_ERROR_INVALID_ARGUMENT, "dt");
  CHECK(ctx == NULL);
  o.dt = 0.02;
  o.backend = (flurry_backend)7;
  FAILS(flurry_context_create(&o, &ctx), FLURRY_ERROR_INVALID_ARGUMENT, "not a flurry_backend");
  o.backend = FLURRY_BACKEND_CPU;
  o.threads = 2;
  OK(flurry_context_create(&o, &ctx));
  OK(flurry_context_time(ctx, &t));
  OK(flurry_context_step_index(ctx, &steps));
  OK(flurry_context_time_step(ctx, &dt));
  CHECK(t == 0 && steps == 0 && dt == 0.02);
  OK(flurry_context_backend(ctx, &b));
  CHECK(b == FLURRY_BACKEND_CPU);
  OK(flurry_context_backend_fallback(ctx, &why));
  CHECK(why && why[0] == 0);
  FAILS(flurry_context_set_time_step(ctx, 0), FLURRY_ERROR_INVALID_ARGUMENT, "dt");
  OK(flurry_context_set_time_step(ctx, 0.05));
  OK(flurry_context_run(ctx, 2));
  OK(flurry_context_step(ctx));
  OK(flurry_context_time(ctx, &t));
  OK(flurry_context_step_index(ctx, &steps));
  CHECK(fabs(t - 0.15) < 1e-9 && steps == 3);

  FAILS(flurry_context_create_group(ctx, "g", 0, &g), FLURRY_ERROR_INVALID_ARGUMENT, "capacity");
  FAILS(flurry_context_create_group(ctx, NULL, 10, &g), FLURRY_ERROR_NULL_ARGUMENT, "name");
  OK(flurry_context_create_group(ctx, "sparks", 10, &g));
  FAILS(flurry_context_create_group(ctx, "sparks", 10, &g2), FLURRY_ERROR_INVALID_ARGUMENT,
        "a group named 'sparks' exists");
  OK(flurry_context_group_count(ctx, &n));
  CHECK(n == 1);
  OK(flurry_context_group(ctx, "sparks", &g2));
  CHECK(g2 == g);
  FAILS(flurry_context_group(ctx, "nope", &g2), FLURRY_ERROR_NOT_FOUND, "no group named 'nope'");
  CHECK(g2 == NULL);
  OK(flurry_context_group_at(ctx, 0, &g2));
  CHECK(g2 == g);
  FAILS(flurry_context_group_at(ctx, 1, &g2), FLURRY_ERROR_NOT_FOUND, "has 1 groups");
  OK(flurry_group_name(g, &name));
  CHECK(strcmp(name, "sparks") == 0);

  /* NULL handles everywhere. */
  FAILS(flurry_context_step(NULL), FLURRY_ERROR_NULL_ARGUMENT, "ctx: is NULL");
  FAILS(flurry_context_run(NULL, 1), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_time(NULL, &t), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_time(ctx, NULL), FLURRY_ERROR_NULL_ARGUMENT, "seconds");
  FAILS(flurry_context_step_index(NULL, &steps), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_time_step(NULL, &dt), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_set_time_step(NULL, 1), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_backend(NULL, &b), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_backend_fallback(NULL, &why), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_create_group(NULL, "x", 1, &g2), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_group(NULL, "x", &g2), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_group_count(NULL, &n), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_group_at(NULL, 0, &g2), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  OK(flurry_context_destroy(ctx));

  /* The default options (NULL). */
  ctx = NULL;
  OK(flurry_context_create(NULL, &ctx));
  CHECK(ctx != NULL);
  OK(flurry_context_destroy(ctx));
}

/* OpenCL asked for where there is no such device (or no OpenCL in this build): a clear status
 * and message; Auto falls back to the CPU and says why. */
/* What the log callback received. */
typedef struct log_record {
  int count;
  flurry_log_level level;
  char message[4096];
} log_record;

static void record_log(flurry_log_level level, const char* message, void* user_data) {
  log_record* r = (log_record*)user_data;
  ++r->count;
  r->level = level;
  snprintf(r->message, sizeof r->message, "%s", message);
}

static void test_missing_device(void) {
  flurry_context_options o;
  flurry_context* ctx = NULL;
  flurry_status s;
  flurry_backend b = FLURRY_BACKEND_OPENCL;
  const char* why = NULL;
  log_record log = {0, FLURRY_LOG_DEBUG, ""};

  OK(flurry_context_options_init(&o));
  o.backend = FLURRY_BACKEND_OPENCL;
  o.device = "no-such-device-anywhere";
  s = flurry_context_create(&o, &ctx);
  CHECK(ctx == NULL);
  if (s == FLURRY_ERROR_NOT_BUILT) {
    CHECK(strstr(flurry_last_error(), "FLURRY_OPENCL=OFF") != NULL);
  } else {
    CHECK(s == FLURRY_ERROR_NO_DEVICE);
    CHECK(strstr(flurry_last_error(), "no device matches 'no-such-device-anywhere'") ||
          strstr(flurry_last_error(), "no OpenCL platform or device found"));
  }
  /* AUTO falls back to the CPU, and says why through the log callback when one is set. */
  o.backend = FLURRY_BACKEND_AUTO;
  OK(flurry_set_log_callback(record_log, &log));
  OK(flurry_context_create(&o, &ctx));
  OK(flurry_context_backend(ctx, &b));
  CHECK(b == FLURRY_BACKEND_CPU);
  OK(flurry_context_backend_fallback(ctx, &why));
  if (s == FLURRY_ERROR_NO_DEVICE) {
    CHECK(strlen(why) > 0);
    CHECK(log.count == 1 && log.level == FLURRY_LOG_INFO);
    CHECK(strstr(log.message, "running on the CPU") && strstr(log.message, why));
  }
  OK(flurry_context_destroy(ctx));
  OK(flurry_set_log_callback(NULL, NULL));
  log.count = 0;
  OK(flurry_context_create(&o, &ctx));
  CHECK(log.count == 0);
  OK(flurry_context_destroy(ctx));
}

static void test_effects(const char* fountain) {
  flurry_effect* fx = NULL;
  flurry_context_options o;
  flurry_context* ctx = NULL;
  const char* name = NULL;
  const char* text = NULL;
  int frames = 0;
  size_t n = 0;
  flurry_group* g = NULL;
  size_t size = 0;

  /* A bad file, a folder, bad JSON, an invalid field: the C++ wording, file and JSON path. */
  FAILS(flurry_effect_load("/nonexistent/x.json", &fx), FLURRY_ERROR_EFFECT,
        "/nonexistent/x.json: cannot open the file");
  CHECK(fx == NULL);
  FAILS(flurry_effect_load("/", &fx), FLURRY_ERROR_EFFECT, "/: is a directory");
  FAILS(flurry_effect_parse("{\"groups\": [", "broken.json", &fx), FLURRY_ERROR_EFFECT,
        "broken.json: parse error at line 1");
  FAILS(flurry_effect_parse("{\"groups\": [{\"name\": \"g\", \"capacity\": 10, \"emitters\": "
                            "[{\"rate\": -1}]}]}",
                            "bad.json", &fx),
        FLURRY_ERROR_EFFECT, "bad.json: groups[0].emitters[0].rate: ");
  FAILS(flurry_effect_parse("{\"groups\": []}", NULL, &fx), FLURRY_ERROR_EFFECT,
        "<effect>: groups: an effect needs at least one group");
  FAILS(flurry_effect_load(NULL, &fx), FLURRY_ERROR_NULL_ARGUMENT, "path");
  FAILS(flurry_effect_load(fountain, NULL), FLURRY_ERROR_NULL_ARGUMENT, "out");
  FAILS(flurry_effect_parse(NULL, "x", &fx), FLURRY_ERROR_NULL_ARGUMENT, "json");

  /* An effect with a warning (no Move), from a string. */
  OK(
      flurry_effect_parse("{\"name\": \"still\", \"dt\": 0.05, \"seed\": 9, \"frames\": 12, "
                          "\"groups\": [{\"name\": \"g\", \"capacity\": 10, \"emitters\": "
                          "[{\"bursts\": [{\"count\": 4}]}]}], \"render\": {\"x\": 1}}",
                          "still.json", &fx));
  OK(flurry_effect_name(fx, &name));
  CHECK(strcmp(name, "still") == 0);
  OK(flurry_effect_frames(fx, &frames));
  CHECK(frames == 12);
  OK(flurry_effect_warning_count(fx, &n));
  CHECK(n == 1);
  OK(flurry_effect_warning(fx, 0, &text));
  CHECK(strcmp(text, "groups[0].actions: has no Move: particles never move or age") == 0);
  FAILS(flurry_effect_warning(fx, 1, &text), FLURRY_ERROR_NOT_FOUND, "warning index 1");
  OK(flurry_effect_render_json(fx, &text));
  CHECK(strcmp(text, "{\"x\":1}") == 0);
  OK(flurry_effect_context_options(fx, &o));
  CHECK(o.seed == 9 && o.dt == 0.05 && o.backend == FLURRY_BACKEND_CPU);
  OK(flurry_context_create(&o, &ctx));
  OK(flurry_effect_build(fx, ctx, 0));
  /* Built twice into one context: the group exists. */
  FAILS(flurry_effect_build(fx, ctx, 0), FLURRY_ERROR_EFFECT,
        "groups[0]: name: a group named 'g' exists");
  OK(flurry_context_group(ctx, "g", &g));
  OK(flurry_context_step(ctx));
  OK(flurry_group_size(g, &size));
  CHECK(size == 4);
  FAILS(flurry_effect_name(NULL, &name), FLURRY_ERROR_NULL_ARGUMENT, "effect");
  FAILS(flurry_effect_frames(NULL, &frames), FLURRY_ERROR_NULL_ARGUMENT, "effect");
  FAILS(flurry_effect_context_options(NULL, &o), FLURRY_ERROR_NULL_ARGUMENT, "effect");
  FAILS(flurry_effect_warning_count(NULL, &n), FLURRY_ERROR_NULL_ARGUMENT, "effect");
  FAILS(flurry_effect_warning(NULL, 0, &text), FLURRY_ERROR_NULL_ARGUMENT, "effect");
  FAILS(flurry_effect_render_json(NULL, &text), FLURRY_ERROR_NULL_ARGUMENT, "effect");
  FAILS(flurry_effect_build(NULL, ctx, 0), FLURRY_ERROR_NULL_ARGUMENT, "effect");
  FAILS(flurry_effect_build(fx, NULL, 0), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  /* Twice the particles and the room: its burst of 4 gives 8. */
  {
    flurry_context* twice = NULL;
    OK(flurry_effect_scale_spawning(fx, 2.0));
    OK(flurry_context_create(&o, &twice));
    OK(flurry_effect_build(fx, twice, 0));
    OK(flurry_context_step(twice));
    OK(flurry_context_group(twice, "g", &g));
    OK(flurry_group_size(g, &size));
    CHECK(size == 8);
    OK(flurry_context_destroy(twice));
    FAILS(flurry_effect_scale_spawning(fx, 0.0), FLURRY_ERROR_INVALID_ARGUMENT, "factor");
    FAILS(flurry_effect_scale_spawning(NULL, 2.0), FLURRY_ERROR_NULL_ARGUMENT, "effect");
  }
  OK(flurry_context_destroy(ctx));
  OK(flurry_effect_destroy(fx));

  /* The fountain file, capped to 500 particles a group. */
  OK(flurry_effect_load(fountain, &fx));
  OK(flurry_effect_context_options(fx, &o));
  OK(flurry_context_create(&o, &ctx));
  OK(flurry_effect_build(fx, ctx, 500));
  OK(flurry_context_group_at(ctx, 0, &g));
  OK(flurry_context_run(ctx, 30));
  OK(flurry_group_size(g, &size));
  CHECK(size > 0 && size <= 500);
  OK(flurry_context_destroy(ctx));
  OK(flurry_effect_destroy(fx));
}

/* Action lists and emitters by name and field, validated by the effect loader. */
static void test_building(void) {
  flurry_action_list* list = NULL;
  flurry_emitter* em = NULL;
  size_t i = 99, n = 0;

  OK(flurry_action_list_create(&list));
  FAILS(flurry_action_list_create(NULL), FLURRY_ERROR_NULL_ARGUMENT, "out");
  FAILS(flurry_action_list_add(list, "Gravty", &i), FLURRY_ERROR_EFFECT,
        "actions[0].type: unknown action \"Gravty\"; did you mean \"Gravity\"?");
  FAILS(flurry_action_list_add(list, "Callback", &i), FLURRY_ERROR_EFFECT,
        "actions[0].type: a Callback runs C++ code");
  FAILS(flurry_action_list_add(list, NULL, &i), FLURRY_ERROR_NULL_ARGUMENT, "action");
  FAILS(flurry_action_list_add(NULL, "Move", &i), FLURRY_ERROR_NULL_ARGUMENT, "list");
  OK(flurry_action_list_count(list, &n));
  CHECK(n == 0);
  OK(flurry_action_list_add(list, "Gravity", &i));
  CHECK(i == 0);
  OK(flurry_action_set_vec3(list, 0, "acceleration", 0, -9.81f, 0));
  OK(flurry_action_list_add(list, "Bounce", &i));
  CHECK(i == 1);
  OK(flurry_action_set_domain(list, 1, "surface", "plane"));
  OK(flurry_action_set_vec3(list, 1, "surface.normal", 0, 1, 0));
  OK(flurry_action_set_float(list, 1, "restitution", 0.5));
  OK(flurry_action_set_float(list, 1, "friction", 0.1));
  OK(flurry_action_list_add(list, "Move", NULL));
  OK(flurry_action_list_add(list, "KillOld", NULL));
  OK(flurry_action_list_add(list, "ColorOverLife", NULL));
  OK(flurry_action_set_float(list, 4, "keys[0].t", 0));
  OK(flurry_action_set_vec4(list, 4, "keys[0].color", 1, 0, 0, 0.5f));
  OK(flurry_action_set_string(list, 4, "mode", "replace"));
  OK(flurry_action_list_count(list, &n));
  CHECK(n == 5);
  OK(flurry_action_list_validate(list));

  /* Invalid values: the message names the field as an effect file would. */
  OK(flurry_action_set_float(list, 1, "restitution", -1));
  FAILS(flurry_action_list_validate(list), FLURRY_ERROR_EFFECT, "actions[1].restitution: ");
  OK(flurry_action_set_string(list, 1, "restitution", "high")); /* a wrong type */
  FAILS(flurry_action_list_validate(list), FLURRY_ERROR_EFFECT,
        "actions[1].restitution: expected a number or \"inf\", got the string \"high\"");
  OK(flurry_action_set_float(list, 1, "restitution", 0.5));
  OK(flurry_action_set_bool(list, 1, "bogus", 1));
  FAILS(flurry_action_list_validate(list), FLURRY_ERROR_EFFECT, "actions[1].bogus: unknown field");
  OK(flurry_action_unset(list, 1, "bogus"));
  OK(flurry_action_list_validate(list));
  OK(flurry_action_unset(list, 1, "bogus")); /* not set: nothing to do */
  OK(flurry_action_unset(list, 1, "surface.point"));
  FAILS(flurry_action_unset(list, 1, "type"), FLURRY_ERROR_INVALID_ARGUMENT, "actions[1].type");
  FAILS(flurry_action_unset(list, 1, "x[0]"), FLURRY_ERROR_INVALID_ARGUMENT,
        "actions[1].x[0]: only a named field can be unset");
  FAILS(flurry_action_unset(NULL, 1, "x"), FLURRY_ERROR_NULL_ARGUMENT, "list");
  OK(flurry_action_set_domain(list, 1, "surface", "sphear"));
  FAILS(flurry_action_list_validate(list), FLURRY_ERROR_EFFECT,
        "actions[1].surface.type: unknown domain \"sphear\"; did you mean \"sphere\"?");
  OK(flurry_action_set_json(list, 1, "surface",
                            "{\"type\": \"sphere\", \"center\": [0, 0, 0], \"outerRadius\": -2}"));
  FAILS(flurry_action_list_validate(list), FLURRY_ERROR_EFFECT, "actions[1].surface.outerRadius");
  OK(flurry_action_set_json(list, 1, "surface", "{\"type\": \"plane\", \"normal\": [0, 1, 0]}"));
  OK(flurry_action_set_int(list, 0, "acceleration", 3));
  FAILS(flurry_action_list_validate(list), FLURRY_ERROR_EFFECT,
        "actions[0].acceleration: expected [x, y, z], got a number");
  OK(flurry_action_set_vec4(list, 0, "acceleration", 0, -9.81f, 0, 1));
  FAILS(flurry_action_list_validate(list), FLURRY_ERROR_EFFECT,
        "actions[0].acceleration: expected [x, y, z], got an array of 4");
  OK(flurry_action_set_vec3(list, 0, "acceleration", 0, -9.81f, 0));
  OK(flurry_action_list_validate(list));

  /* Errors caught as the field is set. */
  FAILS(flurry_action_set_float(list, 0, "strength", NAN), FLURRY_ERROR_INVALID_ARGUMENT,
        "actions[0].strength: is NaN");
  FAILS(flurry_action_set_json(list, 1, "surface", "{\"type\": "), FLURRY_ERROR_EFFECT,
        "actions[1].surface: parse error");
  FAILS(flurry_action_set_float(list, 9, "x", 1), FLURRY_ERROR_NOT_FOUND,
        "action index 9: the list has 5 actions");
  FAILS(flurry_action_set_float(list, 0, "a..b", 1), FLURRY_ERROR_INVALID_ARGUMENT,
        "actions[0].a..b: not a field path");
  FAILS(flurry_action_set_float(list, 0, "", 1), FLURRY_ERROR_INVALID_ARGUMENT,
        "an empty field name");
  FAILS(flurry_action_set_float(list, 0, "a[x]", 1), FLURRY_ERROR_INVALID_ARGUMENT,
        "not a field path");
  FAILS(flurry_action_set_float(list, 0, "a[99999999]", 1), FLURRY_ERROR_INVALID_ARGUMENT,
        "an array index above 65536");
  FAILS(flurry_action_set_string(list, 0, "type", "Move"), FLURRY_ERROR_INVALID_ARGUMENT,
        "actions[0].type: the type is set when the action is added");
  FAILS(flurry_action_set_float(NULL, 0, "x", 1), FLURRY_ERROR_NULL_ARGUMENT, "list");
  FAILS(flurry_action_set_float(list, 0, NULL, 1), FLURRY_ERROR_NULL_ARGUMENT, "field");
  FAILS(flurry_action_set_int(NULL, 0, "x", 1), FLURRY_ERROR_NULL_ARGUMENT, "list");
  FAILS(flurry_action_set_bool(NULL, 0, "x", 1), FLURRY_ERROR_NULL_ARGUMENT, "list");
  FAILS(flurry_action_set_vec3(NULL, 0, "x", 1, 1, 1), FLURRY_ERROR_NULL_ARGUMENT, "list");
  FAILS(flurry_action_set_vec4(NULL, 0, "x", 1, 1, 1, 1), FLURRY_ERROR_NULL_ARGUMENT, "list");
  FAILS(flurry_action_set_string(list, 0, "x", NULL), FLURRY_ERROR_NULL_ARGUMENT, "value");
  FAILS(flurry_action_set_domain(list, 0, "x", NULL), FLURRY_ERROR_NULL_ARGUMENT, "domain");
  FAILS(flurry_action_set_json(list, 0, "x", NULL), FLURRY_ERROR_NULL_ARGUMENT, "json");
  FAILS(flurry_action_list_validate(NULL), FLURRY_ERROR_NULL_ARGUMENT, "list");
  FAILS(flurry_action_list_count(NULL, &n), FLURRY_ERROR_NULL_ARGUMENT, "list");
  OK(flurry_action_list_destroy(list));

  /* Emitters. */
  OK(flurry_emitter_create(&em));
  FAILS(flurry_emitter_create(NULL), FLURRY_ERROR_NULL_ARGUMENT, "out");
  OK(flurry_emitter_validate(em)); /* every field has a default */
  OK(flurry_emitter_set_float(em, "rate", -5));
  FAILS(flurry_emitter_validate(em), FLURRY_ERROR_EFFECT, "emitter.rate: ");
  OK(flurry_emitter_set_float(em, "rate", 100));
  OK(flurry_emitter_set_float(em, "stop", INFINITY)); /* "inf" in the format */
  OK(flurry_emitter_set_float(em, "types[0].lifetime", 2));
  OK(flurry_emitter_set_domain(em, "types[0].velocity", "cone"));
  OK(flurry_emitter_set_vec3(em, "types[0].velocity.base", 0, 5, 0));
  OK(flurry_emitter_set_float(em, "types[0].velocity.outerRadius", 1));
  OK(flurry_emitter_set_vec3(em, "types[0].color", 1, 0.5f, 0));
  OK(flurry_emitter_set_vec4(em, "types[0].up", 0, 1, 0, 0));
  FAILS(flurry_emitter_validate(em), FLURRY_ERROR_EFFECT,
        "emitter.types[0].up: expected [x, y, z], got an array of 4");
  OK(flurry_emitter_set_vec3(em, "types[0].up", 0, 1, 0));
  OK(flurry_emitter_validate(em));
  OK(flurry_emitter_set_int(em, "bursts[0].count", 10));
  OK(flurry_emitter_set_bool(em, "bursts[0].repeat", 1));
  FAILS(flurry_emitter_validate(em), FLURRY_ERROR_EFFECT, "emitter.bursts[0].repeat: ");
  OK(flurry_emitter_unset(em, "bursts[0].repeat"));
  OK(flurry_emitter_validate(em));
  FAILS(flurry_emitter_unset(NULL, "rate"), FLURRY_ERROR_NULL_ARGUMENT, "emitter");
  FAILS(flurry_emitter_unset(em, "a."), FLURRY_ERROR_INVALID_ARGUMENT, "not a field path");
  OK(flurry_emitter_set_json(em, "bursts", "[{\"count\": 10}]"));
  OK(flurry_emitter_set_string(em, "name", "nozzle"));
  OK(flurry_emitter_validate(em));
  OK(flurry_emitter_set_float(em, "types[2].weight", 1)); /* types[1] left null */
  FAILS(flurry_emitter_validate(em), FLURRY_ERROR_EFFECT,
        "emitter.types[1]: expected an object, got null");
  OK(flurry_emitter_set_json(em, "types", "[{\"lifetime\": 2, \"velocity\": [0, 3, 0]}]"));
  FAILS(flurry_emitter_set_float(em, "rate", NAN), FLURRY_ERROR_INVALID_ARGUMENT,
        "emitter.rate: is NaN");
  FAILS(flurry_emitter_set_json(em, "shape", "[1, 2"), FLURRY_ERROR_EFFECT,
        "emitter.shape: parse error");
  FAILS(flurry_emitter_set_float(NULL, "rate", 1), FLURRY_ERROR_NULL_ARGUMENT, "emitter");
  FAILS(flurry_emitter_set_int(NULL, "rate", 1), FLURRY_ERROR_NULL_ARGUMENT, "emitter");
  FAILS(flurry_emitter_set_bool(NULL, "rate", 1), FLURRY_ERROR_NULL_ARGUMENT, "emitter");
  FAILS(flurry_emitter_set_vec3(NULL, "p", 1, 1, 1), FLURRY_ERROR_NULL_ARGUMENT, "emitter");
  FAILS(flurry_emitter_set_vec4(NULL, "p", 1, 1, 1, 1), FLURRY_ERROR_NULL_ARGUMENT, "emitter");
  FAILS(flurry_emitter_set_string(em, "name", NULL), FLURRY_ERROR_NULL_ARGUMENT, "value");
  FAILS(flurry_emitter_set_domain(em, "shape", NULL), FLURRY_ERROR_NULL_ARGUMENT, "domain");
  FAILS(flurry_emitter_set_json(NULL, "shape", "1"), FLURRY_ERROR_NULL_ARGUMENT, "emitter");
  FAILS(flurry_emitter_set_float(em, NULL, 1), FLURRY_ERROR_NULL_ARGUMENT, "field");
  FAILS(flurry_emitter_validate(NULL), FLURRY_ERROR_NULL_ARGUMENT, "emitter");
  OK(flurry_emitter_destroy(em));
}

/* A group built in code: stepping, attribute arrays, statistics, packing, VDB. */
static void test_group(const char* out_dir) {
  flurry_context_options o;
  flurry_context* ctx = NULL;
  flurry_group* g = NULL;
  flurry_action_list* list = NULL;
  flurry_emitter* em = NULL;
  flurry_group_stats st;
  const float* y = NULL;
  const float* ages = NULL;
  float* vy = NULL;
  const uint32_t* ids = NULL;
  const uint64_t* per = NULL;
  const flurry_death_event* deaths = NULL;
  uint64_t dropped = 1, died = 0, by_age = 0, absorbed = 0;
  size_t n = 0, count = 0, stride = 0, cap = 0, written = 0, k;
  int stored = -1, empty = -1, step;
  float lo[3], hi[3];
  float eye[3] = {0, 1, 10};
  unsigned char* bytes;
  char path[4096];

  OK(flurry_context_options_init(&o));
  o.seed = 3;
  o.dt = 0.02;
  o.threads = 1;
  OK(flurry_context_create(&o, &ctx));
  OK(flurry_context_create_group(ctx, "water", 200, &g));
  OK(flurry_group_capacity(g, &cap));
  CHECK(cap == 200);

  OK(flurry_emitter_create(&em));
  OK(flurry_emitter_set_domain(em, "shape", "disc"));
  OK(flurry_emitter_set_vec3(em, "shape.normal", 0, 1, 0));
  OK(flurry_emitter_set_float(em, "shape.outerRadius", 0.1));
  OK(flurry_emitter_set_vec3(em, "position", 0, 0.01f, 0));
  OK(flurry_emitter_set_float(em, "rate", 1000));
  OK(flurry_emitter_set_vec3(em, "types[0].velocity", 0, 4, 0));
  OK(flurry_emitter_set_float(em, "types[0].lifetime", 0.5));
  OK(flurry_group_add_emitter(g, em));
  OK(flurry_emitter_set_float(em, "rate", -1));
  FAILS(flurry_group_add_emitter(g, em), FLURRY_ERROR_EFFECT, "emitter.rate: ");
  FAILS(flurry_group_add_emitter(NULL, em), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_add_emitter(g, NULL), FLURRY_ERROR_NULL_ARGUMENT, "emitter");
  OK(flurry_emitter_destroy(em));

  OK(flurry_action_list_create(&list));
  OK(flurry_action_list_add(list, "Gravity", NULL));
  OK(flurry_action_set_vec3(list, 0, "acceleration", 0, -9.81f, 0));
  OK(flurry_action_list_add(list, "Bounce", NULL));
  OK(flurry_action_set_domain(list, 1, "surface", "plane"));
  FAILS(flurry_group_set_actions(g, list), FLURRY_ERROR_EFFECT,
        "actions[1].surface.normal: missing");
  OK(flurry_action_set_vec3(list, 1, "surface.normal", 0, 1, 0));
  OK(flurry_action_list_add(list, "Sink", NULL));
  OK(flurry_action_set_domain(list, 2, "region", "sphere"));
  OK(flurry_action_set_vec3(list, 2, "region.center", 0, 0.5f, 0));
  OK(flurry_action_set_float(list, 2, "region.outerRadius", 0.05));
  OK(flurry_action_list_add(list, "Move", NULL));
  OK(flurry_action_list_add(list, "KillOld", NULL));
  OK(flurry_group_set_actions(g, list));
  FAILS(flurry_group_set_actions(NULL, list), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_set_actions(g, NULL), FLURRY_ERROR_NULL_ARGUMENT, "list");
  OK(flurry_action_list_destroy(list));

  /* Attributes: stored or not, float or uint32. */
  OK(flurry_group_stores(g, FLURRY_ATTR_USER_DATA, &stored));
  CHECK(stored == 0);
  FAILS(flurry_group_lane(g, FLURRY_ATTR_USER_DATA, 0, &y, &count, &stride),
        FLURRY_ERROR_NOT_STORED, "group 'water' does not store userData");
  OK(flurry_group_require(g, FLURRY_ATTR_USER_DATA));
  OK(flurry_group_stores(g, FLURRY_ATTR_USER_DATA, &stored));
  CHECK(stored == 1);
  FAILS(flurry_group_require(g, (flurry_attribute)99), FLURRY_ERROR_INVALID_ARGUMENT,
        "attribute: 99 is not a flurry_attribute");
  FAILS(flurry_group_stores(g, FLURRY_ATTR_COUNT, &stored), FLURRY_ERROR_INVALID_ARGUMENT,
        "attribute");
  FAILS(flurry_group_lane(g, FLURRY_ATTR_ID, 0, &y, &count, &stride), FLURRY_ERROR_WRONG_TYPE,
        "stored as uint32");
  FAILS(flurry_group_lane(g, FLURRY_ATTR_POSITION, 3, &y, &count, &stride),
        FLURRY_ERROR_INVALID_ARGUMENT, "component: 3 is not a component of position");
  FAILS(flurry_group_visible(g, &ids, &count, &stride), FLURRY_ERROR_NOT_STORED, "visible");
  OK(flurry_group_require_instances(g));
  OK(flurry_group_stores(g, FLURRY_ATTR_COLOR, &stored));
  CHECK(stored == 1);

  /* Empty before the first step. */
  OK(flurry_group_lane(g, FLURRY_ATTR_POSITION, 1, &y, &count, &stride));
  CHECK(count == 0);
  OK(flurry_group_bounds(g, lo, hi, &empty));
  CHECK(empty == 1);

  OK(flurry_group_record_deaths(g, 100000));
  for (step = 0; step < 40; ++step) {
    OK(flurry_context_step(ctx));
    OK(flurry_group_deaths(g, &deaths, &count, &dropped));
    for (k = 0; k < count; ++k) {
      died++;
      by_age += deaths[k].action == 4;
      absorbed += deaths[k].action == 2;
      CHECK(deaths[k].time > 0.0 && deaths[k].action != FLURRY_DEATH_NON_FINITE);
    }
    OK(flurry_group_size(g, &n));
    OK(flurry_group_lane(g, FLURRY_ATTR_POSITION, 1, &y, &count, &stride));
    CHECK(count == n && stride == sizeof(float));
    for (k = 0; k < count; ++k) CHECK(*(const float*)((const char*)y + k * stride) >= 0.0f);
  }
  CHECK(n > 50);
  OK(flurry_group_lane(g, FLURRY_ATTR_AGE, 0, &ages, &count, &stride));
  for (k = 0; k < count; ++k) CHECK(ages[k] >= 0.0f && ages[k] <= 0.5f + 0.02f);
  OK(flurry_group_ids(g, &ids, &count, &stride));
  CHECK(count == n && stride == sizeof(uint32_t));
  for (k = 1; k < count; ++k) CHECK(ids[k] != ids[0]);

  /* Written through the mutable lane, read back. */
  OK(flurry_group_lane_mut(g, FLURRY_ATTR_VELOCITY, 1, &vy, &count, &stride));
  CHECK(count == n);
  vy[0] = 123.0f;
  OK(flurry_group_lane(g, FLURRY_ATTR_VELOCITY, 1, &y, &count, &stride));
  CHECK(y[0] == 123.0f);
  FAILS(flurry_group_lane_mut(g, FLURRY_ATTR_VISIBLE, 0, &vy, &count, &stride),
        FLURRY_ERROR_WRONG_TYPE, "visible");

  OK(flurry_group_bounds(g, lo, hi, &empty));
  CHECK(empty == 0 && lo[1] >= 0 && hi[1] >= lo[1]);

  /* Statistics add up. */
  OK(flurry_group_stats_get(g, &st));
  CHECK(st.emitted ==
        n + st.killed_by_age + st.absorbed + st.dropped_at_capacity + st.killed_non_finite);
  CHECK(st.emitted > 0 && st.killed_by_age > 0 && st.absorbed > 0);
  OK(flurry_group_killed_by_action(g, &per, &count));
  CHECK(count == 5 && per[2] == st.absorbed && per[4] == st.killed_by_age);
  /* Every death was recorded, with what killed it. */
  CHECK(dropped == 0 && died == st.killed_by_age + st.absorbed + st.killed_non_finite);
  CHECK(by_age == st.killed_by_age && absorbed == st.absorbed);
  FAILS(flurry_group_deaths(NULL, &deaths, &count, NULL), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_deaths(g, NULL, &count, NULL), FLURRY_ERROR_NULL_ARGUMENT, "events");
  FAILS(flurry_group_record_deaths(NULL, 1), FLURRY_ERROR_NULL_ARGUMENT, "group");
  OK(flurry_group_record_deaths(g, 0));

  OK(flurry_group_emitted_by_generation(g, &per, &count));
  CHECK(count >= 1 && per[0] == st.emitted);

  /* Packed instances: too small a buffer, then the whole group, sorted from an eye. */
  bytes = (unsigned char*)malloc(n * FLURRY_INSTANCE_STRIDE);
  CHECK(bytes != NULL);
  FAILS(flurry_group_pack_instances(g, bytes, FLURRY_INSTANCE_STRIDE, NULL, &written),
        FLURRY_ERROR_INVALID_ARGUMENT, "out");
  FAILS(flurry_group_pack_instances(g, NULL, 64, NULL, &written), FLURRY_ERROR_NULL_ARGUMENT,
        "out");
  OK(flurry_group_pack_instances(g, bytes, n * FLURRY_INSTANCE_STRIDE, NULL, &written));
  CHECK(written == n);
  {
    float rec[8];
    memcpy(rec, bytes, sizeof rec);
    OK(flurry_group_lane(g, FLURRY_ATTR_POSITION, 1, &y, &count, &stride));
    CHECK(rec[1] == y[0]);           /* y of particle 0 */
    CHECK(rec[3] > 0 && rec[7] > 0); /* radius, alpha */
  }
  OK(flurry_group_pack_instances(g, bytes, n * FLURRY_INSTANCE_STRIDE, eye, &written));
  CHECK(written == n);
  {
    float first[8], last[8];
    double d0, d1;
    memcpy(first, bytes, sizeof first);
    memcpy(last, bytes + (written - 1) * FLURRY_INSTANCE_STRIDE, sizeof last);
    d0 = pow(first[0] - eye[0], 2) + pow(first[1] - eye[1], 2) + pow(first[2] - eye[2], 2);
    d1 = pow(last[0] - eye[0], 2) + pow(last[1] - eye[1], 2) + pow(last[2] - eye[2], 2);
    CHECK(d0 >= d1); /* farthest first */
  }
  free(bytes);

  /* VDB export, or a clear "not built". */
  snprintf(path, sizeof path, "%s/water.vdb", out_dir);
  if (flurry_has_vdb()) {
    FILE* f;
    OK(flurry_group_write_vdb(g, path));
    f = fopen(path, "rb");
    CHECK(f != NULL);
    if (f) fclose(f);
    FAILS(flurry_group_write_vdb(g, "/nonexistent-dir/x/y.vdb"), FLURRY_ERROR_IO,
          "/nonexistent-dir/x/y.vdb");
  } else {
    FAILS(flurry_group_write_vdb(g, path), FLURRY_ERROR_NOT_BUILT, "FLURRY_VDB=OFF");
  }
  FAILS(flurry_group_write_vdb(NULL, path), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_write_vdb(g, NULL), FLURRY_ERROR_NULL_ARGUMENT, "path");

  OK(flurry_group_clear(g));
  OK(flurry_group_size(g, &n));
  CHECK(n == 0);

  /* NULL handles and outputs of the group calls. */
  FAILS(flurry_group_name(NULL, NULL), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_size(NULL, &n), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_size(g, NULL), FLURRY_ERROR_NULL_ARGUMENT, "size");
  FAILS(flurry_group_capacity(NULL, &n), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_require(NULL, FLURRY_ATTR_AGE), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_stores(NULL, FLURRY_ATTR_AGE, &stored), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_clear(NULL), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_lane(NULL, FLURRY_ATTR_AGE, 0, &y, &count, &stride),
        FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_lane(g, FLURRY_ATTR_AGE, 0, NULL, &count, &stride), FLURRY_ERROR_NULL_ARGUMENT,
        "data");
  FAILS(flurry_group_lane_mut(NULL, FLURRY_ATTR_AGE, 0, &vy, &count, &stride),
        FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_ids(NULL, &ids, &count, &stride), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_visible(NULL, &ids, &count, &stride), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_bounds(NULL, lo, hi, &empty), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_stats_get(NULL, &st), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_stats_get(g, NULL), FLURRY_ERROR_NULL_ARGUMENT, "stats");
  FAILS(flurry_group_killed_by_action(NULL, &per, &count), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_emitted_by_generation(NULL, &per, &count), FLURRY_ERROR_NULL_ARGUMENT,
        "group");
  FAILS(flurry_group_require_instances(NULL), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_pack_instances(NULL, NULL, 0, NULL, &written), FLURRY_ERROR_NULL_ARGUMENT,
        "group");
  /* A death emitter in another group: each absorbed particle of `g` gives it 2. */
  {
    flurry_group* splash = NULL;
    flurry_group_stats before, after, got;
    size_t size = 0;
    OK(flurry_context_create_group(ctx, "splash", 100000, &splash));
    OK(flurry_group_add_death_emitter(splash,
                                      "{\"source\": \"water\", \"count\": 2, \"cause\": 2,"
                                      " \"types\": [{\"velocity\": [0, 1, 0]}]}"));
    OK(flurry_group_stats_get(g, &before));
    for (step = 0; step < 10; ++step) OK(flurry_context_step(ctx));
    OK(flurry_group_stats_get(g, &after));
    OK(flurry_group_stats_get(splash, &got));
    OK(flurry_group_size(splash, &size));
    CHECK(after.absorbed > before.absorbed);
    CHECK(got.emitted == 2 * (after.absorbed - before.absorbed) && size == got.emitted);
    FAILS(flurry_group_add_death_emitter(splash, "{\"source\": \"water\", \"count\": -1}"),
          FLURRY_ERROR_EFFECT, "deathEmitter.count");
    FAILS(flurry_group_add_death_emitter(splash, NULL), FLURRY_ERROR_NULL_ARGUMENT, "json");
  }
  OK(flurry_context_destroy(ctx));
}

/* A group with a Block action stores Visible. */
static void test_visible(void) {
  flurry_context* ctx = NULL;
  flurry_group* g = NULL;
  flurry_action_list* list = NULL;
  flurry_emitter* em = NULL;
  const uint32_t* vis = NULL;
  size_t count = 0, stride = 0, n = 0, k, hidden = 0;

  OK(flurry_context_create(NULL, &ctx));
  OK(flurry_context_create_group(ctx, "g", 100, &g));
  OK(flurry_emitter_create(&em));
  OK(flurry_emitter_set_json(em, "bursts", "[{\"count\": 50}]"));
  OK(flurry_emitter_set_json(em, "shape",
                             "{\"type\": \"box\", \"min\": [-1, -1, -1], "
                             "\"max\": [1, 1, 1]}"));
  OK(flurry_group_add_emitter(g, em));
  OK(flurry_emitter_destroy(em));
  OK(flurry_action_list_create(&list));
  OK(flurry_action_list_add(list, "Block", NULL));
  OK(flurry_action_set_json(list, 0, "region",
                            "{\"type\": \"box\", \"min\": [0, -2, -2], \"max\": [2, 2, 2]}"));
  OK(flurry_group_set_actions(g, list));
  OK(flurry_action_list_destroy(list));
  OK(flurry_context_step(ctx));
  OK(flurry_group_size(g, &n));
  OK(flurry_group_visible(g, &vis, &count, &stride));
  CHECK(count == n && n == 50 && stride == 4);
  for (k = 0; k < count; ++k) hidden += vis[k] == 0;
  CHECK(hidden > 0 && hidden < n);
  OK(flurry_context_destroy(ctx));
}

/* An instance's transform: a particle born at the local origin appears at its place; the
 * local space carries it along; bad transforms name their field; prewarm steps alone. */
static void test_transform(void) {
  const char* json =
      "{\"name\": \"t\", \"dt\": 0.1, \"groups\": [{\"name\": \"g\", \"capacity\": 4,"
      " \"emitters\": [{\"bursts\": [{\"time\": 0, \"count\": 1}]}],"
      " \"actions\": [{\"type\": \"Move\"}]}]}";
  flurry_effect* fx = NULL;
  flurry_context* ctx = NULL;
  flurry_context_options o;
  flurry_group* g = NULL;
  const float* x = NULL;
  size_t n = 0, stride = 0;
  float pos[3] = {5, 2, -3}, rot[4] = {0, 0, 0, 1}, back[4] = {0}, scale = 0;
  uint64_t steps = 0;
  flurry_space space = FLURRY_SPACE_WORLD;
  const float nanpos[3] = {NAN, 0, 0}, zero[4] = {0, 0, 0, 0};
  OK(flurry_effect_parse(json, "t", &fx));
  OK(flurry_effect_context_options(fx, &o));
  OK(flurry_context_create(&o, &ctx));
  OK(flurry_effect_build(fx, ctx, 0));
  OK(flurry_context_group(ctx, "g", &g));
  OK(flurry_group_set_transform(g, pos, rot, 2.0f));
  OK(flurry_group_transform(g, NULL, back, &scale));
  CHECK(back[3] == 1 && scale == 2.0f);
  OK(flurry_context_step(ctx));
  OK(flurry_group_lane(g, FLURRY_ATTR_POSITION, 0, &x, &n, &stride));
  CHECK(n == 1 && x[0] == 5.0f);
  /* Local space: the particle moves with the group. */
  OK(flurry_group_set_space(g, FLURRY_SPACE_LOCAL));
  OK(flurry_group_space(g, &space));
  CHECK(space == FLURRY_SPACE_LOCAL);
  pos[0] = 7;
  OK(flurry_group_set_transform(g, pos, rot, 2.0f));
  OK(flurry_group_lane(g, FLURRY_ATTR_POSITION, 0, &x, &n, &stride));
  CHECK(n == 1 && x[0] == 7.0f);
  FAILS(flurry_group_set_transform(g, nanpos, rot, 1), FLURRY_ERROR_INVALID_ARGUMENT,
        "transform.position");
  FAILS(flurry_group_set_transform(g, pos, zero, 1), FLURRY_ERROR_INVALID_ARGUMENT,
        "transform.rotation");
  FAILS(flurry_group_set_transform(g, pos, rot, 0), FLURRY_ERROR_INVALID_ARGUMENT,
        "transform.scale");
  FAILS(flurry_group_set_transform(NULL, pos, rot, 1), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_set_transform(g, NULL, rot, 1), FLURRY_ERROR_NULL_ARGUMENT, "position");
  FAILS(flurry_group_set_transform(g, pos, NULL, 1), FLURRY_ERROR_NULL_ARGUMENT, "rotation");
  FAILS(flurry_group_transform(NULL, pos, rot, &scale), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_set_space(NULL, FLURRY_SPACE_LOCAL), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_set_space(g, (flurry_space)7), FLURRY_ERROR_INVALID_ARGUMENT, "space");
  FAILS(flurry_group_space(NULL, &space), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_space(g, NULL), FLURRY_ERROR_NULL_ARGUMENT, "space");
  /* Prewarm: the group alone runs ahead, the context's clock stays. */
  OK(flurry_context_prewarm(ctx, &g, 1, 0.5, &steps));
  CHECK(steps == 5);
  OK(flurry_context_step_index(ctx, &steps));
  CHECK(steps == 1);
  FAILS(flurry_context_prewarm(ctx, &g, 1, -1, NULL), FLURRY_ERROR_INVALID_ARGUMENT, "seconds");
  FAILS(flurry_context_prewarm(NULL, &g, 1, 1, NULL), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  FAILS(flurry_context_prewarm(ctx, NULL, 1, 1, NULL), FLURRY_ERROR_NULL_ARGUMENT, "groups");
  OK(flurry_context_destroy(ctx));
  OK(flurry_effect_destroy(fx));
}

/* Effect instances: built twice in one context, each placed, moved and prewarmed on its own;
 * destroying one removes its groups. */
static void test_instances(void) {
  const char* json =
      "{\"name\": \"t\", \"dt\": 0.1, \"groups\": [{\"name\": \"g\", \"capacity\": 4,"
      " \"emitters\": [{\"bursts\": [{\"time\": 0, \"count\": 1}]}],"
      " \"actions\": [{\"type\": \"Move\"}]}, {\"name\": \"h\", \"capacity\": 4}]}";
  flurry_effect* fx = NULL;
  flurry_context* ctx = NULL;
  flurry_context_options o;
  flurry_instance *a = NULL, *b = NULL, *dup = NULL;
  flurry_group *g = NULL, *found = NULL;
  const char* name = NULL;
  const float* x = NULL;
  size_t n = 0, stride = 0, count = 0;
  float pos[3] = {5, 2, -3}, rot[4] = {0, 0, 0, 1}, back[3] = {0}, scale = 0;
  const float zero[4] = {0, 0, 0, 0};
  uint64_t steps = 0;
  float lo[3], hi[3];
  int empty = -1;
  OK(flurry_effect_parse(json, "t", &fx));
  OK(flurry_effect_context_options(fx, &o));
  OK(flurry_context_create(&o, &ctx));
  OK(flurry_effect_instantiate(fx, ctx, "a", 0, &a));
  OK(flurry_effect_instantiate(fx, ctx, "b", 0, &b));
  OK(flurry_instance_group_count(a, &count));
  CHECK(count == 2);
  OK(flurry_instance_group_at(a, 0, &g));
  OK(flurry_group_name(g, &name));
  CHECK(strcmp(name, "g@a") == 0);
  OK(flurry_context_group(ctx, "g@a", &found));
  CHECK(found == g);
  OK(flurry_instance_set_transform(a, pos, rot, 2.0f));
  OK(flurry_instance_transform(a, back, NULL, &scale));
  CHECK(back[0] == 5.0f && scale == 2.0f);
  OK(flurry_context_step(ctx));
  OK(flurry_group_lane(g, FLURRY_ATTR_POSITION, 0, &x, &n, &stride));
  CHECK(n == 1 && x[0] == 5.0f); /* born at the instance's place */
  OK(flurry_instance_group_at(b, 0, &g));
  OK(flurry_group_lane(g, FLURRY_ATTR_POSITION, 0, &x, &n, &stride));
  CHECK(n == 1 && x[0] == 0.0f); /* the other instance stayed at the origin */
  OK(flurry_instance_bounds(a, lo, hi, &empty));
  CHECK(empty == 0 && lo[0] == 5.0f && hi[0] == 5.0f && lo[2] == -3.0f);
  FAILS(flurry_instance_bounds(NULL, lo, hi, &empty), FLURRY_ERROR_NULL_ARGUMENT, "instance");
  /* A refused transform leaves the instance where it was. */
  FAILS(flurry_instance_set_transform(a, pos, zero, 1), FLURRY_ERROR_INVALID_ARGUMENT,
        "transform.rotation");
  OK(flurry_instance_transform(a, NULL, NULL, &scale));
  CHECK(scale == 2.0f);
  OK(flurry_instance_prewarm(b, 0.5, &steps));
  CHECK(steps == 5);
  /* Its one burst fired: stopped, it is done when no particle is left; killed, at once. */
  OK(flurry_instance_done(a, &empty));
  CHECK(empty == 0);
  OK(flurry_instance_stop(a));
  OK(flurry_instance_done(a, &empty));
  CHECK(empty == 0); /* the drop still lives */
  OK(flurry_instance_kill(a));
  OK(flurry_instance_done(a, &empty));
  CHECK(empty == 1);
  /* Restarted, its burst at 0 fires again (now), then it is killed once more. */
  OK(flurry_instance_restart(a));
  OK(flurry_context_step(ctx));
  OK(flurry_instance_group_at(a, 0, &g));
  OK(flurry_group_size(g, &n));
  CHECK(n == 1);
  OK(flurry_instance_kill(a));
  FAILS(flurry_instance_restart(NULL), FLURRY_ERROR_NULL_ARGUMENT, "instance");
  OK(flurry_instance_group_at(a, 0, &g));
  OK(flurry_group_size(g, &n));
  CHECK(n == 0);
  FAILS(flurry_instance_done(a, NULL), FLURRY_ERROR_NULL_ARGUMENT, "done");
  FAILS(flurry_instance_set_time_scale(a, -1.0), FLURRY_ERROR_INVALID_ARGUMENT, "scale");
  FAILS(flurry_instance_set_time_scale(NULL, 1.0), FLURRY_ERROR_NULL_ARGUMENT, "instance");
  FAILS(flurry_instance_set_seed(NULL, 1), FLURRY_ERROR_NULL_ARGUMENT, "instance");
  OK(flurry_instance_set_time_scale(a, 0.5));
  OK(flurry_instance_set_seed(a, 99));
  FAILS(flurry_instance_set_update_interval(a, 0), FLURRY_ERROR_INVALID_ARGUMENT, "interval");
  FAILS(flurry_instance_set_update_interval(NULL, 2), FLURRY_ERROR_NULL_ARGUMENT, "instance");
  OK(flurry_instance_set_update_interval(a, 4));
  FAILS(flurry_instance_stop(NULL), FLURRY_ERROR_NULL_ARGUMENT, "instance");
  FAILS(flurry_instance_kill(NULL), FLURRY_ERROR_NULL_ARGUMENT, "instance");
  FAILS(flurry_instance_prewarm(b, -1, NULL), FLURRY_ERROR_INVALID_ARGUMENT, "seconds");
  FAILS(flurry_instance_group_at(a, 2, &g), FLURRY_ERROR_NOT_FOUND, "group index 2");
  FAILS(flurry_effect_instantiate(fx, ctx, NULL, 0, &a), FLURRY_ERROR_NULL_ARGUMENT, "name");
  FAILS(flurry_effect_instantiate(NULL, ctx, "c", 0, &a), FLURRY_ERROR_NULL_ARGUMENT, "effect");
  FAILS(flurry_instance_set_transform(NULL, pos, rot, 1), FLURRY_ERROR_NULL_ARGUMENT, "instance");
  FAILS(flurry_instance_set_transform(a, NULL, rot, 1), FLURRY_ERROR_NULL_ARGUMENT, "position");
  FAILS(flurry_instance_group_count(NULL, &count), FLURRY_ERROR_NULL_ARGUMENT, "instance");
  FAILS(flurry_instance_prewarm(NULL, 1, NULL), FLURRY_ERROR_NULL_ARGUMENT, "instance");
  /* One group alone: at half speed its clock takes half of each step (dt 0.1). */
  {
    double t0 = 0, t1 = 0;
    OK(flurry_instance_group_at(b, 1, &g));
    OK(flurry_group_set_time_scale(g, 0.5));
    OK(flurry_context_group_time(ctx, g, &t0));
    OK(flurry_context_step(ctx));
    OK(flurry_context_group_time(ctx, g, &t1));
    CHECK(fabs(t1 - t0 - 0.05) < 1e-12);
    OK(flurry_group_set_seed(g, 5, 1));
    OK(flurry_group_set_update_interval(g, 2));
    FAILS(flurry_group_set_time_scale(g, NAN), FLURRY_ERROR_INVALID_ARGUMENT, "scale");
    FAILS(flurry_group_set_seed(g, 5, 65536), FLURRY_ERROR_INVALID_ARGUMENT, "stream");
    FAILS(flurry_group_set_update_interval(g, 0), FLURRY_ERROR_INVALID_ARGUMENT, "interval");
    FAILS(flurry_group_set_time_scale(NULL, 1), FLURRY_ERROR_NULL_ARGUMENT, "group");
    FAILS(flurry_context_group_time(ctx, g, NULL), FLURRY_ERROR_NULL_ARGUMENT, "time");
  }
  /* The same name twice is refused (its groups exist). */
  CHECK(flurry_effect_instantiate(fx, ctx, "a", 0, &dup) != FLURRY_OK && dup == NULL);
  OK(flurry_context_group_count(ctx, &count));
  CHECK(count == 4);
  OK(flurry_instance_destroy(a));
  OK(flurry_context_group_count(ctx, &count));
  CHECK(count == 2);
  CHECK(flurry_context_group(ctx, "g@a", &found) == FLURRY_ERROR_NOT_FOUND);
  OK(flurry_instance_destroy(NULL));
  OK(flurry_instance_destroy(b));
  OK(flurry_context_destroy(ctx));
  OK(flurry_effect_destroy(fx));
}

/* Drops falling from 1 m on a floor (action 1) under gravity: every collision there, when it
 * happens, arriving downwards. */
static void test_collisions(void) {
  const char* json =
      "{\"name\": \"t\", \"dt\": 0.02, \"groups\": [{\"name\": \"g\", \"capacity\": 1000,"
      " \"emitters\": [{\"rate\": 1000, \"shape\": [0, 1, 0],"
      " \"types\": [{\"velocity\": [0.5, 0, 0], \"lifetime\": 2}]}],"
      " \"actions\": [{\"type\": \"Gravity\", \"acceleration\": [0, -9.81, 0]},"
      " {\"type\": \"Bounce\", \"surface\": {\"type\": \"plane\", \"point\": [0, 0, 0],"
      " \"normal\": [0, 1, 0]}, \"restitution\": 0.5}, {\"type\": \"Move\"},"
      " {\"type\": \"KillOld\"}]}]}";
  flurry_effect* fx = NULL;
  flurry_context* ctx = NULL;
  flurry_context_options o;
  flurry_group* g = NULL;
  const flurry_collision_event* hits = NULL;
  size_t count = 0, k;
  uint64_t dropped = 1, bounced = 0;
  double t0 = 0, t1 = 0;
  int step;
  OK(flurry_effect_parse(json, "t", &fx));
  OK(flurry_effect_context_options(fx, &o));
  OK(flurry_context_create(&o, &ctx));
  OK(flurry_effect_build(fx, ctx, 0));
  OK(flurry_context_group(ctx, "g", &g));
  OK(flurry_group_record_collisions(g, 100000));
  for (step = 0; step < 60; ++step) {
    OK(flurry_context_time(ctx, &t0));
    OK(flurry_context_step(ctx));
    OK(flurry_context_time(ctx, &t1));
    OK(flurry_group_collisions(g, &hits, &count, &dropped));
    for (k = 0; k < count; ++k) {
      bounced++;
      CHECK(hits[k].action == 1 && fabsf(hits[k].position[1]) < 1e-3f);
      CHECK(hits[k].normal[1] == 1.0f && hits[k].velocity[1] < 0.0f);
      CHECK(hits[k].time >= t0 && hits[k].time <= t1 + 1e-9);
    }
  }
  CHECK(bounced > 100 && dropped == 0);
  {
    flurry_context_stats cs;
    size_t alive = 0;
    OK(flurry_context_stats_get(ctx, &cs));
    OK(flurry_group_size(g, &alive));
    CHECK(cs.groups == 1 && cs.instances == 0 && cs.particles == alive && cs.capacity == 1000);
    CHECK(cs.last_step_seconds > 0 && cs.last_act_seconds > 0 && cs.emitted >= alive);
    FAILS(flurry_context_stats_get(NULL, &cs), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
    FAILS(flurry_context_stats_get(ctx, NULL), FLURRY_ERROR_NULL_ARGUMENT, "stats");
  }
  FAILS(flurry_group_collisions(NULL, &hits, &count, NULL), FLURRY_ERROR_NULL_ARGUMENT, "group");
  FAILS(flurry_group_collisions(g, &hits, NULL, NULL), FLURRY_ERROR_NULL_ARGUMENT, "count");
  FAILS(flurry_group_record_collisions(NULL, 1), FLURRY_ERROR_NULL_ARGUMENT, "group");
  OK(flurry_group_record_collisions(g, 0));
  OK(flurry_context_step(ctx));
  OK(flurry_group_collisions(g, &hits, &count, NULL));
  CHECK(count == 0);
  OK(flurry_context_destroy(ctx));
  OK(flurry_effect_destroy(fx));
}

/* Trails from an effect file, packed as ribbons: at most `length` points each, newest (the
 * furthest along +x) first, the radius narrowing from `width` to taper·width, alpha to 0. */
static void test_trails(void) {
  const char* json =
      "{\"name\": \"t\", \"dt\": 0.1, \"groups\": [{\"name\": \"g\", \"capacity\": 100,"
      " \"emitters\": [{\"rate\": 20, \"types\": [{\"velocity\": [1, 0, 0]}]}],"
      " \"actions\": [{\"type\": \"Move\"}],"
      " \"trail\": {\"length\": 4, \"width\": 0.1, \"taper\": 0.5}}]}";
  flurry_effect* fx = NULL;
  flurry_context* ctx = NULL;
  flurry_context_options o;
  flurry_group* g = NULL;
  float out[100 * 4 * 8];
  uint32_t starts[101];
  size_t vertices = 0, strands = 0, alive = 0, k, v, full = 0;
  int step;
  flurry_trail_options bad = {300, 0.0f, 1.0f, 0.0f};
  OK(flurry_effect_parse(json, "t", &fx));
  OK(flurry_effect_context_options(fx, &o));
  OK(flurry_context_create(&o, &ctx));
  OK(flurry_effect_build(fx, ctx, 0));
  OK(flurry_context_group(ctx, "g", &g));
  for (step = 0; step < 6; ++step) OK(flurry_context_step(ctx));
  OK(flurry_group_size(g, &alive));
  OK(flurry_group_pack_trails(g, out, alive * 4, starts, alive + 1, &vertices, &strands));
  CHECK(strands >= 9 && strands <= alive && starts[0] == 0 && starts[strands] == vertices);
  for (k = 0; k < strands; ++k) {
    const size_t first = starts[k], n = starts[k + 1] - starts[k];
    CHECK(n >= 2 && n <= 4);
    if (n == 4) ++full;
    CHECK(fabsf(out[8 * first + 3] - 0.1f) < 1e-6f && fabsf(out[8 * first + 7] - 1.0f) < 1e-6f);
    CHECK(fabsf(out[8 * (first + n - 1) + 3] - 0.05f) < 1e-6f);
    CHECK(out[8 * (first + n - 1) + 7] == 0.0f);
    /* A particle born at the step's very end has not moved in it: its first two are equal. */
    for (v = first + 1; v < first + n; ++v) CHECK(out[8 * v] <= out[8 * (v - 1)]);
    if (n >= 3) CHECK(out[8 * (first + n - 1)] < out[8 * first]);
  }
  CHECK(full > 0);
  FAILS(flurry_group_pack_trails(g, out, 1, starts, alive + 1, &vertices, &strands),
        FLURRY_ERROR_INVALID_ARGUMENT, "capacity_vertices");
  FAILS(flurry_group_pack_trails(g, out, alive * 4, starts, 1, &vertices, &strands),
        FLURRY_ERROR_INVALID_ARGUMENT, "capacity_starts");
  FAILS(flurry_group_set_trail(g, &bad), FLURRY_ERROR_INVALID_ARGUMENT, "trail.length");
  FAILS(flurry_group_set_trail(g, NULL), FLURRY_ERROR_NULL_ARGUMENT, "options");
  bad.length = 0;
  OK(flurry_group_set_trail(g, &bad));
  OK(flurry_group_pack_trails(g, NULL, 0, starts, 1, &vertices, &strands));
  CHECK(vertices == 0 && strands == 0 && starts[0] == 0);
  OK(flurry_context_destroy(ctx));
  OK(flurry_effect_destroy(fx));
}

/* A particle budget: the context stays within it; a group dropping its oldest kills them. */
static void test_budget(void) {
  const char* json =
      "{\"name\": \"t\", \"dt\": 0.1, \"groups\": [{\"name\": \"g\", \"capacity\": 1000,"
      " \"emitters\": [{\"rate\": 100, \"types\": [{\"lifetime\": 50}]}],"
      " \"actions\": [{\"type\": \"Move\"}, {\"type\": \"KillOld\"}],"
      " \"budget\": \"dropOldest\"}]}";
  flurry_effect* fx = NULL;
  flurry_context* ctx = NULL;
  flurry_context_options o;
  flurry_group* g = NULL;
  flurry_group_stats gs;
  flurry_context_stats cs;
  size_t alive = 0;
  OK(flurry_effect_parse(json, "t", &fx));
  OK(flurry_effect_context_options(fx, &o));
  OK(flurry_context_create(&o, &ctx));
  OK(flurry_effect_build(fx, ctx, 0));
  OK(flurry_context_group(ctx, "g", &g));
  OK(flurry_context_set_particle_budget(ctx, 25));
  OK(flurry_context_run(ctx, 10));
  OK(flurry_group_size(g, &alive));
  OK(flurry_group_stats_get(g, &gs));
  OK(flurry_context_stats_get(ctx, &cs));
  CHECK(alive == 25 && gs.killed_by_budget == 75 && gs.dropped_at_budget == 0);
  CHECK(cs.killed_by_budget == 75 && cs.particles == 25);
  OK(flurry_group_set_budget_policy(g, FLURRY_BUDGET_DROP_NEWEST));
  OK(flurry_context_run(ctx, 10));
  OK(flurry_group_stats_get(g, &gs));
  CHECK(gs.dropped_at_budget == 100 && gs.killed_by_budget == 75);
  FAILS(flurry_group_set_budget_policy(g, 9), FLURRY_ERROR_INVALID_ARGUMENT, "policy");
  FAILS(flurry_context_set_particle_budget(NULL, 1), FLURRY_ERROR_NULL_ARGUMENT, "ctx");
  OK(flurry_context_destroy(ctx));
  OK(flurry_effect_destroy(fx));
}

/* A job system in a few lines: every task on the calling thread, last first. */
typedef struct reverse_scheduler {
  int calls;
  size_t tasks;
} reverse_scheduler;

static void reverse_parallel_for(void* user, size_t count, flurry_task_fn task, void* context) {
  reverse_scheduler* s = (reverse_scheduler*)user;
  size_t i;
  ++s->calls;
  s->tasks += count;
  for (i = count; i-- > 0;) task(context, i);
}

/* 100,000 particles born at once (the emission and the pass in several tasks), 3 steps:
 * their x positions, copied into `x`. */
static void burst_positions(const flurry_scheduler* scheduler, float* x, size_t* n) {
  const char* json =
      "{\"name\": \"t\", \"dt\": 0.05, \"groups\": [{\"name\": \"g\", \"capacity\": 100000,"
      " \"emitters\": [{\"bursts\": [{\"time\": 0, \"count\": 100000}], \"types\":"
      " [{\"velocity\": {\"type\": \"sphere\", \"center\": [0, 1, 0], \"outerRadius\": 1}}]}],"
      " \"actions\": [{\"type\": \"Gravity\", \"acceleration\": [0, -9.8, 0]},"
      " {\"type\": \"Move\"}]}]}";
  flurry_effect* fx = NULL;
  flurry_context* ctx = NULL;
  flurry_context_options o;
  flurry_group* g = NULL;
  const float* lane = NULL;
  size_t stride = 0;
  *n = 0;
  OK(flurry_effect_parse(json, "t", &fx));
  OK(flurry_effect_context_options(fx, &o));
  o.threads = scheduler ? 0 : 1;
  if (scheduler)
    OK(flurry_context_create_with_scheduler(&o, scheduler, &ctx));
  else
    OK(flurry_context_create(&o, &ctx));
  OK(flurry_effect_build(fx, ctx, 0));
  OK(flurry_context_run(ctx, 3));
  OK(flurry_context_group(ctx, "g", &g));
  OK(flurry_group_lane(g, FLURRY_ATTR_POSITION, 0, &lane, n, &stride));
  if (lane && *n <= 100000) memcpy(x, lane, *n * sizeof(float));
  OK(flurry_context_destroy(ctx));
  OK(flurry_effect_destroy(fx));
}

static void test_scheduler(void) {
  static float own[100000], theirs[100000];
  size_t n_own = 0, n_theirs = 0;
  reverse_scheduler counts = {0, 0};
  flurry_scheduler s;
  flurry_context_options o;
  flurry_context* ctx = NULL;
  s.user = &counts;
  s.concurrency = 4;
  s.parallel_for = reverse_parallel_for;
  burst_positions(NULL, own, &n_own);
  burst_positions(&s, theirs, &n_theirs);
  CHECK(n_own == 100000 && n_theirs == n_own);
  CHECK(memcmp(own, theirs, n_own * sizeof(float)) == 0); /* bitwise, in any order */
  CHECK(counts.calls >= 3 && counts.tasks > (size_t)counts.calls);
  OK(flurry_context_options_init(&o));
  o.threads = 2;
  FAILS(flurry_context_create_with_scheduler(&o, &s, &ctx), FLURRY_ERROR_INVALID_ARGUMENT,
        "threads");
  CHECK(ctx == NULL);
  o.threads = 0;
  FAILS(flurry_context_create_with_scheduler(&o, NULL, &ctx), FLURRY_ERROR_NULL_ARGUMENT,
        "scheduler");
  s.concurrency = 0;
  FAILS(flurry_context_create_with_scheduler(&o, &s, &ctx), FLURRY_ERROR_INVALID_ARGUMENT,
        "concurrency");
  s.concurrency = 2;
  s.parallel_for = NULL;
  FAILS(flurry_context_create_with_scheduler(&o, &s, &ctx), FLURRY_ERROR_INVALID_ARGUMENT,
        "parallel_for");
}

int main(int argc, char** argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: test_c_api FOUNTAIN_JSON OUT_DIR\n");
    return 2;
  }
  CHECK(strcmp(flurry_last_error(), "") == 0);
  test_version_and_errors();
  test_context();
  test_missing_device();
  test_effects(argv[1]);
  test_building();
  test_group(argv[2]);
  test_visible();
  test_transform();
  test_instances();
  test_scheduler();
  test_collisions();
  test_trails();
  test_budget();
  if (failures) {
    fprintf(stderr, "%d checks failed\n", failures);
    return 1;
  }
  printf("C API: all checks passed\n");
  return 0;
}
