/* Domains' math, written once for both backends in the kernels' shared C subset
 * (compat_opencl.h on the device, sdk/src/kernel_compat.hpp on the CPU): sampling a point
 * from uniform numbers, containment, the nearest point and the outward normal, per shape and
 * from the shape's values (each side reads them from its own storage: domain.cl from an
 * FlDomain's v[], the CPU from Domain's structs in shape_math.hpp, sampling.cpp and
 * domain.cpp). Meshes and unions keep their loops on each side (the data differs); the
 * per-triangle math they run is here.
 *
 * With FP_CONTRACT off and correctly rounded division and sqrt both backends agree to the bit
 * (Box-Muller's log and cos included: fl_logf and fl_sincos_2pi, not libm's). glm's order is
 * kept where the CPU used it: dot is (x x' + y y') + z z', normalize v * (1 / sqrt(dot(v,
 * v))). The samplers and containment tests are branch-free where the CPU's loops call them
 * per particle, so those loops still vectorise. */
#ifndef FLURRY_KERNELS_DOMAIN_H
#define FLURRY_KERNELS_DOMAIN_H

/* ---- Vectors ------------------------------------------------------------------------------ */

FL_INLINE float fl_dotv(float3 a, float3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
FL_INLINE float fl_lengthv(float3 a) {
  return sqrt(fl_dotv(a, a));
}
FL_INLINE float3 fl_crossv(float3 a, float3 b) { /* glm::cross */
  return make_float3(a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y);
}
FL_INLINE int fl_is_zero(float3 a) {
  return (a.x == 0.0f) & (a.y == 0.0f) & (a.z == 0.0f);
}
FL_INLINE float3 fl_normalize(float3 a) {
  return a * (1.0f / sqrt(fl_dotv(a, a)));
}
/* glm::clamp's rule, min(max(x, lo), hi). */
FL_INLINE float fl_clamp(float x, float lo, float hi) {
  return fl_minf(fl_maxf(x, lo), hi);
}
FL_INLINE float3 fl_clamp3(float3 x, float3 lo, float3 hi) {
  return make_float3(fl_clamp(x.x, lo.x, hi.x), fl_clamp(x.y, lo.y, hi.y),
                     fl_clamp(x.z, lo.z, hi.z));
}

/* Unit vector along v, or zero for a zero vector. Dividing by the largest component first
 * keeps huge and tiny (denormal) vectors from overflowing or underflowing in the dot. */
FL_INLINE float3 fl_unit_or_zero(float3 v) {
  const float m = fl_maxf(fl_maxf(fabs(v.x), fabs(v.y)), fabs(v.z));
  if (!(m > 0.0f)) return make_float3(0.0f, 0.0f, 0.0f);
  return fl_normalize(v / m);
}

/* Two unit vectors completing unit n to an orthonormal basis (Duff et al., JCGT 2017):
 * branch-free apart from the sign, and stable for every n. */
FL_INLINE void fl_basis(float3 n, float3* b1, float3* b2) {
  const float s = copysign(1.0f, n.z);
  const float a = -1.0f / (s + n.z);
  const float b = n.x * n.y * a;
  *b1 = make_float3(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
  *b2 = make_float3(b, s + n.y * n.y * a, -n.y);
}

FL_INLINE float3 fl_any_perpendicular(float3 n) {
  float3 b1, b2;
  fl_basis(n, &b1, &b2);
  return b1;
}

/* ---- Sampling from uniform numbers in [0, 1) ------------------------------------------------ */

/* sin(2 pi u) and cos(2 pi u) for u in [0, 1), |error| < 3e-7, with no libm or device builtin:
 * quadrant reduction and Cephes' minimax polynomials on [-pi/4, pi/4], the quadrant applied
 * with bit operations. */
FL_INLINE void fl_sincos_2pi(float u, float* s, float* c) {
  const float x = 4.0f * u;
  const int q = (int)(x + 0.5f); /* nearest quadrant, u >= 0 */
  const float r = (x - (float)q) * 1.57079632679489662f;
  const float r2 = r * r;
  const float sr =
      r + r * r2 * (-1.6666654611e-1f + r2 * (8.3321608736e-3f + r2 * -1.9515295891e-4f));
  const float cr =
      1.0f - 0.5f * r2 +
      r2 * r2 *
          (4.166664568298827e-2f + r2 * (-1.388731625493765e-3f + r2 * 2.443315711809948e-5f));
  const uint swap = 0u - (uint)(q & 1); /* odd quadrants swap sin and cos */
  const uint sb = as_uint(sr), cb = as_uint(cr);
  const uint sSign = (uint)(q & 2) << 30;
  const uint cSign = (uint)((q + 1) & 2) << 30;
  *s = as_float(((sb & ~swap) | (cb & swap)) ^ sSign);
  *c = as_float(((cb & ~swap) | (sb & swap)) ^ cSign);
}

/* ln(x) for a positive normal float x, with no libm or device builtin (Box-Muller's log, so
 * that a normal draw has the same bits everywhere): FreeBSD's e_logf.c (as musl's logf),
 * within 1 ulp (tests/test_random.cpp checks every input a uniform draw gives).
 * x = m·2^k with m in [sqrt(2)/2, sqrt(2)); ln(m) = 2·atanh(s), s = (m - 1)/(m + 1), by a
 * polynomial in s²; ln 2 in two parts so that k·ln 2 adds no rounding. */
FL_INLINE float fl_logf(float x) {
  uint ix = as_uint(x) + (0x3f800000u - 0x3f3504f3u);
  const int k = (int)(ix >> 23) - 0x7f;
  ix = (ix & 0x007fffffu) + 0x3f3504f3u;
  const float f = as_float(ix) - 1.0f;
  const float s = f / (2.0f + f);
  const float z = s * s, w = z * z;
  const float t1 = w * (0x1.999c26p-2f + w * 0x1.f13c4cp-3f);
  const float t2 = z * (0x1.555554p-1f + w * 0x1.23d3dcp-2f);
  const float hfsq = 0.5f * f * f;
  const float dk = (float)k;
  return s * (hfsq + (t2 + t1)) + dk * 0x1.2fefa2p-17f - hfsq + f + dk * 0x1.62e3p-1f;
}

/* Cube root of x >= 0 to about 1 ulp: an exponent-bits guess refined by Newton's method. */
FL_INLINE float fl_cbrt_nonneg(float x) {
  const uint i = as_uint(x);
  float y = as_float((uint)((float)i * (1.0f / 3.0f)) + 0x2a5137a0u);
  for (int k = 0; k < 4; ++k) y -= (y - x / (y * y)) * (1.0f / 3.0f);
  return x > 0.0f ? y : 0.0f;
}

/* Two independent standard normals from two uniforms in [0, 1) by Box-Muller, r cos and
 * r sin: its log and cos are the ones above, so both backends give the same bits. */
FL_INLINE void fl_normal_pair(float ua, float ub, float* n0, float* n1) {
  float s, c;
  fl_sincos_2pi(ub, &s, &c);
  const float r = sqrt(-2.0f * fl_logf(1.0f - ua));
  *n0 = r * c;
  *n1 = r * s;
}

/* One standard normal from two uniforms (Random::normal() calls it): the pair's first. */
FL_INLINE float fl_normal_from(float ua, float ub) {
  float n0, n1;
  fl_normal_pair(ua, ub, &n0, &n1);
  return n0;
}

/* A fuzzy value (flurry::Fuzzy) from its draws: uniform in center +- spread from one uniform,
 * or normal with standard deviation spread from two. */
FL_INLINE float fl_fuzzy_uniform(float center, float spread, float ua) {
  return center + spread * (2.0f * ua - 1.0f);
}
FL_INLINE float fl_fuzzy_normal(float center, float spread, float ua, float ub) {
  return center + spread * fl_normal_from(ua, ub);
}

/* Uniforms a domain of kind FL_DOMAIN_* draws per sample; a union's depend on its parts
 * (1 + the most any part draws). */
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
      return 4;
    default: /* point, plane (the point itself), union */
      return 0;
  }
}

