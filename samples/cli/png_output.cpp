// `flurry run ... --png DIR`: PNG frames from the offscreen renderer (no display needed), and
// `flurry view EFFECT`: the interactive viewer.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include "builtin.hpp"
#include "flurry/effect.hpp"
#include "flurry/io.hpp"
#include "flurry/render.hpp"
#include "flurry/render_viewer.hpp"
#include "outputs.hpp"

namespace fs = std::filesystem;

namespace flurry::cli {

namespace {

// Look options; each overrides the effect file's `render` object only when given.
struct Look {
  std::string size = "1280x720";
  std::string sprite;
  std::string blend;
  bool unlit = false;
  std::vector<float> orbit;   // yaw, pitch, distance
  std::vector<float> target;  // x, y, z
  float fov = 45.0f;
  CLI::Option* fovOption = nullptr;
  float exposure = 1.0f;
  CLI::Option* exposureOption = nullptr;
};

bool parseSize(const std::string& s, int& w, int& h) {
  char x = 0, extra = 0;
  return std::sscanf(s.c_str(), "%d%c%d%c", &w, &x, &h, &extra) == 3 && (x == 'x' || x == 'X') &&
         w > 0 && h > 0 && w <= 16384 && h <= 16384;
}

void addLookOptions(CLI::App& cmd, Look& look) {
  cmd.add_option("--size", look.size, "image or window size, WxH (default 1280x720)")
      ->check([](const std::string& s) {
        int w, h;
        return parseSize(s, w, h) ? std::string() : "expected WxH, e.g. 1280x720";
      });
  cmd.add_option(
      "--sprite", look.sprite,
      "point, disc, spark, snowflake, glow, puff, or a PNG file drawn for each particle");
  cmd.add_option("--blend", look.blend, "alpha or additive")
      ->check(CLI::IsMember({"alpha", "additive"}));
  cmd.add_flag("--unlit", look.unlit, "draw particles in their own color, without the lights");
  cmd.add_option("--orbit", look.orbit, "camera yaw,pitch (degrees),distance")
      ->expected(3)
      ->delimiter(',');
  cmd.add_option("--target", look.target, "the point the camera looks at, x,y,z")
      ->expected(3)
      ->delimiter(',');
  look.fovOption = cmd.add_option("--fov", look.fov, "vertical field of view, degrees")
                       ->check(CLI::Range(1.0, 170.0));
  // An additive effect run with --spawn-scale N is N times as bright: --exposure 1/N.
  look.exposureOption =
      cmd.add_option("--exposure", look.exposure,
                     "scale the colour before the tone map (additive glow: 1/spawn scale)")
          ->check(CLI::Range(1e-6, 100.0));
}

// The effect's `render` object, then the command line's overrides.
RenderSettings settingsFrom(const std::string& render, const fs::path& effectFile,
                            const Look& look) {
  RenderSettings s;
  try {
    s = parseRenderSettings(render, effectFile.empty() ? fs::path() : effectFile.parent_path());
  } catch (const InvalidArgument& e) {
    // The loader's checker refuses a bad `render` first; name the file here too.
    std::string why = e.what();
    if (why.rfind(e.parameter() + ": ", 0) == 0) why = why.substr(e.parameter().size() + 2);
    throw EffectError(effectFile.string(), e.parameter(), why);
  }
  if (look.sprite == "point")
    s.sprite = Sprite::Point;
  else if (look.sprite == "disc")
    s.sprite = Sprite::Disc;
  else if (look.sprite == "spark")
    s.sprite = Sprite::Spark;
  else if (look.sprite == "snowflake")
    s.sprite = Sprite::Snowflake;
  else if (look.sprite == "glow")
    s.sprite = Sprite::Glow;
  else if (look.sprite == "puff")
    s.sprite = Sprite::Puff;
  else if (!look.sprite.empty()) {
    s.sprite = Sprite::Image;
    s.spriteImage = look.sprite;
  }
  if (!look.blend.empty())
    s.blend = look.blend == "additive" ? BlendMode::Additive : BlendMode::Alpha;
  if (look.unlit) s.shading = false;
  // The command line's look is for every group: the effect's per-group looks give way.
  for (GroupLook& g : s.groups) {
    if (!look.sprite.empty()) g.sprite.reset();
    if (!look.blend.empty()) g.blend.reset();
    if (look.unlit) g.shading.reset();
  }
  if (look.orbit.size() == 3) {
    s.camera.yaw = look.orbit[0];
    s.camera.pitch = look.orbit[1];
    s.camera.distance = look.orbit[2];
  }
  if (look.target.size() == 3)
    s.camera.target = Vec3(look.target[0], look.target[1], look.target[2]);
  if (look.fovOption && look.fovOption->count() > 0) s.camera.fovY = look.fov;
  if (look.exposureOption && look.exposureOption->count() > 0) s.exposure = look.exposure;
  return s;
}

std::string frameName(const std::string& base, int frame) {
  char buf[32];
  std::snprintf(buf, sizeof buf, ".%04d.png", frame);
  return base + buf;
}

class PngPlugin : public Plugin {
 public:
  void addOptions(CLI::App& app, CLI::App& run) override {
    run_ = &run;
    run.add_option("--png", dir_, "folder for PNG frames (rendered offscreen, no display needed)");
    run.add_option("--png-every", every_, "write a PNG every N frames (default: --every)")
        ->check(CLI::Range(1, 1000000));
    run.add_option("--msaa", samples_, "multisamples per pixel for --png")
        ->check(CLI::Range(0, 16));
    addLookOptions(run, runLook_);

    view_ = app.add_subcommand("view",
                               "open an effect in a window (mouse: orbit, wheel: zoom, "
                               "space: pause, S: step, R: restart, Esc: quit)");
    view_->add_option("effect", viewEffect_, "a built-in effect name or an effect file")
        ->required();
    view_->add_option("--capacity", viewCapacity_, "cap every group's capacity (0: the effect's)")
        ->check(CLI::Range(std::size_t(0), std::size_t(1) << 31));
    view_->add_option("--exit-after", viewFrames_, "close after N frames (for scripts)")
        ->check(CLI::Range(0, 100000000));
    // The same bounds as `run --dt`, so a step that runs also views.
    view_->add_option("--dt", viewDt_, "seconds per step (default: the effect's)")
        ->check(CLI::Range(1e-6, 10.0));
    addLookOptions(*view_, viewLook_);
  }

