// Internals of flurry::vdb that need OpenVDB: grid builders. Include in as few files as
// possible, OpenVDB's headers are slow to compile.
#pragma once

#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>

#include "detail.hpp"

namespace flurry::vdb::detail {

struct FogGrids {
  openvdb::FloatGrid::Ptr density;  ///< grid class fog volume
  openvdb::Vec3SGrid::Ptr vel;      ///< null when no group stores velocity
  openvdb::Vec3SGrid::Ptr color;    ///< null when no group stores color and there are no strands
  double mass = 0.0;                ///< sum of what the particles and strands deposited
};

/// Splats the frame's particles and strands into grids of voxel edge `voxelSize`.
FogGrids buildFog(const Frame& frame, const ExportOptions& options, float voxelSize);

/// The `points` PointDataGrid of the frame's particles; `voxelSize` 0 picks one (returned).
openvdb::points::PointDataGrid::Ptr buildPoints(const Frame& frame, const ExportOptions& options,
                                                float& voxelSize);

/// The `strands` PointDataGrid: every strand vertex of the frame, with the strand it is on
/// (`strand_id`) and its place along it (`strand_vertex`); `voxelSize` 0 picks one.
openvdb::points::PointDataGrid::Ptr buildStrandPoints(const Frame& frame,
                                                      const ExportOptions& options,
                                                      float& voxelSize);

}  // namespace flurry::vdb::detail