FL_INLINE float3 fl_line_at(float3 a, float3 e, float u0) {
  return make_float3(a.x + e.x * u0, a.y + e.y * u0, a.z + e.z * u0);
}

/* Triangle a, a + e1, a + e2: su is how far the point lies from a towards the opposite edge;
 * the cross-section there is su long, so su's density grows linearly: su = sqrt(uniform). */
FL_INLINE float3 fl_triangle_at(float3 a, float3 e1, float3 e2, float u0, float u1) {
  const float su = sqrt(u0);
  const float s = su * (1.0f - u1), t = su * u1;
  return make_float3(a.x + e1.x * s + e2.x * t, a.y + e1.y * s + e2.y * t,
                     a.z + e1.z * s + e2.z * t);
}

FL_INLINE float3 fl_parallelogram_at(float3 a, float3 e1, float3 e2, float u0, float u1) {
  return make_float3(a.x + e1.x * u0 + e2.x * u1, a.y + e1.y * u0 + e2.y * u1,
                     a.z + e1.z * u0 + e2.z * u1);
}

/* The min undoes a rounding step past hi, so samples always pass the box's containment. */
FL_INLINE float3 fl_box_at(float3 lo, float3 hi, float u0, float u1, float u2) {
  const float3 e = hi - lo;
  return make_float3(fl_minf(lo.x + e.x * u0, hi.x), fl_minf(lo.y + e.y * u1, hi.y),
                     fl_minf(lo.z + e.z * u2, hi.z));
}

