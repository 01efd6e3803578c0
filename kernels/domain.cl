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

/* Uniforms a domain of a simple kind (not mesh or union) draws: sampling.cpp drawCount. */
FL_INLINE uint fl_draw_count(uint kind) {
  switch (kind) {
    case FL_DOMAIN_LINE:
      return 1;
    case FL_DOMAIN_TRIANGLE:
    case FL_DOMAIN_RECTANGLE:
    case FL_DOMAIN_DISC:
      return 2;
    case FL_DOMAIN_BOX:
    case FL_DOMAIN_SPHERE:
    case FL_DOMAIN_CYLINDER:
    case FL_DOMAIN_CONE:
    case FL_DOMAIN_MESH:
      return 3;
    case FL_DOMAIN_BLOB:
      return 6;
    default: /* point, plane */
      return 0;
  }
}

/* sampling.cpp triangle(). */
FL_INLINE float3 fl_triangle_at(float3 a, float3 e1, float3 e2, float u0, float u1) {
  const float su = sqrt(u0);
  const float s = su * (1.0f - u1), t = su * u1;
  return (float3)(a.x + e1.x * s + e2.x * t, a.y + e1.y * s + e2.y * t,
                  a.z + e1.z * s + e2.z * t);
}

/* A point of a domain of a simple kind from its uniforms u[0 .. fl_draw_count(kind)): the
 * CPU's formulas (sampling.cpp sampleBatch with a batch of one), operation for operation. */
FL_INLINE float3 fl_sample_u(__global const float* v, uint kind, const float* u) {
  const float3 a = fl_v3(v);
  switch (kind) {
    case FL_DOMAIN_LINE: {
      const float3 e = fl_v3(v + 3) - a;
      return (float3)(a.x + e.x * u[0], a.y + e.y * u[0], a.z + e.z * u[0]);
    }
    case FL_DOMAIN_TRIANGLE:
      return fl_triangle_at(a, fl_v3(v + 3) - a, fl_v3(v + 6) - a, u[0], u[1]);
    case FL_DOMAIN_RECTANGLE: {
      const float3 e1 = fl_v3(v + 3), e2 = fl_v3(v + 6);
      return (float3)(a.x + e1.x * u[0] + e2.x * u[1], a.y + e1.y * u[0] + e2.y * u[1],
                      a.z + e1.z * u[0] + e2.z * u[1]);
    }
    case FL_DOMAIN_BOX: {
      const float3 hi = fl_v3(v + 3);
      const float3 e = hi - a;
      return (float3)(fl_min(a.x + e.x * u[0], hi.x), fl_min(a.y + e.y * u[1], hi.y),
                      fl_min(a.z + e.z * u[2], hi.z));
    }
    case FL_DOMAIN_DISC:
    case FL_DOMAIN_CYLINDER: {
      /* disc: center e1 e2 outer inner (ur uphi); cylinder: p0 axis e1 e2 outer inner
       * (ut ur uphi) */
      const int cyl = kind == FL_DOMAIN_CYLINDER;
      const float ut = cyl ? u[0] : 0.0f;
      const float ur = u[cyl ? 1 : 0];
      const float uphi = u[cyl ? 2 : 1];
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
      const float ro = v[3], ri = v[4];
      const float ri3 = ri * ri * ri, span = ro * ro * ro - ri3;
      const float r = fl_cbrt_nonneg(u[0] * span + ri3);
      const float cz = 1.0f - 2.0f * u[1];
      const float q = 1.0f - cz * cz;
      const float sz = sqrt(0.0f < q ? q : 0.0f);
      float s, c;
      fl_sincos_2pi(u[2], &s, &c);
      return (float3)(a.x + sz * c * r, a.y + sz * s * r, a.z + cz * r);
    }
    case FL_DOMAIN_CONE: {
      const float3 axis = fl_v3(v + 3), e1 = fl_v3(v + 6), e2 = fl_v3(v + 9);
      const float ro = v[12], ri = v[13];
      float t, r;
      if (ri < ro) {
        const float ri2 = ri * ri, span = ro * ro - ri2;
        t = fl_cbrt_nonneg(u[0]);
        r = t * sqrt(u[1] * span + ri2);
      } else { /* the lateral surface alone */
        t = sqrt(u[0]);
        r = t * ro;
      }
      float s, c;
      fl_sincos_2pi(u[2], &s, &c);
      return (float3)(a.x + axis.x * t + (e1.x * c + e2.x * s) * r,
                      a.y + axis.y * t + (e1.y * c + e2.y * s) * r,
                      a.z + axis.z * t + (e1.z * c + e2.z * s) * r);
    }
    case FL_DOMAIN_BLOB: {
      const float sd = v[3];
      return (float3)(a.x + sd * fl_normal_from(u[0], u[1]), a.y + sd * fl_normal_from(u[2], u[3]),
                      a.z + sd * fl_normal_from(u[4], u[5]));
    }
    default: /* point, plane: the point itself */
      return a;
  }
}

