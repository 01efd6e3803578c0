// `flurry`: runs effect files (built-in or on disk) from the command line.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <new>
#include <optional>

#include "builtin.hpp"
#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"
#include "outputs.hpp"
#ifdef FLURRY_CLI_VDB
#include "flurry/vdb.hpp"
#endif
#ifdef FLURRY_CLI_PNG
#include "flurry/render.hpp"
#endif

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

struct RunOptions {
  std::string effect;
  std::optional<int> frames;
  std::string out;
  int every = 10;
  std::optional<std::uint64_t> seed;
  std::optional<double> dt;
  unsigned threads = 0;
  std::size_t capacity = 0;
  double spawnScale = 1.0;
  bool quiet = false;
  std::string backend = "cpu";
  std::string device;
};

std::vector<std::unique_ptr<flurry::cli::Plugin>> makePlugins() {
  std::vector<std::unique_ptr<flurry::cli::Plugin>> plugins;
#ifdef FLURRY_CLI_PNG
  plugins.push_back(flurry::cli::makePngPlugin());
#endif
#ifdef FLURRY_CLI_VDB
  plugins.push_back(flurry::cli::makeVdbPlugin());
#endif
#ifdef FLURRY_CLI_OPENCL
  plugins.push_back(flurry::cli::makeOpenCLPlugin());
#endif
  return plugins;
}

/// "emitted N = alive A + killed by age K + ...": where every particle went (GroupStats).
std::string accounting(unsigned long long emitted, unsigned long long alive,
                       unsigned long long byAge, unsigned long long absorbed,
                       unsigned long long nonFinite, unsigned long long dropped) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "emitted %llu = alive %llu + killed by age %llu + absorbed %llu + non-finite "
                "%llu + dropped at capacity %llu",
                emitted, alive, byAge, absorbed, nonFinite, dropped);
  return buf;
}

/// The loader's warnings, one line each on stderr; they do not stop anything.
void printWarnings(const flurry::Effect& fx, const std::string& label) {
  const std::string where = fx.file.empty() ? label : fx.file.string();
  for (const flurry::EffectWarning& w : fx.warnings)
    std::cerr << "flurry: warning: " << where << ": " << w.message() << "\n";
}

/// One line for any failure: the tool never ends in std::terminate.
void printError(const std::string& prefix) {
  try {
    throw;
  } catch (const flurry::Error& e) {
    std::cerr << "flurry: " << prefix << e.what() << "\n";
  } catch (const std::bad_alloc&) {
    std::cerr << "flurry: " << prefix << "out of memory\n";
  } catch (const std::exception& e) {
    std::cerr << "flurry: " << prefix << e.what() << "\n";
  } catch (...) {
    std::cerr << "flurry: " << prefix << "unknown error\n";
  }
}

}  // namespace

namespace flurry::cli {

EffectLoadOptions effectLoadOptions() {
  EffectLoadOptions o;
#ifdef FLURRY_CLI_VDB
  // The core does not link OpenVDB; the tool lends the loader its reader.
  o.fieldResolver = [](const fs::path& file, const std::string& grid) {
    return vdb::readVectorField(file, grid);
  };
#endif
#ifdef FLURRY_CLI_PNG
  // The core does not read `render`; the renderer's parser checks it at load, so that
  // `validate` catches what `run --png` would refuse, and the error names the file.
  o.renderChecker = [](std::string_view render, const fs::path& baseDir) {
    const RenderSettings s = parseRenderSettings(render, baseDir);
    std::error_code ec;
    if (s.sprite == Sprite::Image && !fs::is_regular_file(s.spriteImage, ec))
      throw InvalidArgument("render.sprite", "no such file: " + s.spriteImage);
    for (const GroupLook& g : s.groups)
      if (g.sprite == Sprite::Image && !fs::is_regular_file(g.spriteImage, ec))
        throw InvalidArgument("render.groups." + g.group + ".sprite",
                              "no such file: " + g.spriteImage);
  };
#endif
  return o;
}

Effect loadEffectForCli(const std::string& nameOrPath) {
  Effect fx = samples::loadEffectOrSample(nameOrPath, effectLoadOptions());
#ifdef FLURRY_CLI_PNG
  // The loader's render checker sees the render object alone, not the groups.
  const RenderSettings s = parseRenderSettings(fx.render, fx.file.parent_path());
  for (const GroupLook& g : s.groups) {
    std::string names;
    bool found = false;
    for (const EffectGroup& eg : fx.groups) {
      found = found || eg.name == g.group;
      names += (names.empty() ? "" : ", ") + eg.name;
    }
    if (!found)
      throw EffectError(fx.file.empty() ? nameOrPath : fx.file.string(), "render.groups." + g.group,
                        "no group named \"" + g.group + "\" (groups: " + names + ")");
  }
#endif
  return fx;
}

}  // namespace flurry::cli

