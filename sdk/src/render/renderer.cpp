#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <variant>
#include <vector>

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

// Instances of stretched billboards: PackLayout::instances() (position, radius, rgba), then
// the velocity at byte 32.
const PackLayout& stretchLayout() {
  static const PackLayout layout =
      PackLayout::interleaved({{Attribute::Position, PackFormat::Float32},
                               {Attribute::Size, PackFormat::Float32},
                               {Attribute::Color, PackFormat::Float32},
                               {Attribute::Velocity, PackFormat::Float32}});
  return layout;
}

GLint loc(GLuint program, const char* name) {
  return glGetUniformLocation(program, name);
}

// Scene geometry as line and triangle vertices: x y z r g b a each.
struct GeometryBuilder {
  std::vector<float>& lines;
  std::vector<float>& faces;
  Vec4 line, face;
  float extent;  // half-size of an infinite plane's drawn square

  static void put(std::vector<float>& out, Vec3 p, Vec4 c) {
    const float v[7] = {p.x, p.y, p.z, c.r, c.g, c.b, c.a};
    out.insert(out.end(), v, v + 7);
  }
  void segment(Vec3 a, Vec3 b) {
    put(lines, a, line);
    put(lines, b, line);
  }
  void triangle(Vec3 a, Vec3 b, Vec3 c) {
    put(faces, a, face);
    put(faces, b, face);
    put(faces, c, face);
  }
  void quad(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
    triangle(a, b, c);
    triangle(a, c, d);
  }
  // Two unit vectors spanning the plane of unit normal n.
  static void basis(Vec3 n, Vec3& u, Vec3& v) {
    const Vec3 helper = std::abs(n.y) < 0.9f ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
    u = glm::normalize(glm::cross(helper, n));
    v = glm::cross(n, u);
  }
  void circle(Vec3 c, Vec3 n, float r, int segments = 48) {
    Vec3 u, v;
    basis(n, u, v);
    for (int k = 0; k < segments; ++k) {
      const float a0 = 6.2831853f * float(k) / float(segments);
      const float a1 = 6.2831853f * float(k + 1) / float(segments);
      segment(c + r * (std::cos(a0) * u + std::sin(a0) * v),
              c + r * (std::cos(a1) * u + std::sin(a1) * v));
    }
  }
  void annulus(Vec3 c, Vec3 n, float outer, float inner, int segments = 48) {
    Vec3 u, v;
    basis(n, u, v);
    for (int k = 0; k < segments; ++k) {
      const float a0 = 6.2831853f * float(k) / float(segments);
      const float a1 = 6.2831853f * float(k + 1) / float(segments);
      const Vec3 d0 = std::cos(a0) * u + std::sin(a0) * v, d1 = std::cos(a1) * u + std::sin(a1) * v;
      quad(c + inner * d0, c + outer * d0, c + outer * d1, c + inner * d1);
    }
  }

