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

/* Spatial culling: whether the box (lo, hi) a block's or work-group's paths lie in, with
 * `scale` its largest |coordinate|, is apart from an action's reach box (rlo, rhi; rscale its
 * largest |coordinate|, rquad its margin term in scale^2) by more than the rounding of the
 * action's own tests, which lies far below this margin. */
FL_INLINE int fl_reach_apart(const float* lo, const float* hi, float scale,
                             FL_GLOBAL const float* rlo, FL_GLOBAL const float* rhi, float rscale,
                             float rquad) {
  const float s = scale + rscale;
  const float margin = 1e-4f * (1.0f + s) + rquad * s * s;
  int out = 0;
  for (int c = 0; c < 3; ++c) out |= (lo[c] - margin > rhi[c]) | (hi[c] + margin < rlo[c]);
  return out;
}

#endif /* FLURRY_KERNELS_MATH_H */