namespace {

std::string frameName(const std::string& base, int frame, const char* ext) {
  char buf[32];
  std::snprintf(buf, sizeof buf, ".%04d.%s", frame, ext);
  return base + buf;
}

std::string hms(double secs) {
  const long s = long(secs + 0.5);
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  return buf;
}

/// A progress bar with ETA on stderr, on a terminal or when FLURRY_PROGRESS=1. A terminal
/// gets one line redrawn in place, once a run has taken a second (short runs stay silent); a
/// log gets a whole line at each tenth of the run, ten lines however long it is.
class Progress {
 public:
  Progress(int total, bool quiet) : total_(total), start_(Clock::now()) {
    tty_ = ::isatty(STDERR_FILENO) == 1;
    const char* env = std::getenv("FLURRY_PROGRESS");
    active_ = !quiet && (env ? std::string(env) == "1" : tty_);
  }
  ~Progress() { clear(); }
  bool active() const { return active_; }
  /// Starts the clock (after the outputs' set-up, so that the ETA measures steps alone).
  void start() { start_ = Clock::now(); }

  void update(int done) {
    if (!active_) return;
    const auto now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (tty_) {
      if (elapsed < 1.0 ||
          (shown_ && now - last_ < std::chrono::milliseconds(100) && done < total_))
        return;
    } else {
      const int tenth = total_ > 0 ? int(std::int64_t(done) * 10 / total_) : 10;
      if (tenth == 0 || tenth == lastTenth_) return;
      lastTenth_ = tenth;
    }
    last_ = now;
    shown_ = tty_;  // a log's line is finished: nothing to clear
    const double frac = total_ > 0 ? double(done) / total_ : 1.0;
    const int width = 30, fill = int(frac * width);
    std::string bar(std::size_t(fill), '#');
    bar.append(std::size_t(width - fill), '.');
    const double eta = done > 0 ? elapsed * (total_ - done) / done : 0.0;
    std::fprintf(stderr, "%s[%s] %3d%%  frame %d/%d  %s elapsed  ETA %s%s", tty_ ? "\r" : "",
                 bar.c_str(), int(frac * 100), done, total_, hms(elapsed).c_str(), hms(eta).c_str(),
                 tty_ ? "\033[K" : "\n");
    std::fflush(stderr);
  }

  /// Removes the bar (before anything else is printed, and at the end).
  void clear() {
    if (!shown_) return;
    std::fprintf(stderr, tty_ ? "\r\033[K" : "");
    std::fflush(stderr);
    shown_ = false;
  }