  void add(const Domain& domain) {
    std::visit([&](const auto& d) { shape(d); }, domain.shape());
  }
  void shape(const PointDomain&) {}
  void shape(const BlobDomain&) {}
  void shape(const LineDomain& d) { segment(d.p0, d.p1); }
  void shape(const TriangleDomain& d) {
    segment(d.p0, d.p1);
    segment(d.p1, d.p2);
    segment(d.p2, d.p0);
    triangle(d.p0, d.p1, d.p2);
  }
  void shape(const PlaneDomain& d) {
    // A ground: a square of grid lines around the plane's point, faintly filled.
    Vec3 u, v;
    basis(d.normal, u, v);
    const int cells = 16;
    const float step = 2.0f * extent / float(cells);
    for (int k = 0; k <= cells; ++k) {
      const float t = -extent + step * float(k);
      segment(d.point + t * u - extent * v, d.point + t * u + extent * v);
      segment(d.point - extent * u + t * v, d.point + extent * u + t * v);
    }
    quad(d.point - extent * u - extent * v, d.point + extent * u - extent * v,
         d.point + extent * u + extent * v, d.point - extent * u + extent * v);
  }
  void shape(const RectangleDomain& d) {
    const Vec3 a = d.origin, b = d.origin + d.u, c = d.origin + d.u + d.v, e = d.origin + d.v;
    segment(a, b);
    segment(b, c);
    segment(c, e);
    segment(e, a);
    quad(a, b, c, e);
  }
  void shape(const DiscDomain& d) {
    circle(d.center, d.normal, d.outerRadius);
    if (d.innerRadius > 0.0f) circle(d.center, d.normal, d.innerRadius);
    annulus(d.center, d.normal, d.outerRadius, d.innerRadius);
  }
  void shape(const BoxDomain& d) {
    const Vec3 lo = d.min, hi = d.max;
    auto corner = [&](int i) {
      return Vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    };
    for (int i = 0; i < 8; ++i)
      for (int bit : {1, 2, 4})
        if (!(i & bit)) segment(corner(i), corner(i | bit));
    // Faces: the pairs of corners differing in two of the three axes.
    for (int axis : {1, 2, 4}) {
      const int a = axis == 1 ? 2 : 1, b = axis == 4 ? 2 : 4;
      for (int side : {0, axis})
        quad(corner(side), corner(side | a), corner(side | a | b), corner(side | b));
    }
  }
  void shape(const SphereDomain& d) {
    for (int k = -2; k <= 2; ++k) {  // latitude rings
      const float y = d.outerRadius * float(k) / 3.0f;
      circle(d.center + Vec3(0, y, 0), Vec3(0, 1, 0),
             std::sqrt(d.outerRadius * d.outerRadius - y * y));
    }
    for (int k = 0; k < 4; ++k) {  // meridians
      const float a = 3.14159265f * float(k) / 4.0f;
      circle(d.center, Vec3(std::cos(a), 0, std::sin(a)), d.outerRadius);
    }
  }
  void shape(const CylinderDomain& d) {
    const Vec3 axis = d.p1 - d.p0;
    const float len = glm::length(axis);
    if (len <= 0.0f) return;
    const Vec3 n = axis / len;
    circle(d.p0, n, d.outerRadius);
    circle(d.p1, n, d.outerRadius);
    Vec3 u, v;
    basis(n, u, v);
    for (int k = 0; k < 8; ++k) {
      const float a = 6.2831853f * float(k) / 8.0f;
      const Vec3 o = d.outerRadius * (std::cos(a) * u + std::sin(a) * v);
      segment(d.p0 + o, d.p1 + o);
    }
  }
  void shape(const ConeDomain& d) {
    const Vec3 axis = d.base - d.apex;
    const float len = glm::length(axis);
    if (len <= 0.0f) return;
    const Vec3 n = axis / len;
    circle(d.base, n, d.outerRadius);
    Vec3 u, v;
    basis(n, u, v);
    for (int k = 0; k < 8; ++k) {
      const float a = 6.2831853f * float(k) / 8.0f;
      segment(d.apex, d.base + d.outerRadius * (std::cos(a) * u + std::sin(a) * v));
    }
  }
  void shape(const MeshDomain& d) {
    for (const glm::uvec3& t : d.mesh->triangles) {
      const Vec3 a = d.mesh->vertices[t.x], b = d.mesh->vertices[t.y], c = d.mesh->vertices[t.z];
      segment(a, b);
      segment(b, c);
      segment(c, a);
      triangle(a, b, c);
    }
  }
  void shape(const UnionDomain& d) {
    for (const Domain& part : d.parts->parts) add(part);
  }
};

}  // namespace

