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

/* e^x in float arithmetic alone, within an ulp (tests/test_random.cpp checks it against double
 * precision): the decays and approaches of a newborn's own step length, a falloff's, a blast
 * front's. libm's expf is a call per particle the vectoriser cannot take, and the device's exp
 * rounds its last bit its own way; this is a handful of multiplies and adds on either, with
 * the same bits on both. Cephes' expf: x = n ln2 + r with n = round(x / ln2) (by adding
 * 1.5·2^23, whose float spacing is 1, and reading n from the bits: no float-to-int conversion,
 * so a NaN is no undefined behaviour), ln2 in two parts so that n·ln2's first part is exact,
 * e^r by a polynomial on |r| <= ln2/2, then 2^n in two factors so that a result below the
 * normal range rounds once. e^0 is exactly 1; below -104 it is 0, above 89 infinite; NaN
 * stays NaN. */
FL_INLINE float fl_expf(float x) {
  x = x < -104.0f ? -104.0f : x;
  x = x > 89.0f ? 89.0f : x;
  const float t = x * 1.44269504088896341f + 12582912.0f;
  const int n = (int)(as_uint(t) & 0x007fffffu) - 0x400000;
  const float nf = t - 12582912.0f;
  const float r = (x - nf * 0.693359375f) - nf * -2.12194440e-4f;
  const float p =
      ((((1.9875691500e-4f * r + 1.3981999507e-3f) * r + 8.3334519073e-3f) * r +
        4.1665795894e-2f) * r + 1.6666665459e-1f) * r + 5.0000001201e-1f;
  const float e = p * (r * r) + r + 1.0f;
  const int n1 = n / 2, n2 = n - n1;
  return e * as_float((uint)(n1 + 127) << 23) * as_float((uint)(n2 + 127) << 23);
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