  bool runCommand(CLI::App& /*app*/, int& exitCode) override {
    if (!view_->parsed()) return false;
    const Effect fx = loadEffectForCli(viewEffect_);
    for (const EffectWarning& w : fx.warnings)
      std::fprintf(stderr, "flurry: warning: %s: %s\n",
                   (fx.file.empty() ? viewEffect_ : fx.file.string()).c_str(), w.message().c_str());
    ViewerOptions vo;
    parseSize(viewLook_.size, vo.width, vo.height);
    vo.title = "flurry " + fx.name;
    vo.maxFrames = viewFrames_;
    const RenderSettings settings = settingsFrom(fx.render, fx.file, viewLook_);
    try {
      runViewer(
          [&] {
            ViewerScene scene;
            ContextOptions co = fx.contextOptions();
            if (viewDt_) co.dt = *viewDt_;
            scene.context = std::make_unique<Context>(co);
            fx.build(*scene.context, viewCapacity_);
            return scene;
          },
          settings, vo);
    } catch (const RenderError& e) {
      throw Error(std::string("view: ") + e.what() +
                  " (the viewer needs a display; without one, `flurry run " + viewEffect_ +
                  " --png DIR` writes frames)");
    }
    exitCode = 0;
    return true;
  }

  bool enabled() const override { return !dir_.empty(); }

  void begin(Context& ctx, const RunInfo& info) override {
    info_ = info;
    if (every_ == 0) every_ = everyOfRun(*run_);
    std::error_code ec;
    fs::create_directories(dir_, ec);
    if (ec) throw IoError(dir_, "cannot create the --png folder: " + ec.message());
    // PNG temporaries that a run killed before its rename left behind.
    const auto removed = removeStaleTemporaries(
        dir_, [&](std::string_view f) { return isFrameFileName(f, info.effect, "png"); });
    if (!info.quiet && !removed.empty())
      std::printf("png: removed %zu stale temporary files of an earlier run from %s\n",
                  removed.size(), dir_.c_str());
    OffscreenOptions oo;
    parseSize(runLook_.size, oo.width, oo.height);
    oo.samples = samples_;
    try {
      renderer_ = std::make_unique<OffscreenRenderer>(
          oo, settingsFrom(info.render, info.effectFile ? info.effectFile->file : fs::path(),
                           runLook_));
    } catch (const RenderError& e) {
      throw Error(std::string("--png: ") + e.what());
    }
    for (Group* g : ctx.groups()) g->require(Renderer::attributes());
    if (!info.quiet)
      std::printf("png: %dx%d frames of %s with %s%s\n", oo.width, oo.height, info.effect.c_str(),
                  renderer_->glInfo().c_str(),
                  renderer_->startedXvfb() ? " (on a private Xvfb)" : "");
  }

  void frame(Context& ctx, int frame) override {
    if (frame % every_ != 0 && frame != info_.frames) return;
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<Group*> groups = ctx.groups();
    std::vector<const Group*> cgroups(groups.begin(), groups.end());
    const Image img = renderer_->render(cgroups);
    const auto t1 = std::chrono::steady_clock::now();
    writePng(img, fs::path(dir_) / frameName(info_.effect, frame));
    const auto t2 = std::chrono::steady_clock::now();
    renderSecs_ += std::chrono::duration<double>(t1 - t0).count();
    writeSecs_ += std::chrono::duration<double>(t2 - t1).count();
    ++written_;
  }

  void end(Context& /*ctx*/) override {
    renderer_.reset();  // stops a private Xvfb now rather than at exit
    if (written_ > 0)
      std::printf("wrote %d PNG frames to %s (render %.1f ms, PNG %.1f ms per frame)\n", written_,
                  dir_.c_str(), 1e3 * renderSecs_ / written_, 1e3 * writeSecs_ / written_);
  }

 private:
  CLI::App* run_ = nullptr;
  CLI::App* view_ = nullptr;
  std::string dir_;
  int every_ = 0;
  int samples_ = 4;
  Look runLook_, viewLook_;
  std::string viewEffect_;
  std::size_t viewCapacity_ = 0;
  int viewFrames_ = 0;
  std::optional<double> viewDt_;
  RunInfo info_;
  std::unique_ptr<OffscreenRenderer> renderer_;
  double renderSecs_ = 0, writeSecs_ = 0;
  int written_ = 0;
};

}  // namespace

std::unique_ptr<Plugin> makePngPlugin() {
  return std::make_unique<PngPlugin>();
}

}  // namespace flurry::cli