struct Renderer::Impl {
  RenderSettings settings;
  GLuint billboard = 0, points = 0, strands = 0, geometry = 0, toneMap = 0;
  GLuint geometryVbo = 0, geometryVao = 0, emptyVao = 0;
  std::vector<float> geometryLines, geometryFaces;
  // The HDR target of a tone-mapped frame: multisampled like the caller's framebuffer, then
  // resolved into a texture that the tone map reads.
  GLuint hdrMsFbo = 0, hdrMsColor = 0, hdrMsDepth = 0, hdrFbo = 0, hdrTexture = 0, hdrDepth = 0;
  int hdrWidth = 0, hdrHeight = 0, hdrSamples = -1;
  GLint target = 0;  // the draw framebuffer bound at begin()
  bool hdrFrame = false;
  GLuint quadVbo = 0, instanceVbo = 0, strandVbo = 0;
  GLuint billboardVao = 0, stretchVao = 0, pointVao = 0, strandVao = 0;
  // Sprite textures made so far, one per (kind, PNG): groups may draw different sprites.
  struct SpriteTexture {
    Sprite kind;
    std::string path;
    GLuint texture;
  };
  std::vector<SpriteTexture> sprites;
  int width = 1, height = 1;
  std::size_t drawn = 0;
  std::vector<std::byte> packed;
  std::vector<float> strandVerts;
  std::vector<GLint> strandFirst;
  std::vector<GLsizei> strandCount;
  Strands trails;  ///< scratch: a group's trails as ribbons (trailStrands)

  glm::mat4 view{1.0f}, proj{1.0f};

  // What one group is drawn with: the settings, then its GroupLook.
  struct Look {
    Sprite sprite;
    const std::string* spriteImage;
    BlendMode blend;
    bool sortForAlpha, shading;
    float stretch, maxStretch;
  };

  Look lookFor(const Group& group) const {
    const RenderSettings& s = settings;
    Look k{s.sprite, &s.spriteImage, s.blend, s.sortForAlpha, s.shading, s.stretch, s.maxStretch};
    const std::string& name = group.name();
    const std::string_view base = std::string_view(name).substr(0, name.find('@'));
    for (const GroupLook& g : s.groups) {
      if (g.group != name && g.group != base) continue;
      if (g.sprite) {
        k.sprite = *g.sprite;
        k.spriteImage = &g.spriteImage;
      }
      if (g.blend) k.blend = *g.blend;
      if (g.sortForAlpha) k.sortForAlpha = *g.sortForAlpha;
      if (g.shading) k.shading = *g.shading;
      if (g.stretch) k.stretch = *g.stretch;
      if (g.maxStretch) k.maxStretch = *g.maxStretch;
      break;
    }
    return k;
  }

