/* Domains on the device: reading an FlDomain's v[] (or a mesh's or union's table) and
 * dispatching on its kind to the shapes' math in domain.h, which the CPU backend runs too. */

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

/* A point of a domain of a simple kind from its uniforms u[0 .. fl_draw_count(kind)): the
 * CPU's formulas (sampling.cpp sampleBatch with a batch of one), operation for operation. */
FL_INLINE float3 fl_sample_u(__global const float* v, uint kind, const float* u) {
  const float3 a = fl_v3(v);
  switch (kind) {
    case FL_DOMAIN_LINE:
      return fl_line_at(a, fl_v3(v + 3) - a, u[0]);
    case FL_DOMAIN_TRIANGLE:
      return fl_triangle_at(a, fl_v3(v + 3) - a, fl_v3(v + 6) - a, u[0], u[1]);
    case FL_DOMAIN_RECTANGLE:
      return fl_parallelogram_at(a, fl_v3(v + 3), fl_v3(v + 6), u[0], u[1]);
    case FL_DOMAIN_BOX:
      return fl_box_at(a, fl_v3(v + 3), u[0], u[1], u[2]);
    case FL_DOMAIN_DISC: /* center e1 e2 outer inner */
      return fl_annulus_at(a, make_float3(0.0f, 0.0f, 0.0f), fl_v3(v + 3), fl_v3(v + 6), v[10],
                           v[9], 0.0f, u[0], u[1]);
    case FL_DOMAIN_CYLINDER: /* p0 axis e1 e2 outer inner */
      return fl_annulus_at(a, fl_v3(v + 3), fl_v3(v + 6), fl_v3(v + 9), v[13], v[12], u[0], u[1],
                           u[2]);
    case FL_DOMAIN_SPHERE:
      return fl_sphere_at(a, v[4], v[3], u[0], u[1], u[2]);
    case FL_DOMAIN_CONE: /* apex axis e1 e2 outer inner */
      if (v[13] < v[12])
        return fl_cone_solid_at(a, fl_v3(v + 3), fl_v3(v + 6), fl_v3(v + 9), v[13], v[12], u[0],
                                u[1], u[2]);
      return fl_cone_surface_at(a, fl_v3(v + 3), fl_v3(v + 6), fl_v3(v + 9), v[12], u[0], u[2]);
    case FL_DOMAIN_BLOB:
      return fl_blob_at(a, v[3], u[0], u[1], u[2], u[3]);
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

/* The triangle of a mesh a uniform u picks, in proportion to area: its record (vertices a b
 * c, then its unit normal). */
FL_INLINE __global const float* fl_mesh_triangle(__global const float* v, float u,
                                                 __global const float* shapes) {
  __global const float* m = shapes + fl_word(v);
  return m + fl_pick(m, fl_word(v + 1), FL_MESH_STRIDE, u) * FL_MESH_STRIDE + 2;
}

/* A point of a mesh from u[0..2]: a triangle by area, then a point on it. */
FL_INLINE float3 fl_sample_mesh(__global const float* v, const float* u,
                                __global const float* shapes) {
  __global const float* t = fl_mesh_triangle(v, u[0], shapes);
  const float3 a = fl_v3(t);
  return fl_triangle_at(a, fl_v3(t + 3) - a, fl_v3(t + 6) - a, u[1], u[2]);
}

/* The leaf a union's sample from draws u picks: a part by measure from the next uniform at
 * each level of nesting. Leaves the leaf's v in *v and its kind in *kind, and returns where
 * the leaf's own draws start in u. */
FL_INLINE uint fl_union_leaf(__global const float** v, uint* kind, const float* u,
                             __global const float* shapes) {
  uint next = 0;
  while (*kind == FL_DOMAIN_UNION) {
    __global const float* parts = shapes + fl_word(*v);
    const uint k = fl_pick(parts, fl_word(*v + 1), FL_UNION_STRIDE, u[next++]);
    __global const FlDomain* part = (__global const FlDomain*)(parts + k * FL_UNION_STRIDE + 2);
    *v = part->v;
    *kind = part->kind;
  }
  return next;
}

/* A point of a union: its draws first (a fixed count), then a part by measure from the next
 * uniform at each level of nesting, and the part's own draws after that. */
FL_NOINLINE float3 fl_sample_union(__global const float* v, FlRandom* rng,
                                   __global const float* shapes) {
  float u[FL_MAX_DOMAIN_DRAWS];
  const uint n = fl_word(v + 2);
  for (uint k = 0; k < n && k < FL_MAX_DOMAIN_DRAWS; ++k) u[k] = fl_uniform(rng);
  uint kind = FL_DOMAIN_UNION;
  const uint next = fl_union_leaf(&v, &kind, u, shapes);
  if (kind == FL_DOMAIN_MESH) return fl_sample_mesh(v, u + next, shapes);
  return fl_sample_u(v, kind, u + next);
}

/* The uniforms a sample of the domain takes (sampling.cpp drawCount): a union's are in its
 * table. */
FL_INLINE uint fl_domain_draws(__global const FlDomain* d, uint kind) {
  return kind == FL_DOMAIN_UNION ? fl_word(d->v + 2) : fl_draw_count(kind);
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

/* Whether (x, y, z) is in the domain (kind a literal: the tests fold away). */
FL_INLINE int fl_inside(__global const float* v, uint kind, float x, float y, float z) {
  const float3 p = make_float3(x, y, z), a = fl_v3(v);
  switch (kind) {
    case FL_DOMAIN_PLANE:
      return fl_inside_plane(a, fl_v3(v + 3), p);
    case FL_DOMAIN_BOX:
      return fl_inside_box(a, fl_v3(v + 3), p);
    case FL_DOMAIN_SPHERE:
      return fl_inside_sphere(a, v[3], v[4], p);
    case FL_DOMAIN_CYLINDER:
    case FL_DOMAIN_CONE:
      return fl_inside_axial(a, fl_v3(v + 3), v[12], v[13], kind == FL_DOMAIN_CONE, p);
    case FL_DOMAIN_BLOB:
      return fl_inside_blob(a, v[3], p);
    default: /* points, segments and plane pieces have no inside */
      return 0;
  }
}

/* ---- Nearest points and normals (Emitter::normalSpeed, surfaces). Packed extras: triangle
 * and rectangle normal in v[9..11], disc normal in v[11..13] (codegen.cpp packDomain). */

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
  float3 n;
  switch (kind) {
    case FL_DOMAIN_LINE:
      return fl_closest_segment(a, fl_v3(v + 3), p);
    case FL_DOMAIN_TRIANGLE:
      return fl_closest_triangle(a, fl_v3(v + 3), fl_v3(v + 6), p);
    case FL_DOMAIN_PLANE:
      return fl_closest_plane(a, fl_v3(v + 3), p);
    case FL_DOMAIN_RECTANGLE:
      return fl_closest_rectangle(a, fl_v3(v + 3), fl_v3(v + 6), p);
    case FL_DOMAIN_DISC: /* e1 = fl_any_perpendicular(normal), packed */
      return fl_closest_disc(a, fl_v3(v + 11), fl_v3(v + 3), v[9], v[10], p);
    case FL_DOMAIN_BOX:
      return fl_closest_box(a, fl_v3(v + 3), p);
    case FL_DOMAIN_SPHERE:
      return fl_closest_ball(a, v[3], v[4], p, &n);
    case FL_DOMAIN_BLOB:
      return fl_closest_ball(a, v[3], 0.0f, p, &n);
    case FL_DOMAIN_CYLINDER:
    case FL_DOMAIN_CONE:
      return fl_closest_axial(a, fl_v3(v + 3), v[12], v[13], kind == FL_DOMAIN_CONE, p);
    case FL_DOMAIN_MESH:
      fl_mesh_nearest(v, p, shapes, &n);
      return n;
    default: /* point */
      return a;
  }
}

/* Domain::normal for every kind but the union. */
FL_INLINE float3 fl_normal_leaf(__global const float* v, uint kind, float3 p,
                                __global const float* shapes) {
  const float3 a = fl_v3(v);
  float3 n;
  switch (kind) {
    case FL_DOMAIN_POINT:
      return fl_point_normal(a, p);
    case FL_DOMAIN_LINE:
      return fl_line_normal(a, fl_v3(v + 3), p);
    case FL_DOMAIN_TRIANGLE:
    case FL_DOMAIN_RECTANGLE:
      return fl_v3(v + 9);
    case FL_DOMAIN_PLANE:
      return fl_v3(v + 3);
    case FL_DOMAIN_DISC:
      return fl_v3(v + 11);
    case FL_DOMAIN_BOX:
      return fl_box_normal(a, fl_v3(v + 3), p);
    case FL_DOMAIN_SPHERE:
      fl_closest_ball(a, v[3], v[4], p, &n);
      return n;
    case FL_DOMAIN_BLOB:
      fl_closest_ball(a, v[3], 0.0f, p, &n);
      return n;
    case FL_DOMAIN_CYLINDER:
    case FL_DOMAIN_CONE:
      return fl_axial_normal(a, fl_v3(v + 3), v[12], v[13], kind == FL_DOMAIN_CONE, p);
    case FL_DOMAIN_MESH: {
      const uint k = fl_mesh_nearest(v, p, shapes, &n);
      return fl_v3(shapes + fl_word(v) + k * FL_MESH_STRIDE + 11);
    }
    default:
      return make_float3(0.0f, 1.0f, 0.0f);
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

/* The normal where a sample of the domain from draws u landed, at p (Emitter::normalSpeed):
 * a mesh's is that of the triangle the sample picked, and a union's that of the leaf it
 * picked, found again from the same draws (sampling.cpp sampledNormals): a search as the
 * sample's, not a nearest part's over all of them, and a point on an edge two faces share
 * keeps its own face's normal. */
FL_NOINLINE float3 fl_sampled_normal(__global const FlDomain* d, uint kind, const float* u,
                                     float3 p, __global const float* shapes) {
  __global const float* v = d->v;
  const uint next = fl_union_leaf(&v, &kind, u, shapes);
  if (kind == FL_DOMAIN_MESH) return fl_v3(fl_mesh_triangle(v, u[next], shapes) + 9);
  return fl_normal_leaf(v, kind, p, shapes);
}

/* ---- Meshes and unions as actions' regions (containment, closest points); `shapes` is the
 * act kernel's `extra`. */

/* A mesh: nothing outside its bounds; else the parity of a ray's crossings (domain.h). */
FL_INLINE int fl_inside_mesh(__global const float* v, float x, float y, float z,
                             __global const float* shapes) {
  const float3 p = make_float3(x, y, z);
  if (fl_outside_bounds(fl_v3(v + 2), fl_v3(v + 5), p)) return 0;
  const float3 dir = fl_mesh_ray();
  __global const float* m = shapes + fl_word(v);
  const uint n = fl_word(v + 1);
  uint crossings = 0;
  for (uint k = 0; k < n; ++k) {
    __global const float* t = m + k * FL_MESH_STRIDE + 2;
    crossings += (uint)fl_ray_crosses(dir, fl_v3(t), fl_v3(t + 3), fl_v3(t + 6), p);
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
