// Memory for the small pieces a game's thousands of groups each hold (their lanes, the group
// itself), carved out of 2 MiB pages. A small group's step touches a few kilobytes at a dozen
// places; from the general heap each place is its own 4 KiB page, and thousands of groups
// cost a TLB miss (a page walk, dearer still under a hypervisor) at nearly every one of them:
// bench_runtime's 10,000 instances ran at half the speed.
#pragma once

#include <cstddef>

namespace flurry::detail {

/// The largest piece the arena serves; larger ones come from the heap (or, for lanes, their
/// own huge pages).
inline constexpr std::size_t kArenaMostBytes = std::size_t(64) << 10;

/// `bytes` (at most kArenaMostBytes), 64-byte aligned, from the arena: a piece of the same
/// rounded size freed before, or the next one of a 2 MiB page (madvise'd for a huge page).
/// Throws std::bad_alloc when no page can be had. Thread-safe.
void* arenaAllocate(std::size_t bytes);
/// Gives back a piece of `bytes` that arenaAllocate returned, for reuse by a piece of the
/// same rounded size only: the pages stay with the process, so its peak use of each size
/// stays too (groups of a few capacities, as a game's effects have, reuse theirs).
void arenaFree(void* piece, std::size_t bytes) noexcept;

}  // namespace flurry::detail
