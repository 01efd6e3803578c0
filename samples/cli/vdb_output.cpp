// `flurry run ... --vdb DIR`: an OpenVDB file per due frame (fog volume and points), written on
// a background thread while the simulation goes on, with a progress bar and a cost report.
// An effect of hair alone is static: a frame is written only when strands were added.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <optional>
#include <thread>
#include <vector>

#include "flurry/vdb.hpp"
#include "outputs.hpp"

namespace flurry::cli {

namespace {

using Clock = std::chrono::steady_clock;

class VdbPlugin final : public Plugin {
 public:
  void addOptions(CLI::App&, CLI::App& run) override {
    run.add_option("--vdb", folder_,
                   "write OpenVDB files (EFFECT.0001.vdb, ...) to this folder: fog grids density, "
                   "vel, Cd and the point grid 'points'; hair also as curves, the point grid "
                   "'strands' whose strand_id and strand_vertex rebuild them (docs/vdb-export.md); "
                   "static hair is written once, not every frame");
    run.add_option("--vdb-every", every_,
                   "write a VDB file every N frames, and the last (default: --every's N, as PNG "
                   "and PLY; 1 for a whole sequence)")
        ->check(CLI::Range(1, 1000000));
    run_ = &run;
    run.add_flag("--vdb-fog", fogOnly_, "write only the fog volume (density, vel, Cd)");
    run.add_flag("--vdb-points", pointsOnly_, "write only the points (PointDataGrid 'points')");
    run.add_option("--voxel-size", options_.fogVoxelSize,
                   "fog voxel size in world units (default: half the median particle radius, "
                   "or for hair half a strand segment; coarser if the fog would pass 2^24 voxels)")
        ->check(CLI::PositiveNumber);
    run.add_option("--points-voxel-size", options_.pointsVoxelSize,
                   "voxel size of the points and strands grids (default: about 8 points per voxel)")
        ->check(CLI::PositiveNumber);
    run.add_option("--vdb-density", options_.density, "fog density inside a particle")
        ->check(CLI::NonNegativeNumber);
    run.add_flag("--keep-hidden", options_.keepHidden, "also export particles a blocker hides");
  }

  bool enabled() const override { return !folder_.empty(); }

  void begin(Context& ctx, const RunInfo& info) override {
    info_ = info;
    // Every output follows --every unless told otherwise: a file per frame of a 300-frame
    // effect is gigabytes and minutes of export, so a whole sequence is asked for by name.
    if (every_ == 0) every_ = everyOfRun(*run_);
    if (fogOnly_ || pointsOnly_) {
      options_.fog = fogOnly_;
      options_.points = pointsOnly_;
    }
    // The exporter reads these; the group stores only what someone reads.
    AttributeSet need{Attribute::Velocity, Attribute::Color, Attribute::Size};
    if (options_.points) need.insert(Attribute::Age);
    for (Group* g : ctx.groups()) g->require(need);
    vdb::SequenceOptions so;
    so.folder = folder_;
    so.name = info.effect;
    so.content = options_;
    writer_.emplace(so);  // removes the temporaries of a run killed mid-write
    if (!info.quiet && !writer_->removedTemporaries().empty())
      std::printf("vdb: removed %zu stale temporary files of an earlier run from %s\n",
                  writer_->removedTemporaries().size(), folder_.c_str());
    for (int f = 1; f <= info.frames; ++f)
      if (due(f)) ++toWrite_;
    hairOnly_ = !ctx.groups().empty();
    for (const Group* g : ctx.groups()) hairOnly_ = hairOnly_ && g->hair().enabled;
    tty_ = ::isatty(STDERR_FILENO) == 1;
    start_ = Clock::now();
  }

  void frame(Context& ctx, int frame) override {
    if (!due(frame)) return;
    if (hairOnly_) {
      // Hair is static: strands never move once made, so a frame differs from the file
      // before it only if strands were added (they are only ever appended).
      strandCounts_.clear();
      for (const Group* g : ctx.groups()) {
        strandCounts_.push_back(g->strands().size());
        strandCounts_.push_back(g->strands().vertexCount());
      }
      if (queued_ > 0 && strandCounts_ == lastStrandCounts_) {
        ++unchanged_;
        --toWrite_;
        return;
      }
      lastStrandCounts_ = strandCounts_;
    }
    try {
      writer_->write(ctx.groups(), frame, ctx.time());
    } catch (...) {
      endLine();
      throw;
    }
    ++queued_;
    if (!info_.progress) progress(false);  // the tool's own bar is on: draw none beside it
  }

