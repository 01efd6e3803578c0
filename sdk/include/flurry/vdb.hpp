// OpenVDB export and import (target flurry::vdb): particles as a fog volume (`density`,
// `vel`, `Cd` grids) and as a point cloud (a PointDataGrid named `points`), hair strands
// rasterised into the fog volume and as points of a `strands` PointDataGrid, one file per frame
// written atomically on a background thread (temporaries that a killed run left are cleaned up by
// the next sequence), and OpenVDB vector grids read back as a VectorField for the sampled-field
// force.
//
// This header does not include OpenVDB: a game that includes it links flurry::vdb, which
// links OpenVDB privately.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "flurry/error.hpp"
#include "flurry/field.hpp"
#include "flurry/group.hpp"
#include "flurry/math.hpp"
#include "flurry/strands.hpp"

namespace flurry::vdb {

/// What goes into a file, and how.
///
/// Fog volume: each particle deposits the mass `density · (4/3)·π·r³` (r its size, its
/// radius) with a smooth kernel of radius r: flat to r/2, then a smoothstep falloff to zero
/// at r. The kernel's weights are normalised over the voxels it covers, so the density
/// integral (the sum of density · voxelSize³) equals the sum of the particles' masses up to
/// float rounding, however small a particle is against the voxel: a kernel never shrinks
/// below fogMinKernelVoxels voxels, it spreads the particle's mass instead. A strand deposits
/// the volume of its tube, `density · π · ∫ r(s)² ds`, with r linear along each segment.
/// `vel` and `Cd` are mass-weighted averages over the voxel.
struct ExportOptions {
  bool fog = true;  ///< the `density`, `vel` and `Cd` grids
  /// The `points` PointDataGrid of the particles, and the `strands` PointDataGrid of the
  /// strands' vertices (with `strand_id` and `strand_vertex`, to rebuild them as curves).
  bool points = true;
  /// Fog voxel edge in world units; 0 picks the median of what each particle and strand
  /// vertex asks for: half a particle's radius (a typical particle is four voxels across);
  /// for a strand vertex, half its radius or half its segment's length, the larger (a thin
  /// strand keeps its volume in voxels wider than it; finer ones add nothing along it).
  float fogVoxelSize = 0.0f;
  /// Memory cap of the automatic fog voxel size: where the voxel size above would make more
  /// active voxels than this (estimated from the kernels' volumes, at most the bounding
  /// box's voxel count; overlaps make it an overestimate, the voxel lattice can add a few
  /// percent), it is made just coarse enough to fit (0: no cap). Each voxel costs
  /// 28 bytes in the grids while building and about 13 in the file: 2^24 voxels are about
  /// 470 MB and 200 MB. An explicit fogVoxelSize is not capped.
  std::uint64_t fogMaxVoxels = std::uint64_t(1) << 24;
  /// Points voxel edge (of `points` and `strands`); 0 picks, per grid, a size giving about
  /// pointsPerVoxel points per voxel.
  float pointsVoxelSize = 0.0f;
  std::uint32_t pointsPerVoxel = 8;
  /// Density inside a particle's sphere (the fog volume's unit of mass per volume).
  float density = 1.0f;
  /// A particle's kernel radius is at least this many voxels (below ~1.5 a kernel covers too
  /// few voxel centres and a moving particle flickers).
  float fogMinKernelVoxels = 1.5f;
  /// Radius used where the group does not store Attribute::Size (Particle's default).
  float defaultRadius = 0.05f;
  /// Export particles hidden by a blocker (Attribute::Visible == 0) too.
  bool keepHidden = false;
};

/// The particles of one group, copied out for export: only those exported (visible ones,
/// unless keepHidden), only the attributes the export reads. A vector is empty where the
/// group does not store that attribute; position and id are always filled.
struct Particles {
  std::string group;
  std::vector<Vec3> position;
  std::vector<std::uint32_t> id;
  std::vector<Vec3> velocity;  ///< world units per second
  std::vector<Vec3> color;     ///< rgb (alpha is not exported)
  std::vector<float> radius;
  std::vector<float> age;  ///< seconds
  std::size_t hidden = 0;  ///< live particles left out because a blocker hid them

