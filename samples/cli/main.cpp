// `flurry`: runs sample effects from the command line.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "builtin.hpp"
#include "flurry/flurry.hpp"
#include "outputs.hpp"

namespace fs = std::filesystem;

namespace {

struct RunOptions {
  std::string effect;
  int frames = 300;
  std::string out;
  int every = 10;
  std::uint64_t seed = 1;
  double dt = 1.0 / 30.0;
  unsigned threads = 0;
  std::size_t capacity = 1'000'000;
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

std::string frameName(const std::string& base, int frame, const char* ext) {
  char buf[32];
  std::snprintf(buf, sizeof buf, ".%04d.%s", frame, ext);
  return base + buf;
}

int run(const RunOptions& o, std::vector<std::unique_ptr<flurry::cli::Plugin>>& plugins) {
  const flurry::samples::Sample* sample = flurry::samples::findSample(o.effect);
  if (!sample) {
    std::cerr << "flurry: no built-in effect named '" << o.effect << "' (see `flurry list`)\n";
    return 2;
  }
  if (!o.out.empty()) {
    std::error_code ec;
    fs::create_directories(o.out, ec);
    if (ec) {
      std::cerr << "flurry: cannot create output folder " << o.out << ": " << ec.message() << "\n";
      return 1;
    }
  }
  flurry::ContextOptions opts;
  opts.seed = o.seed;
  opts.dt = o.dt;
  opts.threads = o.threads;
  opts.backend = o.backend == "opencl" ? flurry::Backend::OpenCL
                 : o.backend == "auto" ? flurry::Backend::Auto
                                       : flurry::Backend::Cpu;
  opts.device = o.device;
  flurry::Context ctx(opts);
  sample->build(ctx, o.capacity);
  const flurry::cli::RunInfo info{o.effect, o.frames, o.quiet};
  for (auto& p : plugins)
    if (p->enabled()) p->begin(ctx, info);

  const auto start = std::chrono::steady_clock::now();
  int written = 0;
  for (int frame = 1; frame <= o.frames; ++frame) {
    ctx.step();
    const bool save = !o.out.empty() && (frame % o.every == 0 || frame == o.frames);
    for (flurry::Group* g : ctx.groups()) {
      if (!o.quiet) {
        const flurry::Bounds b = g->bounds();
        std::printf("frame %4d  t=%7.3fs  %-10s live %8zu", frame, ctx.time(), g->name().c_str(),
                    g->size());
        if (!b.empty)
          std::printf("  bounds (%.2f %.2f %.2f)..(%.2f %.2f %.2f)", b.min.x, b.min.y, b.min.z,
                      b.max.x, b.max.y, b.max.z);
        std::printf("\n");
      }
      if (save) {
        flurry::writePly(*g, fs::path(o.out) / frameName(g->name(), frame, "ply"));
        ++written;
      }
    }
    for (auto& p : plugins)
      if (p->enabled()) p->frame(ctx, frame);
  }
  for (auto& p : plugins)
    if (p->enabled()) p->end(ctx);
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (flurry::Group* g : ctx.groups()) {
    const auto& s = g->stats();
    std::printf("%s: %d steps in %.3f s; emitted %llu, alive %zu, killed by age %llu, absorbed %llu, "
                "dropped at capacity %llu\n",
                g->name().c_str(), o.frames, secs, (unsigned long long)s.emitted, g->size(),
                (unsigned long long)s.killedByAge, (unsigned long long)s.absorbed,
                (unsigned long long)s.droppedAtCapacity);
  }
  if (!o.out.empty()) std::printf("wrote %d PLY files to %s\n", written, o.out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"flurry: run particle effects"};
  app.require_subcommand(1);
  RunOptions o;
  CLI::App* runCmd = app.add_subcommand("run", "run an effect and write its frames");
  runCmd->add_option("effect", o.effect, "a built-in effect name (see `flurry list`)")->required();
  runCmd->add_option("--frames", o.frames, "steps to run")->check(CLI::Range(1, 100000000));
  runCmd->add_option("--out", o.out, "folder for the frames (PLY point clouds)");
  runCmd->add_option("--every", o.every, "write every N frames")->check(CLI::Range(1, 1000000));
  runCmd->add_option("--seed", o.seed, "random seed");
  runCmd->add_option("--dt", o.dt, "seconds per step")->check(CLI::Range(1e-6, 10.0));
  runCmd->add_option("--threads", o.threads, "worker threads (0: all cores)");
  runCmd->add_option("--capacity", o.capacity, "particles per group at most")
      ->check(CLI::Range(std::size_t(1), std::size_t(1) << 31));
  runCmd->add_flag("--quiet", o.quiet, "print only the summary");
  runCmd->add_option("--backend", o.backend, "cpu, opencl or auto")
      ->check(CLI::IsMember({"cpu", "opencl", "auto"}));
  runCmd->add_option("--device", o.device, "OpenCL platform or device name (a substring)");
  app.add_subcommand("list", "list the built-in effects");
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
    return run(o, plugins);
  } catch (const flurry::Error& e) {
    std::cerr << "flurry: " << e.what() << "\n";
    return 1;
  }
}
