// Windows and contexts: GLFW initialisation shared by the process, and a private Xvfb when
// there is no display to use.
#pragma once

#include <sys/types.h>

#include <memory>
#include <string>

struct GLFWwindow;

namespace flurry::detail {

/// An Xvfb child process on a display number it picked itself (-displayfd).
class XServer {
 public:
  /// Starts Xvfb; returns null and sets `why` when it cannot.
  static std::unique_ptr<XServer> start(std::string& why);
  ~XServer();
  XServer(const XServer&) = delete;
  XServer& operator=(const XServer&) = delete;

  const std::string& display() const { return display_; }  ///< ":N"
  pid_t pid() const { return pid_; }

 private:
  XServer(pid_t pid, std::string display) : pid_(pid), display_(std::move(display)) {}
  pid_t pid_;
  std::string display_;
};

/// glfwInit() for as long as someone holds the session; glfwTerminate() then stops the
/// private Xvfb, if one was started (in that order: Xlib exits the process when its server
/// goes away under it).
class GlfwSession {
 public:
  /// The process's session, made on first use. With `allowXvfb`, a missing or unusable
  /// DISPLAY is replaced by a private Xvfb. Throws RenderError "no usable OpenGL: ...".
  static std::shared_ptr<GlfwSession> acquire(bool allowXvfb);
  ~GlfwSession();

  bool startedXvfb() const { return xserver_ != nullptr; }

  /// A window with an OpenGL 3.3 core context, made current; throws RenderError.
  GLFWwindow* createWindow(int width, int height, const char* title, bool visible, int samples = 0);

 private:
  GlfwSession() = default;
  std::unique_ptr<XServer> xserver_;
};

/// The description of the last GLFW error on this thread ("" if none).
std::string lastGlfwError();

}  // namespace flurry::detail
