#include "../backend.hpp"

namespace flurry::detail {

namespace {
class CpuBackend final : public BackendImpl {
 public:
  const char* name() const override { return "cpu"; }
  void step(GroupImpl& group, const StepParams& params) override {
    actFused(group, params);
    emitAndCompact(group, params);
    if (group.hair.enabled) simulateHair(group, params);
  }
};
}  // namespace

std::unique_ptr<BackendImpl> makeCpuBackend() { return std::make_unique<CpuBackend>(); }

}  // namespace flurry::detail
