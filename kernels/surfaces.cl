/* Deflectors, absorbers, blockers, 2-D constraints and the actions that read neighbours
 * (sdk/src/opencl/actions_surfaces.cpp generates their calls and packs their constants).
 * Each follows sdk/src/cpu/kernels.hpp and actions_more.hpp operation by operation: float3
 * arithmetic is per component (FP_CONTRACT is off) and dot products add x, y, z in glm's
 * order, so the results agree with the CPU's to the bit. */

/* ---- helpers ----------------------------------------------------------------------------
 * Closest points, normals, containment, dot products and clamps are domain.cl's
 * (fl_closest_any, fl_normal_any, fl_inside_any, fl_dotv, fl_clamp), which follow
 * domain.cpp operation by operation. A mesh's or union's data is in `shapes`, the act
 * kernel's `extra` (actions_surfaces.cpp packs it there). */

FL_INLINE int fl_surf_planar(uint kind) {
  return kind == FL_DOMAIN_PLANE || kind == FL_DOMAIN_RECTANGLE || kind == FL_DOMAIN_DISC ||
         kind == FL_DOMAIN_TRIANGLE;
}

/* Domain::distance. */
FL_INLINE float fl_surf_distance(__global const FlActionParams* a, uint kind, float3 p,
                                 __global const float* shapes) {
  return fl_lengthv(p - fl_closest_any(a->domain.v, kind, p, shapes));
}

/* ---- Bounce ------------------------------------------------------------------------------ */

/* How the deflector reflects (kernels/deflect.h). */
FL_INLINE FlReflect fl_reflect_of(__global const FlActionParams* a) {
  __global const FlBounceParams* b = &a->own.bounce;
  FlReflect r;
  r.restitution = b->restitution;
  r.keep = b->keep;
  r.cutoff2 = b->cutoff2;
  return r;
}

/* A two-sided planar deflector (kernels/deflect.h, as on the CPU). Every parameter is read
 * before the test: a CPU driver that runs work-items as vector lanes then reads each once,
 * not per vector under the test's mask (a gather). */
FL_INLINE void fl_bounce_planar(__global const FlActionParams* a, int piece, float dt, float* px,
                                float* py, float* pz, float* vxs, float* vys, float* vzs) {
  const FlBounceParams b = a->own.bounce;
  const FlReflect rf = fl_reflect_of(a);
  const float Px = b.point.x, Py = b.point.y, Pz = b.point.z;
  const float Nx = b.normal.x, Ny = b.normal.y, Nz = b.normal.z;
  float side, tau, hx, hy, hz;
  const int reaches = fl_planar_hit(*px, *py, *pz, *vxs, *vys, *vzs, dt, Px, Py, Pz, Nx, Ny, Nz,
                                    &side, &tau, &hx, &hy, &hz);
  if (!(reaches && fl_on_piece(&b, piece, hx, hy, hz))) return;
  fl_planar_bounce(rf, 1, side, tau, hx, hy, hz, dt, Px, Py, Pz, Nx, Ny, Nz, px, py, pz, vxs, vys,
                   vzs);
}

/* The same deflector when the following Move integrates with the acceleration (ax, ay, az)
 * taken as constant over the step (kernels/deflect.h, as on the CPU). */
FL_INLINE void fl_bounce_planar_accel(__global const FlActionParams* a, int piece, float dt,
                                      float ax, float ay, float az, float* px, float* py, float* pz,
                                      float* vxs, float* vys, float* vzs) {
  const FlBounceParams b = a->own.bounce; /* read before the test, as above */
  const FlReflect rf = fl_reflect_of(a);
  const float Px = b.point.x, Py = b.point.y, Pz = b.point.z;
  const float Nx = b.normal.x, Ny = b.normal.y, Nz = b.normal.z;
  float side, tau, hx, hy, hz;
  const int hit = fl_planar_accel_hit(*px, *py, *pz, *vxs, *vys, *vzs, ax, ay, az, dt, Px, Py, Pz,
                                      Nx, Ny, Nz, &side, &tau, &hx, &hy, &hz) &
                  fl_on_piece(&b, piece, hx, hy, hz);
  if (!hit) return;
  fl_planar_accel_bounce(rf, side, tau, hx, hy, hz, dt, ax, ay, az, Px, Py, Pz, Nx, Ny, Nz, px, py,
                         pz, vxs, vys, vzs);
}

/* A sphere deflecting from outside (inside == 0) or keeping particles in: kernels/deflect.h,
 * as on the CPU. */
