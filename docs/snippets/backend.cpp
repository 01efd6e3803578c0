// docs/snippets/backend.cpp: built and run by tests/docs (label opencl)
#include <flurry/flurry.hpp>
#include <flurry/opencl.hpp>  // OpenCLError, openclDevices()

#include <cstdio>

static std::size_t fountain(const flurry::ContextOptions& options) {
  flurry::Context ctx(options);
  flurry::Group& g = ctx.createGroup("water", 10'000);
  flurry::Emitter nozzle;
  nozzle.rate = 1000;
  nozzle.types[0].velocity = flurry::Domain::cone({0, 0, 0}, {0, 6, 0}, 1.0f);
  g.addEmitter(nozzle);
  g.setActions({flurry::Gravity{},
                flurry::Bounce{flurry::Domain::plane({0, 0, 0}, {0, 1, 0}), 0.5f}, flurry::Move{},
                flurry::KillOld{}});
  ctx.run(60);
  return g.size();
}

int main() {
  for (const flurry::OpenCLDeviceInfo& d : flurry::openclDevices())
    std::printf("OpenCL: %s / %s (%s)\n", d.platform.c_str(), d.name.c_str(), d.type.c_str());

  std::size_t cpu = fountain({.seed = 5, .backend = flurry::Backend::Cpu});
  // Throws flurry::OpenCLError when there is no device; Backend::Auto falls back to the CPU.
  std::size_t ocl = fountain({.seed = 5, .backend = flurry::Backend::OpenCL});
  std::printf("CPU %zu particles, OpenCL %zu\n", cpu, ocl);
  return cpu == ocl && cpu > 0 ? 0 : 1;
}
