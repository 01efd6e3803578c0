// flurry::render: draws groups (snow mode) and strands (hair mode) with the seed's simple
// shading model, with OpenGL 3.3 core; into a game's own context (Renderer), into an
// offscreen image (OffscreenRenderer, which needs no display: with DISPLAY unset it starts
// its own Xvfb for the process and stops it afterwards), or in a window (render_viewer.hpp).
//
// Link flurry::render for these; a game that draws by itself links flurry::flurry alone and
// reads packed particles through <flurry/interop.hpp>.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "flurry/domain.hpp"
#include "flurry/error.hpp"
#include "flurry/group.hpp"
#include "flurry/render_shading.hpp"
#include "flurry/strands.hpp"

namespace flurry {

/// No usable OpenGL (no display, no Xvfb, no 3.3 core context), or a GL object failed.
class RenderError : public Error {
 public:
  using Error::Error;
};

/// How a particle's fragments combine with what is behind them.
enum class BlendMode {
  Alpha,     ///< over: back-to-front sorted when RenderSettings::sortForAlpha
  Additive,  ///< glow: order-independent, brightens where particles overlap
};

/// What each particle is drawn as in snow mode.
enum class Sprite {
  Point,      ///< a square GL point of the particle's projected size, never shaded
  Disc,       ///< a camera-facing billboard of a built-in soft disc
  Spark,      ///< ... of a built-in spark (a glowing core with four rays)
  Snowflake,  ///< ... of a built-in six-armed snowflake
  Image,      ///< ... of the PNG named by RenderSettings::spriteImage
  Glow,       ///< ... of a soft round glow (gaussian), shaded flat: sparks, fire, stars
  Puff,       ///< ... of a soft, lumpy puff, shaded flat (no lit ball): smoke, mist, dust
};

/// How the accumulated (HDR) colour becomes an 8-bit one. With a tone map the renderer draws
/// into a floating-point buffer first, so additive cores keep their hue instead of clipping.
enum class ToneMap {
  None,      ///< draw straight into the target; colours above 1 clip
  Reinhard,  ///< c / (1 + c) per channel, after `exposure`
  Aces,      ///< Narkowicz's fit of the ACES film curve, after `exposure`
};

/// The scene's surfaces drawn as faint geometry: deflectors (Bounce), absorbers (Sink, not
/// the `outside` / `leave` bounds) and blockers (Block) of each drawn group's action list.
struct SceneGeometry {
  bool show = false;
  Vec3 color{0.55f, 0.6f, 0.7f};
  float opacity = 0.35f;  ///< of the outlines; faces are drawn at a third of it
  bool bounce = true, sink = true, block = true;
};

/// How strands are drawn in hair mode.
enum class StrandStyle {
  Ribbon,  ///< camera-facing ribbons 2·radius wide, shaded with the tangent model
  Line,    ///< 1-pixel lines, never shaded; a strand thinner than a pixel is drawn fainter
};

/// An orbit camera: it looks at `target` from `distance` away, turned by yaw and pitch.
struct Camera {
  Vec3 target{0.0f, 1.5f, 0.0f};
  float distance = 9.0f;
  float yaw = 30.0f;    ///< degrees about +y; 0 puts the eye on +z looking towards -z
  float pitch = 15.0f;  ///< degrees above the horizontal plane, within (-90, 90)
  float fovY = 45.0f;   ///< vertical field of view, degrees
  float nearPlane = 0.05f;
  float farPlane = 1000.0f;

