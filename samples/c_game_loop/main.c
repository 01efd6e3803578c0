/* How a game embeds Flurry through the C API: load an effect, step it at a fixed display rate
 * (the simulation owes dt-sized steps for each displayed frame's time), and draw the particles
 * with the game's own OpenGL from the packed instance data (position, radius, color).
 *
 *   c_game_loop [EFFECT.json] [--frames N] [--rate HZ]
 *
 * --frames N closes the window after N frames (the test runs it under Xvfb); --rate sets the
 * display rate the simulation keeps up with (default: the monitor's, else 60 Hz). */
#include <GLFW/glfw3.h>
#include <flurry.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Prints the failing call's message and leaves. */
#define TRY(call)                                                                            \
  do {                                                                                       \
    flurry_status s_ = (call);                                                               \
    if (s_ != FLURRY_OK) {                                                                   \
      fprintf(stderr, "c_game_loop: %s: %s\n", flurry_status_name(s_), flurry_last_error()); \
      goto done;                                                                             \
    }                                                                                        \
  } while (0)

int main(int argc, char** argv) {
  const char* path = FLURRY_SAMPLE_EFFECT;
  long frames = -1; /* run until the window closes */
  double rate = 0.0;
  int i, code = 1;
  flurry_effect* fx = NULL;
  flurry_context* ctx = NULL;
  flurry_group* group = NULL;
  flurry_context_options options;
  GLFWwindow* window = NULL;
  unsigned char* buffer = NULL;
  size_t capacity = 0, drawn = 0;
  double dt = 0.0, owed = 0.0;
  uint64_t steps = 0;
  long frame = 0;

  for (i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc)
      frames = strtol(argv[++i], NULL, 10);
    else if (strcmp(argv[i], "--rate") == 0 && i + 1 < argc)
      rate = strtod(argv[++i], NULL);
    else if (argv[i][0] != '-')
      path = argv[i];
    else {
      fprintf(stderr, "usage: c_game_loop [EFFECT.json] [--frames N] [--rate HZ]\n");
      return 2;
    }
  }

  /* The effect, its context and its first group. */
  TRY(flurry_effect_load(path, &fx));
  TRY(flurry_effect_context_options(fx, &options));
  options.backend = FLURRY_BACKEND_AUTO; /* OpenCL where there is a device, else the CPU */
  TRY(flurry_context_create(&options, &ctx));
  TRY(flurry_effect_build(fx, ctx, 0));
  TRY(flurry_context_group_at(ctx, 0, &group));
  TRY(flurry_group_require_instances(group)); /* the attributes the packed record reads */
  TRY(flurry_group_capacity(group, &capacity));
  TRY(flurry_context_time_step(ctx, &dt));
  buffer = (unsigned char*)malloc(capacity * FLURRY_INSTANCE_STRIDE); /* allocated once */
  if (!buffer) goto done;

  if (!glfwInit()) {
    fprintf(stderr, "c_game_loop: GLFW cannot start (no display?)\n");
    goto done;
  }
  window = glfwCreateWindow(800, 600, "Flurry from C", NULL, NULL);
  if (!window) {
    fprintf(stderr, "c_game_loop: no OpenGL window\n");
    goto done;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  if (rate <= 0) {
    const GLFWvidmode* mode = glfwGetVideoMode(glfwGetPrimaryMonitor());
    rate = mode && mode->refreshRate > 0 ? mode->refreshRate : 60.0;
  }

  while (!glfwWindowShouldClose(window) && (frames < 0 || frame < frames)) {
    int width, height;
    /* The simulation keeps the display's pace: each frame shows 1/rate s more of it. */
    owed += 1.0 / rate;
    while (owed >= dt) {
      TRY(flurry_context_step(ctx));
      owed -= dt;
      ++steps;
    }
    /* Farthest first from the eye: blending needs no depth buffer then. */
    {
      const float eye[3] = {0.0f, 3.0f, 12.0f};
      TRY(flurry_group_pack_instances(group, buffer, capacity * FLURRY_INSTANCE_STRIDE, eye,
                                      &drawn));
    }

    glfwGetFramebufferSize(window, &width, &height);
    glViewport(0, 0, width, height);
    glClearColor(0.05f, 0.05f, 0.08f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glFrustum(-0.1 * width / (height ? height : 1), 0.1 * width / (height ? height : 1), -0.1, 0.1,
              0.2, 100.0);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glTranslatef(0.0f, -3.0f, -12.0f);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glPointSize(3.0f);
    /* The packed record: x y z radius r g b a, 32 bytes. */
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, FLURRY_INSTANCE_STRIDE, buffer);
    glColorPointer(4, GL_FLOAT, FLURRY_INSTANCE_STRIDE, buffer + 16);
    glDrawArrays(GL_POINTS, 0, (GLsizei)drawn);
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    if (glGetError() != GL_NO_ERROR) {
      fprintf(stderr, "c_game_loop: an OpenGL error\n");
      goto done;
    }
    glfwSwapBuffers(window);
    glfwPollEvents();
    ++frame;
  }
  printf("c_game_loop: %ld frames at %g Hz, %llu steps of %g s, %zu particles drawn\n", frame, rate,
         (unsigned long long)steps, dt, drawn);
  code = 0;

done:
  if (window) glfwDestroyWindow(window);
  glfwTerminate();
  free(buffer);
  flurry_context_destroy(ctx);
  flurry_effect_destroy(fx);
  return code;
}