FL_INLINE void fl_bounce_sphere(__global const FlActionParams* a, int inside, float dt, float* px,
                                float* py, float* pz, float* vxs, float* vys, float* vzs) {
  const FlReflect rf = fl_reflect_of(a);
  const FlXyz C = a->own.bounce.point;
  const struct FlBounceSphere s = a->own.bounce.piece.sphere;
  fl_bounce_sphere_once(rf, C.x, C.y, C.z, s.radius, s.radius2, s.invRadius, s.reach, inside, dt,
                        px, py, pz, vxs, vys, vzs);
  if (inside)
    fl_bounce_sphere_again(rf, C.x, C.y, C.z, s.radius, s.radius2, dt, px, py, pz, vxs, vys, vzs);
}

/* A box keeping particles in (inside == 1) or deflecting them from outside: kernels/deflect.h.
 * The box is a->domain.v: min, max. */
FL_INLINE void fl_bounce_box(__global const FlActionParams* a, int inside, float dt, float* px,
                             float* py, float* pz, float* vxs, float* vys, float* vzs) {
  __global const float* box = a->domain.v;
  const float lo[3] = {box[0], box[1], box[2]}, hi[3] = {box[3], box[4], box[5]};
  if (inside)
    fl_bounce_box_inside(fl_reflect_of(a), lo, hi, dt, px, py, pz, vxs, vys, vzs);
  else
    fl_bounce_box_outside(fl_reflect_of(a), lo, hi, dt, px, py, pz, vxs, vys, vzs);
}

/* A collision event (Group::recordCollisions; cpu/collisions.hpp logCollisions, which finds
 * the same): Bounce `action` (solid 0 a planar piece, 1 a sphere, 2 a box) changed the velocity
 * of a live particle that had position p and velocity v before it, bouncing it with the
 * acceleration acc (zero off the curve). Appended to `hits`: hits[0] counts every event, the
 * first `room` are written, 16 words each (the key: particle index, then sub-step << 16 |
 * action; position, velocity, normal, id, the time's bits); the host sorts them by key. */
FL_INLINE void fl_log_collision(__global const FlActionParams* a, int solid, int inside, float px,
                                float py, float pz, float vx, float vy, float vz, float ax,
                                float ay, float az, float dt, fl_real start, uint i, uint sub,
                                uint action, uint id, __global uint* hits, uint room) {
  float hx, hy, hz, nx, ny, nz, tau;
  if (solid == 0) {
    float side;
    const FlXyz P = a->own.bounce.point, N = a->own.bounce.normal;
    const float Nx = N.x, Ny = N.y, Nz = N.z;
    fl_planar_accel_hit(px, py, pz, vx, vy, vz, ax, ay, az, dt, P.x, P.y, P.z, Nx, Ny, Nz, &side,
                        &tau, &hx, &hy, &hz);
    nx = Nx * side;
    ny = Ny * side;
    nz = Nz * side;
  } else {
    if (solid == 1) {
      const FlXyz C = a->own.bounce.point;
      tau = fl_sphere_hit(px, py, pz, vx, vy, vz, C.x, C.y, C.z, a->own.bounce.piece.sphere.radius,
                          inside, dt, &nx, &ny, &nz);
    } else {
      __global const float* box = a->domain.v;
      const float p[3] = {px, py, pz}, v[3] = {vx, vy, vz};
      const float lo[3] = {box[0], box[1], box[2]}, hi[3] = {box[3], box[4], box[5]};
      float n[3];
      tau = fl_box_hit(p, v, lo, hi, inside, dt, n);
      nx = n[0];
      ny = n[1];
      nz = n[2];
    }
    hx = px + vx * tau;
    hy = py + vy * tau;
    hz = pz + vz * tau;
    if (inside) { /* towards where the particle came from */
      nx = -nx;
      ny = -ny;
      nz = -nz;
    }
  }
  const float ux = vx + ax * tau, uy = vy + ay * tau, uz = vz + az * tau;
  const fl_real time = start + (fl_real)tau;
  /* A particle left NaN or infinite by the list is killed by the step, not reported. */
  const float sum = hx + hy + hz + ux + uy + uz + (float)time;
  if (!isfinite(sum)) return;
  const uint k = atomic_inc(hits);
  if (k >= room) return;
  __global uint* e = hits + 16u + 16u * k;
  e[0] = i;
  e[1] = (sub << 16) | (action & 0xFFFFu);
  e[2] = as_uint(hx);
  e[3] = as_uint(hy);
  e[4] = as_uint(hz);
  e[5] = as_uint(ux);
  e[6] = as_uint(uy);
  e[7] = as_uint(uz);
  e[8] = as_uint(nx);
  e[9] = as_uint(ny);
  e[10] = as_uint(nz);
  e[11] = id;
#ifdef FL_FP64
  const ulong tb = as_ulong(time);
  e[12] = (uint)tb;
  e[13] = (uint)(tb >> 32);
#else
  e[12] = as_uint(time);
  e[13] = 0u;
#endif
}