  GLuint spriteTexture(Sprite kind, const std::string& path) {
    const std::string& key = kind == Sprite::Image ? path : std::string();
    for (const SpriteTexture& t : sprites)
      if (t.kind == kind && t.path == key) return t.texture;
    const Image img = detail::spriteBitmap(kind, path);
    GLuint sprite = 0;
    glGenTextures(1, &sprite);
    glBindTexture(GL_TEXTURE_2D, sprite);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, img.width, img.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                 img.rgba.data());
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    sprites.push_back({kind, key, sprite});
    return sprite;
  }

  void setCommon(GLuint p, bool shading) {
    glUseProgram(p);
    glUniformMatrix4fv(loc(p, "uView"), 1, GL_FALSE, glm::value_ptr(view));
    glUniformMatrix4fv(loc(p, "uProj"), 1, GL_FALSE, glm::value_ptr(proj));
    glUniform2f(loc(p, "uViewport"), float(width), float(height));
    glUniform1f(loc(p, "uLitMinPixels"), settings.litMinPixels);
    glUniform1i(loc(p, "uShading"), shading ? 1 : 0);
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

  void releaseHdr() {
    const GLuint fbs[] = {hdrMsFbo, hdrFbo};
    glDeleteFramebuffers(2, fbs);
    const GLuint rbs[] = {hdrMsColor, hdrMsDepth, hdrDepth};
    glDeleteRenderbuffers(3, rbs);
    if (hdrTexture) glDeleteTextures(1, &hdrTexture);
    hdrMsFbo = hdrMsColor = hdrMsDepth = hdrFbo = hdrTexture = hdrDepth = 0;
    hdrWidth = hdrHeight = 0;
    hdrSamples = -1;
  }

  void ensureHdr(int samples) {
    if (hdrFbo && hdrWidth == width && hdrHeight == height && hdrSamples == samples) return;
    releaseHdr();
    glGenTextures(1, &hdrTexture);
    glBindTexture(GL_TEXTURE_2D, hdrTexture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glGenFramebuffers(1, &hdrFbo);
    glBindFramebuffer(GL_FRAMEBUFFER, hdrFbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, hdrTexture, 0);
    glGenRenderbuffers(1, &hdrDepth);
    glBindRenderbuffer(GL_RENDERBUFFER, hdrDepth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, hdrDepth);
    bool ok = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    if (ok && samples > 1) {
      glGenFramebuffers(1, &hdrMsFbo);
      glBindFramebuffer(GL_FRAMEBUFFER, hdrMsFbo);
      glGenRenderbuffers(1, &hdrMsColor);
      glBindRenderbuffer(GL_RENDERBUFFER, hdrMsColor);
      glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA16F, width, height);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, hdrMsColor);
      glGenRenderbuffers(1, &hdrMsDepth);
      glBindRenderbuffer(GL_RENDERBUFFER, hdrMsDepth);
      glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width,
                                       height);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, hdrMsDepth);
      ok = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, GLuint(target));
    if (!ok) {
      releaseHdr();
      throw RenderError("cannot make a " + std::to_string(width) + "x" + std::to_string(height) +
                        " floating-point framebuffer for the tone map");
    }
    hdrWidth = width;
    hdrHeight = height;
    hdrSamples = samples;
  }

  void drawGeometry(const Group& group) {
    const SceneGeometry& g = settings.geometry;
    geometryLines.clear();
    geometryFaces.clear();
    GeometryBuilder b{geometryLines, geometryFaces, Vec4(g.color, g.opacity),
                      Vec4(g.color, g.opacity / 3.0f), settings.camera.distance};
    for (const Action& a : group.actions().actions()) {
      if (const auto* x = std::get_if<Bounce>(&a); x && g.bounce) b.add(x->surface);
      if (const auto* x = std::get_if<Sink>(&a); x && g.sink) {
        // An `outside` or `leave` absorber bounds the scene; it is not an object in it.
        const bool bounds = x->mode == Sink::Mode::Outside || x->mode == Sink::Mode::Leave;
        if (!bounds) b.add(x->region);
      }
      if (const auto* x = std::get_if<Block>(&a); x && g.block) b.add(x->region);
    }
    if (geometryLines.empty() && geometryFaces.empty()) return;
    setBlend(false, false);
    glUseProgram(geometry);
    glUniformMatrix4fv(loc(geometry, "uView"), 1, GL_FALSE, glm::value_ptr(view));
    glUniformMatrix4fv(loc(geometry, "uProj"), 1, GL_FALSE, glm::value_ptr(proj));
    glBindVertexArray(geometryVao);
    glBindBuffer(GL_ARRAY_BUFFER, geometryVbo);
    for (const auto& [verts, mode] : {std::pair{&geometryFaces, GLenum(GL_TRIANGLES)},
                                      std::pair{&geometryLines, GLenum(GL_LINES)}}) {
      if (verts->empty()) continue;
      const auto bytes = GLsizeiptr(verts->size() * sizeof(float));
      glBufferData(GL_ARRAY_BUFFER, bytes, nullptr, GL_STREAM_DRAW);
      glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, verts->data());
      glDrawArrays(mode, 0, GLsizei(verts->size() / 7));
    }
    glBindVertexArray(0);
  }

  void setBlend(bool depthWrite, bool additive) {
    glEnable(GL_BLEND);
    // Opaque backgrounds keep alpha 1; a transparent one accumulates coverage in alpha.
    const bool t = settings.transparent;
    if (additive)
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE, t ? GL_ONE : GL_ZERO, GL_ONE);
    else
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, t ? GL_ONE : GL_ZERO,
                          t ? GL_ONE_MINUS_SRC_ALPHA : GL_ONE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(depthWrite ? GL_TRUE : GL_FALSE);
  }

  /// Strands as ribbons or lines (settings.strandStyle). Hair writes depth (opaque strands
  /// hide what is behind them); a particle's trail fades, so it blends as particles do.
  void drawStrands(const Strands& strands, bool depthWrite, bool additive, bool shading);
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
  d.geometry = link(g::kGeometryVs, g::kGeometryFs, "geometry");
  d.toneMap = link(g::kToneMapVs, g::kToneMapFs, "tone map");

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
  // Stretched billboards: the same fields, then the velocity (stretchLayout()).
  const GLsizei vstride = GLsizei(stretchLayout().stride);
  glGenVertexArrays(1, &d.stretchVao);
  glBindVertexArray(d.stretchVao);
  glBindBuffer(GL_ARRAY_BUFFER, d.quadVbo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  glBindBuffer(GL_ARRAY_BUFFER, d.instanceVbo);
  for (GLuint a = 1; a <= 3; ++a) {
    glEnableVertexAttribArray(a);
    glVertexAttribDivisor(a, 1);
  }
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, vstride, nullptr);
  glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, vstride, reinterpret_cast<void*>(16));
  glVertexAttribPointer(3, 3, GL_FLOAT, GL_FALSE, vstride, reinterpret_cast<void*>(32));

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

  glGenBuffers(1, &d.geometryVbo);
  glGenVertexArrays(1, &d.geometryVao);
  glBindVertexArray(d.geometryVao);
  glBindBuffer(GL_ARRAY_BUFFER, d.geometryVbo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 7 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, 7 * sizeof(float), reinterpret_cast<void*>(12));
  glGenVertexArrays(1, &d.emptyVao);  // the tone map's triangle needs no vertex data
  glBindVertexArray(0);
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    throw RenderError("OpenGL error " + std::to_string(e) + " setting up the renderer");
}