  void end(Context&) override {
    // Wait for the worker, keeping the bar moving; finish() then throws the first error.
    while (writer_->pending() > 0) {
      progress(false);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    vdb::ExportCost cost;
    try {
      cost = writer_->finish();
    } catch (...) {
      endLine();
      throw;
    }
    progress(true);
    endLine();
    const double wall = std::chrono::duration<double>(Clock::now() - start_).count();
    std::printf(
        "vdb: wrote %zu files to %s in %.2f s: %.1f ms/frame on the export thread (build %.1f, "
        "write %.1f), %.2f MB/frame; simulation thread %.2f ms/frame (copy %.2f, waiting %.2f)\n",
        cost.files, folder_.c_str(), wall, 1e3 * cost.secondsPerFrame(),
        cost.files ? 1e3 * cost.buildSeconds / double(cost.files) : 0.0,
        cost.files ? 1e3 * cost.writeSeconds / double(cost.files) : 0.0, cost.bytesPerFrame() / 1e6,
        cost.files ? 1e3 * (cost.captureSeconds + cost.waitSeconds) / double(cost.files) : 0.0,
        cost.files ? 1e3 * cost.captureSeconds / double(cost.files) : 0.0,
        cost.files ? 1e3 * cost.waitSeconds / double(cost.files) : 0.0);
    const vdb::FileStats last = writer_->last();
    if (cost.files) {
      std::printf("vdb: last file %s: %zu points, %llu fog voxels of %.4g (points voxel %.4g)",
                  last.path.c_str(), last.points, (unsigned long long)last.fogVoxels,
                  double(last.fogVoxelSize), double(last.pointsVoxelSize));
      if (last.strandVertices > 0) std::printf(", %zu strand vertices", last.strandVertices);
      std::printf("\n");
    }
    if (unchanged_ > 0)
      std::printf(
          "vdb: hair is static: %d later frames, unchanged since the last file, not "
          "written\n",
          unchanged_);
  }

 private:
  bool due(int frame) const { return frame % every_ == 0 || frame == info_.frames; }

  /// A bar with ETA on stderr: redrawn in place on a terminal (at most 10 times a second),
  /// a line per tenth of the work otherwise (logs stay short). While the tool draws its own
  /// bar (RunInfo::progress) it is drawn only in end(), for the files still being written.
  void progress(bool final) {
    if (info_.quiet || toWrite_ == 0) return;
    const std::size_t done = writer_->written();
    const auto now = Clock::now();
    if (tty_) {
      if (!final && now - lastDraw_ < std::chrono::milliseconds(100)) return;
    } else {
      const std::size_t tenth = done * 10 / std::size_t(toWrite_);
      if (!final && tenth == lastTenth_) return;
      lastTenth_ = tenth;
    }
    lastDraw_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double eta = done ? elapsed / double(done) * double(toWrite_ - int(done)) : 0.0;
    constexpr int kWidth = 30;
    const int fill = int(double(done) / toWrite_ * kWidth);
    char bar[kWidth + 1];
    for (int i = 0; i < kWidth; ++i) bar[i] = i < fill ? '#' : '.';
    bar[kWidth] = '\0';
    const vdb::ExportCost c = writer_->cost();
    std::fprintf(stderr, "%svdb [%s] %zu/%d files (%d queued)  %.2f MB/file  ETA %.0f s%s",
                 tty_ ? "\r" : "", bar, done, toWrite_, queued_ - int(done),
                 c.bytesPerFrame() / 1e6, eta, tty_ ? "\033[K" : "\n");
    std::fflush(stderr);
    drawn_ = tty_;
  }

  void endLine() {
    if (drawn_) std::fputc('\n', stderr);
    drawn_ = false;
  }

  std::string folder_;
  int every_ = 0;  ///< 0: --every's
  CLI::App* run_ = nullptr;
  bool fogOnly_ = false, pointsOnly_ = false;
  vdb::ExportOptions options_;
  RunInfo info_;
  std::optional<vdb::SequenceWriter> writer_;
  int toWrite_ = 0, queued_ = 0;
  bool hairOnly_ = false;  ///< every group is in hair mode: nothing but strands to write
  std::vector<std::size_t> strandCounts_, lastStrandCounts_;  ///< per group: strands, vertices
  int unchanged_ = 0;
  bool tty_ = false, drawn_ = false;
  std::size_t lastTenth_ = std::size_t(-1);
  Clock::time_point start_, lastDraw_;
};

}  // namespace

std::unique_ptr<Plugin> makeVdbPlugin() {
  return std::make_unique<VdbPlugin>();
}

}  // namespace flurry::cli
