// Capturing particles, writing files atomically, and the background sequence writer. No
// OpenVDB headers here (see grids.hpp).
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <exception>
#include <limits>
#include <mutex>
#include <numbers>
#include <thread>

#include "detail.hpp"
#include "flurry/io.hpp"

namespace fs = std::filesystem;

namespace flurry::vdb {

namespace detail {

std::atomic<BeforeRenameHook> beforeRename{nullptr};

double particleMass(float radius, float density) {
  const double r = radius;
  return double(density) * (4.0 / 3.0) * std::numbers::pi * r * r * r;
}

void validate(const ExportOptions& o) {
  auto nonNegative = [](float v, const char* name) {
    if (!std::isfinite(v) || v < 0.0f) throw InvalidArgument(name, "must be finite and >= 0");
  };
  nonNegative(o.fogVoxelSize, "fogVoxelSize");
  nonNegative(o.pointsVoxelSize, "pointsVoxelSize");
  nonNegative(o.density, "density");
  nonNegative(o.defaultRadius, "defaultRadius");
  if (!std::isfinite(o.fogMinKernelVoxels) || o.fogMinKernelVoxels <= 0.0f)
    throw InvalidArgument("fogMinKernelVoxels", "must be finite and > 0");
  if (o.pointsPerVoxel < 1) throw InvalidArgument("pointsPerVoxel", "must be >= 1");
  if (!o.fog && !o.points) throw InvalidArgument("fog", "neither fog nor points is exported");
}

namespace {

/// write() until done, retrying short writes; returns 0 or errno.
int writeAll(int fd, std::string_view bytes) {
  const char* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, std::min<std::size_t>(left, std::size_t(1) << 30));
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    p += n;
    left -= std::size_t(n);
  }
  return 0;
}

}  // namespace

void writeAtomic(const fs::path& path, std::string_view bytes) {
  const fs::path tmp = path.string() + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw IoError(path.string(), std::string("cannot create: ") + std::strerror(errno));
  int err = writeAll(fd, bytes);
  // fsync before the rename: after a power cut the name must not point at missing blocks.
  if (!err && ::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) err = errno;
  if (::close(fd) != 0 && !err && errno != EINTR) err = errno;
  if (err) {
    ::unlink(tmp.c_str());
    throw IoError(path.string(), std::string("write failed: ") + std::strerror(err));
  }
  if (BeforeRenameHook hook = beforeRename.load()) hook(tmp, path);
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    err = errno;
    ::unlink(tmp.c_str());
    throw IoError(path.string(), std::string("rename failed: ") + std::strerror(err));
  }
  // Make the rename itself durable; a folder that cannot be synced is not an error.
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace detail

Particles Particles::capture(const Group& group, const ExportOptions& o) {
  Particles out;
  out.group = group.name();
  const std::size_t n = group.size();
  const AttributeSet stored = group.attributes();
  // What it reads, back from a device in one transfer.
  AttributeSet reads{Attribute::Position, Attribute::Id,   Attribute::Velocity,
                     Attribute::Color,    Attribute::Size, Attribute::Visible};
  if (o.points) reads.insert(Attribute::Age);
  group.fetch(reads);
  // Which particles: all, or those no blocker hides. Visible not stored: none is hidden.
  std::vector<std::uint32_t> keep;
  const bool filter = !o.keepHidden && stored.has(Attribute::Visible);
  if (filter) {
    const auto vis = group.visible();
    keep.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
      if (vis[i]) keep.push_back(std::uint32_t(i));
    out.hidden = n - keep.size();
  }
  const std::size_t m = filter ? keep.size() : n;
  auto pick = [&](std::size_t k) { return filter ? std::size_t(keep[k]) : k; };
  auto vec3 = [&](Attribute a, std::vector<Vec3>& dst) {
    const auto x = group.lane(a, 0), y = group.lane(a, 1), z = group.lane(a, 2);
    dst.resize(m);
    for (std::size_t k = 0; k < m; ++k) {
      const std::size_t i = pick(k);
      dst[k] = Vec3(x[i], y[i], z[i]);
    }
  };
  auto scalar = [&](Attribute a, std::vector<float>& dst) {
    const auto x = group.lane(a, 0);
    dst.resize(m);
    for (std::size_t k = 0; k < m; ++k) dst[k] = x[pick(k)];
  };
  vec3(Attribute::Position, out.position);
  const auto ids = group.ids();
  out.id.resize(m);
  for (std::size_t k = 0; k < m; ++k) out.id[k] = ids[pick(k)];
  if (stored.has(Attribute::Velocity)) vec3(Attribute::Velocity, out.velocity);
  if (stored.has(Attribute::Color)) vec3(Attribute::Color, out.color);
  if (stored.has(Attribute::Size)) scalar(Attribute::Size, out.radius);
  if (o.points && stored.has(Attribute::Age)) scalar(Attribute::Age, out.age);
  return out;
}

