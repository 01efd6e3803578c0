#include "runtime.hpp"

#include <dlfcn.h>
#include <link.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <vector>

#include "flurry/io.hpp"
#include "log.hpp"

namespace flurry {

OpenCLError::OpenCLError(int code, const std::string& what, std::string buildLog,
                         std::string source)
    : Error(what), code_(code), buildLog_(std::move(buildLog)), source_(std::move(source)) {}

const char* OpenCLError::codeName(int code) noexcept {
  switch (code) {
#define FL_CASE(c) \
  case c:          \
    return #c;
    FL_CASE(CL_SUCCESS)
    FL_CASE(CL_DEVICE_NOT_FOUND)
    FL_CASE(CL_DEVICE_NOT_AVAILABLE)
    FL_CASE(CL_COMPILER_NOT_AVAILABLE)
    FL_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    FL_CASE(CL_OUT_OF_RESOURCES)
    FL_CASE(CL_OUT_OF_HOST_MEMORY)
    FL_CASE(CL_BUILD_PROGRAM_FAILURE)
    FL_CASE(CL_MAP_FAILURE)
    FL_CASE(CL_INVALID_VALUE)
    FL_CASE(CL_INVALID_DEVICE)
    FL_CASE(CL_INVALID_CONTEXT)
    FL_CASE(CL_INVALID_COMMAND_QUEUE)
    FL_CASE(CL_INVALID_MEM_OBJECT)
    FL_CASE(CL_INVALID_BINARY)
    FL_CASE(CL_INVALID_BUILD_OPTIONS)
    FL_CASE(CL_INVALID_PROGRAM)
    FL_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    FL_CASE(CL_INVALID_KERNEL_NAME)
    FL_CASE(CL_INVALID_KERNEL)
    FL_CASE(CL_INVALID_ARG_INDEX)
    FL_CASE(CL_INVALID_ARG_VALUE)
    FL_CASE(CL_INVALID_ARG_SIZE)
    FL_CASE(CL_INVALID_KERNEL_ARGS)
    FL_CASE(CL_INVALID_WORK_DIMENSION)
    FL_CASE(CL_INVALID_WORK_GROUP_SIZE)
    FL_CASE(CL_INVALID_WORK_ITEM_SIZE)
    FL_CASE(CL_INVALID_GLOBAL_OFFSET)
    FL_CASE(CL_INVALID_EVENT_WAIT_LIST)
    FL_CASE(CL_INVALID_EVENT)
    FL_CASE(CL_INVALID_OPERATION)
    FL_CASE(CL_INVALID_BUFFER_SIZE)
    FL_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
    FL_CASE(CL_INVALID_PLATFORM)
    FL_CASE(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
#undef FL_CASE
    case -1001:
      return "CL_PLATFORM_NOT_FOUND_KHR";
    default:
      return "CL_UNKNOWN_ERROR";
  }
}

namespace {

std::string platformString(cl_platform_id p, cl_platform_info what) {
  std::size_t n = 0;
  if (clGetPlatformInfo(p, what, 0, nullptr, &n) != CL_SUCCESS || n == 0) return {};
  std::string s(n, '\0');
  clGetPlatformInfo(p, what, n, s.data(), nullptr);
  s.resize(std::strlen(s.c_str()));
  return s;
}

std::string deviceString(cl_device_id d, cl_device_info what) {
  std::size_t n = 0;
  if (clGetDeviceInfo(d, what, 0, nullptr, &n) != CL_SUCCESS || n == 0) return {};
  std::string s(n, '\0');
  clGetDeviceInfo(d, what, n, s.data(), nullptr);
  s.resize(std::strlen(s.c_str()));
  return s;
}

template <class T>
T deviceValue(cl_device_id d, cl_device_info what) {
  T v{};
  clGetDeviceInfo(d, what, sizeof v, &v, nullptr);
  return v;
}

std::filesystem::path diskCacheDir() {
  if (const char* e = std::getenv("FLURRY_OPENCL_CACHE")) {
    const std::string v = e;
    if (v == "off" || v == "0" || v.empty()) return {};
    return v;
  }
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x)
    return std::filesystem::path(x) / "flurry" / "opencl";
  if (const char* h = std::getenv("HOME"); h && *h)
    return std::filesystem::path(h) / ".cache" / "flurry" / "opencl";
  return {};
}

// PoCL keeps its own cache of compiled kernels, in POCL_CACHE_DIR as the driver reads it when
// it loads (the first clGetPlatformIDs): put it inside Flurry's cache, so that one folder
// holds both and clearing it clears both. Not when the user chose PoCL's folder, nor when
// Flurry's cache is off.
void placePoclCache() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (std::getenv("POCL_CACHE_DIR")) return;
    const std::filesystem::path dir = diskCacheDir();
    if (!dir.empty()) ::setenv("POCL_CACHE_DIR", (dir / "pocl").c_str(), 0);
  });
}

