// The interactive viewer: a GLFW window drawing a live scene with flurry::Renderer.
//
//   mouse drag: orbit; wheel: zoom; space: pause / run; right arrow or S: one step while
//   paused; R: restart (builds the scene again); Esc or Q: quit. The title bar shows the
//   particle count, the step time and the frame rate.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "flurry/context.hpp"
#include "flurry/render.hpp"

namespace flurry {

/// What the viewer shows: a context stepped in real time (as many steps of its time step as
/// the wall clock has advanced, at most 4 a frame), and optional static strands.
struct ViewerScene {
  std::unique_ptr<Context> context;
  Strands strands;
};

struct ViewerOptions {
  std::string title = "flurry";
  int width = 1280;
  int height = 720;
  /// Close by itself after this many frames (0: when the user closes the window).
  int maxFrames = 0;
  bool vsync = true;
};

/// Opens the window (a display is needed: throws RenderError if DISPLAY is unusable) and
/// runs until it is closed. `build` makes the scene, at start and on every restart; the
/// viewer requires Renderer::attributes() of every group before the first step.
void runViewer(const std::function<ViewerScene()>& build, RenderSettings settings = {},
               ViewerOptions options = {});

}  // namespace flurry