/* A point drawn from the domain: the draws come from rng in the CPU's order. */
FL_INLINE float3 fl_sample(__global const FlDomain* d, uint kind, FlRandom* rng) {
  /* kind is a literal in the generated emission code: the switch folds away, and with it
   * every data-dependent branch of the random stream. */
  float u[6];
  const uint n = fl_draw_count(kind);
  for (uint k = 0; k < n; ++k) u[k] = fl_uniform(rng);
  return fl_sample_u(d->v, kind, u);
}

/* ---- Meshes and unions: their data is in a table `shapes` (emission.hpp ShapePacker): the
 * step's shape table for emitters, the list's `extra` for actions; the FlDomain holds where.
 * Integers travel as float bits.
 *  mesh:  v[0] offset, v[1] triangles, v[2..4] and v[5..7] the bounds' min and max; per
 *         triangle FL_MESH_STRIDE floats: the running area sum (double bits, low word
 *         first), vertices a b c, unit normal
 *  union: v[0] offset, v[1] parts, v[2] draws per sample (sampling.cpp drawCount),
 *         v[3] offset and v[4] count of its leaves (the non-union parts, nested unions
 *         flattened in order: what the nearest part is chosen from);
 *         per part FL_UNION_STRIDE floats: the running measure sum (double bits), its FlDomain
 */
#define FL_MESH_STRIDE 14u
#define FL_UNION_STRIDE 20u
#define FL_MAX_DOMAIN_DRAWS 16
/* The union's paths dispatch on kinds at run time: one copy of them, called, keeps programs
 * with many emitters quick to build. */
#define FL_NOINLINE __attribute__((noinline))

FL_INLINE uint fl_word(__global const float* p) { return as_uint(*p); }

FL_INLINE fl_real fl_real_at(__global const float* p) {
  return fl_real_from_bits(((ulong)as_uint(p[1]) << 32) | (ulong)as_uint(p[0]));
}

/* std::upper_bound over n running sums `stride` floats apart, clamped to n - 1 as the CPU
 * clamps it: the entry a uniform u picks in proportion to the sums' steps. */
