// The OpenCL runtime under the backend: error checking, device choice, one context per
// device shared by every Flurry context in the process, and the program cache.
#pragma once

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/cl.h>

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "flurry/opencl.hpp"

namespace flurry::detail::ocl {

/// Throws OpenCLError("what: CL_NAME (code)") unless err is CL_SUCCESS.
void check(cl_int err, const char* what);

/// An owning handle for an OpenCL object (retain/release by the given functions).
template <class T, cl_int (*Release)(T)>
class Handle {
 public:
  Handle() = default;
  explicit Handle(T h) : h_(h) {}
  ~Handle() { reset(); }
  Handle(Handle&& o) noexcept : h_(std::exchange(o.h_, nullptr)) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      h_ = std::exchange(o.h_, nullptr);
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  void reset() noexcept {
    if (h_) Release(h_);  // a release cannot usefully fail here; destructors never throw
    h_ = nullptr;
  }
  T get() const { return h_; }
  explicit operator bool() const { return h_ != nullptr; }

 private:
  T h_ = nullptr;
};

using Mem = Handle<cl_mem, clReleaseMemObject>;
using Kernel = Handle<cl_kernel, clReleaseKernel>;
using Program = Handle<cl_program, clReleaseProgram>;
using Queue = Handle<cl_command_queue, clReleaseCommandQueue>;
using Event = Handle<cl_event, clReleaseEvent>;
using ContextHandle = Handle<cl_context, clReleaseContext>;

struct Device {
  cl_platform_id platform = nullptr;
  cl_device_id id = nullptr;
  OpenCLDeviceInfo info;
  bool cpu = false;
};

/// The device `want` names (a substring of the platform or device name, any case); empty
/// takes the first GPU, else the first device. Throws OpenCLError (CL_DEVICE_NOT_FOUND) when
/// there is no platform, no device, or none matching, saying which.
Device selectDevice(const std::string& want);

/// Whether this process turned LLVM's SLP vectorizer off for PoCL before 6, so that it
/// vectorises a kernel's work-items (runtime.cpp); done by the first Runtime on such a device.
bool poclSlpOff();

struct CacheStats {
  std::uint64_t builds = 0;      ///< programs compiled from source
  std::uint64_t memoryHits = 0;  ///< programs found in this process's cache
  std::uint64_t diskHits = 0;    ///< programs loaded as binaries from the disk cache
  double buildSeconds = 0;       ///< time spent in clBuildProgram (from source and binary)
};

/// One device's context and its programs, shared by every backend on that device in this
/// process (so a second Context on the same device pays no compile).
class Runtime {
 public:
  static std::shared_ptr<Runtime> get(const Device& device);
  ~Runtime();

  cl_context context() const { return context_.get(); }
  const Device& device() const { return device_; }

  /// The program built from (source, options) for this device: from memory, else from the
  /// disk cache (FLURRY_OPENCL_CACHE: a folder, or "off"; default ~/.cache/flurry/opencl),
  /// else compiled. Throws OpenCLError with the build log and the source on failure.
  /// The returned handle is retained for the caller.
  cl_program program(const std::string& source, const std::string& options);

  static CacheStats cacheStats();
  /// Forgets the in-memory programs of every device (the benchmarks' cold/warm timings).
  static void clearMemoryCache();

 private:
  explicit Runtime(const Device& device);
  cl_program buildFromSource(const std::string& source, const std::string& options,
                             const std::string& diskPath);
  cl_program buildFromBinary(const std::string& binary, const std::string& options);

  Device device_;
  ContextHandle context_;
  std::mutex mutex_;
  std::map<std::string, Program> programs_;  // by hash of (device, options, source)
};

/// The key hash used for the caches (FNV-1a 64, hex).
std::string hashKey(const std::string& a, const std::string& b, const std::string& c);

}  // namespace flurry::detail::ocl
