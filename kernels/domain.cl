/* Domains on the device: sampling (emission) and containment (Sink). Each formula follows
 * sdk/src/sampling.cpp and sdk/src/shape_math.hpp operation by operation, in the same order,
 * so that with FP_CONTRACT off and correctly rounded division and sqrt the two backends
 * agree to the bit, except in Box-Muller's log and cos (normal fuzzy values, blobs). */

/* Doubles arrive as bit patterns (see params.h). */
#ifdef FL_FP64
typedef double fl_real;
FL_INLINE fl_real fl_real_from_bits(ulong b) { return as_double(b); }
#else
typedef float fl_real;
/* A device without doubles: convert the bits to the nearest float (normal numbers; smaller
 * ones flush to zero, larger ones saturate). */
FL_INLINE fl_real fl_real_from_bits(ulong b) {
  const uint sign = (uint)(b >> 63);
  const int e = (int)((b >> 52) & 0x7FF) - 1023;
  if (e < -126) return sign ? -0.0f : 0.0f;
  if (e > 127) return sign ? -INFINITY : INFINITY;
  const uint m = (uint)((b >> 29) & 0x7FFFFF);
  return as_float((sign << 31) | ((uint)(e + 127) << 23) | m);
}
#endif

FL_INLINE float3 fl_v3(__global const float* v) { return (float3)(v[0], v[1], v[2]); }

/* sampling.hpp sinCos2Pi: sin(2 pi u) and cos(2 pi u) for u in [0, 1) by the CPU's polynomials, so
 * both backends get the same bits (no libm or OpenCL builtin in the path). */
FL_INLINE void fl_sincos_2pi(float u, float* s, float* c) {
  const float x = 4.0f * u;
  const int q = (int)(x + 0.5f);
  const float r = (x - (float)q) * 1.57079632679489662f;
  const float r2 = r * r;
  const float sr =
      r + r * r2 * (-1.6666654611e-1f + r2 * (8.3321608736e-3f + r2 * -1.9515295891e-4f));
  const float cr = 1.0f - 0.5f * r2 +
                   r2 * r2 *
                       (4.166664568298827e-2f +
                        r2 * (-1.388731625493765e-3f + r2 * 2.443315711809948e-5f));
  const uint swap = 0u - (uint)(q & 1);
  const uint sb = as_uint(sr), cb = as_uint(cr);
  const uint sSign = (uint)(q & 2) << 30;
  const uint cSign = (uint)((q + 1) & 2) << 30;
  *s = as_float(((sb & ~swap) | (cb & swap)) ^ sSign);
  *c = as_float(((cb & ~swap) | (sb & swap)) ^ cSign);
}

/* sampling.hpp cbrtNonNegative. */
FL_INLINE float fl_cbrt_nonneg(float x) {
  const uint i = as_uint(x);
  float y = as_float((uint)((float)i * (1.0f / 3.0f)) + 0x2a5137a0u);
  for (int k = 0; k < 4; ++k) y -= (y - x / (y * y)) * (1.0f / 3.0f);
  return x > 0.0f ? y : 0.0f;
}

FL_INLINE float fl_min(float a, float b) { return b < a ? b : a; } /* std::min's rule */

/* Random::normal() / sampling.cpp normalFrom: the one place with libm calls (log, cos),
 * where the device's builtins may differ from glibc by an ulp or two. */
FL_INLINE float fl_normal_from(float ua, float ub) {
  return sqrt(-2.0f * log(1.0f - ua)) * cos(6.28318530718f * ub);
}

/* A point drawn from the domain (sampling.cpp sampleBatch with a batch of one): the draws
 * come from rng in the CPU's order, the formulas are the CPU's operation for operation. */