namespace {

/// What one sampled particle or strand vertex adds to the fog's active voxels.
struct Footprint {
  float r;    ///< its radius
  float len;  ///< a strand vertex: its segment's length (to the next vertex); particle: < 0
  bool root;  ///< a strand's first vertex: the tube's two end caps, one ball
};

/// Active voxels of the fog at voxel size v, estimated from above: each kernel's volume in
/// voxels (a ball per particle, a tube per segment; overlaps counted twice), and at most the
/// voxels of the bounding box grown by the largest kernel.
double estimateVoxels(const std::vector<Footprint>& fp, double weight, Vec3 lo, Vec3 hi, float maxR,
                      double v, double minKernel) {
  double sum = 0.0;
  for (const Footprint& f : fp) {
    const double h = std::max(double(f.r) / v, minKernel);  // kernel radius in voxels
    double n = 0.0;
    if (f.len < 0.0f || f.root) n += std::max(1.0, 4.0 / 3.0 * std::numbers::pi * h * h * h);
    if (f.len > 0.0f) n += std::numbers::pi * h * h * double(f.len) / v;
    sum += n;
  }
  sum *= weight;
  const double pad = 2.0 * std::max(double(maxR), minKernel * v);
  double box = 1.0;
  for (int a = 0; a < 3; ++a) box *= std::floor((double(hi[a]) - lo[a] + pad) / v) + 1.0;
  return std::min(sum, box);
}

}  // namespace

float fogVoxelSize(const Frame& frame, const ExportOptions& o) {
  if (o.fogVoxelSize > 0.0f) return o.fogVoxelSize;
  // The median of what each sample asks for; a strided sample of at most ~64k is plenty.
  // A particle asks for half its radius (four voxels across). A strand vertex asks for no
  // less than half its segment: finer voxels add nothing along a polyline, and a strand
  // thinner than a voxel still deposits its whole tube volume (the kernel spreads it), so
  // thin hair is not resolved across at the cost of millions of voxels. What the strands
  // and particles are, not how far apart they lie, sets the size; fogMaxVoxels bounds it.
  std::vector<float> wanted;
  std::vector<Footprint> fp;
  std::size_t total = 0;
  for (const Particles& g : frame.groups) total += g.size();
  for (const Strands& s : frame.strands) total += s.vertexCount();
  const std::size_t stride = std::max<std::size_t>(1, total / 65536);
  constexpr float kHuge = std::numeric_limits<float>::max();
  Vec3 lo(kHuge), hi(-kHuge);
  float maxR = 0.0f;
  auto extend = [&](Vec3 p, float r) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return;
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
    if (std::isfinite(r)) maxR = std::max(maxR, r);
  };
  std::size_t k = 0;
  for (const Particles& g : frame.groups)
    for (std::size_t i = 0; i < g.size(); ++i, ++k) {
      const float r = g.radius.empty() ? o.defaultRadius : g.radius[i];
      extend(g.position[i], r);
      if (k % stride != 0) continue;
      wanted.push_back(0.5f * r);
      fp.push_back({r, -1.0f, false});
    }
  for (const Strands& s : frame.strands)
    for (std::size_t j = 0; j + 1 < s.start.size(); ++j) {
      const std::uint32_t a = s.start[j],
                          b = std::min<std::size_t>(s.start[j + 1], s.vertexCount());
      for (std::uint32_t i = a; i < b; ++i, ++k) {
        const float r = s.radius.size() > i ? s.radius[i] : o.defaultRadius;
        extend(s.position[i], r);
        if (k % stride != 0) continue;
        // The segment that starts here, or for the last vertex the one that ends here.
        const std::uint32_t n = i + 1 < b ? i + 1 : (i > a ? i - 1 : i);
        float seg = glm::length(s.position[n] - s.position[i]);
        if (!std::isfinite(seg)) seg = 0.0f;
        wanted.push_back(0.5f * std::max(r, seg));
        fp.push_back({r, i + 1 < b ? seg : 0.0f, i == a});
      }
    }
  std::erase_if(wanted, [](float w) { return !(w > 0.0f) || !std::isfinite(w); });
  if (wanted.empty()) return o.defaultRadius > 0.0f ? 0.5f * o.defaultRadius : 0.025f;
  auto mid = wanted.begin() + std::ptrdiff_t(wanted.size() / 2);
  std::nth_element(wanted.begin(), mid, wanted.end());
  const double v = *mid;
  if (o.fogMaxVoxels == 0) return float(v);
  // The memory cap: the coarsest voxel that still fits would waste detail; find the finest
  // one that fits, by bisection on a log scale (the estimate falls as the voxel grows).
  const double cap = double(o.fogMaxVoxels), minK = o.fogMinKernelVoxels;
  auto fits = [&](double x) {
    return estimateVoxels(fp, double(stride), lo, hi, maxR, x, minK) <= cap;
  };
  if (fits(v)) return float(v);
  double fine = v, coarse = 2.0 * v;
  // The bounding box's count falls as coarse³ down to a few voxels: a cap below that is met
  // as nearly as it can be.
  for (int i = 0; i < 64 && !fits(coarse); ++i) {
    fine = coarse;
    coarse *= 2.0;
  }
  for (int i = 0; i < 24; ++i) {
    const double m = std::sqrt(fine * coarse);
    (fits(m) ? coarse : fine) = m;
  }
  return float(coarse);
}