// PoCL before 6.0 runs LLVM's SLP vectorizer over a kernel's code for one work-item before
// it wraps the work-items in a loop (PoCL's "Do not vectorize before the WILoops", 6.0). The
// short vectors it makes there (a point's y and z, a dot product's terms) are values the loop
// vectorizer cannot widen, so it leaves the work-item loop scalar: every act kernel ran one
// particle at a time, at a fifth of the CPU backend's speed. LLVM's options belong to the
// process: through the libLLVM the PoCL driver loaded, the SLP vectorizer gets a cost
// threshold nothing passes, and the loop vectorizer runs eight or sixteen work-items at once
// (the arithmetic of each is unchanged: no contraction, no reassociation). Only for PoCL
// before 6 on a CPU device (its CPU drivers are the ones that vectorize work-items);
// FLURRY_POCL_SLP=1 leaves PoCL as it is. A process that compiles with the same libLLVM
// otherwise (a software rasteriser's shaders) shares the setting.
std::atomic<bool> gPoclSlpOff{false};

void letPoclVectorizeWorkItems(const detail::ocl::Device& d) {
  static std::once_flag once;
  if (!d.cpu || d.info.platform.find("Portable Computing Language") == std::string::npos) return;
  const std::string version = platformString(d.platform, CL_PLATFORM_VERSION);
  const std::size_t at = version.find("PoCL ");
  if (at == std::string::npos || std::atoi(version.c_str() + at + 5) >= 6) return;
  if (const char* e = std::getenv("FLURRY_POCL_SLP"); e && *e && std::string(e) != "0") return;
  // The platform's version names the LLVM it compiles with ("... LLVM 15.0.6, ...").
  const std::size_t llvmAt = version.find("LLVM ");
  if (llvmAt == std::string::npos) return;
  const int llvmMajor = std::atoi(version.c_str() + llvmAt + 5);
  if (llvmMajor <= 0) return;
  std::call_once(once, [llvmMajor] {
    // That libLLVM, as the driver loaded it (at clGetPlatformIDs): libLLVM-15.so.1 or
    // libLLVM.so.18.1. Never another (a process may hold two), never a new one; none when the
    // driver links LLVM statically.
    struct Find {
      std::string dash, dot, path;
    } find{"libLLVM-" + std::to_string(llvmMajor) + ".so",
           "libLLVM.so." + std::to_string(llvmMajor) + ".",
           {}};
    dl_iterate_phdr(
        [](dl_phdr_info* info, std::size_t, void* data) {
          auto& f = *static_cast<Find*>(data);
          const std::string name = info->dlpi_name ? info->dlpi_name : "";
          const std::string base = name.substr(name.find_last_of('/') + 1);
          if (base.rfind(f.dash, 0) != 0 && base.rfind(f.dot, 0) != 0) return 0;
          f.path = name;
          return 1;
        },
        &find);
    const std::string& path = find.path;
    if (path.empty()) return;
    void* llvm = dlopen(path.c_str(), RTLD_LAZY | RTLD_NOLOAD);
    if (!llvm) return;
    using Parse = void (*)(int, const char* const*, const char*);
    if (auto parse = reinterpret_cast<Parse>(dlsym(llvm, "LLVMParseCommandLineOptions"))) {
      // (an option given twice would end the process: once per process, and nothing else
      // sets this one)
      const char* argv[] = {"flurry", "-slp-threshold=1000000"};
      parse(2, argv, nullptr);
      gPoclSlpOff = true;
      detail::log(LogLevel::Info,
                  "opencl: PoCL before 6: its SLP vectorizer is off, so that work-items "
                  "vectorize (FLURRY_POCL_SLP=1 keeps it)");
    }
    dlclose(llvm);
  });
}

std::vector<cl_platform_id> platforms() {
  placePoclCache();
  cl_uint n = 0;
  const cl_int err = clGetPlatformIDs(0, nullptr, &n);
  if (err == -1001 /* CL_PLATFORM_NOT_FOUND_KHR: the ICD loader found no platform */ || n == 0)
    return {};
  detail::ocl::check(err, "clGetPlatformIDs");
  std::vector<cl_platform_id> ids(n);
  detail::ocl::check(clGetPlatformIDs(n, ids.data(), nullptr), "clGetPlatformIDs");
  return ids;
}