/* Disc (axis zero, ut 0) and cylinder: an annulus of radii ri..ro (its area grows with r^2)
 * around a + axis ut, in the plane of the unit vectors e1, e2. */
FL_INLINE float3 fl_annulus_at(float3 a, float3 axis, float3 e1, float3 e2, float ri, float ro,
                               float ut, float ur, float uphi) {
  const float ri2 = ri * ri, span = ro * ro - ri2;
  const float r = sqrt(ur * span + ri2);
  float s, c;
  fl_sincos_2pi(uphi, &s, &c);
  return make_float3(a.x + axis.x * ut + (e1.x * c + e2.x * s) * r,
                     a.y + axis.y * ut + (e1.y * c + e2.y * s) * r,
                     a.z + axis.z * ut + (e1.z * c + e2.z * s) * r);
}

/* Sphere: the volume inside radius r grows with r^3 (ri == ro: the surface); uniform
 * cos(theta) and phi give a uniform direction. */
FL_INLINE float3 fl_sphere_at(float3 c0, float ri, float ro, float u0, float u1, float u2) {
  const float ri3 = ri * ri * ri, span = ro * ro * ro - ri3;
  const float r = fl_cbrt_nonneg(u0 * span + ri3);
  const float cz = 1.0f - 2.0f * u1;
  const float sz = sqrt(fl_maxf(0.0f, 1.0f - cz * cz));
  float s, c;
  fl_sincos_2pi(u2, &s, &c);
  return make_float3(c0.x + sz * c * r, c0.y + sz * s * r, c0.z + cz * r);
}

/* A cone's point at t along the axis (0 at the apex), r from it, azimuth from uphi. */
FL_INLINE float3 fl_cone_point(float3 apex, float3 axis, float3 e1, float3 e2, float t, float r,
                               float uphi) {
  float s, c;
  fl_sincos_2pi(uphi, &s, &c);
  return make_float3(apex.x + axis.x * t + (e1.x * c + e2.x * s) * r,
                     apex.y + axis.y * t + (e1.y * c + e2.y * s) * r,
                     apex.z + axis.z * t + (e1.z * c + e2.z * s) * r);
}

/* Solid cone (ri < ro): the cross-section's area grows with t^2, the volume up to t with t^3. */
FL_INLINE float3 fl_cone_solid_at(float3 apex, float3 axis, float3 e1, float3 e2, float ri,
                                  float ro, float u0, float u1, float u2) {
  const float ri2 = ri * ri, span = ro * ro - ri2;
  const float t = fl_cbrt_nonneg(u0);
  return fl_cone_point(apex, axis, e1, e2, t, t * sqrt(u1 * span + ri2), u2);
}

/* The lateral surface alone (ri == ro): its circumference grows with t, its area with t^2. */
FL_INLINE float3 fl_cone_surface_at(float3 apex, float3 axis, float3 e1, float3 e2, float ro,
                                    float u0, float u2) {
  const float t = sqrt(u0);
  return fl_cone_point(apex, axis, e1, e2, t, t * ro, u2);
}