FL_INLINE uint fl_pick(__global const float* sums, uint n, uint stride, float u) {
  const fl_real target = (fl_real)u * fl_real_at(sums + (n - 1) * stride);
  uint lo = 0, hi = n;
  while (lo < hi) {
    const uint mid = (lo + hi) / 2;
    if (target < fl_real_at(sums + mid * stride))
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo < n - 1 ? lo : n - 1;
}

/* A point of a mesh from u[0..2]: a triangle by area, then a point on it. */
FL_INLINE float3 fl_sample_mesh(__global const float* v, const float* u,
                                __global const float* shapes) {
  __global const float* m = shapes + fl_word(v);
  const uint k = fl_pick(m, fl_word(v + 1), FL_MESH_STRIDE, u[0]);
  __global const float* t = m + k * FL_MESH_STRIDE + 2;
  const float3 a = fl_v3(t);
  return fl_triangle_at(a, fl_v3(t + 3) - a, fl_v3(t + 6) - a, u[1], u[2]);
}

/* A point of a union: its draws first (a fixed count), then a part by measure from the next
 * uniform at each level of nesting, and the part's own draws after that. */
FL_NOINLINE float3 fl_sample_union(__global const float* v, FlRandom* rng,
                                   __global const float* shapes) {
  float u[FL_MAX_DOMAIN_DRAWS];
  const uint n = fl_word(v + 2);
  for (uint k = 0; k < n && k < FL_MAX_DOMAIN_DRAWS; ++k) u[k] = fl_uniform(rng);
  uint kind = FL_DOMAIN_UNION, next = 0;
  while (kind == FL_DOMAIN_UNION) {
    __global const float* parts = shapes + fl_word(v);
    const uint k = fl_pick(parts, fl_word(v + 1), FL_UNION_STRIDE, u[next++]);
    __global const FlDomain* part = (__global const FlDomain*)(parts + k * FL_UNION_STRIDE + 2);
    v = part->v;
    kind = part->kind;
  }
  if (kind == FL_DOMAIN_MESH) return fl_sample_mesh(v, u + next, shapes);
  return fl_sample_u(v, kind, u + next);
}

/* fl_sample for every kind, meshes and unions too. */
FL_INLINE float3 fl_sample_any(__global const FlDomain* d, uint kind, FlRandom* rng,
                               __global const float* shapes) {
  if (kind == FL_DOMAIN_MESH) {
    float u[3];
    for (int k = 0; k < 3; ++k) u[k] = fl_uniform(rng);
    return fl_sample_mesh(d->v, u, shapes);
  }
  if (kind == FL_DOMAIN_UNION) return fl_sample_union(d->v, rng, shapes);
  return fl_sample(d, kind, rng);
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

/* ---- Normals (Emitter::normalSpeed): domain.cpp normalShape and the closest points it
 * rests on, operation for operation (glm's dot is (x x' + y y') + z z', its normalize
 * v * (1 / sqrt(dot(v, v)))). Packed extras: triangle and rectangle normal in v[9..11],
 * disc normal in v[11..13] (codegen.cpp packDomain). */

FL_INLINE float fl_dotv(float3 a, float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
FL_INLINE float fl_lengthv(float3 a) { return sqrt(fl_dotv(a, a)); }
FL_INLINE int fl_is_zero(float3 a) { return (a.x == 0.0f) & (a.y == 0.0f) & (a.z == 0.0f); }
FL_INLINE float fl_max(float a, float b) { return a < b ? b : a; } /* std::max's rule */
FL_INLINE float fl_clamp(float x, float lo, float hi) { return fl_min(fl_max(x, lo), hi); }
FL_INLINE float3 fl_clamp3(float3 x, float3 lo, float3 hi) {
  return (float3)(fl_clamp(x.x, lo.x, hi.x), fl_clamp(x.y, lo.y, hi.y), fl_clamp(x.z, lo.z, hi.z));
}

/* domain.cpp unitOrZero: divided by the largest component first. */
FL_INLINE float3 fl_unit_or_zero(float3 v) {
  const float m = fl_max(fl_max(fabs(v.x), fabs(v.y)), fabs(v.z));
  if (!(m > 0.0f)) return (float3)(0.0f);
  const float3 w = v / m;
  return w * (1.0f / sqrt(fl_dotv(w, w)));
}

/* domain.cpp anyPerpendicular: the first vector of basis(n). */
FL_INLINE float3 fl_any_perpendicular(float3 n) {
  const float s = copysign(1.0f, n.z);
  const float a = -1.0f / (s + n.z);
  const float b = n.x * n.y * a;
  return (float3)(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
}

FL_INLINE float3 fl_closest_segment(float3 a, float3 b, float3 p) {
  const float3 ab = b - a;
  const float len2 = fl_dotv(ab, ab);
  const float t = len2 > 0.0f ? fl_clamp(fl_dotv(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return a + ab * t;
}

/* domain.cpp closestOnTriangle (Ericson 5.1.5). */
FL_INLINE float3 fl_closest_triangle(float3 a, float3 b, float3 c, float3 p) {
  const float3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = fl_dotv(ab, ap), d2 = fl_dotv(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return a;
  const float3 bp = p - b;
  const float d3 = fl_dotv(ab, bp), d4 = fl_dotv(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return a + ab * (d1 / (d1 - d3));
  const float3 cp = p - c;
  const float d5 = fl_dotv(ab, cp), d6 = fl_dotv(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float denom = 1.0f / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

/* domain.cpp solidNormal. */
FL_INLINE float3 fl_solid_normal(int inside, float3 p, float3 c, float3 face, float scale) {
  if (!inside && fl_lengthv(p - c) > 1e-5f * scale) return fl_unit_or_zero(p - c);
  return face;
}

/* domain.cpp closestBall: the nearest point, and the outward normal there in *n. */
FL_INLINE float3 fl_closest_ball(float3 center, float outer, float inner, float3 p, float3* n) {
  const float3 r = p - center;
  float3 dir = fl_unit_or_zero(r);
  if (fl_is_zero(dir)) dir = (float3)(1.0f, 0.0f, 0.0f);
  const int toInner = inner > 0.0f && inner < outer && fl_lengthv(r) < 0.5f * (inner + outer);
  *n = toInner ? -dir : dir;
  return center + dir * (toInner ? inner : outer);
}

/* domain.cpp nearestBoxFace: the face (axis * 2 + side) whose plane is nearest. */
FL_INLINE int fl_box_face(float3 lo3, float3 hi3, float3 p) {
  const float pv[3] = {p.x, p.y, p.z}, mn[3] = {lo3.x, lo3.y, lo3.z}, mx[3] = {hi3.x, hi3.y, hi3.z};
  int face = 0;
  float dist = INFINITY;
  for (int i = 0; i < 3; ++i) {
    const float lo = pv[i] - mn[i], hi = mx[i] - pv[i];
    if (lo < dist) dist = lo, face = 2 * i;
    if (hi < dist) dist = hi, face = 2 * i + 1;
  }
  return face;
}

/* Cylinders and cones in the half-plane through the axis and p (domain.cpp AxialFrame). */
typedef struct FlDomAxial {
  float3 origin, w, e;
  float length, a, rho;
} FlDomAxial;

FL_INLINE FlDomAxial fl_axial(float3 origin, float3 axis, float3 p) {
  FlDomAxial f;
  f.origin = origin;
  f.length = fl_lengthv(axis);
  f.w = axis / f.length;
  const float3 d = p - origin;
  f.a = fl_dotv(d, f.w);
  const float3 radial = d - f.w * f.a;
  f.e = fl_unit_or_zero(radial);
  if (fl_is_zero(f.e)) f.e = fl_any_perpendicular(f.w);
  f.rho = fl_dotv(radial, f.e);
  return f;
}

typedef struct FlDomHit2 {
  float a, rho, na, nrho, dist2;
} FlDomHit2;

FL_INLINE void fl_segment2(const FlDomAxial* f, float a0, float r0, float a1, float r1, float na,
                           float nr, FlDomHit2* best) {
  const float da = a1 - a0, dr = r1 - r0;
  const float len2 = da * da + dr * dr;
  float t = len2 > 0.0f ? ((f->a - a0) * da + (f->rho - r0) * dr) / len2 : 0.0f;
  t = fl_clamp(t, 0.0f, 1.0f);
  const float ca = a0 + da * t, cr = r0 + dr * t;
  const float d2 = (f->a - ca) * (f->a - ca) + (f->rho - cr) * (f->rho - cr);
  if (d2 < best->dist2) {
    best->a = ca;
    best->rho = cr;
    best->na = na;
    best->nrho = nr;
    best->dist2 = d2;
  }
}

/* domain.cpp nearestCylinder / nearestCone. */
FL_INLINE FlDomHit2 fl_nearest_axial(const FlDomAxial* f, int cone, float ro, float ri) {
  const float L = f->length;
  FlDomHit2 h = {0.0f, 0.0f, 0.0f, 0.0f, INFINITY};
  if (!cone) {
    fl_segment2(f, 0.0f, ro, L, ro, 0.0f, 1.0f, &h);
    if (ri < ro) {
      fl_segment2(f, 0.0f, ri, 0.0f, ro, -1.0f, 0.0f, &h);
      fl_segment2(f, L, ri, L, ro, 1.0f, 0.0f, &h);
      if (ri > 0.0f) fl_segment2(f, 0.0f, ri, L, ri, 0.0f, -1.0f, &h);
    }
  } else {
    const float so = sqrt(L * L + ro * ro);
    fl_segment2(f, 0.0f, 0.0f, L, ro, -ro / so, L / so, &h);
    if (ri < ro) {
      fl_segment2(f, L, ri, L, ro, 1.0f, 0.0f, &h);
      if (ri > 0.0f) {
        const float si = sqrt(L * L + ri * ri);
        fl_segment2(f, 0.0f, 0.0f, L, ri, ri / si, -L / si, &h);
      }
    }
  }
  return h;
}

FL_INLINE float3 fl_axial_world(const FlDomAxial* f, float a, float rho) {
  return f->origin + f->w * a + f->e * rho;
}

/* The nearest of a mesh's triangles to p (the first of equals), as domain.cpp's loops. */
FL_INLINE uint fl_mesh_nearest(__global const float* v, float3 p, __global const float* shapes,
                               float3* closest) {
  __global const float* m = shapes + fl_word(v);
  const uint n = fl_word(v + 1);
  uint best = 0;
  float bestD2 = INFINITY;
  *closest = fl_v3(m + 2);
  for (uint k = 0; k < n; ++k) {
    __global const float* t = m + k * FL_MESH_STRIDE + 2;
    const float3 c = fl_closest_triangle(fl_v3(t), fl_v3(t + 3), fl_v3(t + 6), p);
    const float d2 = fl_dotv(c - p, c - p);
    if (d2 < bestD2) {
      bestD2 = d2;
      best = k;
      *closest = c;
    }
  }
  return best;
}

/* domain.cpp closestShape for every kind but the union. */
FL_INLINE float3 fl_closest(__global const float* v, uint kind, float3 p,
                            __global const float* shapes) {
  const float3 a = fl_v3(v);
  switch (kind) {
    case FL_DOMAIN_LINE:
      return fl_closest_segment(a, fl_v3(v + 3), p);
    case FL_DOMAIN_TRIANGLE:
      return fl_closest_triangle(a, fl_v3(v + 3), fl_v3(v + 6), p);
    case FL_DOMAIN_PLANE: {
      const float3 n = fl_v3(v + 3);
      return p - n * fl_dotv(p - a, n);
    }
    case FL_DOMAIN_RECTANGLE: {
      const float3 u = fl_v3(v + 3), w = fl_v3(v + 6);
      const float3 r = p - a;
      const float uu = fl_dotv(u, u), uv = fl_dotv(u, w), vv = fl_dotv(w, w);
      const float ru = fl_dotv(r, u), rv = fl_dotv(r, w);
      const float3 c = (float3)(u.y * w.z - w.y * u.z, u.z * w.x - w.z * u.x,
                                u.x * w.y - w.x * u.y); /* glm::cross(u, v) */
      const float det = fl_dotv(c, c);
      const float s = (vv * ru - uv * rv) / det, t = (uu * rv - uv * ru) / det;
      if (s >= 0.0f && s <= 1.0f && t >= 0.0f && t <= 1.0f) return a + u * s + w * t;
      const float3 b = a + u, cc = a + u + w, e = a + w;
      float3 best = fl_closest_segment(a, b, p);
      float bestD2 = fl_dotv(p - best, p - best);
      const float3 q[3] = {fl_closest_segment(b, cc, p), fl_closest_segment(cc, e, p),
                           fl_closest_segment(e, a, p)};
      for (int k = 0; k < 3; ++k) {
        const float d2 = fl_dotv(p - q[k], p - q[k]);
        if (d2 < bestD2) bestD2 = d2, best = q[k];
      }
      return best;
    }
    case FL_DOMAIN_DISC: {
      const float3 n = fl_v3(v + 11);
      const float ro = v[9], ri = v[10];
      const float3 r = p - a;
      const float3 inPlane = r - n * fl_dotv(r, n);
      float3 dir = fl_unit_or_zero(inPlane);
      if (fl_is_zero(dir)) {
        if (ri == 0.0f) return a;
        dir = fl_v3(v + 3); /* e1 = anyPerpendicular(normal), packed */
      }
      const float rho = fl_clamp(fl_dotv(inPlane, dir), ri, ro);
      return a + dir * rho;
    }
    case FL_DOMAIN_BOX: {
      const float3 hi = fl_v3(v + 3);
      if (!fl_inside(v, FL_DOMAIN_BOX, p.x, p.y, p.z)) return fl_clamp3(p, a, hi);
      const int face = fl_box_face(a, hi, p);
      float c[3] = {p.x, p.y, p.z};
      c[face / 2] = (face & 1) ? v[3 + face / 2] : v[face / 2];
      return (float3)(c[0], c[1], c[2]);
    }
    case FL_DOMAIN_SPHERE:
    case FL_DOMAIN_BLOB: {
      float3 n;
      return kind == FL_DOMAIN_SPHERE ? fl_closest_ball(a, v[3], v[4], p, &n)
                                      : fl_closest_ball(a, v[3], 0.0f, p, &n);
    }
    case FL_DOMAIN_CYLINDER:
    case FL_DOMAIN_CONE: {
      const FlDomAxial f = fl_axial(a, fl_v3(v + 3), p);
      const FlDomHit2 h = fl_nearest_axial(&f, kind == FL_DOMAIN_CONE, v[12], v[13]);
      return fl_axial_world(&f, h.a, h.rho);
    }
    case FL_DOMAIN_MESH: {
      float3 c;
      fl_mesh_nearest(v, p, shapes, &c);
      return c;
    }
    default: /* point */
      return a;
  }
}

/* domain.cpp normalShape for every kind but the union. */
FL_INLINE float3 fl_normal_leaf(__global const float* v, uint kind, float3 p,
                                __global const float* shapes) {
  const float3 a = fl_v3(v);
  switch (kind) {
    case FL_DOMAIN_POINT: {
      const float3 n = fl_unit_or_zero(p - a);
      return fl_is_zero(n) ? (float3)(0.0f, 1.0f, 0.0f) : n;
    }
    case FL_DOMAIN_LINE: {
      const float3 b = fl_v3(v + 3);
      const float3 n = fl_unit_or_zero(p - fl_closest_segment(a, b, p));
      if (!fl_is_zero(n)) return n;
      const float3 d = b - a;
      return fl_any_perpendicular(d * (1.0f / sqrt(fl_dotv(d, d))));
    }
    case FL_DOMAIN_TRIANGLE:
    case FL_DOMAIN_RECTANGLE:
      return fl_v3(v + 9);
    case FL_DOMAIN_PLANE:
      return fl_v3(v + 3);
    case FL_DOMAIN_DISC:
      return fl_v3(v + 11);
    case FL_DOMAIN_BOX: {
      const float3 hi = fl_v3(v + 3);
      const int face = fl_box_face(a, hi, p);
      float n[3] = {0.0f, 0.0f, 0.0f};
      n[face / 2] = (face & 1) ? 1.0f : -1.0f;
      return fl_solid_normal(fl_inside(v, FL_DOMAIN_BOX, p.x, p.y, p.z), p, fl_clamp3(p, a, hi),
                             (float3)(n[0], n[1], n[2]), fl_lengthv(hi - a));
    }
    case FL_DOMAIN_SPHERE:
    case FL_DOMAIN_BLOB: {
      float3 n;
      if (kind == FL_DOMAIN_SPHERE)
        fl_closest_ball(a, v[3], v[4], p, &n);
      else
        fl_closest_ball(a, v[3], 0.0f, p, &n);
      return n;
    }
    case FL_DOMAIN_CYLINDER:
    case FL_DOMAIN_CONE: {
      const float ro = v[12], ri = v[13];
      const FlDomAxial f = fl_axial(a, fl_v3(v + 3), p);
      const FlDomHit2 h = fl_nearest_axial(&f, kind == FL_DOMAIN_CONE, ro, ri);
      const float3 face = f.w * h.na + f.e * h.nrho;
      if (ri == ro) return face; /* a bare surface: its outward side */
      return fl_solid_normal(fl_inside(v, kind, p.x, p.y, p.z), p, fl_axial_world(&f, h.a, h.rho),
                             face, f.length + ro);
    }
    case FL_DOMAIN_MESH: {
      float3 c;
      const uint k = fl_mesh_nearest(v, p, shapes, &c);
      return fl_v3(shapes + fl_word(v) + k * FL_MESH_STRIDE + 11);
    }
    default:
      return (float3)(0.0f, 1.0f, 0.0f);
  }
}

/* The leaf of a union nearest to p, as domain.cpp nearestPart: the first of equals by
 * distance (a nested union's distance is its nearest leaf's, so the flattened leaves give
 * the same part). */
FL_INLINE __global const FlDomain* fl_union_nearest(__global const float* v, float3 p,
                                                    __global const float* shapes) {
  __global const float* leaves = shapes + fl_word(v + 3);
  const uint n = fl_word(v + 4);
  uint best = 0;
  float bestD = INFINITY;
  for (uint k = 0; k < n; ++k) {
    __global const FlDomain* part = (__global const FlDomain*)(leaves + k * 18u);
    const float dist = fl_lengthv(p - fl_closest(part->v, part->kind, p, shapes));
    if (dist < bestD) {
      bestD = dist;
      best = k;
    }
  }
  return (__global const FlDomain*)(leaves + best * 18u);
}

/* A union's normal is that of its part nearest to p. */
FL_NOINLINE float3 fl_normal_union(__global const float* v, float3 p,
                                   __global const float* shapes) {
  __global const FlDomain* part = fl_union_nearest(v, p, shapes);
  return fl_normal_leaf(part->v, part->kind, p, shapes);
}

/* Domain::normal at p, for every kind. */
FL_INLINE float3 fl_normal_at(__global const FlDomain* d, uint kind, float3 p,
                              __global const float* shapes) {
  if (kind == FL_DOMAIN_UNION) return fl_normal_union(d->v, p, shapes);
  return fl_normal_leaf(d->v, kind, p, shapes);
}

/* ---- Meshes and unions as actions' regions (containment, closest points); `shapes` is the
 * act kernel's `extra`. */

FL_INLINE float3 fl_crossv(float3 a, float3 b) { /* glm::cross */
  return (float3)(a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y);
}

/* domain.cpp inside(MeshDomain): nothing outside the bounds; else the parity of the crossings
 * of a skewed ray from p (Moller-Trumbore), each test as the CPU's. */
FL_INLINE int fl_inside_mesh(__global const float* v, float x, float y, float z,
                             __global const float* shapes) {
  if (x < v[2] || y < v[3] || z < v[4] || x > v[5] || y > v[6] || z > v[7]) return 0;
  const float3 d0 = (float3)(1.0f, 0.1234567f, 0.0765432f);
  const float3 dir = d0 * (1.0f / sqrt(fl_dotv(d0, d0))); /* glm::normalize */
  const float3 p = (float3)(x, y, z);
  __global const float* m = shapes + fl_word(v);
  const uint n = fl_word(v + 1);
  uint crossings = 0;
  for (uint k = 0; k < n; ++k) {
    __global const float* t = m + k * FL_MESH_STRIDE + 2;
    const float3 a = fl_v3(t), e1 = fl_v3(t + 3) - a, e2 = fl_v3(t + 6) - a;
    const float3 h = fl_crossv(dir, e2);
    const float det = fl_dotv(e1, h);
    if (fabs(det) < 1e-12f) continue;
    const float inv = 1.0f / det;
    const float3 s = p - a;
    const float u = fl_dotv(s, h) * inv;
    if (u < 0.0f || u > 1.0f) continue;
    const float3 q = fl_crossv(s, e1);
    const float w = fl_dotv(dir, q) * inv;
    if (w < 0.0f || u + w > 1.0f) continue;
    if (fl_dotv(e2, q) * inv > 0.0f) ++crossings;
  }
  return (int)(crossings & 1u);
}

/* domain.cpp inside(UnionDomain): in some part, that is in some leaf. */
FL_NOINLINE int fl_inside_union(__global const float* v, float x, float y, float z,
                                __global const float* shapes) {
  __global const float* leaves = shapes + fl_word(v + 3);
  const uint n = fl_word(v + 4);
  for (uint k = 0; k < n; ++k) {
    __global const FlDomain* part = (__global const FlDomain*)(leaves + k * 18u);
    const int in = part->kind == FL_DOMAIN_MESH ? fl_inside_mesh(part->v, x, y, z, shapes)
                                                : fl_inside(part->v, part->kind, x, y, z);
    if (in) return 1;
  }
  return 0;
}

/* fl_inside for every kind, meshes and unions too (kind a literal: the tests fold away). */
FL_INLINE int fl_inside_any(__global const float* v, uint kind, float x, float y, float z,
                            __global const float* shapes) {
  if (kind == FL_DOMAIN_MESH) return fl_inside_mesh(v, x, y, z, shapes);
  if (kind == FL_DOMAIN_UNION) return fl_inside_union(v, x, y, z, shapes);
  return fl_inside(v, kind, x, y, z);
}

/* domain.cpp closestShape(UnionDomain): its nearest part's closest point. */
FL_NOINLINE float3 fl_closest_union(__global const float* v, float3 p,
                                    __global const float* shapes) {
  __global const FlDomain* part = fl_union_nearest(v, p, shapes);
  return fl_closest(part->v, part->kind, p, shapes);
}

/* Domain::closestPoint for every kind. */
FL_INLINE float3 fl_closest_any(__global const float* v, uint kind, float3 p,
                                __global const float* shapes) {
  if (kind == FL_DOMAIN_UNION) return fl_closest_union(v, p, shapes);
  return fl_closest(v, kind, p, shapes);
}

/* Domain::normal for every kind, from the domain's v[]. */
FL_INLINE float3 fl_normal_any(__global const float* v, uint kind, float3 p,
                               __global const float* shapes) {
  if (kind == FL_DOMAIN_UNION) return fl_normal_union(v, p, shapes);
  return fl_normal_leaf(v, kind, p, shapes);
}
