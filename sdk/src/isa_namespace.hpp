// The fused pass is compiled once per instruction set (sdk/CMakeLists.txt). An inline
// function it shares with other translation units would be emitted once per build, and the
// linker keeps one copy for all of them: the SSE2 path would then run AVX2 code. Internal
// headers therefore put their functions in an inline namespace named after the instruction
// set the translation unit is compiled for, so each build keeps its own copies by
// construction. Names in source stay unqualified; only the mangled names differ.
// FLURRY_ISA_FLOATS is the floats in that instruction set's widest vector (what a loop pads a
// few items to, so as to run whole vectors and no scalar remainder).
#pragma once

#if defined(__AVX512F__)
#define FLURRY_ISA_NAMESPACE isa_avx512
#define FLURRY_ISA_FLOATS 16
#elif defined(__AVX2__)
#define FLURRY_ISA_NAMESPACE isa_avx2
#define FLURRY_ISA_FLOATS 8
#elif defined(__AVX__)
#define FLURRY_ISA_NAMESPACE isa_avx
#define FLURRY_ISA_FLOATS 8
#else
#define FLURRY_ISA_NAMESPACE isa_baseline
#define FLURRY_ISA_FLOATS 4
#endif
