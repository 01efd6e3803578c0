/* Scalar helpers of the kernels' shared C subset (compat_opencl.h, sdk/src/kernel_compat.hpp),
 * with the C++ standard library's rules, so that both backends select the same operand. */
#ifndef FLURRY_KERNELS_MATH_H
#define FLURRY_KERNELS_MATH_H

FL_INLINE float fl_maxf(float a, float b) { return a < b ? b : a; } /* std::max's rule */

FL_INLINE float fl_minf(float a, float b) { return b < a ? b : a; } /* std::min's rule */

FL_INLINE int fl_mini(int a, int b) { return b < a ? b : a; } /* OpenCL's min(int, int) */

FL_INLINE float fl_clampf(float v, float lo, float hi) { /* std::clamp's rule */
  return v < lo ? lo : hi < v ? hi : v;
}

#endif /* FLURRY_KERNELS_MATH_H */
