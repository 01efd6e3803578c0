#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "flurry/interop.hpp"
#include "flurry/render.hpp"
#include "render/gl.hpp"
#include "render/shaders.hpp"
#include "render/sprites.hpp"

namespace flurry {

Vec3 Camera::eye() const {
  const float y = glm::radians(yaw), p = glm::radians(pitch);
  return target +
         distance * Vec3(std::cos(p) * std::sin(y), std::sin(p), std::cos(p) * std::cos(y));
}

namespace {

GLuint compile(GLenum type, const std::string& src, const char* what) {
  const GLuint s = glCreateShader(type);
  const char* text = src.c_str();
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    glDeleteShader(s);
    throw RenderError(std::string("shader ") + what + " failed to compile: " + log);
  }
  return s;
}

GLuint link(const std::string& vs, const std::string& fs, const char* what) {
  const std::string head = "#version 330 core\n";
  const GLuint v = compile(GL_VERTEX_SHADER, head + vs, what);
  GLuint f = 0;
  try {
    f = compile(GL_FRAGMENT_SHADER, head + fs, what);
  } catch (...) {
    glDeleteShader(v);
    throw;
  }
  const GLuint p = glCreateProgram();
  glAttachShader(p, v);
  glAttachShader(p, f);
  glLinkProgram(p);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    glDeleteProgram(p);
    throw RenderError(std::string("shader ") + what + " failed to link: " + log);
  }
  return p;
}

GLint loc(GLuint program, const char* name) {
  return glGetUniformLocation(program, name);
}

}  // namespace

struct Renderer::Impl {
  RenderSettings settings;
  GLuint billboard = 0, points = 0, strands = 0;
  GLuint quadVbo = 0, instanceVbo = 0, strandVbo = 0;
  GLuint billboardVao = 0, pointVao = 0, strandVao = 0;
  GLuint sprite = 0;
  Sprite spriteKind{};
  std::string spritePath;
  bool spriteLoaded = false;
  int width = 1, height = 1;
  std::size_t drawn = 0;
  std::vector<std::byte> packed;
  std::vector<float> strandVerts;
  std::vector<GLint> strandFirst;
  std::vector<GLsizei> strandCount;

  glm::mat4 view{1.0f}, proj{1.0f};

  void ensureSprite() {
    const RenderSettings& s = settings;
    if (spriteLoaded && spriteKind == s.sprite && spritePath == s.spriteImage) return;
    const Image img = detail::spriteBitmap(s.sprite, s.spriteImage);
    if (!sprite) glGenTextures(1, &sprite);
    glBindTexture(GL_TEXTURE_2D, sprite);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, img.width, img.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                 img.rgba.data());
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    spriteKind = s.sprite;
    spritePath = s.spriteImage;
    spriteLoaded = true;
  }

  void setCommon(GLuint p) {
    glUseProgram(p);
    glUniformMatrix4fv(loc(p, "uView"), 1, GL_FALSE, glm::value_ptr(view));
    glUniformMatrix4fv(loc(p, "uProj"), 1, GL_FALSE, glm::value_ptr(proj));
    glUniform2f(loc(p, "uViewport"), float(width), float(height));
    glUniform1f(loc(p, "uLitMinPixels"), settings.litMinPixels);
    glUniform1i(loc(p, "uShading"), settings.shading ? 1 : 0);
    const Vec3 eye = settings.camera.eye();
    glUniform3fv(loc(p, "uEye"), 1, glm::value_ptr(eye));
  }

  void setLighting(GLuint p) {
    const Lighting& l = settings.lighting;
    if (l.lights.size() > std::size_t(detail::glsl::kMaxLights))
      throw InvalidArgument("lighting.lights",
                            "at most " + std::to_string(detail::glsl::kMaxLights) +
                                " lights, not " + std::to_string(l.lights.size()));
    const int n = int(l.lights.size());
    int types[detail::glsl::kMaxLights] = {};
    float vecs[detail::glsl::kMaxLights * 3] = {}, is[detail::glsl::kMaxLights * 3] = {};
    for (int k = 0; k < n; ++k) {
      const Light& li = l.lights[std::size_t(k)];
      types[k] = li.type == Light::Type::Point ? 1 : 0;
      const Vec3 v = li.type == Light::Type::Point ? li.vector : glm::normalize(li.vector);
      std::memcpy(&vecs[3 * k], &v, sizeof v);
      std::memcpy(&is[3 * k], &li.intensity, sizeof(Vec3));
    }
    glUniform1i(loc(p, "uLightCount"), n);
    glUniform1iv(loc(p, "uLightType"), detail::glsl::kMaxLights, types);
    glUniform3fv(loc(p, "uLightVec"), detail::glsl::kMaxLights, vecs);
    glUniform3fv(loc(p, "uLightI"), detail::glsl::kMaxLights, is);
    glUniform3fv(loc(p, "uAmbient"), 1, glm::value_ptr(l.ambient));
    glUniform3fv(loc(p, "uKa"), 1, glm::value_ptr(l.material.ka));
    glUniform3fv(loc(p, "uKd"), 1, glm::value_ptr(l.material.kd));
    glUniform3fv(loc(p, "uKs"), 1, glm::value_ptr(l.material.ks));
    glUniform1f(loc(p, "uN"), l.material.n);
    glUniform1i(loc(p, "uFalloff"), int(l.falloff));
  }

  void setBlend(bool depthWrite) {
    glEnable(GL_BLEND);
    if (settings.blend == BlendMode::Additive)
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE, GL_ZERO, GL_ONE);
    else
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(depthWrite ? GL_TRUE : GL_FALSE);
  }
};