/* A blob's point: three normals from four uniforms (both of one Box-Muller pair, the first of
 * another), each an independent standard normal. */
FL_INLINE float3 fl_blob_at(float3 c, float sd, float u0, float u1, float u2, float u3) {
  float nx, ny;
  fl_normal_pair(u0, u1, &nx, &ny);
  return make_float3(c.x + sd * nx, c.y + sd * ny, c.z + sd * fl_normal_from(u2, u3));
}

/* ---- Crossing a planar piece's plane (Sink's Hit, Avoid) ----------------------------------- */

/* Whether the straight path p -> q crosses the plane through o with normal n (a side
 * includes the plane: d >= 0), and then where, *h. */
FL_INLINE int fl_path_crosses(float3 p, float3 q, float3 o, float3 n, float3* h) {
  const float d0 = fl_dotv(p - o, n), d1 = fl_dotv(q - o, n);
  if (!((d0 >= 0.0f) != (d1 >= 0.0f))) return 0;
  *h = p + (q - p) * (d0 / (d0 - d1));
  return 1;
}

/* ---- Containment (branch-free: the CPU's Sink and regions test whole blocks) --------------- */

FL_INLINE int fl_inside_plane(float3 point, float3 normal, float3 p) {
  return fl_dotv(p - point, normal) >= 0.0f;
}

FL_INLINE int fl_inside_box(float3 lo, float3 hi, float3 p) {
  return (p.x >= lo.x) & (p.x <= hi.x) & (p.y >= lo.y) & (p.y <= hi.y) & (p.z >= lo.z) &
         (p.z <= hi.z);
}

/* A shell ri..ro; a bare surface (ri == ro) has no inside. */
FL_INLINE int fl_inside_sphere(float3 c, float ro, float ri, float3 p) {
  const float3 r = p - c;
  const float r2 = fl_dotv(r, r);
  return (r2 <= ro * ro) & (r2 >= ri * ri) & (ri < ro);
}

/* Cylinder (cone 0) or cone (cone 1, the radii scaled by t) from origin (the apex) along axis
 * (to the base's centre). */
FL_INLINE int fl_inside_axial(float3 origin, float3 axis, float ro, float ri, int cone, float3 p) {
  const float len2 = fl_dotv(axis, axis);
  const float3 r = p - origin;
  const float t = fl_dotv(r, axis) / len2; /* position along the axis, 0..1 inside */
  const float3 radial = r - axis * t;
  const float q2 = fl_dotv(radial, radial);
  const float o = cone ? ro * t : ro, i = cone ? ri * t : ri;
  return (t >= 0.0f) & (t <= 1.0f) & (q2 <= o * o) & (q2 >= i * i) & (ri < ro);
}

/* A blob contains the ball of one standard deviation. */
FL_INLINE int fl_inside_blob(float3 c, float sd, float3 p) {
  const float3 r = p - c;
  return fl_dotv(r, r) <= sd * sd;
}

/* A mesh's inside is the parity of the crossings of a ray from p along this direction: skewed
 * so that it does not run along the axis-aligned edges and faces meshes are full of. */
FL_INLINE float3 fl_mesh_ray(void) {
  return fl_normalize(make_float3(1.0f, 0.1234567f, 0.0765432f));
}

/* Whether the ray from p along dir crosses triangle a b c (Moller-Trumbore). */
FL_INLINE int fl_ray_crosses(float3 dir, float3 a, float3 b, float3 c, float3 p) {
  const float3 e1 = b - a, e2 = c - a;
  const float3 h = fl_crossv(dir, e2);
  const float det = fl_dotv(e1, h);
  if (fabs(det) < 1e-12f) return 0;
  const float inv = 1.0f / det;
  const float3 s = p - a;
  const float u = fl_dotv(s, h) * inv;
  if (u < 0.0f || u > 1.0f) return 0;
  const float3 q = fl_crossv(s, e1);
  const float w = fl_dotv(dir, q) * inv;
  if (w < 0.0f || u + w > 1.0f) return 0;
  return fl_dotv(e2, q) * inv > 0.0f;
}

/* Outside a mesh's bounds lo..hi: no crossing count needed. */
FL_INLINE int fl_outside_bounds(float3 lo, float3 hi, float3 p) {
  return p.x < lo.x || p.y < lo.y || p.z < lo.z || p.x > hi.x || p.y > hi.y || p.z > hi.z;
}