FL_INLINE float3 fl_sample(__global const FlDomain* d, uint kind, FlRandom* rng) {
  /* kind is a literal in the generated emission code: the switch folds away, and with it
   * every data-dependent branch of the random stream. */
  __global const float* v = d->v;
  const float3 a = fl_v3(v);
  switch (kind) {
    case FL_DOMAIN_LINE: {
      const float u0 = fl_uniform(rng);
      const float3 e = fl_v3(v + 3) - a;
      return (float3)(a.x + e.x * u0, a.y + e.y * u0, a.z + e.z * u0);
    }
    case FL_DOMAIN_TRIANGLE: {
      const float u0 = fl_uniform(rng), u1 = fl_uniform(rng);
      const float3 e1 = fl_v3(v + 3) - a, e2 = fl_v3(v + 6) - a;
      const float su = sqrt(u0);
      const float s = su * (1.0f - u1), t = su * u1;
      return (float3)(a.x + e1.x * s + e2.x * t, a.y + e1.y * s + e2.y * t,
                      a.z + e1.z * s + e2.z * t);
    }
    case FL_DOMAIN_RECTANGLE: {
      const float u0 = fl_uniform(rng), u1 = fl_uniform(rng);
      const float3 e1 = fl_v3(v + 3), e2 = fl_v3(v + 6);
      return (float3)(a.x + e1.x * u0 + e2.x * u1, a.y + e1.y * u0 + e2.y * u1,
                      a.z + e1.z * u0 + e2.z * u1);
    }
    case FL_DOMAIN_BOX: {
      const float u0 = fl_uniform(rng), u1 = fl_uniform(rng), u2 = fl_uniform(rng);
      const float3 hi = fl_v3(v + 3);
      const float3 e = hi - a;
      return (float3)(fl_min(a.x + e.x * u0, hi.x), fl_min(a.y + e.y * u1, hi.y),
                      fl_min(a.z + e.z * u2, hi.z));
    }
    case FL_DOMAIN_DISC:
    case FL_DOMAIN_CYLINDER: {
      /* disc: center e1 e2 outer inner; cylinder: p0 axis e1 e2 outer inner */
      const int cyl = kind == FL_DOMAIN_CYLINDER;
      const float ut = cyl ? fl_uniform(rng) : 0.0f;
      const float ur = fl_uniform(rng);
      const float uphi = fl_uniform(rng);
      const float3 axis = cyl ? fl_v3(v + 3) : (float3)(0.0f);
      const float3 e1 = fl_v3(v + (cyl ? 6 : 3)), e2 = fl_v3(v + (cyl ? 9 : 6));
      const float ro = v[cyl ? 12 : 9], ri = v[cyl ? 13 : 10];
      const float ri2 = ri * ri, span = ro * ro - ri2;
      const float r = sqrt(ur * span + ri2);
      float s, c;
      fl_sincos_2pi(uphi, &s, &c);
      return (float3)(a.x + axis.x * ut + (e1.x * c + e2.x * s) * r,
                      a.y + axis.y * ut + (e1.y * c + e2.y * s) * r,
                      a.z + axis.z * ut + (e1.z * c + e2.z * s) * r);
    }
    case FL_DOMAIN_SPHERE: {
      const float u0 = fl_uniform(rng), u1 = fl_uniform(rng), u2 = fl_uniform(rng);
      const float ro = v[3], ri = v[4];
      const float ri3 = ri * ri * ri, span = ro * ro * ro - ri3;
      const float r = fl_cbrt_nonneg(u0 * span + ri3);
      const float cz = 1.0f - 2.0f * u1;
      const float q = 1.0f - cz * cz;
      const float sz = sqrt(0.0f < q ? q : 0.0f);
      float s, c;
      fl_sincos_2pi(u2, &s, &c);
      return (float3)(a.x + sz * c * r, a.y + sz * s * r, a.z + cz * r);
    }
    case FL_DOMAIN_CONE: {
      const float u0 = fl_uniform(rng), u1 = fl_uniform(rng), u2 = fl_uniform(rng);
      const float3 axis = fl_v3(v + 3), e1 = fl_v3(v + 6), e2 = fl_v3(v + 9);
      const float ro = v[12], ri = v[13];
      float t, r;
      if (ri < ro) {
        const float ri2 = ri * ri, span = ro * ro - ri2;
        t = fl_cbrt_nonneg(u0);
        r = t * sqrt(u1 * span + ri2);
      } else { /* the lateral surface alone */
        t = sqrt(u0);
        r = t * ro;
      }
      float s, c;
      fl_sincos_2pi(u2, &s, &c);
      return (float3)(a.x + axis.x * t + (e1.x * c + e2.x * s) * r,
                      a.y + axis.y * t + (e1.y * c + e2.y * s) * r,
                      a.z + axis.z * t + (e1.z * c + e2.z * s) * r);
    }
    case FL_DOMAIN_BLOB: {
      float u[6];
      for (int k = 0; k < 6; ++k) u[k] = fl_uniform(rng);
      const float sd = v[3];
      return (float3)(a.x + sd * fl_normal_from(u[0], u[1]),
                      a.y + sd * fl_normal_from(u[2], u[3]),
                      a.z + sd * fl_normal_from(u[4], u[5]));
    }
    default: /* point, plane: the point itself */
      return a;
  }
}

FL_INLINE float fl_dot3(float ax, float ay, float az, float bx, float by, float bz) {
  return ax * bx + ay * by + az * bz;
}

/* shape_math.hpp inside(): whether (x, y, z) is in the domain. */
FL_INLINE int fl_inside(__global const float* v, uint kind, float x, float y, float z) {
  switch (kind) {
    case FL_DOMAIN_PLANE:
      return fl_dot3(x - v[0], y - v[1], z - v[2], v[3], v[4], v[5]) >= 0.0f;
    case FL_DOMAIN_BOX:
      return (x >= v[0]) & (x <= v[3]) & (y >= v[1]) & (y <= v[4]) & (z >= v[2]) & (z <= v[5]);
    case FL_DOMAIN_SPHERE: {
      const float rx = x - v[0], ry = y - v[1], rz = z - v[2];
      const float r2 = fl_dot3(rx, ry, rz, rx, ry, rz);
      return (r2 <= v[3] * v[3]) & (r2 >= v[4] * v[4]) & (v[4] < v[3]);
    }
    case FL_DOMAIN_CYLINDER:
    case FL_DOMAIN_CONE: {
      /* v: p0 (apex), axis = p1 - p0 (base - apex), e1, e2, outer, inner */
      const float ax = v[3], ay = v[4], az = v[5];
      const float len2 = fl_dot3(ax, ay, az, ax, ay, az);
      const float rx = x - v[0], ry = y - v[1], rz = z - v[2];
      const float t = fl_dot3(rx, ry, rz, ax, ay, az) / len2;
      const float qx = rx - ax * t, qy = ry - ay * t, qz = rz - az * t;
      const float q2 = fl_dot3(qx, qy, qz, qx, qy, qz);
      const float ro = kind == FL_DOMAIN_CONE ? v[12] * t : v[12];
      const float ri = kind == FL_DOMAIN_CONE ? v[13] * t : v[13];
      return (t >= 0.0f) & (t <= 1.0f) & (q2 <= ro * ro) & (q2 >= ri * ri) & (v[13] < v[12]);
    }
    case FL_DOMAIN_BLOB: {
      const float rx = x - v[0], ry = y - v[1], rz = z - v[2];
      return fl_dot3(rx, ry, rz, rx, ry, rz) <= v[3] * v[3];
    }
    default: /* points, segments and plane pieces have no inside */
      return 0;
  }
}
