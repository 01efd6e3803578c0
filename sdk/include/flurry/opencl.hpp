// The OpenCL backend's public face: its exception and the list of devices it can use.
// Pick the backend with ContextOptions::backend (Backend::OpenCL or Backend::Auto) and a
// device with ContextOptions::device. Only present when Flurry is built with FLURRY_OPENCL.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "flurry/error.hpp"

namespace flurry {

/// An OpenCL call failed. code() is the OpenCL error code (CL_OUT_OF_RESOURCES is -5, ...);
/// for a kernel program that did not build, buildLog() holds the compiler's log and
/// source() the generated source, so the failure can be reproduced outside Flurry.
class OpenCLError : public Error {
 public:
  OpenCLError(int code, const std::string& what, std::string buildLog = {},
              std::string source = {});
  int code() const noexcept { return code_; }
  const std::string& buildLog() const noexcept { return buildLog_; }
  const std::string& source() const noexcept { return source_; }
  /// "CL_OUT_OF_RESOURCES", ... ("CL_UNKNOWN_ERROR" for a code it does not know).
  static const char* codeName(int code) noexcept;

 private:
  int code_;
  std::string buildLog_, source_;
};

/// One OpenCL device as the backend sees it.
struct OpenCLDeviceInfo {
  std::string platform;  ///< platform name ("Portable Computing Language")
  std::string name;      ///< device name
  std::string type;      ///< "cpu", "gpu", "accelerator" or "other"
  std::string version;   ///< the device's OpenCL version string
  std::string driver;    ///< driver version
  unsigned computeUnits = 0;
  std::uint64_t globalMemory = 0;   ///< bytes
  std::uint64_t maxAllocation = 0;  ///< bytes in one buffer: bounds a group's capacity
  bool fp64 = false;  ///< doubles: needed for bitwise parity of emission times with the CPU
};

/// Every device of every OpenCL platform; empty when there is no platform (no ICD installed).
/// Throws OpenCLError if the platforms cannot be queried for another reason.
std::vector<OpenCLDeviceInfo> openclDevices();

}  // namespace flurry
