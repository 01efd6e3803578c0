/* The core actions (Move, KillOld, ...); forces.cl and surfaces.cl hold the other families.
 * Each function is called in list order by the fused act kernel that the backend generates
 * for each action list (particles live in registers for the whole list) and follows
 * sdk/src/cpu/kernels.hpp operation by operation.
 *
 * Adding an action: a function in its family's .cl file, and a case in that family's
 * generator and packer (sdk/src/opencl/actions_*.cpp). */

FL_INLINE void fl_kill_old(float age, float life, uint code, uint* dead) {
  const uint k = age > life ? code : 0u;
  *dead = *dead != 0u ? *dead : k;
}

FL_INLINE void fl_move(float dt, float* px, float* py, float* pz, float vx, float vy, float vz) {
  *px += vx * dt;
  *py += vy * dt;
  *pz += vz * dt;
}

/* Move turns the up vector with the angular velocity, exactly: about w by |w|*dt (Rodrigues;
 * kernels.hpp apply(Move)). cos and sin are the device's: an ulp from glibc's. */
FL_INLINE void fl_turn_up(float dt, float* ux, float* uy, float* uz, float wx, float wy,
                          float wz) {
  const float speed = sqrt(wx * wx + wy * wy + wz * wz);
  if (!(speed > 0.0f)) return;
  const float kx = wx / speed, ky = wy / speed, kz = wz / speed;
  const float x = *ux, y = *uy, z = *uz;
  const float ct = cos(speed * dt), st = sin(speed * dt);
  const float cx = ky * z - y * kz, cy = kz * x - z * kx, cz = kx * y - x * ky;
  const float d = (kx * x + ky * y + kz * z) * (1.0f - ct);
  *ux = x * ct + cx * st + kx * d;
  *uy = y * ct + cy * st + ky * d;
  *uz = z * ct + cz * st + kz * d;
}

/* A double that travels as two uints of FlActionParams::u (low word first). */
FL_INLINE fl_real fl_real_from_words(uint lo, uint hi) {
  return fl_real_from_bits(((ulong)hi << 32) | (ulong)lo);
}

/* Restore (actions_more.hpp apply(Restore)): steer to PositionB so as to arrive on time.
 * u[0..1]: start, u[2..3]: start + duration, as doubles. dt: the particle's sub-step. */
FL_INLINE void fl_restore(__global const FlActionParams* a, float dt, fl_real time, float* px,
                          float* py, float* pz, float* vx, float* vy, float* vz, float hx,
                          float hy, float hz) {
  const fl_real start = fl_real_from_words(a->u[0], a->u[1]);
  if (time + (fl_real)1e-9 < start) return;
  const float left = (float)(fl_real_from_words(a->u[2], a->u[3]) - time);
  const float dx = hx - *px, dy = hy - *py, dz = hz - *pz;
  /* A newborn born at the step's very end has h = 0: its velocity is left as it is. */
  if (dt > 0.0f) {
    const float by = left > dt ? left : dt;
    *vx = dx / by;
    *vy = dy / by;
    *vz = dz / by;
  }
  if (left <= 0.0f) {
    *px = hx;
    *py = hy;
    *pz = hz;
    *vx = 0.0f;
    *vy = 0.0f;
    *vz = 0.0f;
  }
}