namespace {

void checkFinite(const Frame& frame) {
  for (std::size_t g = 0; g < frame.groups.size(); ++g) {
    const Particles& p = frame.groups[g];
    auto where = [&](const char* what, std::size_t i) {
      return "groups[" + std::to_string(g) + "]." + what + "[" + std::to_string(i) + "]";
    };
    if (p.id.size() != p.size()) throw InvalidArgument(where("id", 0), "needs one id per particle");
    auto sized = [&](std::size_t n, const char* what) {
      if (n != 0 && n != p.size())
        throw InvalidArgument(where(what, 0), "needs one value per particle, or none");
    };
    sized(p.velocity.size(), "velocity");
    sized(p.color.size(), "color");
    sized(p.radius.size(), "radius");
    sized(p.age.size(), "age");
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Vec3 x = p.position[i];
      if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z))
        throw InvalidArgument(where("position", i), "is not finite");
    }
    for (std::size_t i = 0; i < p.radius.size(); ++i)
      if (!std::isfinite(p.radius[i]) || p.radius[i] < 0.0f)
        throw InvalidArgument(where("radius", i), "must be finite and >= 0");
  }
}

}  // namespace

FileStats writeFile(const fs::path& path, const Frame& frame, const ExportOptions& options) {
  detail::validate(options);
  checkFinite(frame);
  FileStats st;
  st.path = path;
  const std::string bytes = detail::encode(frame, options, st);
  const auto start = std::chrono::steady_clock::now();
  detail::writeAtomic(path, bytes);
  st.writeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  st.bytes = bytes.size();
  return st;
}

FileStats writeFile(const fs::path& path, const Group& group, const ExportOptions& options) {
  Frame f;
  f.groups.push_back(Particles::capture(group, options));
  return writeFile(path, f, options);
}

FileStats writeFog(const fs::path& path, const Strands& strands, const ExportOptions& options) {
  Frame f;
  f.strands.push_back(strands);
  ExportOptions o = options;
  o.fog = true;
  o.points = false;
  return writeFile(path, f, o);
}

// ---------------------------------------------------------------------------------------

struct SequenceWriter::Impl {
  SequenceOptions options;
  mutable std::mutex mutex;
  std::condition_variable changed;
  std::deque<Frame> queue;
  bool busy = false;  ///< the worker holds a frame
  bool stop = false;
  std::exception_ptr error;
  ExportCost cost;
  FileStats last;
  std::vector<fs::path> removedTemporaries;
  std::thread worker;

