// `flurry devices`: the OpenCL platforms and devices the OpenCL backend can use
// (`flurry run --backend opencl --device NAME` picks one by a substring of its name).
#include <cstdio>

#include "flurry/opencl.hpp"
#include "outputs.hpp"

namespace flurry::cli {

namespace {

class OpenCLPlugin final : public Plugin {
 public:
  void addOptions(CLI::App& app, CLI::App& /*run*/) override {
    devices_ = app.add_subcommand("devices", "list the OpenCL devices (--backend opencl)");
  }

  bool runCommand(CLI::App& /*app*/, int& exitCode) override {
    if (!devices_ || !devices_->parsed()) return false;
    const auto list = openclDevices();  // OpenCLError (a flurry::Error) reaches main()
    if (list.empty()) {
      std::printf(
          "no OpenCL platform or device found (install an ICD, e.g. pocl-opencl-icd);\n"
          "--backend auto uses the CPU backend\n");
      exitCode = 0;
      return true;
    }
    std::string platform;
    for (const auto& d : list) {
      if (d.platform != platform) {
        platform = d.platform;
        std::printf("%s\n", platform.c_str());
      }
      std::printf("  %-4s %s\n", d.type.c_str(), d.name.c_str());
      std::printf("       %s, driver %s, %u compute units, %.1f GiB, buffers up to %.1f GiB%s\n",
                  d.version.c_str(), d.driver.c_str(), d.computeUnits,
                  double(d.globalMemory) / double(1u << 30),
                  double(d.maxAllocation) / double(1u << 30),
                  d.fp64 ? ", fp64" : ", no fp64 (emission times in float)");
    }
    exitCode = 0;
    return true;
  }

  bool enabled() const override { return false; }  // no output of its own for `flurry run`
  void frame(Context& /*ctx*/, int /*frame*/) override {}

 private:
  CLI::App* devices_ = nullptr;
};

}  // namespace

std::unique_ptr<Plugin> makeOpenCLPlugin() {
  return std::make_unique<OpenCLPlugin>();
}

}  // namespace flurry::cli