Renderer::~Renderer() {
  Impl& d = *impl_;
  glDeleteProgram(d.billboard);
  glDeleteProgram(d.points);
  glDeleteProgram(d.strands);
  glDeleteProgram(d.geometry);
  glDeleteProgram(d.toneMap);
  const GLuint buffers[] = {d.quadVbo, d.instanceVbo, d.strandVbo, d.geometryVbo};
  glDeleteBuffers(4, buffers);
  const GLuint vaos[] = {d.billboardVao, d.stretchVao,  d.pointVao,
                         d.strandVao,    d.geometryVao, d.emptyVao};
  glDeleteVertexArrays(6, vaos);
  d.releaseHdr();
  for (const Impl::SpriteTexture& t : d.sprites) glDeleteTextures(1, &t.texture);
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
  return stretchLayout().attributes();
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
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &d.target);
  d.hdrFrame = d.settings.toneMap != ToneMap::None;
  if (d.hdrFrame) {
    // As many samples as the caller's framebuffer has: its MSAA covers the HDR image too.
    GLint samples = 0;
    glGetIntegerv(GL_SAMPLES, &samples);
    d.ensureHdr(samples > 1 ? samples : 0);
    glBindFramebuffer(GL_FRAMEBUFFER, d.hdrMsFbo ? d.hdrMsFbo : d.hdrFbo);
  }
  const Vec3 bg = d.settings.background;
  if (d.settings.transparent)
    glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  else
    glClearColor(bg.r, bg.g, bg.b, 1.0f);
  glDepthMask(GL_TRUE);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  d.drawn = 0;
}

void Renderer::end() {
  Impl& d = *impl_;
  if (!d.hdrFrame) return;
  d.hdrFrame = false;
  if (d.hdrMsFbo) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, d.hdrMsFbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, d.hdrFbo);
    glBlitFramebuffer(0, 0, d.width, d.height, 0, 0, d.width, d.height, GL_COLOR_BUFFER_BIT,
                      GL_NEAREST);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, GLuint(d.target));
  glDisable(GL_BLEND);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(d.toneMap);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, d.hdrTexture);
  glUniform1i(loc(d.toneMap, "uHdr"), 0);
  glUniform1i(loc(d.toneMap, "uCurve"), d.settings.toneMap == ToneMap::Reinhard ? 1 : 2);
  glUniform1f(loc(d.toneMap, "uExposure"), d.settings.exposure);
  glUniform1i(loc(d.toneMap, "uTransparent"), d.settings.transparent ? 1 : 0);
  glBindVertexArray(d.emptyVao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glEnable(GL_DEPTH_TEST);
}