/* After a Move by an integrator other than semi-implicit Euler: a particle that its curved
 * step left on the wrong side of the deflector, compared with where it began the step
 * (sx, sy, sz), is put back on its side and reflected (fused_pass.cpp guard). The surface is
 * a->domain (packSurfaceAction); a segment's wall is its FlBounceParams plane. */
FL_INLINE void fl_bounce_guard(__global const FlActionParams* a, uint kind, int inside, float sx,
                               float sy, float sz, float* px, float* py, float* pz, float* vx,
                               float* vy, float* vz, __global const float* shapes) {
  __global const float* d = a->domain.v;
  const float3 p0 = (float3)(sx, sy, sz), p1 = (float3)(*px, *py, *pz);
  const int seg = kind == FL_DOMAIN_LINE;
  float3 nrm, back;
  if (fl_surf_planar(kind) || seg) {
    const FlXyz wallN = a->own.bounce.normal, wallP = a->own.bounce.point;
    nrm = seg ? (float3)(wallN.x, wallN.y, wallN.z) : fl_normal_leaf(d, kind, p0, shapes);
    const float3 o = seg ? (float3)(wallP.x, wallP.y, wallP.z) : fl_closest(d, kind, p0, shapes);
    float3 hit;
    if (!fl_guard_planar(p0, p1, o, &nrm, &hit, &back)) return;
    if (!seg && !fl_guard_on_piece(fl_surf_distance(a, kind, hit, shapes), hit)) return;
  } else {
    if (!fl_guard_crossed(fl_inside(d, kind, p0.x, p0.y, p0.z), fl_inside(d, kind, p1.x, p1.y, p1.z),
                          inside))
      return;
    const float3 c = fl_closest(d, kind, p1, shapes);
    nrm = fl_normal_leaf(d, kind, c, shapes);
    back = fl_guard_solid_back(c, inside, &nrm);
  }
  const float3 v = fl_guard_reflect((float3)(*vx, *vy, *vz), nrm, a->own.bounce.restitution);
  *px = back.x;
  *py = back.y;
  *pz = back.z;
  *vx = v.x;
  *vy = v.y;
  *vz = v.z;
}

/* ---- Sink, SinkVelocity, Block ----------------------------------------------------------- */

/* Inside or Outside (absorb.h). */
FL_INLINE void fl_sink(__global const FlActionParams* a, uint kind, int killInside, float x,
                       float y, float z, uint code, uint* dead, __global const float* shapes) {
  *dead = fl_dead_sink(fl_inside_any(a->domain.v, kind, x, y, z, shapes), killInside, code, *dead);
}

/* Enter or Leave in the coming Move (absorb.h). */
FL_INLINE void fl_sink_motion(__global const FlActionParams* a, uint kind, int enter, float dt,
                              float x, float y, float z, float vx, float vy, float vz, uint code,
                              uint* dead, __global const float* shapes) {
  const int now = fl_inside_any(a->domain.v, kind, x, y, z, shapes);
  const int next = fl_inside_any(a->domain.v, kind, x + vx * dt, y + vy * dt, z + vz * dt, shapes);
  *dead = fl_dead_sink_motion(now, next, enter, code, *dead);
}

/* Hit: the coming Move crosses the plane piece (actions_more.hpp apply(Sink)). */
FL_INLINE void fl_sink_hit(__global const FlActionParams* a, uint kind, float dt, float x, float y,
                           float z, float vx, float vy, float vz, uint code, uint* dead,
                           __global const float* shapes) {
  __global const float* d = a->domain.v;
  const float3 p = (float3)(x, y, z), v = (float3)(vx, vy, vz);
  float3 h;
  if (!fl_path_crosses(p, p + v * dt, fl_closest(d, kind, p, shapes),
                       fl_normal_leaf(d, kind, p, shapes), &h))
    return;
  *dead = fl_dead_sink_hit(fl_surf_distance(a, kind, h, shapes), h, code, *dead);
}

/* The particles this absorber just took survive if they pass it (absorb.h). */
FL_INLINE void fl_sink_pass(__global const FlActionParams* a, uint id, uint code, uint* dead,
                            uint seedLo, uint seedHi, uint key) {
  *dead = fl_dead_after_pass(*dead, code, id, key, seedLo, seedHi, a->own.sink.passThrough);
}

/* Hides the particles inside the region (absorb.h); the list's first blocker has set vis to 1
 * before. */
