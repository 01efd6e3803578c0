#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "flurry/render_viewer.hpp"
#include "render/gl.hpp"
#include "render/platform.hpp"

namespace flurry {

namespace {

// What the input callbacks change; reached through the window's user pointer.
struct ViewerState {
  Camera* camera = nullptr;
  bool paused = false;
  bool stepOnce = false;
  bool restart = false;
  bool dragging = false;
  double lastX = 0, lastY = 0;
};

ViewerState& state(GLFWwindow* w) {
  return *static_cast<ViewerState*>(glfwGetWindowUserPointer(w));
}

void onKey(GLFWwindow* w, int key, int /*scancode*/, int action, int /*mods*/) {
  if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
  ViewerState& s = state(w);
  switch (key) {
    case GLFW_KEY_SPACE:
      if (action == GLFW_PRESS) s.paused = !s.paused;
      break;
    case GLFW_KEY_RIGHT:
    case GLFW_KEY_S:
      s.stepOnce = true;
      break;
    case GLFW_KEY_R:
      if (action == GLFW_PRESS) s.restart = true;
      break;
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q:
      glfwSetWindowShouldClose(w, GLFW_TRUE);
      break;
    default:
      break;
  }
}

void onButton(GLFWwindow* w, int button, int action, int /*mods*/) {
  if (button != GLFW_MOUSE_BUTTON_LEFT) return;
  ViewerState& s = state(w);
  s.dragging = action == GLFW_PRESS;
  glfwGetCursorPos(w, &s.lastX, &s.lastY);
}

void onCursor(GLFWwindow* w, double x, double y) {
  ViewerState& s = state(w);
  if (!s.dragging) return;
  s.camera->yaw -= float(x - s.lastX) * 0.3f;
  s.camera->pitch = std::clamp(s.camera->pitch + float(y - s.lastY) * 0.3f, -89.0f, 89.0f);
  s.lastX = x;
  s.lastY = y;
}

void onScroll(GLFWwindow* w, double /*dx*/, double dy) {
  Camera& c = *state(w).camera;
  c.distance = std::clamp(c.distance * float(std::pow(0.9, dy)), 0.01f, c.farPlane * 0.5f);
}

}  // namespace

void runViewer(const std::function<ViewerScene()>& build, RenderSettings settings,
               ViewerOptions options) {
  auto session = detail::GlfwSession::acquire(false);
  GLFWwindow* window =
      session->createWindow(options.width, options.height, options.title.c_str(), true, 4);
  struct WindowGuard {
    GLFWwindow* w;
    ~WindowGuard() {
      glfwMakeContextCurrent(nullptr);
      glfwDestroyWindow(w);
    }
  } guard{window};
  glfwSwapInterval(options.vsync ? 1 : 0);
  glEnable(GL_MULTISAMPLE);

  // The renderer's GL objects must go before the window's context does.
  auto renderer = std::make_unique<Renderer>(std::move(settings));
  ViewerState st;
  st.camera = &renderer->settings().camera;
  glfwSetWindowUserPointer(window, &st);
  glfwSetKeyCallback(window, onKey);
  glfwSetMouseButtonCallback(window, onButton);
  glfwSetCursorPosCallback(window, onCursor);
  glfwSetScrollCallback(window, onScroll);

  auto load = [&] {
    ViewerScene scene = build();
    if (!scene.context) throw InvalidArgument("build", "the viewer's scene has no context");
    for (Group* g : scene.context->groups()) g->require(Renderer::attributes());
    return scene;
  };
  ViewerScene scene = load();
  double stepMs = 0.0;  // smoothed
  int frames = 0, framesSinceTitle = 0;
  auto titleClock = std::chrono::steady_clock::now();
  auto lastFrame = titleClock;
  double wall = 0.0;  // seconds the scene has run (paused time excluded)
  try {
    while (!glfwWindowShouldClose(window)) {
      glfwPollEvents();
      if (st.restart) {
        st.restart = false;
        scene = load();
        wall = 0.0;
      }
      // Real time: step while the simulation is behind the wall clock, at most 4 steps a
      // frame (a slow effect then plays slower rather than stalling the window).
      const auto frameStart = std::chrono::steady_clock::now();
      if (!st.paused) wall += std::chrono::duration<double>(frameStart - lastFrame).count();
      lastFrame = frameStart;
      int steps = 0;
      if (st.stepOnce) {
        st.stepOnce = false;
        steps = 1;
      } else if (!st.paused) {
        const double dt = scene.context->timeStep();
        while (steps < 4 && scene.context->time() + double(steps) * dt < wall) ++steps;
        if (steps == 4) wall = scene.context->time() + 4 * dt;  // drop what cannot be caught up
      }
      for (int k = 0; k < steps; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        scene.context->step();
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        stepMs = stepMs == 0.0 ? ms : 0.9 * stepMs + 0.1 * ms;
      }
      int w = 0, h = 0;
      glfwGetFramebufferSize(window, &w, &h);
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      renderer->begin(w, h);
      if (scene.strands.size() > 0) renderer->draw(scene.strands);
      std::size_t live = 0;
      for (Group* g : scene.context->groups()) {
        renderer->draw(*g);
        live += g->size();
      }
      renderer->end();
      glfwSwapBuffers(window);
      ++frames;
      ++framesSinceTitle;
      const auto now = std::chrono::steady_clock::now();
      const double since = std::chrono::duration<double>(now - titleClock).count();
      if (since >= 0.5 || frames == 1) {
        char title[256];
        std::snprintf(title, sizeof title,
                      "%s | %zu particles | step %.2f ms | %.0f fps | t=%.2fs%s",
                      options.title.c_str(), live, stepMs, framesSinceTitle / std::max(since, 1e-3),
                      scene.context->time(), st.paused ? " | paused" : "");
        glfwSetWindowTitle(window, title);
        titleClock = now;
        framesSinceTitle = 0;
      }
      if (options.maxFrames > 0 && frames >= options.maxFrames) break;
    }
  } catch (...) {
    renderer.reset();
    throw;
  }
  renderer.reset();
}

}  // namespace flurry