  void run() {
    std::unique_lock lock(mutex);
    for (;;) {
      changed.wait(lock, [&] { return stop || !queue.empty(); });
      if (queue.empty()) return;  // stop, and nothing left
      Frame frame = std::move(queue.front());
      queue.pop_front();
      busy = true;
      const bool failed = error != nullptr;
      lock.unlock();
      FileStats st;
      std::exception_ptr e;
      if (!failed) {  // after an error the sequence is broken: drop the rest
        const fs::path path = pathFor(frame.number);
        try {
          st = writeFile(path, frame, options.content);
        } catch (const Error&) {
          e = std::current_exception();
        } catch (const std::exception& x) {  // bad_alloc, OpenVDB's own: name the file
          e = std::make_exception_ptr(IoError(path.string(), x.what()));
        }
      }
      lock.lock();
      busy = false;
      if (e && !error) error = e;
      if (!failed && !e) {
        ++cost.files;
        cost.bytes += st.bytes;
        cost.buildSeconds += st.buildSeconds;
        cost.writeSeconds += st.writeSeconds;
        last = st;
      }
      changed.notify_all();
    }
  }

  fs::path pathFor(int frame) const {
    char digits[32];
    std::snprintf(digits, sizeof digits, ".%0*d.vdb", options.padding, frame);
    return options.folder / (options.name + digits);
  }

  void rethrow() const {
    if (error) std::rethrow_exception(error);
  }
};

SequenceWriter::SequenceWriter(SequenceOptions options) : impl_(std::make_unique<Impl>()) {
  detail::validate(options.content);
  if (options.name.empty()) throw InvalidArgument("name", "must not be empty");
  if (options.padding < 1 || options.padding > 12) throw InvalidArgument("padding", "1 to 12");
  if (options.maxPending < 1) throw InvalidArgument("maxPending", "must be >= 1");
  std::error_code ec;
  fs::create_directories(options.folder, ec);
  if (ec || !fs::is_directory(options.folder))
    throw IoError(
        options.folder.string(),
        "cannot create the output folder: " + (ec ? ec.message() : std::string("not a directory")));
  // A run killed between write and rename left `name.N.vdb.tmp.PID`: only this sequence's
  // own temporaries of dead processes go (another writer may be at work in the folder).
  if (options.cleanStaleTemporaries)
    impl_->removedTemporaries =
        removeStaleTemporaries(options.folder, [&name = options.name](std::string_view file) {
          return isFrameFileName(file, name, "vdb");
        });
  impl_->options = std::move(options);
  impl_->worker = std::thread([impl = impl_.get()] { impl->run(); });
}

SequenceWriter::~SequenceWriter() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stop = true;
  }
  impl_->changed.notify_all();
  if (impl_->worker.joinable()) impl_->worker.join();
}

void SequenceWriter::write(std::span<Group* const> groups, int frame, double time) {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->rethrow();  // don't copy particles for a sequence that has already failed
  }
  const auto start = std::chrono::steady_clock::now();
  Frame f;
  f.number = frame;
  f.time = time;
  for (const Group* g : groups) {
    f.groups.push_back(Particles::capture(*g, impl_->options.content));
    // Hair groups hold strands, not live particles: their strands go into the fog volume.
    if (g->hair().enabled && g->strands().size() > 0) f.strands.push_back(g->strands());
  }
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  {
    std::lock_guard lock(impl_->mutex);
    impl_->cost.captureSeconds += secs;
  }
  write(std::move(f));
}

void SequenceWriter::write(const Group& group, int frame, double time) {
  Group* g = const_cast<Group*>(&group);  // the span is of non-const pointers; only read
  write(std::span<Group* const>(&g, 1), frame, time);
}

void SequenceWriter::write(Frame frame) {
  std::unique_lock lock(impl_->mutex);
  impl_->rethrow();
  const auto start = std::chrono::steady_clock::now();
  impl_->changed.wait(lock, [&] {
    return impl_->error || impl_->queue.size() + (impl_->busy ? 1 : 0) < impl_->options.maxPending;
  });
  impl_->cost.waitSeconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  impl_->rethrow();
  impl_->queue.push_back(std::move(frame));
  impl_->changed.notify_all();
}

fs::path SequenceWriter::pathFor(int frame) const {
  return impl_->pathFor(frame);
}

std::size_t SequenceWriter::written() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->cost.files;
}

std::size_t SequenceWriter::pending() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->queue.size() + (impl_->busy ? 1 : 0);
}

const std::vector<fs::path>& SequenceWriter::removedTemporaries() const {
  return impl_->removedTemporaries;
}

ExportCost SequenceWriter::cost() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->cost;
}

FileStats SequenceWriter::last() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->last;
}

ExportCost SequenceWriter::finish() {
  std::unique_lock lock(impl_->mutex);
  impl_->changed.wait(lock, [&] { return impl_->queue.empty() && !impl_->busy; });
  impl_->rethrow();
  return impl_->cost;
}

}  // namespace flurry::vdb