FL_INLINE void fl_block(__global const FlActionParams* a, uint kind, float x, float y, float z,
                        uint* vis, __global const float* shapes) {
  *vis = fl_visible_after_block(fl_inside_any(a->domain.v, kind, x, y, z, shapes), *vis);
}

/* ---- Avoid (Constrain2D is forces.h's) ------------------------------------------------------------------ */

/* actions_more.hpp apply(Avoid). */
FL_INLINE void fl_avoid(__global const FlActionParams* a, uint kind, float dt, float x, float y,
                        float z, float* vx, float* vy, float* vz, __global const float* shapes) {
  __global const float* d = a->domain.v;
  const int planar = fl_surf_planar(kind);
  const float3 p = (float3)(x, y, z), v = (float3)(*vx, *vy, *vz);
  const float3 ahead = p + v * a->own.avoid.lookAhead;
  int threat;
  if (planar) {
    float3 h;
    threat = fl_path_crosses(p, ahead, fl_closest_any(d, kind, p, shapes),
                             fl_normal_any(d, kind, p, shapes), &h) &&
             fl_surf_distance(a, kind, h, shapes) < 1e-4f * (1.0f + fl_lengthv(p));
  } else {
    threat = !fl_inside_any(d, kind, p.x, p.y, p.z, shapes) &&
             fl_inside_any(d, kind, ahead.x, ahead.y, ahead.z, shapes);
  }
  if (!threat) return;
  const float dist = fl_surf_distance(a, kind, p, shapes);
  float3 away = fl_normal_any(d, kind, p, shapes);
  if (planar && fl_dotv(p - fl_closest_any(d, kind, p, shapes), away) < 0.0f) away = -away;
  fl_add_scaled(away.x, away.y, away.z, fl_avoid_step(a->own.avoid, dist, dt), vx, vy, vz);
}

/* ---- Neighbours: the particles as they were at the start of the step (FL_SNAP) ----------- */

/* forces.h fl_soft_pull towards d, added to acc. */
FL_INLINE void fl_add_soft_pull(__global const FlActionParams* a, float3 d, float3* acc) {
  float x, y, z;
  fl_pull(a->own.pull, d.x, d.y, d.z, &x, &y, &z);
  *acc += (float3)(x, y, z);
}

/* Gravitate's acceleration at p: towards every other particle (integrate.hpp accumulate). */
FL_INLINE float3 fl_gravitate_acc(__global const FlActionParams* a, __global const float* snap,
                                  uint snapStride, uint snapN, uint self, float3 p) {
  float3 acc = (float3)(0.0f);
  for (uint j = 0; j < snapN; ++j) {
    if (j == self) continue;
    const float3 q = (float3)(FL_SNAP(0, 0, j), FL_SNAP(0, 1, j), FL_SNAP(0, 2, j));
    fl_add_soft_pull(a, q - p, &acc);
  }
  return acc;
}

/* Follow's acceleration at p: towards the next particle by index; the last one leads. */
FL_INLINE float3 fl_follow_acc(__global const FlActionParams* a, __global const float* snap,
                               uint snapStride, uint snapN, uint self, float3 p) {
  float3 acc = (float3)(0.0f);
  const uint next = self + 1u;
  if (next >= snapN) return acc;
  const float3 q = (float3)(FL_SNAP(0, 0, next), FL_SNAP(0, 1, next), FL_SNAP(0, 2, next));
  fl_add_soft_pull(a, q - p, &acc);
  return acc;
}

/* apply(Gravitate) and apply(Follow): v += acc dt. */
FL_INLINE void fl_add_accel(float3 acc, float dt, float* vx, float* vy, float* vz) {
  const float3 r = (float3)(*vx, *vy, *vz) + acc * dt;
  *vx = r.x;
  *vy = r.y;
  *vz = r.z;
}

/* actions_more.hpp matchMean: towards the mean of the neighbours' field (snapshot attribute
 * `field`: 1 velocity, 2 angular velocity) within maxR; a dt other than the packed one
 * (sub-steps) computes its own approach. */
FL_INLINE void fl_match_toward_mean(__global const FlActionParams* a, __global const float* snap,
                                    uint snapStride, uint snapN, uint self, uint field, float dt,
                                    float px, float py, float pz, float* ox, float* oy, float* oz) {
  const float k = fl_match_k(a->own.match, dt);
  fl_match_mean(&FL_SNAP(0, 0, 0), &FL_SNAP(0, 1, 0), &FL_SNAP(0, 2, 0), &FL_SNAP(field, 0, 0),
                &FL_SNAP(field, 1, 0), &FL_SNAP(field, 2, 0), snapN, self, a->own.match.maxRadius2, px, py, pz, k,
                ox, oy, oz);
}
