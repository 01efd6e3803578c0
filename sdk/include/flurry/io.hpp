// Writing particles to files.
#pragma once

#include <filesystem>

#include "flurry/group.hpp"

namespace flurry {

/// Writes the live particles as a binary little-endian PLY point cloud (x y z, and the
/// velocity, color, size, age and id where stored). The file is written under a temporary
/// name and renamed, so a reader never sees a torn file; throws IoError naming the path.
void writePly(const Group& group, const std::filesystem::path& path);

/// Writes `bytes` to `path` atomically: to a temporary file in the same folder, flushed,
/// then renamed. On failure the temporary is removed and IoError names the path.
void writeFileAtomic(const std::filesystem::path& path, std::span<const char> bytes);

}  // namespace flurry