Renderer::Renderer(RenderSettings settings) : impl_(std::make_unique<Impl>()) {
  impl_->settings = std::move(settings);
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  if (major * 10 + minor < 33)
    throw RenderError("no usable OpenGL: the current context is " + std::to_string(major) + "." +
                      std::to_string(minor) + ", 3.3 core is needed");
  namespace g = detail::glsl;
  Impl& d = *impl_;
  d.billboard = link(std::string(g::kProjection) + g::kBillboardVs,
                     std::string(g::kLighting) + g::kBillboardFs, "billboard");
  d.points = link(std::string(g::kProjection) + g::kPointVs, g::kPointFs, "point");
  d.strands = link(std::string(g::kProjection) + g::kStrandVs,
                   std::string(g::kLighting) + g::kStrandFs, "strand");

  const float quad[] = {-1, -1, 1, -1, -1, 1, 1, 1};
  glGenBuffers(1, &d.quadVbo);
  glBindBuffer(GL_ARRAY_BUFFER, d.quadVbo);
  glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
  glGenBuffers(1, &d.instanceVbo);
  glGenBuffers(1, &d.strandVbo);

  // Instances: PackLayout::instances(), position xyz + radius, then rgba.
  const GLsizei stride = GLsizei(PackLayout::instances().stride);
  auto instanceAttribs = [&](GLuint divisor) {
    glBindBuffer(GL_ARRAY_BUFFER, d.instanceVbo);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, stride, nullptr);
    glVertexAttribDivisor(1, divisor);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(16));
    glVertexAttribDivisor(2, divisor);
  };
  glGenVertexArrays(1, &d.billboardVao);
  glBindVertexArray(d.billboardVao);
  glBindBuffer(GL_ARRAY_BUFFER, d.quadVbo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  instanceAttribs(1);
  glGenVertexArrays(1, &d.pointVao);
  glBindVertexArray(d.pointVao);
  instanceAttribs(0);

  glGenVertexArrays(1, &d.strandVao);
  glBindVertexArray(d.strandVao);
  glBindBuffer(GL_ARRAY_BUFFER, d.strandVbo);
  const GLsizei sstride = 12 * sizeof(float);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sstride, nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sstride, reinterpret_cast<void*>(12));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, sstride, reinterpret_cast<void*>(24));
  glEnableVertexAttribArray(3);
  glVertexAttribPointer(3, 4, GL_FLOAT, GL_FALSE, sstride, reinterpret_cast<void*>(32));
  glBindVertexArray(0);
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    throw RenderError("OpenGL error " + std::to_string(e) + " setting up the renderer");
}

Renderer::~Renderer() {
  Impl& d = *impl_;
  glDeleteProgram(d.billboard);
  glDeleteProgram(d.points);
  glDeleteProgram(d.strands);
  const GLuint buffers[] = {d.quadVbo, d.instanceVbo, d.strandVbo};
  glDeleteBuffers(3, buffers);
  const GLuint vaos[] = {d.billboardVao, d.pointVao, d.strandVao};
  glDeleteVertexArrays(3, vaos);
  if (d.sprite) glDeleteTextures(1, &d.sprite);
}

RenderSettings& Renderer::settings() {
  return impl_->settings;
}
const RenderSettings& Renderer::settings() const {
  return impl_->settings;
}
std::size_t Renderer::lastDrawn() const {
  return impl_->drawn;
}

AttributeSet Renderer::attributes() {
  return PackLayout::instances().attributes();
}

void Renderer::begin(int width, int height) {
  Impl& d = *impl_;
  d.width = std::max(width, 1);
  d.height = std::max(height, 1);
  const Camera& c = d.settings.camera;
  d.view = glm::lookAt(c.eye(), c.target, Vec3(0.0f, 1.0f, 0.0f));
  d.proj = glm::perspective(glm::radians(c.fovY), float(d.width) / float(d.height), c.nearPlane,
                            c.farPlane);
  glViewport(0, 0, d.width, d.height);
  const Vec3 bg = d.settings.background;
  glClearColor(bg.r, bg.g, bg.b, 1.0f);
  glDepthMask(GL_TRUE);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  d.drawn = 0;
}

