// Forces, random and target actions and curves over life on the device: the calls the fused
// act kernel makes (kernels/forces.cl) and the constants they read.
#include <cmath>
#include <string>

#include "codegen.hpp"

namespace flurry::detail::ocl {

bool generateForceAction(const Action& act, ActionSource& s) {
  const std::string& ap = s.in.params;
  if (const auto* g = std::get_if<Gravity>(&act)) {
    if (g->falloff.radius < kInfinity) notOnDevice("Gravity with a falloff radius");
    s.reads.insert(Attribute::Velocity);
    s.writes.insert(Attribute::Velocity);
    s.apply = "fl_gravity(" + ap + ", &vx, &vy, &vz);\n";
    // f[3..5]: the acceleration itself (f[0..2] is it times dt).
    s.accel = "ax += " + ap + "->f[3]; ay += " + ap + "->f[4]; az += " + ap + "->f[5];\n";
    return true;
  }
  if (const auto* d = std::get_if<Damping>(&act)) {
    if (d->falloff.radius < kInfinity) notOnDevice("Damping with a falloff radius");
    s.reads.insert(Attribute::Velocity);
    s.writes.insert(Attribute::Velocity);
    s.apply = "fl_damping(" + ap + ", &vx, &vy, &vz);\n";
    // integrate.hpp: acc = -rate * v (times a falloff weight of 1).
    s.accel = "ax += -" + ap + "->f[3] * vx; ay += -" + ap + "->f[4] * vy; az += -" + ap +
              "->f[5] * vz;\n";
    return true;
  }
  return false;
}

bool packForceAction(const Action& act, ActionPack& p) {
  const float dt = p.dt;
  float* f = p.p.f;
  if (const auto* g = std::get_if<Gravity>(&act)) {
    putVec(f, 0, Vec3(g->acceleration.x * dt, g->acceleration.y * dt, g->acceleration.z * dt));
    putVec(f, 3, g->acceleration);
    return true;
  }
  if (const auto* d = std::get_if<Damping>(&act)) {
    putVec(f, 0,
           Vec3(std::exp(-d->rate.x * dt), std::exp(-d->rate.y * dt), std::exp(-d->rate.z * dt)));
    putVec(f, 3, d->rate);
    return true;
  }
  return false;
}

}  // namespace flurry::detail::ocl
