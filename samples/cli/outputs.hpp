// Optional parts of the `flurry` tool (PNG frames, VDB export, the viewer, OpenCL devices)
// plug in here, each from its own source file, so the tool builds with whatever parts the
// library was built with.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"

namespace flurry::cli {

struct RunInfo {
  std::string effect;  ///< the effect's name, used to name output files
  int frames = 0;
  bool quiet = false;
  /// The loaded effect file (valid during the run).
  const Effect* effectFile = nullptr;
  /// Its `render` object as JSON text ("{}" when it has none); see docs/rendering.md.
  std::string render = "{}";
  /// The tool draws a progress bar with ETA on stderr during this run: a plugin should draw
  /// none of its own (it may report in end()).
  bool progress = false;
};

/// An output's cadence when its own option (`--png-every`, `--vdb-every`) was not given:
/// `run --every`'s N (default 10), so that every output writes the same frames.
inline int everyOfRun(const CLI::App& run) {
  if (const CLI::Option* o = run.get_option_no_throw("--every"))
    if (o->count() > 0 || !o->as<std::string>().empty()) return o->as<int>();
  return 10;
}

class Plugin {
 public:
  virtual ~Plugin() = default;
  /// Adds the plugin's flags to `flurry run` and any subcommands of its own to `app`.
  virtual void addOptions(CLI::App& app, CLI::App& run) = 0;
  /// Runs the plugin's own subcommand if it was given; returns true if it handled the call.
  virtual bool runCommand(CLI::App& /*app*/, int& /*exitCode*/) { return false; }
  /// Whether a flag of `flurry run` asked for this output.
  virtual bool enabled() const = 0;
  /// After the effect is built, before the first step: require the attributes it reads.
  virtual void begin(Context& /*ctx*/, const RunInfo& /*info*/) {}
  /// After each step; frame counts from 1.
  virtual void frame(Context& ctx, int frame) = 0;
  /// After the last step (wait for background work, print costs).
  virtual void end(Context& /*ctx*/) {}
};

/// The options every command loads effects with: the VDB field reader and the render
/// settings' checker where the tool has those parts (main.cpp).
EffectLoadOptions effectLoadOptions();
/// Loads an effect file or a built-in sample with effectLoadOptions(), then checks what the
/// loader cannot: that the `render` object's per-group looks name the effect's groups.
Effect loadEffectForCli(const std::string& nameOrPath);

// Each factory is defined by its part's source file, compiled in when that part is built.
std::unique_ptr<Plugin> makePngPlugin();     // png_output.cpp   (FLURRY_VIEWER)
std::unique_ptr<Plugin> makeVdbPlugin();     // vdb_output.cpp   (FLURRY_VDB)
std::unique_ptr<Plugin> makeOpenCLPlugin();  // opencl_devices.cpp (FLURRY_OPENCL)

}  // namespace flurry::cli
