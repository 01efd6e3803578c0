#include <algorithm>
#include <cstring>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "flurry/render.hpp"
#include "render/gl.hpp"
#include "render/platform.hpp"

namespace flurry {

struct OffscreenRenderer::Impl {
  std::shared_ptr<detail::GlfwSession> session;
  GLFWwindow* window = nullptr;
  std::unique_ptr<Renderer> renderer;
  int width = 0, height = 0, samples = 0;
  GLuint msFbo = 0, msColor = 0, msDepth = 0;  // where it draws (multisampled if asked)
  GLuint fbo = 0, color = 0, depth = 0;        // what is read back
  std::string info;

  void current() const { glfwMakeContextCurrent(window); }

  static void attach(GLuint& fb, GLuint& col, GLuint& dep, int w, int h, int s) {
    glGenFramebuffers(1, &fb);
    glBindFramebuffer(GL_FRAMEBUFFER, fb);
    glGenRenderbuffers(1, &col);
    glBindRenderbuffer(GL_RENDERBUFFER, col);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, s, GL_RGBA8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, col);
    glGenRenderbuffers(1, &dep);
    glBindRenderbuffer(GL_RENDERBUFFER, dep);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, s, GL_DEPTH_COMPONENT24, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, dep);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw RenderError("no usable OpenGL: cannot make a " + std::to_string(w) + "x" +
                        std::to_string(h) + " framebuffer with " + std::to_string(s) + " samples");
  }

  void release() {
    if (!window) return;
    current();
    renderer.reset();
    const GLuint fbs[] = {msFbo, fbo};
    glDeleteFramebuffers(2, fbs);
    const GLuint rbs[] = {msColor, msDepth, color, depth};
    glDeleteRenderbuffers(4, rbs);
    glfwMakeContextCurrent(nullptr);
    glfwDestroyWindow(window);
    window = nullptr;
  }
};

OffscreenRenderer::OffscreenRenderer(OffscreenOptions options, RenderSettings settings)
    : impl_(std::make_unique<Impl>()) {
  if (options.width <= 0 || options.height <= 0 || options.width > 16384 || options.height > 16384)
    throw InvalidArgument("size", "width and height must be within 1..16384, not " +
                                      std::to_string(options.width) + "x" +
                                      std::to_string(options.height));
  Impl& d = *impl_;
  d.session = detail::GlfwSession::acquire(true);
  d.width = options.width;
  d.height = options.height;
  d.samples = options.samples > 1 ? options.samples : 0;
  try {
    // The window is never shown and never drawn to; the framebuffer objects are the target.
    d.window = d.session->createWindow(16, 16, "flurry offscreen", false);
    GLint maxSamples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
    d.samples = std::min(d.samples, int(maxSamples));
    if (d.samples > 0) Impl::attach(d.msFbo, d.msColor, d.msDepth, d.width, d.height, d.samples);
    Impl::attach(d.fbo, d.color, d.depth, d.width, d.height, 0);
    d.info = std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))) + ", " +
             reinterpret_cast<const char*>(glGetString(GL_VERSION));
    d.renderer = std::make_unique<Renderer>(std::move(settings));
  } catch (...) {
    d.release();
    throw;
  }
}

OffscreenRenderer::~OffscreenRenderer() {
  impl_->release();
}

RenderSettings& OffscreenRenderer::settings() {
  return impl_->renderer->settings();
}
std::size_t OffscreenRenderer::lastDrawn() const {
  return impl_->renderer->lastDrawn();
}
std::string OffscreenRenderer::glInfo() const {
  return impl_->info;
}
bool OffscreenRenderer::startedXvfb() const {
  return impl_->session->startedXvfb();
}

Image OffscreenRenderer::render(std::span<const Group* const> groups, const Strands* strands) {
  Impl& d = *impl_;
  d.current();
  glBindFramebuffer(GL_FRAMEBUFFER, d.samples > 0 ? d.msFbo : d.fbo);
  d.renderer->begin(d.width, d.height);
  // Strands first: they write depth, so particles behind them are hidden.
  if (strands) d.renderer->draw(*strands);
  for (const Group* g : groups) d.renderer->draw(*g);
  d.renderer->end();
  if (d.samples > 0) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, d.msFbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, d.fbo);
    glBlitFramebuffer(0, 0, d.width, d.height, 0, 0, d.width, d.height, GL_COLOR_BUFFER_BIT,
                      GL_NEAREST);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, d.fbo);
  Image img;
  img.width = d.width;
  img.height = d.height;
  img.rgba.resize(std::size_t(d.width) * d.height * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, d.width, d.height, GL_RGBA, GL_UNSIGNED_BYTE, img.rgba.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    throw RenderError("OpenGL error " + std::to_string(e) + " rendering a frame");
  // GL's rows run bottom to top; images run top to bottom.
  const std::size_t row = std::size_t(d.width) * 4;
  for (int y = 0; y < d.height / 2; ++y)
    std::swap_ranges(img.rgba.begin() + std::ptrdiff_t(y * row),
                     img.rgba.begin() + std::ptrdiff_t((y + 1) * row),
                     img.rgba.begin() + std::ptrdiff_t((d.height - 1 - y) * row));
  // Images hold straight alpha; blending on a transparent background left it premultiplied
  // (the tone map already divides it out).
  const RenderSettings& rs = d.renderer->settings();
  if (rs.transparent && rs.toneMap == ToneMap::None)
    for (std::size_t i = 0; i < img.rgba.size(); i += 4) {
      const unsigned a = img.rgba[i + 3];
      for (std::size_t c = 0; c < 3; ++c)
        img.rgba[i + c] =
            a == 0 ? 0 : std::uint8_t(std::min(255u, (img.rgba[i + c] * 255u + a / 2) / a));
    }
  return img;
}

Image OffscreenRenderer::render(const Group& group) {
  const Group* g[] = {&group};
  return render(g, nullptr);
}

Image OffscreenRenderer::render(const Strands& strands) {
  return render({}, &strands);
}

}  // namespace flurry
