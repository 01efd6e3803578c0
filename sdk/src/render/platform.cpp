#include "render/platform.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <optional>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "flurry/render.hpp"

extern char** environ;

namespace flurry::detail {

namespace {

thread_local std::string tGlfwError;

void onGlfwError(int code, const char* description) {
  tGlfwError = std::string(description ? description : "unknown error") + " (GLFW error 0x" +
               [code] {
                 char b[16];
                 std::snprintf(b, sizeof b, "%x", code);
                 return std::string(b);
               }() +
               ")";
}

// Sets an environment variable for the scope, restoring the previous value after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

void stopChild(pid_t pid) {
  if (kill(pid, SIGTERM) != 0) return;
  // Xvfb exits within milliseconds on SIGTERM; do not wait forever on a wedged one.
  for (int i = 0; i < 200; ++i) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return;
    usleep(10'000);
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
}

}  // namespace

std::string lastGlfwError() {
  return tGlfwError;
}

std::unique_ptr<XServer> XServer::start(std::string& why) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    why = std::string("pipe: ") + std::strerror(errno);
    return nullptr;
  }
  // The child gets the pipe's write end as fd 3 (dup2 clears close-on-exec on the copy);
  // Xvfb writes the display number it picked there once it accepts connections.
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, fds[1], 3);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  // -terminate: the server exits when its last client (us) disconnects, so it does not
  // outlive a process that dies without running destructors.
  const char* argv[] = {"Xvfb",         "-displayfd", "3",   "-screen",    "0",
                        "1920x1080x24", "-nolisten",  "tcp", "-terminate", nullptr};
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "Xvfb", &fa, nullptr, const_cast<char* const*>(argv), environ);
  posix_spawn_file_actions_destroy(&fa);
  close(fds[1]);
  if (rc != 0) {
    close(fds[0]);
    why = std::string("cannot start Xvfb: ") + std::strerror(rc) +
          (rc == ENOENT ? " (install the xvfb package, or set DISPLAY)" : "");
    return nullptr;
  }
  std::string number;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(15);
  while (number.find('\n') == std::string::npos) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                          deadline - std::chrono::steady_clock::now())
                          .count();
    pollfd p{fds[0], POLLIN, 0};
    if (left <= 0 || poll(&p, 1, int(left)) <= 0) {
      why = "Xvfb did not report a display within 15 s";
      break;
    }
    char buf[32];
    const ssize_t n = read(fds[0], buf, sizeof buf);
    if (n <= 0) {
      why = "Xvfb exited before reporting a display";
      break;
    }
    number.append(buf, std::size_t(n));
  }
  close(fds[0]);
  const auto nl = number.find('\n');
  if (nl == std::string::npos || nl == 0) {
    stopChild(pid);
    return nullptr;
  }
  std::string display = ":";
  display.append(number, 0, nl);
  return std::unique_ptr<XServer>(new XServer(pid, std::move(display)));
}

XServer::~XServer() {
  stopChild(pid_);
}

namespace {
std::mutex gSessionMutex;
std::weak_ptr<GlfwSession> gSession;
}  // namespace

std::shared_ptr<GlfwSession> GlfwSession::acquire(bool allowXvfb) {
  std::lock_guard lock(gSessionMutex);
  if (auto s = gSession.lock()) return s;
  glfwSetErrorCallback(onGlfwError);
  std::shared_ptr<GlfwSession> s(new GlfwSession);
  std::string why;
  const char* display = std::getenv("DISPLAY");
  bool ok = false;
  if (display && *display) {
    tGlfwError.clear();
    ok = glfwInit() == GLFW_TRUE;
    if (!ok) why = "cannot use DISPLAY=" + std::string(display) + ": " + lastGlfwError();
  } else {
    why = "DISPLAY is not set";
  }
  if (!ok && allowXvfb) {
    std::string xwhy;
    s->xserver_ = XServer::start(xwhy);
    if (!s->xserver_) {
      why += "; " + xwhy;
    } else {
      // GLFW opens the display named by $DISPLAY in glfwInit and keeps the connection.
      ScopedEnv env("DISPLAY", s->xserver_->display());
      tGlfwError.clear();
      ok = glfwInit() == GLFW_TRUE;
      if (!ok) {
        why +=
            "; Xvfb on " + s->xserver_->display() + " started but GLFW failed: " + lastGlfwError();
        s->xserver_.reset();
      }
    }
  }
  if (!ok) throw RenderError("no usable OpenGL: " + why);
  gSession = s;
  return s;
}

GlfwSession::~GlfwSession() {
  glfwTerminate();
  xserver_.reset();
}

GLFWwindow* GlfwSession::createWindow(int width, int height, const char* title, bool visible,
                                      int samples) {
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
  glfwWindowHint(GLFW_SAMPLES, samples);
  tGlfwError.clear();
  GLFWwindow* w = glfwCreateWindow(width, height, title, nullptr, nullptr);
  if (!w) throw RenderError("no usable OpenGL: no OpenGL 3.3 core context: " + lastGlfwError());
  glfwMakeContextCurrent(w);
  return w;
}

}  // namespace flurry::detail
