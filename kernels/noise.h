/* Gradient noise with its analytic gradient, and the divergence-free curl noise built from
 * it (Bridson, Hourihan, Nordenstam: "Curl-noise for procedural fluid flow", 2007). Written
 * once for both backends (compat_opencl.h, sdk/src/kernel_compat.hpp): Turbulence on the
 * CPU and on the device. */
#ifndef FLURRY_KERNELS_NOISE_H
#define FLURRY_KERNELS_NOISE_H

/* A hash of integer lattice coordinates (and a seed): no table, so nothing to upload. */
FL_INLINE uint fl_lattice_hash(int x, int y, int z, uint seed) {
  uint h = seed ^ 0x9E3779B9u;
  h ^= (uint)x * 0x85EBCA6Bu;
  h = (h << 13) | (h >> 19);
  h ^= (uint)y * 0xC2B2AE35u;
  h = (h << 13) | (h >> 19);
  h ^= (uint)z * 0x27D4EB2Fu;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  h ^= h >> 16;
  return h;
}

/* One of the 12 cube edge directions: (a, b, 0) for h % 12 in 0-3, (a, 0, b) in 4-7, (0, a, b)
 * in 8-11, a's sign from bit 0 and b's from bit 1. Selects, not a switch: a loop over
 * particles on the CPU then vectorises. */
FL_INLINE float3 fl_lattice_gradient(uint h) {
  const uint k = h % 12u;
  const float a = (k & 1u) ? -1.0f : 1.0f;
  const float b = (k & 2u) ? -1.0f : 1.0f;
  return make_float3(k < 8u ? a : 0.0f, k < 4u ? b : (k < 8u ? 0.0f : a), k < 4u ? 0.0f : b);
}

/* The quintic fade and its derivative. */
FL_INLINE float fl_noise_fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
FL_INLINE float fl_noise_dfade(float t) { return 30.0f * t * t * (t * (t - 2.0f) + 1.0f); }

/* The lattice cell of a coordinate's floor f as an int, f held within +-2^30 first: a float
 * beyond int's range (or NaN) converted to int is undefined behaviour in C++ and unspecified
 * on a device, and a particle flung 1e32 away still reads the noise. Every f inside is
 * unchanged; that far out a float has no fraction left anyway. */
FL_INLINE int fl_lattice_cell(float f) {
  return (int)(f < -1073741824.0f ? -1073741824.0f : (f < 1073741824.0f ? f : 1073741824.0f));
}

/* The exact gradient of Perlin gradient noise (quintic fade) at p. */
FL_INLINE float3 fl_noise_gradient(float px, float py, float pz, uint seed) {
  const float fx = floor(px), fy = floor(py), fz = floor(pz);
  const int ix = fl_lattice_cell(fx), iy = fl_lattice_cell(fy), iz = fl_lattice_cell(fz);
  const float tx = px - fx, ty = py - fy, tz = pz - fz;
  const float ux = fl_noise_fade(tx), uy = fl_noise_fade(ty), uz = fl_noise_fade(tz);
  const float dux = fl_noise_dfade(tx), duy = fl_noise_dfade(ty), duz = fl_noise_dfade(tz);
  float gx = 0.0f, gy = 0.0f, gz = 0.0f;
  FL_UNROLL
  for (int c = 0; c < 8; ++c) {
    const int ox = c & 1, oy = (c >> 1) & 1, oz = (c >> 2) & 1;
    const float3 g = fl_lattice_gradient(fl_lattice_hash(ix + ox, iy + oy, iz + oz, seed));
    const float dx = tx - (float)ox, dy = ty - (float)oy, dz = tz - (float)oz;
    const float n = g.x * dx + g.y * dy + g.z * dz;
    const float wx = ox ? ux : 1.0f - ux, wy = oy ? uy : 1.0f - uy, wz = oz ? uz : 1.0f - uz;
    const float sx = ox ? dux : -dux, sy = oy ? duy : -duy, sz = oz ? duz : -duz;
    const float w = wx * wy * wz;
    /* d/dp (w n) = n dw/dp + w g */
    gx = gx + (g.x * w + sx * wy * wz * n);
    gy = gy + (g.y * w + wx * sy * wz * n);
    gz = gz + (g.z * w + wx * wy * sz * n);
  }
  return make_float3(gx, gy, gz);
}

/* One octave of fl_curl_noise at q (p times the octave's frequency), k its scale times its
 * frequency: the curl's terms added to (*cx, *cy, *cz). */
FL_INLINE void fl_curl_octave(float qx, float qy, float qz, uint o, float k, float* cx, float* cy,
                              float* cz) {
  const float3 g1 = fl_noise_gradient(qx, qy, qz, 0x1234u + 3u * o);
  const float3 g2 = fl_noise_gradient(qx + 31.416f, qy + 47.853f, qz + 12.793f, 0x5678u + 3u * o);
  const float3 g3 = fl_noise_gradient(qx + -61.77f, qy + 19.19f, qz + 83.41f, 0x9ABCu + 3u * o);
  /* The derivatives are with respect to q = p freq: d/dp = freq d/dq (k). */
  *cx = *cx + (g3.y - g2.z) * k;
  *cy = *cy + (g1.z - g3.x) * k;
  *cz = *cz + (g2.x - g1.y) * k;
}

/* The curl of a vector potential of three noise fields: divergence-free by construction.
 * Octaves double the frequency and halve the amplitude. */
FL_INLINE float3 fl_curl_noise(float px, float py, float pz, uint octaves) {
  float cx = 0.0f, cy = 0.0f, cz = 0.0f;
  float scale = 1.0f, freq = 1.0f;
  for (uint o = 0; o < octaves; ++o) {
    fl_curl_octave(px * freq, py * freq, pz * freq, o, scale * freq, &cx, &cy, &cz);
    scale *= 0.5f;
    freq *= 2.0f;
  }
  return make_float3(cx, cy, cz);
}

/* ---- Turbulence ----------------------------------------------------------------------------- */

typedef struct FlTurbulence {
  float amplitude, frequency, driftX, driftY, driftZ;
  uint octaves;
} FlTurbulence;

/* Turbulence's acceleration without its falloff, at p and time t: the amplitude times the
 * curl noise at (p - drift t) frequency. */
FL_INLINE float3 fl_turbulence_field(FlTurbulence a, float t, float px, float py, float pz) {
  const float sx = a.driftX * t, sy = a.driftY * t, sz = a.driftZ * t;
  const float3 c = fl_curl_noise((px - sx) * a.frequency, (py - sy) * a.frequency,
                                 (pz - sz) * a.frequency, a.octaves);
  return make_float3(c.x * a.amplitude, c.y * a.amplitude, c.z * a.amplitude);
}

/* As a force (the integrators): adds the field times the falloff's weight w to *a. */
FL_INLINE void fl_turbulence_accel(FlTurbulence a, float t, float w, float px, float py, float pz,
                                   float* ax, float* ay, float* az) {
  const float3 f = fl_turbulence_field(a, t, px, py, pz);
  *ax += f.x * w;
  *ay += f.y * w;
  *az += f.z * w;
}

#endif /* FLURRY_KERNELS_NOISE_H */