  std::size_t size() const { return position.size(); }
  /// Copies what `options` exports from `group` (call on the thread that steps it).
  static Particles capture(const Group& group, const ExportOptions& options = {});
};

/// Everything one file holds.
struct Frame {
  int number = 0;     ///< frame number, written as metadata and used in the file name
  double time = 0.0;  ///< simulation time in seconds
  std::vector<Particles> groups;
  std::vector<Strands> strands;  ///< hair: rasterised into the fog volume, vertices as points
};

/// What writing one file did and cost.
struct FileStats {
  std::filesystem::path path;
  std::uint64_t bytes = 0;
  std::size_t points = 0;          ///< points in the `points` grid
  std::uint64_t fogVoxels = 0;     ///< active voxels of `density`
  float fogVoxelSize = 0.0f;       ///< 0 if no fog was written
  float pointsVoxelSize = 0.0f;    ///< 0 if no points were written
  std::size_t strandVertices = 0;  ///< points in the `strands` grid
  float strandsVoxelSize = 0.0f;   ///< 0 if no strands grid was written
  double mass = 0.0;               ///< sum of the particles' and strands' masses (double)
  double buildSeconds = 0.0;       ///< splatting and building the grids
  double writeSeconds = 0.0;       ///< serialising, writing, syncing, renaming
};

/// Writes one frame to `path` (written to `path.tmp.PID` in the same folder, PID this
/// process's id, flushed to disk, then renamed: a reader never sees a torn file, and a failed
/// write removes the temporary). A process killed before the rename leaves that complete
/// temporary behind, never a file under `path`; SequenceWriter removes such leftovers of dead
/// processes when it starts (SequenceOptions::cleanStaleTemporaries), flurry::
/// removeStaleTemporaries does it for any folder. Throws IoError naming the path, or
/// InvalidArgument for a bad option.
FileStats writeFile(const std::filesystem::path& path, const Frame& frame,
                    const ExportOptions& options = {});
/// Writes the visible particles of one group.
FileStats writeFile(const std::filesystem::path& path, const Group& group,
                    const ExportOptions& options = {});
/// Writes hair strands as a fog volume (their points are not written).
FileStats writeFog(const std::filesystem::path& path, const Strands& strands,
                   const ExportOptions& options = {});

/// The fog voxel size writeFile would pick for this frame (options.fogVoxelSize if set).
float fogVoxelSize(const Frame& frame, const ExportOptions& options = {});

/// Reads the Vec3s or Vec3d grid `gridName` (empty: the file's first Vec3 grid) over its
/// active voxels' bounding box into a dense VectorField. The grid's transform must be a
/// uniform scale and translation (no rotation). Throws IoError naming the path if the file,
/// the grid or its type is wrong, InvalidArgument if a value is NaN or infinite.
VectorField readVectorField(const std::filesystem::path& path, const std::string& gridName = {},
                            std::size_t maxSamples = std::size_t(1) << 27);

/// Writes `field` as a Vec3s grid (vector type: contravariant relative) named `gridName`,
/// every sample an active voxel; the inverse of readVectorField.
void writeVectorField(const std::filesystem::path& path, const VectorField& field,
                      const std::string& gridName = "vel");

/// Totals over a sequence.
struct ExportCost {
  std::size_t files = 0;
  std::uint64_t bytes = 0;
  double captureSeconds = 0.0;  ///< copying particles, on the simulation's thread
  double waitSeconds = 0.0;     ///< the simulation waited for the exporter to catch up
  double buildSeconds = 0.0;    ///< splatting and building grids, on the worker
  double writeSeconds = 0.0;    ///< serialising and writing files, on the worker

  double bytesPerFrame() const { return files ? double(bytes) / double(files) : 0.0; }
  /// Worker time per file (build + write).
  double secondsPerFrame() const {
    return files ? (buildSeconds + writeSeconds) / double(files) : 0.0;
  }
};

struct SequenceOptions {
  std::filesystem::path folder;  ///< created if missing
  std::string name = "flurry";   ///< files are name.0001.vdb
  ExportOptions content;
  int padding = 4;  ///< digits of the frame number
  /// Frames captured but not yet written; write() waits while this many are pending, so
  /// memory stays bounded when the disk is slower than the simulation.
  std::size_t maxPending = 2;
  /// On construction, delete the temporaries an earlier run killed mid-write left in
  /// `folder`: only files named exactly `name.N.vdb.tmp.PID` (N a frame number) whose
  /// process PID is no longer running. PIDs are only meaningful on one machine: turn this
  /// off for a folder that writers on several machines share.
  bool cleanStaleTemporaries = true;
};

/// Writes a sequence of frames on a background thread. write() copies the particles on the
/// caller's thread (cheap) and returns; a worker splats, builds and writes the file while
/// the simulation goes on. An error on the worker stops the sequence and is thrown, as the
/// IoError naming the file, by the next write() and by finish().
class SequenceWriter {
 public:
  /// Creates the folder (throws IoError naming it if that fails) and removes stale
  /// temporaries of this sequence from it (see SequenceOptions::cleanStaleTemporaries).
  explicit SequenceWriter(SequenceOptions options);
  /// Waits for pending frames; never throws (call finish() to see errors).
  ~SequenceWriter();
  SequenceWriter(const SequenceWriter&) = delete;
  SequenceWriter& operator=(const SequenceWriter&) = delete;

  /// Captures `groups` now and queues them as frame `frame` at `time` seconds.
  void write(std::span<Group* const> groups, int frame, double time);
  void write(const Group& group, int frame, double time);
  /// Queues an already captured frame (strands, hand-built particles).
  void write(Frame frame);

  /// The file frame `frame` goes to.
  std::filesystem::path pathFor(int frame) const;
  /// Files completely written so far.
  std::size_t written() const;
  /// Frames queued or being written.
  std::size_t pending() const;
  /// Costs so far.
  ExportCost cost() const;
  /// The last file written (empty before the first).
  FileStats last() const;
  /// The stale temporaries the constructor removed.
  const std::vector<std::filesystem::path>& removedTemporaries() const;
  /// Waits for every pending frame; throws the first error. Returns the totals.
  ExportCost finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace flurry::vdb