 private:
  int total_;
  Clock::time_point start_, last_;
  int lastTenth_ = 0;
  bool tty_ = false, active_ = false, shown_ = false;
};

void printStats(const flurry::Group& g, int frame, double time) {
  const flurry::Bounds b = g.bounds();
  std::printf("frame %4d  t=%7.3fs  %-10s live %8zu", frame, time, g.name().c_str(), g.size());
  if (!b.empty)
    std::printf("  bounds (%.2f %.2f %.2f)..(%.2f %.2f %.2f)", b.min.x, b.min.y, b.min.z, b.max.x,
                b.max.y, b.max.z);
  if (!g.strands().position.empty())
    std::printf("  strands %zu (%zu vertices)", g.strands().size(), g.strands().vertexCount());
  std::printf("\n");
}

int run(const RunOptions& o, std::vector<std::unique_ptr<flurry::cli::Plugin>>& plugins) {
  flurry::Effect fx = flurry::cli::loadEffectForCli(o.effect);
  printWarnings(fx, o.effect);
  if (o.spawnScale != 1.0) fx.scaleSpawning(o.spawnScale);
  const int frames = o.frames.value_or(fx.frames);
  if (!o.out.empty()) {
    std::error_code ec;
    fs::create_directories(o.out, ec);
    if (ec) {
      std::cerr << "flurry: cannot create output folder " << o.out << ": " << ec.message() << "\n";
      return 1;
    }
  }
  flurry::ContextOptions opts = fx.contextOptions();
  if (o.seed) opts.seed = *o.seed;
  if (o.dt) opts.dt = *o.dt;
  opts.threads = o.threads;
  opts.backend = o.backend == "opencl" ? flurry::Backend::OpenCL
                 : o.backend == "auto" ? flurry::Backend::Auto
                                       : flurry::Backend::Cpu;
  opts.device = o.device;
  flurry::Context ctx(opts);
  if (!ctx.backendFallback().empty())
    std::cerr << "flurry: " << ctx.backendFallback() << "; using the CPU backend\n";
  fx.build(ctx, o.capacity);
  if (!o.out.empty()) {  // PLY temporaries that a run killed before its rename left behind
    const std::vector<flurry::Group*> groups = ctx.groups();
    const auto removed = flurry::removeStaleTemporaries(o.out, [&](std::string_view f) {
      for (const flurry::Group* g : groups)
        if (flurry::isFrameFileName(f, g->name(), "ply")) return true;
      return false;
    });
    if (!o.quiet && !removed.empty())
      std::printf("removed %zu stale temporary files of an earlier run from %s\n", removed.size(),
                  o.out.c_str());
  }

  flurry::cli::RunInfo info{fx.name, frames, o.quiet};
  info.effectFile = &fx;
  info.render = fx.render;
  Progress progress(frames, o.quiet);
  info.progress = progress.active();
  for (auto& p : plugins)
    if (p->enabled()) p->begin(ctx, info);
  progress.start();

  // Per-frame lines only where no bar is drawn (a log, a pipe): the bar replaces them.
  const bool perFrame = !o.quiet && !progress.active();
  const auto start = Clock::now();
  int written = 0;
  try {
    for (int frame = 1; frame <= frames; ++frame) {
      ctx.step();
      const bool save = !o.out.empty() && (frame % o.every == 0 || frame == frames);
      for (flurry::Group* g : ctx.groups()) {
        if (perFrame) printStats(*g, frame, ctx.time());
        if (save) {
          flurry::writePly(*g, fs::path(o.out) / frameName(g->name(), frame, "ply"));
          ++written;
        }
      }
      for (auto& p : plugins)
        if (p->enabled()) p->frame(ctx, frame);
      progress.update(frame);
    }
    progress.clear();
    for (auto& p : plugins)
      if (p->enabled()) p->end(ctx);
  } catch (...) {
    progress.clear();
    throw;
  }
  const double secs = std::chrono::duration<double>(Clock::now() - start).count();
  if (o.quiet) {
    // One line for scripts.
    unsigned long long emitted = 0, alive = 0, killed = 0, absorbed = 0, nonFinite = 0, dropped = 0;
    for (flurry::Group* g : ctx.groups()) {
      const auto& s = g->stats();
      emitted += s.emitted, alive += g->size(), killed += s.killedByAge, absorbed += s.absorbed,
          nonFinite += s.killedNonFinite, dropped += s.droppedAtCapacity;
    }
    std::printf("%s: %d steps in %.3f s; %s\n", fx.name.c_str(), frames, secs,
                accounting(emitted, alive, killed, absorbed, nonFinite, dropped).c_str());
    return 0;
  }
  for (flurry::Group* g : ctx.groups()) {
    if (!perFrame) printStats(*g, frames, ctx.time());
    const auto& s = g->stats();
    std::printf("%s: %d steps in %.3f s; %s", g->name().c_str(), frames, secs,
                accounting(s.emitted, g->size(), s.killedByAge, s.absorbed, s.killedNonFinite,
                           s.droppedAtCapacity)
                    .c_str());
    if (s.emittersSpawned > 0)
      std::printf(", emitters spawned %llu", (unsigned long long)s.emittersSpawned);
    std::printf("\n");
  }
  if (!o.out.empty()) std::printf("wrote %d PLY files to %s\n", written, o.out.c_str());
  return 0;
}

/// Loads each effect and builds it into a scratch context (so the core's own checks run too).
int validate(const std::vector<std::string>& files) {
  int bad = 0;
  for (const std::string& f : files) {
    try {
      const flurry::Effect fx = flurry::cli::loadEffectForCli(f);
      flurry::ContextOptions co = fx.contextOptions();
      co.threads = 1;
      flurry::Context ctx(co);
      fx.build(ctx, 64);  // a small capacity: the checks do not depend on it
      printWarnings(fx, f);
      if (fx.warnings.empty())
        std::printf("%s: ok\n", f.c_str());
      else
        std::printf("%s: ok, %zu warning%s\n", f.c_str(), fx.warnings.size(),
                    fx.warnings.size() == 1 ? "" : "s");
    } catch (const flurry::Error& e) {
      std::cerr << "flurry: " << e.what() << "\n";
      ++bad;
    } catch (...) {
      printError(f + ": ");  // out of memory, ...: name the file, go on with the next
      ++bad;
    }
  }
  return bad ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Whole lines on stdout even into a pipe or a file: the progress lines on stderr then fall
  // between its lines, never inside one (a full buffer would be flushed mid-line).
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  flurry::setLogCallback(flurry::logToStderr);  // the library's messages, as the tool's own
  CLI::App app{"flurry: run particle effects"};
  app.require_subcommand(1);
  RunOptions o;
  CLI::App* runCmd = app.add_subcommand("run", "run an effect and write its frames");
  runCmd
      ->add_option("effect", o.effect,
                   "a built-in effect name (see `flurry list`) or an effect file (.json)")
      ->required();
  runCmd->add_option("--frames", o.frames, "steps to run (default: the effect's)")
      ->check(CLI::Range(1, 100000000));
  runCmd->add_option("--out", o.out, "folder for the frames (PLY point clouds)");
  runCmd->add_option("--every", o.every, "write every N frames")->check(CLI::Range(1, 1000000));
  runCmd->add_option("--seed", o.seed, "random seed (default: the effect's)");
  runCmd->add_option("--dt", o.dt, "seconds per step (default: the effect's)")
      ->check(CLI::Range(1e-6, 10.0));
  runCmd->add_option("--threads", o.threads, "worker threads (0: all cores)");
  runCmd->add_option("--capacity", o.capacity, "cap every group's capacity (0: the effect's)")
      ->check(CLI::Range(std::size_t(0), std::size_t(1) << 31));
  runCmd
      ->add_option("--spawn-scale", o.spawnScale,
                   "scale every emitter's rate and bursts, and the capacities (a quality knob)")
      ->check(CLI::Range(1e-6, 1e6));
  runCmd->add_flag("--quiet", o.quiet, "print only errors, warnings and a one-line summary");
  runCmd->add_option("--backend", o.backend, "cpu, opencl or auto")
      ->check(CLI::IsMember({"cpu", "opencl", "auto"}));
  runCmd->add_option("--device", o.device, "OpenCL platform or device name (a substring)");
  app.add_subcommand("list", "list the built-in effects");
  std::vector<std::string> toValidate;
  CLI::App* validateCmd = app.add_subcommand(
      "validate", "check effect files: print \"ok\" (and any warnings) or the first error");
  validateCmd->add_option("effect", toValidate, "effect files (or built-in names)")->required();
  auto plugins = makePlugins();
  for (auto& p : plugins) p->addOptions(app, *runCmd);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    for (auto& p : plugins) {
      int code = 0;
      if (p->runCommand(app, code)) return code;
    }
    if (app.got_subcommand("list")) {
      for (const auto& s : flurry::samples::builtinSamples())
        std::printf("%-12s %s\n", s.name.c_str(), s.description.c_str());
      return 0;
    }
    if (validateCmd->parsed()) return validate(toValidate);
    return run(o, plugins);
  } catch (...) {
    printError("");
    return 1;
  }
}
