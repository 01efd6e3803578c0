// Internals of flurry::vdb shared by its source files. No OpenVDB here: grids.hpp has the
// parts that need it, so only the files that build grids pay for its headers.
#pragma once

#include <atomic>
#include <filesystem>
#include <string>
#include <string_view>

#include "flurry/vdb.hpp"

namespace flurry::vdb::detail {

/// Throws InvalidArgument naming the first bad field of `options`.
void validate(const ExportOptions& options);

/// Builds the grids of `frame` and serialises them as a .vdb file image (what
/// openvdb::io::File would write). Fills stats' grid fields and buildSeconds.
std::string encode(const Frame& frame, const ExportOptions& options, FileStats& stats);

/// Writes `bytes` to a temporary file next to `path` (`path.tmp.PID`), flushes it to disk,
/// renames it to `path`. On failure removes the temporary and throws IoError naming `path`.
void writeAtomic(const std::filesystem::path& path, std::string_view bytes);

/// For tests: called with (temporary, final) after the temporary is complete and synced
/// and before the rename; a test simulates a crash there.
using BeforeRenameHook = void (*)(const std::filesystem::path& tmp,
                                  const std::filesystem::path& final);
extern std::atomic<BeforeRenameHook> beforeRename;

/// Mass one particle of radius r deposits: density · (4/3)·π·r³.
double particleMass(float radius, float density);

}  // namespace flurry::vdb::detail