std::vector<detail::ocl::Device> allDevices() {
  std::vector<detail::ocl::Device> out;
  for (cl_platform_id p : platforms()) {
    cl_uint n = 0;
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, nullptr, &n) != CL_SUCCESS || n == 0) continue;
    std::vector<cl_device_id> ids(n);
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, n, ids.data(), nullptr) != CL_SUCCESS) continue;
    for (cl_device_id d : ids) {
      detail::ocl::Device dev;
      dev.platform = p;
      dev.id = d;
      auto& i = dev.info;
      i.platform = platformString(p, CL_PLATFORM_NAME);
      i.name = deviceString(d, CL_DEVICE_NAME);
      const auto type = deviceValue<cl_device_type>(d, CL_DEVICE_TYPE);
      i.type = (type & CL_DEVICE_TYPE_GPU)           ? "gpu"
               : (type & CL_DEVICE_TYPE_CPU)         ? "cpu"
               : (type & CL_DEVICE_TYPE_ACCELERATOR) ? "accelerator"
                                                     : "other";
      dev.cpu = (type & CL_DEVICE_TYPE_CPU) != 0;
      i.version = deviceString(d, CL_DEVICE_VERSION);
      i.driver = deviceString(d, CL_DRIVER_VERSION);
      i.computeUnits = deviceValue<cl_uint>(d, CL_DEVICE_MAX_COMPUTE_UNITS);
      i.globalMemory = deviceValue<cl_ulong>(d, CL_DEVICE_GLOBAL_MEM_SIZE);
      i.maxAllocation = deviceValue<cl_ulong>(d, CL_DEVICE_MAX_MEM_ALLOC_SIZE);
      i.fp64 = deviceValue<cl_device_fp_config>(d, CL_DEVICE_DOUBLE_FP_CONFIG) != 0;
      out.push_back(std::move(dev));
    }
  }
  return out;
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

std::vector<OpenCLDeviceInfo> openclDevices() {
  std::vector<OpenCLDeviceInfo> out;
  for (auto& d : allDevices()) out.push_back(d.info);
  return out;
}

