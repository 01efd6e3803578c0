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

/* e^r for |r| <= ln2/2 (a little beyond is fine): Cephes' degree-5 polynomial, fl_expf's and
 * fl_powf's after their reduction. */
FL_MATH_INLINE float fl_exp_reduced(float r) {
  const float p =
      ((((1.9875691500e-4f * r + 1.3981999507e-3f) * r + 8.3334519073e-3f) * r +
        4.1665795894e-2f) * r + 1.6666665459e-1f) * r + 5.0000001201e-1f;
  return p * (r * r) + r + 1.0f;
}

/* e·2^n for n in [-200, 200], in two factors so that a result below the normal range rounds
 * once: fl_expf's and fl_powf's end. */
FL_MATH_INLINE float fl_exp_scaled(float e, int n) {
  const int n1 = n / 2, n2 = n - n1;
  return e * as_float((uint)(n1 + 127) << 23) * as_float((uint)(n2 + 127) << 23);
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
FL_MATH_INLINE float fl_expf(float x) {
  x = x < -104.0f ? -104.0f : x;
  x = x > 89.0f ? 89.0f : x;
  const float t = x * 1.44269504088896341f + 12582912.0f;
  const int n = (int)(as_uint(t) & 0x007fffffu) - 0x400000;
  const float nf = t - 12582912.0f;
  const float r = (x - nf * 0.693359375f) - nf * -2.12194440e-4f;
  return fl_exp_scaled(fl_exp_reduced(r), n);
}

/* Veltkamp's split of a (|a| < 2^100) into two halves of 12 bits whose products are exact. */
FL_MATH_INLINE void fl_split(float a, float* hi, float* lo) {
  const float c = 4097.0f * a;
  *hi = c - (c - a);
  *lo = a - *hi;
}

/* a·b = *p + *e exactly (Dekker's product: no fused multiply-add, which the backends do not
 * share, is needed). */
FL_MATH_INLINE void fl_two_prod(float a, float b, float* p, float* e) {
  float ah, al, bh, bl;
  fl_split(a, &ah, &al);
  fl_split(b, &bh, &bl);
  *p = a * b;
  *e = ((ah * bh - *p) + ah * bl + al * bh) + al * bl;
}

/* x^y for x >= 0 (or NaN) and finite y >= 0, within 2 ulp (tests/test_random.cpp checks it
 * against double precision): a falloff's fade, a vortex's swirl outside its core. libm's pow
 * is a call per particle the vectoriser cannot take and rounds its own way on each device;
 * this is straight-line float arithmetic, the same bits on both. 2^(y log2 x) with log2 x and
 * y log2 x carried in two floats, so that a large y·log2 x keeps its fraction: x = 2^e m with
 * m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(s) for s = (m - 1)/(m + 1) (|s| <= 0.172, the
 * series to s^11), times log2(e) in two parts; then 2^n e^(f ln2) as fl_expf ends. Special
 * values as C's pow: x^0 = 1 (NaN too), 0^y = 0, 1^y = 1, inf^y = inf, NaN^y = NaN. */
FL_MATH_INLINE float fl_powf(float x, float y) {
  /* A subnormal x scaled into the normal range by 2^24. */
  const int tiny = x < 1.17549435e-38f;
  const uint bits = as_uint(tiny ? x * 16777216.0f : x);
  int e = (int)((bits >> 23) & 0xffu) - (tiny ? 151 : 127);
  float m = as_float((bits & 0x007fffffu) | 0x3f800000u);
  const int high = m > 1.41421356f;
  m = high ? m * 0.5f : m;
  e += high;
  /* s = (m - 1)/(m + 1) in two parts: m - 1 is exact, m + 1 = dh + dl exactly. */
  const float num = m - 1.0f, dh = m + 1.0f, dl = m - (dh - 1.0f);
  const float sh = num / dh;
  float q, qe;
  fl_two_prod(sh, dh, &q, &qe);
  const float sl = (((num - q) - qe) - sh * dl) / dh;
  const float z = sh * sh;
  const float series =
    (((((0.181818182f * z + 0.222222222f) * z + 0.285714286f) * z + 0.4f) * z) +
     0.666666667f) * (z * sh);
  /* ln m = 2 sh + (2 sl + series); log2 m = that times log2(e) = 1.44269502f + 1.92596303e-8. */
  const float lh = 2.0f * sh, ll = 2.0f * sl + series;
  float a, ae;
  fl_two_prod(lh, 1.44269502f, &a, &ae);
  const float al = ae + (lh * 1.92596303e-8f + ll * 1.44269502f);
  /* log2 m = bh + bl with bl below bh's last bit, then log2 x = th + tl by adding e the same
   * way (Fast2Sum: |a| > |al|; |e| >= 1 > |bh|, or e = 0). */
  const float bh = a + al, bl = al - (bh - a);
  const float ef = (float)e;
  const float th = ef + bh;
  const float tl = ((ef - th) + bh) + bl;
  /* y log2 x = ph + pl, ph clamped where the result is 0 or infinite anyway. */
  const float yc = y < 1e30f ? y : 1e30f;
  float ph, pe;
  fl_two_prod(yc, th, &ph, &pe);
  float pl = pe + yc * tl;
  const int over = !(ph > -200.0f && ph < 200.0f); /* (NaN too: replaced below) */
  ph = over ? (ph > 0.0f ? 200.0f : -200.0f) : ph;
  pl = over ? 0.0f : pl;
  /* 2^ph 2^pl = 2^n e^((ph - n + pl) ln2), n = round(ph): ph - n is exact. */
  const float t = ph + 12582912.0f;
  const int n = (int)(as_uint(t) & 0x007fffffu) - 0x400000;
  const float r = ((ph - (t - 12582912.0f)) + pl) * 0.693147181f;
  float v = fl_exp_scaled(fl_exp_reduced(r), n);
  v = x == 0.0f ? 0.0f : v;
  v = x == 1.0f ? 1.0f : v;
  v = x > 3.40282347e38f ? x : v;
  v = x != x ? x : v;
  return y == 0.0f ? 1.0f : v;
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