  Vec3 eye() const;
};

/// One group's own look over RenderSettings' (a field left unset keeps the settings' value):
/// e.g. additive glowing fire and alpha-blended smoke in one effect.
struct GroupLook {
  std::string group;  ///< the group's name; a built instance's "NAME@INSTANCE" matches too
  std::optional<Sprite> sprite;
  std::string spriteImage;  ///< the PNG for Sprite::Image
  std::optional<BlendMode> blend;
  std::optional<bool> sortForAlpha;
  std::optional<bool> shading;
  std::optional<float> stretch;
  std::optional<float> maxStretch;
};

/// Everything that decides how a scene looks. A plain aggregate; effect files fill it.
struct RenderSettings {
  Vec3 background{0.03f, 0.04f, 0.07f};  ///< clear color; blockers never change it
  Camera camera;
  Lighting lighting;    ///< Ia, lights, ka kd ks n, falloff (render_shading.hpp)
  bool shading = true;  ///< false draws every particle in its own color
  /// Particles whose projected radius is below this many pixels are drawn in their own
  /// color, unshaded (the seed: a pixel-sized particle does not depend on the lights).
  /// Particles under half a pixel are drawn as one pixel whose alpha is their coverage.
  float litMinPixels = 1.0f;
  BlendMode blend = BlendMode::Alpha;
  bool sortForAlpha = true;  ///< sort back to front each frame under BlendMode::Alpha
  Sprite sprite = Sprite::Disc;
  std::string spriteImage;  ///< a PNG for Sprite::Image; its rgb scales the particle color
  StrandStyle strandStyle = StrandStyle::Ribbon;
  /// Render-time blockers: particles (and strand vertices) inside any of these regions are
  /// not drawn. Particles whose stored Visible attribute is 0 are never drawn either.
  std::vector<Domain> blockers;
  ToneMap toneMap = ToneMap::None;
  float exposure = 1.0f;  ///< scales the HDR colour before the tone map
  /// Clears to alpha 0 and keeps the particles' coverage in alpha (straight, not
  /// premultiplied, in images): for compositing. `background` is then unused.
  bool transparent = false;
  SceneGeometry geometry;
  /// Velocity-stretched sprites (billboards, not Sprite::Point): each is drawn along its
  /// screen-space velocity, covering the path of the last `stretch` seconds (0: round), so
  /// fast sparks and rain streak. Reads the Velocity attribute (a group without it: round).
  float stretch = 0.0f;
  /// The most a stretched sprite's length may be, in widths (>= 1).
  float maxStretch = 8.0f;
  /// Per-group looks; the first naming a group applies to it.
  std::vector<GroupLook> groups;
};

/// Reads an effect file's `render` object (JSON text, docs/rendering.md) over `defaults`:
/// fields it does not give keep their value. A relative sprite PNG path is taken from
/// `baseDir` (the effect file's folder). Throws InvalidArgument naming the field
/// ("render.camera.pitch") for unknown fields, wrong types and values out of range.
RenderSettings parseRenderSettings(std::string_view json, const std::filesystem::path& baseDir = {},
                                   RenderSettings defaults = {});

/// An 8-bit RGBA image, rows from top to bottom.
struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;

  const std::uint8_t* pixel(int x, int y) const { return &rgba[(std::size_t(y) * width + x) * 4]; }
  std::uint8_t* pixel(int x, int y) { return &rgba[(std::size_t(y) * width + x) * 4]; }
};

/// Writes a PNG under a temporary name and renames it (IoError names the path).
void writePng(const Image& image, const std::filesystem::path& path);
/// Reads a PNG as RGBA (IoError names the path).
Image readPng(const std::filesystem::path& path);

/// Draws into the framebuffer bound in the OpenGL 3.3 core context current on this thread
/// (a game's own, or one flurry made). Construct, use and destroy it with that context
/// current. Throws RenderError if the context is older than 3.3 or a shader fails.
class Renderer {
 public:
  explicit Renderer(RenderSettings settings = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  RenderSettings& settings();
  const RenderSettings& settings() const;
  /// The attributes snow mode reads (Velocity for stretched sprites): call Group::require()
  /// with them before stepping.
  static AttributeSet attributes();

  /// Sets the viewport to width x height and clears it to the background.
  void begin(int width, int height);
  /// Snow mode: the group's visible particles as sprites or points; a hair-mode group's
  /// strands (Group::strands()) are drawn first.
  void draw(const Group& group);
  /// Hair mode: strands as ribbons or lines.
  void draw(const Strands& strands);
  /// Ends the frame: with a tone map, resolves the HDR image into the framebuffer that was
  /// bound at begin(). Without one it does nothing; call it anyway after the last draw.
  void end();
  /// Particles drawn by the last draw(Group) (after Visible and blockers).
  std::size_t lastDrawn() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct OffscreenOptions {
  int width = 1280;
  int height = 720;
  int samples = 4;  ///< multisampling; 0 or 1 for none
};

/// Renders into images without showing anything: a hidden GLFW window's context and a
/// framebuffer object of the asked size. Uses $DISPLAY when it works; otherwise starts Xvfb
/// (found on PATH) on a free display number, shared by the process's offscreen renderers
/// and stopped when the last one is destroyed. Throws RenderError "no usable OpenGL: ..."
/// when neither gives an OpenGL 3.3 core context. Use from one thread (GLFW's rule: the
/// main thread).
class OffscreenRenderer {
 public:
  explicit OffscreenRenderer(OffscreenOptions options = {}, RenderSettings settings = {});
  ~OffscreenRenderer();
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  RenderSettings& settings();
  /// Draws the groups' particles, then the strands (either may be empty), and reads back.
  Image render(std::span<const Group* const> groups, const Strands* strands = nullptr);
  Image render(const Group& group);
  Image render(const Strands& strands);
  /// The particles drawn by the last render.
  std::size_t lastDrawn() const;
  /// GL_RENDERER and GL_VERSION, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile)
  /// Mesa 22.3.6".
  std::string glInfo() const;
  /// Whether this process started its own Xvfb for it.
  bool startedXvfb() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace flurry