/* ---- Nearest points and normals (Emitter::normalSpeed, Bounce off a domain, ...) ----------- */

FL_INLINE float3 fl_closest_segment(float3 a, float3 b, float3 p) {
  const float3 ab = b - a;
  const float len2 = fl_dotv(ab, ab);
  const float t = len2 > 0.0f ? fl_clampf(fl_dotv(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return a + ab * t;
}

/* Ericson, Real-Time Collision Detection, 5.1.5: classify p against the Voronoi regions of the
 * vertices and edges, otherwise project onto the face. */
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

/* c ? a : b, one component at a time (a choice of whole vectors is a copy through memory on
 * the CPU, which a vector loop cannot take). */
FL_INLINE float3 fl_choose3(int c, float3 a, float3 b) {
  return make_float3(c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z);
}

/* fl_closest_triangle with every case computed and the first that holds chosen: the same
 * point, bit for bit (tests/test_domain.cpp), without a branch, for a loop over many points
 * that vectorises (a chunk's crossings of a triangle). The cases not chosen may divide by
 * zero; their values are dropped. The tests are combined with & (not &&: GCC does not
 * evaluate a float comparison that && would skip, and the loop keeps a branch). */
FL_INLINE float3 fl_closest_triangle_chosen(float3 a, float3 b, float3 c, float3 p) {
  const float3 ab = b - a, ac = c - a, ap = p - a, bp = p - b, cp = p - c;
  const float d1 = fl_dotv(ab, ap), d2 = fl_dotv(ac, ap);
  const float d3 = fl_dotv(ab, bp), d4 = fl_dotv(ac, bp);
  const float d5 = fl_dotv(ab, cp), d6 = fl_dotv(ac, cp);
  const float vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  const float denom = 1.0f / (va + vb + vc);
  float3 q = a + ab * (vb * denom) + ac * (vc * denom);
  /* From the last case to the first, so that the first that holds is the one kept. */
  q = fl_choose3((va <= 0.0f) & ((d4 - d3) >= 0.0f) & ((d5 - d6) >= 0.0f),
                 b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), q);
  q = fl_choose3((vb <= 0.0f) & (d2 >= 0.0f) & (d6 <= 0.0f), a + ac * (d2 / (d2 - d6)), q);
  q = fl_choose3((d6 >= 0.0f) & (d5 <= d6), c, q);
  q = fl_choose3((vc <= 0.0f) & (d1 >= 0.0f) & (d3 <= 0.0f), a + ab * (d1 / (d1 - d3)), q);
  q = fl_choose3((d3 >= 0.0f) & (d4 <= d3), b, q);
  q = fl_choose3((d1 <= 0.0f) & (d2 <= 0.0f), a, q);
  return q;
}

/* The nearest point of a plane through `point` with unit normal n. */
FL_INLINE float3 fl_closest_plane(float3 point, float3 n, float3 p) {
  return p - n * fl_dotv(p - point, n);
}

/* p's projection's coordinates (s, t) on the parallelogram of origin a and edges u and w, in
 * its (possibly skewed) basis, from the normal equations of the 2x2 least-squares problem
 * (|u x w|^2 is their determinant without cancellation). */
FL_INLINE void fl_rectangle_coords(float3 a, float3 u, float3 w, float3 p, float* s, float* t) {
  const float3 r = p - a;
  const float uu = fl_dotv(u, u), uv = fl_dotv(u, w), vv = fl_dotv(w, w);
  const float ru = fl_dotv(r, u), rv = fl_dotv(r, w);
  const float3 c = fl_crossv(u, w);
  const float det = fl_dotv(c, c);
  *s = (vv * ru - uv * rv) / det;
  *t = (uu * rv - uv * ru) / det;
}
/* Parallelogram origin a, edges u and w. Inside: p's projection (fl_rectangle_coords).
 * Outside, clamping the coordinates separately is wrong for skewed edges: the nearest point of
 * a convex polygon to an outside point is on its boundary. */
FL_INLINE float3 fl_closest_rectangle(float3 a, float3 u, float3 w, float3 p) {
  float s, t;
  fl_rectangle_coords(a, u, w, p, &s, &t);
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

/* fl_closest_segment's point with its guard of a degenerate segment as a mask of bits: t's
 * bits are kept where len2 > 0 and are +0 where not, as the guard's 0. In a loop over points
 * the segment is the same for all, and GCC 12 vectorises no choice by a loop-invariant
 * comparison (its AVX-512 loop stays scalar); an AND with an invariant mask it takes. */
FL_INLINE float3 fl_closest_segment_masked(float3 a, float3 b, float3 p) {
  const float3 ab = b - a;
  const float len2 = fl_dotv(ab, ab);
  const uint keep = 0u - (uint)(len2 > 0.0f);
  const float t = as_float(as_uint(fl_clampf(fl_dotv(p - a, ab) / len2, 0.0f, 1.0f)) & keep);
  return a + ab * t;
}

/* fl_closest_rectangle with both cases computed and chosen component by component, as
 * fl_closest_triangle_chosen: the same point, bit for bit (tests/test_domain.cpp), for the
 * loops over a chunk's crossings of a rectangle. The nearest of the edges' points is taken as
 * the branching form takes it (the first of equals kept). */
FL_INLINE float3 fl_closest_rectangle_chosen(float3 a, float3 u, float3 w, float3 p) {
  float s, t;
  fl_rectangle_coords(a, u, w, p, &s, &t);
  const float3 b = a + u, cc = a + u + w, e = a + w;
  float3 best = fl_closest_segment_masked(a, b, p);
  float bestD2 = fl_dotv(p - best, p - best);
  const float3 q1 = fl_closest_segment_masked(b, cc, p);
  const float d1 = fl_dotv(p - q1, p - q1);
  const int n1 = d1 < bestD2;
  best = fl_choose3(n1, q1, best);
  bestD2 = n1 ? d1 : bestD2;
  const float3 q2 = fl_closest_segment_masked(cc, e, p);
  const float d2 = fl_dotv(p - q2, p - q2);
  const int n2 = d2 < bestD2;
  best = fl_choose3(n2, q2, best);
  bestD2 = n2 ? d2 : bestD2;
  const float3 q3 = fl_closest_segment_masked(e, a, p);
  const float d3 = fl_dotv(p - q3, p - q3);
  best = fl_choose3(d3 < bestD2, q3, best);
  return fl_choose3((s >= 0.0f) & (s <= 1.0f) & (t >= 0.0f) & (t <= 1.0f), a + u * s + w * t,
                    best);
}

/* Disc or ring ri..ro around `center` with unit normal n; `perp` is fl_any_perpendicular(n),
 * the direction taken on the axis of a ring, where every rim point is as near. */
FL_INLINE float3 fl_closest_disc(float3 center, float3 n, float3 perp, float ro, float ri,
                                 float3 p) {
  const float3 r = p - center;
  const float3 inPlane = r - n * fl_dotv(r, n);
  float3 dir = fl_unit_or_zero(inPlane);
  if (fl_is_zero(dir)) {
    if (ri == 0.0f) return center;
    dir = perp;
  }
  const float rho = fl_clampf(fl_dotv(inPlane, dir), ri, ro);
  return center + dir * rho;
}

/* Box: the face (axis * 2 + side) whose plane is nearest, by signed inside-distance; for an
 * outside point the most violated face. */
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

FL_INLINE float3 fl_closest_box(float3 lo, float3 hi, float3 p) {
  if (!fl_inside_box(lo, hi, p)) return fl_clamp3(p, lo, hi);
  const int face = fl_box_face(lo, hi, p);
  float c[3] = {p.x, p.y, p.z};
  const float side[3] = {(face & 1) ? hi.x : lo.x, (face & 1) ? hi.y : lo.y,
                         (face & 1) ? hi.z : lo.z};
  c[face / 2] = side[face / 2];
  return make_float3(c[0], c[1], c[2]);
}

/* Outward normal of a solid at its nearest boundary point c. Outside the solid (by more than
 * rounding) it is the direction from c to p, which is the face normal on a face and the
 * distance field's gradient at an edge or corner; inside, and on the surface, it is the
 * nearest face's normal. */
FL_INLINE float3 fl_solid_normal(int inside, float3 p, float3 c, float3 face, float scale) {
  if (!inside && fl_lengthv(p - c) > 1e-5f * scale) return fl_unit_or_zero(p - c);
  return face;
}

FL_INLINE float3 fl_box_normal(float3 lo, float3 hi, float3 p) {
  const int face = fl_box_face(lo, hi, p);
  float n[3] = {0.0f, 0.0f, 0.0f};
  n[face / 2] = (face & 1) ? 1.0f : -1.0f;
  return fl_solid_normal(fl_inside_box(lo, hi, p), p, fl_clamp3(p, lo, hi),
                         make_float3(n[0], n[1], n[2]), fl_lengthv(hi - lo));
}

/* Ball of `outer` hollowed to `inner` (0: solid; inner == outer: the surface alone): the
 * nearest point, and the outward normal there in *n. */
FL_INLINE float3 fl_closest_ball(float3 center, float outer, float inner, float3 p, float3* n) {
  const float3 r = p - center;
  float3 dir = fl_unit_or_zero(r);
  if (fl_is_zero(dir)) dir = make_float3(1.0f, 0.0f, 0.0f); /* at the centre: any direction */
  const int toInner = inner > 0.0f && inner < outer && fl_lengthv(r) < 0.5f * (inner + outer);
  *n = toInner ? -dir : dir;
  return center + dir * (toInner ? inner : outer);
}

FL_INLINE float3 fl_point_normal(float3 a, float3 p) {
  const float3 n = fl_unit_or_zero(p - a);
  return fl_is_zero(n) ? make_float3(0.0f, 1.0f, 0.0f) : n;
}

FL_INLINE float3 fl_line_normal(float3 a, float3 b, float3 p) {
  const float3 n = fl_unit_or_zero(p - fl_closest_segment(a, b, p));
  return fl_is_zero(n) ? fl_any_perpendicular(fl_normalize(b - a)) : n;
}

/* Cylinders and cones are surfaces of revolution: the nearest point lies in the half-plane
 * through the axis and p, so the problem reduces to 2-D coordinates (a along the axis, rho
 * away from it) and the shape to a few boundary segments, each with its outward normal. */
typedef struct FlDomAxial {
  float3 origin, w, e; /* w: unit axis; e: unit radial direction towards p */
  float length;        /* of the axis */
  float a, rho;        /* p's coordinates */
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
  if (fl_is_zero(f.e)) f.e = fl_any_perpendicular(f.w); /* on the axis: any azimuth will do */
  f.rho = fl_dotv(radial, f.e);
  return f;
}

/* The nearest boundary point (a, rho) and its segment's outward normal (na, nrho). */
typedef struct FlDomHit2 {
  float a, rho, na, nrho, dist2;
} FlDomHit2;

FL_INLINE void fl_segment2(const FlDomAxial* f, float a0, float r0, float a1, float r1, float na,
                           float nr, FlDomHit2* best) {
  const float da = a1 - a0, dr = r1 - r0;
  const float len2 = da * da + dr * dr;
  float t = len2 > 0.0f ? ((f->a - a0) * da + (f->rho - r0) * dr) / len2 : 0.0f;
  t = fl_clampf(t, 0.0f, 1.0f);
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

/* A solid or a thick shell has caps; the curved surface alone (ri == ro) has none. */
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

FL_INLINE float3 fl_closest_axial(float3 origin, float3 axis, float ro, float ri, int cone,
                                  float3 p) {
  const FlDomAxial f = fl_axial(origin, axis, p);
  const FlDomHit2 h = fl_nearest_axial(&f, cone, ro, ri);
  return f.origin + f.w * h.a + f.e * h.rho;
}

FL_INLINE float3 fl_axial_normal(float3 origin, float3 axis, float ro, float ri, int cone,
                                 float3 p) {
  const FlDomAxial f = fl_axial(origin, axis, p);
  const FlDomHit2 h = fl_nearest_axial(&f, cone, ro, ri);
  const float3 face = f.w * h.na + f.e * h.nrho;
  if (ri == ro) return face; /* a bare surface: its outward side */
  return fl_solid_normal(fl_inside_axial(origin, axis, ro, ri, cone, p), p,
                         f.origin + f.w * h.a + f.e * h.rho, face, f.length + ro);
}

#endif /* FLURRY_KERNELS_DOMAIN_H */
