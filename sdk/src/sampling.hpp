// Drawing from domains and fuzzy values in batches, for emission.
//
// Random numbers are compute-bound (Philox is ~2 ns per uniform here), so emission draws them
// for a whole batch of newborns at once, one Philox block per particle per loop, and every
// shape samples a batch from arrays of uniforms with branch-free, libm-free formulas the
// compiler vectorises (kernels/domain.h, the OpenCL backend's too). Domain::sample() is the same
// code with a batch of one, so a particle's attributes do not depend on which path drew them.
// Uniform number k of a stream is always word k % 4 of Philox block k / 4 (the flurry::Random
// order), on every backend.
#pragma once

#include <cstddef>
#include <cstdint>

#include "flurry/domain.hpp"
#include "flurry/fuzzy.hpp"
#include "flurry/random.hpp"
#include "isa_namespace.hpp"

namespace flurry::detail {
// Compiled once per instruction set, like the fused pass that samples for its random
// actions (isa_namespace.hpp): each build calls its own copies.
inline namespace FLURRY_ISA_NAMESPACE {

/// Uniform numbers a shape consumes per sample (at most kMaxDomainDraws).
int drawCount(const Domain& d);
inline constexpr int kMaxDomainDraws = 16;
/// Uniform numbers a fuzzy value consumes per sample (0 if constant, 2 if normal).
inline int drawCount(const Fuzzy& f) {
  return f.spread == 0.0f ? 0 : f.distribution == Fuzzy::Distribution::Normal ? 2 : 1;
}

/// Samples n points of `d` into x, y, z from the uniform arrays u[0 .. drawCount(d)).
void sampleBatch(const Domain& d, const float* const* u, std::size_t n, float* x, float* y,
                 float* z);
/// The normals where the n samples sampleBatch(d, u, ...) drew landed, at (x, y, z): a
/// mesh's are those of the triangles the samples picked and a union's those of the parts
/// they picked (the same draws picking them again: a search, where Domain::normal's nearest
/// part is a walk over all of them, and a point on an edge two faces share keeps its own
/// face's); every other shape's is Domain::normal's.
void sampledNormals(const Domain& d, const float* const* u, std::size_t n, const float* x,
                    const float* y, const float* z, float* nx, float* ny, float* nz);
/// Samples n fuzzy values into out from u[0 .. drawCount(f)).
void sampleBatch(const Fuzzy& f, const float* const* u, std::size_t n, float* out);

/// Fills words[0..3][i] with Philox block `block` of the stream (seed, firstId + i, c1, c2)
/// for i < n, and converts them to uniforms in [0, 1).
void uniformBatch(std::uint64_t seed, std::uint32_t firstId, std::uint32_t c1, std::uint32_t c2,
                  std::uint32_t block, std::size_t n, float* u0, float* u1, float* u2, float* u3);
/// The same for the streams (seed, id[i], c1, c2): id[i] in place of firstId + i.
void uniformBatchOfIds(std::uint64_t seed, const std::uint32_t* id, std::uint32_t c1,
                       std::uint32_t c2, std::uint32_t block, std::size_t n, float* u0, float* u1,
                       float* u2, float* u3);

}  // namespace FLURRY_ISA_NAMESPACE
}  // namespace flurry::detail