void Renderer::draw(const Group& group) {
  // A hair-mode group's strands first: they write depth, so its particles behind them hide.
  if (!group.strands().position.empty()) draw(group.strands());
  Impl& d = *impl_;
  const RenderSettings& s = d.settings;
  PackOptions opts;
  opts.blockers = s.blockers;
  if (s.blend == BlendMode::Alpha && s.sortForAlpha) opts.sortFromEye = s.camera.eye();
  const PackLayout layout = PackLayout::instances();
  d.packed.resize(group.size() * layout.stride);
  const std::size_t n = packParticles(group, layout, d.packed, opts);
  d.drawn += n;
  if (n == 0) return;
  glBindBuffer(GL_ARRAY_BUFFER, d.instanceVbo);
  // Orphan the old storage so the driver need not wait for the last frame's draw.
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(n * layout.stride), nullptr, GL_STREAM_DRAW);
  glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(n * layout.stride), d.packed.data());
  d.setBlend(false);
  if (s.sprite == Sprite::Point) {
    d.setCommon(d.points);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glBindVertexArray(d.pointVao);
    glDrawArrays(GL_POINTS, 0, GLsizei(n));
  } else {
    d.ensureSprite();
    d.setCommon(d.billboard);
    d.setLighting(d.billboard);
    const glm::mat3 viewToWorld = glm::transpose(glm::mat3(d.view));
    glUniformMatrix3fv(loc(d.billboard, "uViewToWorld"), 1, GL_FALSE, glm::value_ptr(viewToWorld));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, d.sprite);
    glUniform1i(loc(d.billboard, "uSprite"), 0);
    glBindVertexArray(d.billboardVao);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(n));
  }
  glBindVertexArray(0);
}

void Renderer::draw(const Strands& strands) {
  Impl& d = *impl_;
  const RenderSettings& s = d.settings;
  const bool lines = s.strandStyle == StrandStyle::Line;
  d.strandVerts.clear();
  d.strandFirst.clear();
  d.strandCount.clear();
  auto emit = [&](std::size_t i, Vec3 t, float side) {
    const Vec3& p = strands.position[i];
    const Vec4 c = i < strands.color.size() ? strands.color[i] : Vec4(1.0f);
    const float r = i < strands.radius.size() ? strands.radius[i] : 0.01f;
    const float v[12] = {p.x, p.y, p.z, t.x, t.y, t.z, r, side, c.r, c.g, c.b, c.a};
    d.strandVerts.insert(d.strandVerts.end(), v, v + 12);
  };
  auto hidden = [&](std::size_t i) {
    for (const Domain& b : s.blockers)
      if (b.contains(strands.position[i])) return true;
    return false;
  };
  for (std::size_t k = 0; k < strands.size(); ++k) {
    const std::size_t begin = strands.start[k], end = strands.start[k + 1];
    // A blocker cuts a strand into the runs of vertices outside it.
    std::size_t i = begin;
    while (i < end) {
      while (i < end && hidden(i)) ++i;
      std::size_t j = i;
      while (j < end && !hidden(j)) ++j;
      if (j - i >= 2) {
        const GLint first = GLint(d.strandVerts.size() / 12);
        for (std::size_t v = i; v < j; ++v) {
          // The tangent from the strand's neighbours, not the run's: cuts do not bend it.
          const Vec3 a = strands.position[v > begin ? v - 1 : v];
          const Vec3 b = strands.position[v + 1 < end ? v + 1 : v];
          Vec3 t = b - a;
          const float len = glm::length(t);
          t = len > 0.0f ? t / len : Vec3(0.0f, 1.0f, 0.0f);
          if (lines) {
            emit(v, t, 0.0f);
          } else {
            emit(v, t, -1.0f);
            emit(v, t, 1.0f);
          }
        }
        d.strandFirst.push_back(first);
        d.strandCount.push_back(GLsizei(d.strandVerts.size() / 12) - first);
      }
      i = j;
    }
  }
  if (d.strandFirst.empty()) return;
  glBindBuffer(GL_ARRAY_BUFFER, d.strandVbo);
  const auto bytes = GLsizeiptr(d.strandVerts.size() * sizeof(float));
  glBufferData(GL_ARRAY_BUFFER, bytes, nullptr, GL_STREAM_DRAW);
  glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, d.strandVerts.data());
  // Opaque strands hide what is behind them, particles included; translucent ones blend.
  d.setBlend(true);
  d.setCommon(d.strands);
  d.setLighting(d.strands);
  glUniform1i(loc(d.strands, "uLines"), lines ? 1 : 0);
  glBindVertexArray(d.strandVao);
  glMultiDrawArrays(lines ? GL_LINE_STRIP : GL_TRIANGLE_STRIP, d.strandFirst.data(),
                    d.strandCount.data(), GLsizei(d.strandFirst.size()));
  glBindVertexArray(0);
}

}  // namespace flurry
