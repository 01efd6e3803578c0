/* Forces, random and target actions, curves over life (sdk/src/opencl/actions_forces.cpp
 * generates their calls and packs their constants). Each follows sdk/src/cpu/kernels.hpp and
 * actions_more.hpp operation by operation. */

FL_INLINE void fl_gravity(__global const FlActionParams* a, float* vx, float* vy, float* vz) {
  *vx += a->f[0];
  *vy += a->f[1];
  *vz += a->f[2];
}

FL_INLINE void fl_damping(__global const FlActionParams* a, float* vx, float* vy, float* vz) {
  *vx *= a->f[0];
  *vy *= a->f[1];
  *vz *= a->f[2];
}

