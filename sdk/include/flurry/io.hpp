// Writing particles to files.
#pragma once

#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "flurry/group.hpp"

namespace flurry {

/// Writes the live particles as a binary little-endian PLY point cloud (x y z, and the
/// velocity, color, size, age and id where stored). The file is written under a temporary
/// name and renamed, so a reader never sees a torn file; throws IoError naming the path.
void writePly(const Group& group, const std::filesystem::path& path);

/// Writes `bytes` to `path` atomically: to a temporary file in the same folder
/// (`path.tmp.PID`, PID this process's id), flushed, then renamed. On failure the temporary is
/// removed and IoError names the path. A process killed before the rename leaves the
/// temporary behind (never a file under the final name): see removeStaleTemporaries.
void writeFileAtomic(const std::filesystem::path& path, std::span<const char> bytes);

/// Removes the temporaries that writers killed before their rename left in `folder`: files
/// named exactly `NAME.tmp.PID` (what writeFileAtomic and flurry::vdb write), NAME accepted by
/// `isOutput`, PID a process id that is no longer running. A running process's temporary,
/// this process's included, and every other file are left alone. Call it before a run writes
/// into `folder`. PIDs mean something on this machine only: do not use it on a folder that
/// writers on other machines share. Returns the files removed; a missing folder, or a file
/// that cannot be removed, is skipped.
std::vector<std::filesystem::path> removeStaleTemporaries(
    const std::filesystem::path& folder, const std::function<bool(std::string_view)>& isOutput);

/// Whether `name` is a frame file name `BASE.N.EXT`, N a frame number (digits, optionally
/// negative: `%0*d`): what the flurry tool and vdb::SequenceWriter name their frames.
bool isFrameFileName(std::string_view name, std::string_view base, std::string_view ext);

}  // namespace flurry
