#pragma once

namespace flurry {
inline constexpr int kVersionMajor = 0;
inline constexpr int kVersionMinor = 1;
inline constexpr int kVersionPatch = 0;
const char* versionString();
/// The instruction set the CPU backend's fused pass, emission and domain sampling run in on
/// this machine: "avx512", "avx2" or "baseline" (SSE2), the widest the CPU has, picked once
/// per process. The environment variable FLURRY_ISA=baseline|avx2|avx512 picks a narrower one
/// (for comparisons; one the CPU lacks is not taken). Benchmarks print it beside their figures.
const char* cpuInstructionSet();
}  // namespace flurry
