/* The OpenCL side of the kernels' shared C subset. The files in kernels/ that end in .h and
 * hold math (noise.h, ...) are written once and compile both as OpenCL C 1.2 (here) and as
 * C++ for the CPU backend (sdk/src/kernel_compat.hpp gives them the same names there), as
 * Blender Cycles' kernels do. The subset: FL_INLINE functions of scalars, float3 built by
 * make_float3 and read by .x/.y/.z, uint and int, the builtins floor/sqrt/fabs/... */
#ifndef FLURRY_KERNELS_COMPAT_OPENCL_H
#define FLURRY_KERNELS_COMPAT_OPENCL_H

/* Every helper is forced inline: PoCL made a kernel ~11x slower when Philox was left as a
 * call. */
#define FL_INLINE inline __attribute__((always_inline))
#define FL_MATH_INLINE FL_INLINE
#define make_float3(x, y, z) ((float3)((x), (y), (z)))
/* A pointer into a buffer the host wrote (a group's lanes, its start-of-step snapshot). */
#define FL_GLOBAL __global
/* Unrolls the loop that follows (Philox's rounds). */
#define FL_UNROLL _Pragma("unroll")

#endif /* FLURRY_KERNELS_COMPAT_OPENCL_H */