namespace detail::ocl {

void check(cl_int err, const char* what) {
  if (err == CL_SUCCESS) return;
  std::string msg = std::string("OpenCL: ") + what + " failed: " + OpenCLError::codeName(err) +
                    " (" + std::to_string(err) + ")";
  if (err == CL_MEM_OBJECT_ALLOCATION_FAILURE || err == CL_OUT_OF_RESOURCES ||
      err == CL_OUT_OF_HOST_MEMORY)
    msg += ": the device is out of memory";
  throw OpenCLError(err, msg);
}

Device selectDevice(const std::string& want) {
  const auto devices = allDevices();
  if (devices.empty())
    throw OpenCLError(CL_DEVICE_NOT_FOUND,
                      "OpenCL: no OpenCL platform or device found (install an ICD, e.g. "
                      "pocl-opencl-icd for the CPU)");
  if (!want.empty()) {
    const std::string w = lower(want);
    for (const auto& d : devices)
      if (lower(d.info.name).find(w) != std::string::npos ||
          lower(d.info.platform).find(w) != std::string::npos)
        return d;
    std::string names;
    for (const auto& d : devices) names += "\n  " + d.info.platform + ": " + d.info.name;
    throw OpenCLError(CL_DEVICE_NOT_FOUND,
                      "OpenCL: no device matches '" + want + "'; found:" + names);
  }
  for (const auto& d : devices)
    if (d.info.type == "gpu") return d;
  return devices.front();
}

bool poclSlpOff() {
  return gPoclSlpOff;
}

std::string hashKey(const std::string& a, const std::string& b, const std::string& c) {
  std::uint64_t h = 1469598103934665603ull;
  for (const std::string* s : {&a, &b, &c}) {
    for (unsigned char ch : *s) h = (h ^ ch) * 1099511628211ull;
    h = (h ^ 0xFFu) * 1099511628211ull;  // separator: ("ab", "c") != ("a", "bc")
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

namespace {

std::mutex gRegistryMutex;
// Runtimes live as long as the process, so that their programs outlive the Contexts that
// built them. Never destroyed: releasing OpenCL objects during static destruction may run
// after the driver has unloaded.
auto& gRuntimes = *new std::map<cl_device_id, std::shared_ptr<Runtime>>;
std::mutex gStatsMutex;
CacheStats gStats;

std::string buildLog(cl_program p, cl_device_id d) {
  std::size_t n = 0;
  clGetProgramBuildInfo(p, d, CL_PROGRAM_BUILD_LOG, 0, nullptr, &n);
  std::string s(n, '\0');
  if (n) clGetProgramBuildInfo(p, d, CL_PROGRAM_BUILD_LOG, n, s.data(), nullptr);
  s.resize(std::strlen(s.c_str()));
  return s;
}

double since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

Runtime::Runtime(const Device& device) : device_(device) {
  letPoclVectorizeWorkItems(device);  // before this device compiles anything
  cl_int err = CL_SUCCESS;
  const cl_context_properties props[] = {
      CL_CONTEXT_PLATFORM, reinterpret_cast<cl_context_properties>(device.platform), 0};
  context_ = ContextHandle(clCreateContext(props, 1, &device.id, nullptr, nullptr, &err));
  check(err, "clCreateContext");
}

Runtime::~Runtime() = default;

std::shared_ptr<Runtime> Runtime::get(const Device& device) {
  std::lock_guard lock(gRegistryMutex);
  auto& slot = gRuntimes[device.id];
  if (!slot) slot.reset(new Runtime(device));
  return slot;
}

CacheStats Runtime::cacheStats() {
  std::lock_guard lock(gStatsMutex);
  return gStats;
}

void Runtime::clearMemoryCache() {
  std::lock_guard lock(gRegistryMutex);
  for (auto& [id, r] : gRuntimes) {
    std::lock_guard l2(r->mutex_);
    r->programs_.clear();
  }
}

cl_program Runtime::program(const std::string& source, const std::string& options) {
  std::lock_guard lock(mutex_);
  const std::string key = options + '\0' + source;
  auto it = programs_.find(key);
  if (it != programs_.end()) {
    {
      std::lock_guard s(gStatsMutex);
      ++gStats.memoryHits;
    }
    clRetainProgram(it->second.get());
    return it->second.get();
  }
  const std::string devKey = device_.info.platform + '\n' + device_.info.name + '\n' +
                             device_.info.driver + '\n' + device_.info.version;
  std::string diskPath;
  const auto dir = diskCacheDir();
  if (!dir.empty()) diskPath = (dir / (hashKey(devKey, options, source) + ".bin")).string();

  cl_program p = nullptr;
  if (!diskPath.empty()) {
    std::ifstream in(diskPath, std::ios::binary);
    if (in) {
      std::ostringstream ss;
      ss << in.rdbuf();
      p = buildFromBinary(ss.str(), options);  // null if stale or rejected: rebuild
    }
  }
  if (!p) p = buildFromSource(source, options, diskPath);
  programs_.emplace(key, Program(p));
  clRetainProgram(p);
  return p;
}

cl_program Runtime::buildFromBinary(const std::string& binary, const std::string& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto* bytes = reinterpret_cast<const unsigned char*>(binary.data());
  const std::size_t size = binary.size();
  cl_int status = CL_SUCCESS, err = CL_SUCCESS;
  cl_program p = clCreateProgramWithBinary(context(), 1, &device_.id, &size, &bytes, &status, &err);
  if (err != CL_SUCCESS || status != CL_SUCCESS) {
    if (p) clReleaseProgram(p);
    return nullptr;
  }
  if (clBuildProgram(p, 1, &device_.id, options.c_str(), nullptr, nullptr) != CL_SUCCESS) {
    clReleaseProgram(p);
    return nullptr;
  }
  std::lock_guard s(gStatsMutex);
  ++gStats.diskHits;
  gStats.buildSeconds += since(t0);
  return p;
}

cl_program Runtime::buildFromSource(const std::string& source, const std::string& options,
                                    const std::string& diskPath) {
  const auto t0 = std::chrono::steady_clock::now();
  const char* src = source.c_str();
  const std::size_t len = source.size();
  cl_int err = CL_SUCCESS;
  Program p(clCreateProgramWithSource(context(), 1, &src, &len, &err));
  check(err, "clCreateProgramWithSource");
  err = clBuildProgram(p.get(), 1, &device_.id, options.c_str(), nullptr, nullptr);
  if (err != CL_SUCCESS) {
    std::string log = buildLog(p.get(), device_.id);
    throw OpenCLError(err,
                      std::string("OpenCL: building the kernel program failed: ") +
                          OpenCLError::codeName(err) + " (" + std::to_string(err) + ") on " +
                          device_.info.name + "\n" + log,
                      log, source);
  }
  {
    std::lock_guard s(gStatsMutex);
    ++gStats.builds;
    gStats.buildSeconds += since(t0);
  }
  if (!diskPath.empty()) {
    // Best effort: a cache that cannot be written only costs the next run a compile.
    std::size_t size = 0;
    if (clGetProgramInfo(p.get(), CL_PROGRAM_BINARY_SIZES, sizeof size, &size, nullptr) ==
            CL_SUCCESS &&
        size > 0) {
      std::vector<char> bin(size);
      unsigned char* ptr = reinterpret_cast<unsigned char*>(bin.data());
      if (clGetProgramInfo(p.get(), CL_PROGRAM_BINARIES, sizeof ptr, &ptr, nullptr) == CL_SUCCESS) {
        try {
          std::filesystem::create_directories(std::filesystem::path(diskPath).parent_path());
          writeFileAtomic(diskPath, bin);
        } catch (const std::exception&) {
        }
      }
    }
  }
  cl_program out = p.get();
  clRetainProgram(out);
  return out;  // p releases its reference; the caller owns `out`'s
}

}  // namespace detail::ocl
}  // namespace flurry