void Renderer::draw(const Group& group) {
  // A hair-mode group's strands first: they write depth, so its particles behind them hide.
  Impl& d = *impl_;
  const RenderSettings& s = d.settings;
  if (s.geometry.show) d.drawGeometry(group);
  if (!group.strands().position.empty()) draw(group.strands());
  const Impl::Look look = d.lookFor(group);
  if (group.trail().length > 0 && trailStrands(group, d.trails) > 0)
    d.drawStrands(d.trails, false, look.blend == BlendMode::Additive, look.shading);
  PackOptions opts;
  opts.blockers = s.blockers;
  if (look.blend == BlendMode::Alpha && look.sortForAlpha) opts.sortFromEye = s.camera.eye();
  const bool stretched = look.stretch > 0.0f && look.sprite != Sprite::Point;
  const PackLayout& layout = stretched ? stretchLayout() : PackLayout::instances();
  d.packed.resize(group.size() * layout.stride);
  const std::size_t n = packParticles(group, layout, d.packed, opts);
  d.drawn += n;
  if (n == 0) return;
  glBindBuffer(GL_ARRAY_BUFFER, d.instanceVbo);
  // Orphan the old storage so the driver need not wait for the last frame's draw.
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(n * layout.stride), nullptr, GL_STREAM_DRAW);
  glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(n * layout.stride), d.packed.data());
  d.setBlend(false, look.blend == BlendMode::Additive);
  if (look.sprite == Sprite::Point) {
    d.setCommon(d.points, look.shading);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glBindVertexArray(d.pointVao);
    glDrawArrays(GL_POINTS, 0, GLsizei(n));
  } else {
    const GLuint sprite = d.spriteTexture(look.sprite, *look.spriteImage);
    d.setCommon(d.billboard, look.shading);
    d.setLighting(d.billboard);
    const glm::mat3 viewToWorld = glm::transpose(glm::mat3(d.view));
    glUniformMatrix3fv(loc(d.billboard, "uViewToWorld"), 1, GL_FALSE, glm::value_ptr(viewToWorld));
    glUniform1i(loc(d.billboard, "uFlat"),
                look.sprite == Sprite::Glow || look.sprite == Sprite::Puff);
    glUniform1f(loc(d.billboard, "uStretch"), stretched ? look.stretch : 0.0f);
    glUniform1f(loc(d.billboard, "uMaxStretch"), look.maxStretch);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, sprite);
    glUniform1i(loc(d.billboard, "uSprite"), 0);
    glBindVertexArray(stretched ? d.stretchVao : d.billboardVao);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(n));
  }
  glBindVertexArray(0);
}

void Renderer::draw(const Strands& strands) {
  const RenderSettings& s = impl_->settings;
  impl_->drawStrands(strands, true, s.blend == BlendMode::Additive, s.shading);
}

void Renderer::Impl::drawStrands(const Strands& strands, bool depthWrite, bool additive,
                                 bool shading) {
  Impl& d = *this;
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
  d.setBlend(depthWrite, additive);
  d.setCommon(d.strands, shading);
  d.setLighting(d.strands);
  glUniform1i(loc(d.strands, "uLines"), lines ? 1 : 0);
  glBindVertexArray(d.strandVao);
  glMultiDrawArrays(lines ? GL_LINE_STRIP : GL_TRIANGLE_STRIP, d.strandFirst.data(),
                    d.strandCount.data(), GLsizei(d.strandFirst.size()));
  glBindVertexArray(0);
}

}  // namespace flurry
