// Forces, random and target actions and curves over life on the device: the calls the fused
// act kernel makes (kernels/forces.cl) and the constants they read. The f[] and u[] of each
// action are listed with its function in forces.cl.
//
// Products with dt are made on the device (dt there is the sub-step's): a host-made product
// would be wrong under sub-steps. Exponentials of -rate·dt are the exception: the host packs
// std::exp's value together with the dt it was made for, and the device uses it when its dt
// is that one (bit for bit the CPU's) and its own exp otherwise.
#include <cmath>
#include <string>

#include "codegen.hpp"
#include "emission.hpp"

namespace flurry::detail::ocl {

namespace {

using A = Attribute;

constexpr int kFalloff = 27;  // forces.cl FL_FALLOFF

void putFalloff(float* f, const Falloff& fo) {
  putVec(f, kFalloff, fo.center);
  f[kFalloff + 3] = fo.radius;
  f[kFalloff + 4] = fo.power;
}

// A domain the device samples: its kind as a literal (fl_sample_any folds its switch on
// it); a mesh's or union's data is in the list's `extra` (packSampled), which the calls pass.
std::string kindOf(const Domain& d) {
  return std::to_string(d.shape().index()) + "u";
}

cl::FlDomain packSampled(const Domain& d, ActionPack& p) {
  return ShapePacker{p.extra, {}, {}}.pack(d);
}

// The random-stream arguments the fl_* functions take after the lanes.
std::string rngArgs(const ActionSource& s) {
  return "id, seedLo, seedHi, fl_step, " + s.in.stream;
}

std::string call(const std::string& fn, const std::string& args) {
  return fn + "(" + args + ");\n";
}

// An accel statement: the function adds to ax, ay, az in its own block.
std::string acc(const std::string& fn, const std::string& args) {
  return "{ " + fn + "(" + args + ", &ax, &ay, &az); }\n";
}

const std::string kP = "px, py, pz", kV = "vx, vy, vz", kPV = "&vx, &vy, &vz",
                  kPP = "&px, &py, &pz";

}  // namespace

bool generateForceAction(const Action& act, ActionSource& s) {
  const std::string& ap = s.in.params;
  const std::string apDt = ap + ", dt";
  if (const auto* g = std::get_if<Gravity>(&act)) {
    // Without a falloff the CPU adds a·dt (kernels.hpp addLoop), with one a·(dt·w).
    s.apply = g->falloff.radius < kInfinity
                  ? call("fl_gravity_falloff", apDt + ", " + kP + ", " + kPV)
                  : call("fl_gravity", apDt + ", " + kPV);
    s.accel = acc("fl_gravity_acc", ap + ", " + kP);
    return true;
  }
  if (const auto* d = std::get_if<Damping>(&act)) {
    // Without a falloff the CPU scales by exp(-rate·dt) made once per step (the host's).
    s.apply = d->falloff.radius < kInfinity
                  ? call("fl_damping_falloff", apDt + ", " + kP + ", " + kPV)
                  : call("fl_damping", apDt + ", " + kPV);
    s.accel = acc("fl_damping_acc", ap + ", " + kP + ", " + kV);
    return true;
  }
  if (std::holds_alternative<RotDamping>(act)) {
    s.apply = call("fl_damping", apDt + ", &rotx, &roty, &rotz");
    return true;
  }
  if (std::holds_alternative<OrbitPoint>(act)) {
    s.apply = call("fl_orbit_point", apDt + ", " + kP + ", " + kPV);
    s.accel = acc("fl_orbit_point_acc", ap + ", " + kP);
    return true;
  }
  if (std::holds_alternative<OrbitLine>(act)) {
    s.apply = call("fl_orbit_line", apDt + ", " + kP + ", " + kPV);
    s.accel = acc("fl_orbit_line_acc", ap + ", " + kP);
    return true;
  }
  if (std::holds_alternative<Vortex>(act)) {
    s.apply = call("fl_vortex", apDt + ", " + kP + ", " + kPV);
    s.accel = acc("fl_vortex_acc", ap + ", " + kP + ", " + kV);
    return true;
  }
  if (const auto* j = std::get_if<Jet>(&act)) {
    const std::string kind = kindOf(j->acceleration);
    s.apply = call("fl_jet",
                   ap + ", " + kind + ", dt, " + kP + ", " + kPV + ", " + rngArgs(s) + ", extra");
    s.accel = acc("fl_jet_acc", ap + ", " + kind + ", " + kP + ", " + rngArgs(s) + ", extra");
    return true;
  }
  if (std::holds_alternative<Explosion>(act)) {
    s.apply = call("fl_explosion", apDt + ", time, " + kP + ", " + kPV);
    s.accel = acc("fl_explosion_acc", ap + ", t, " + kP);
    return true;
  }
  if (const auto* r = std::get_if<RandomAccel>(&act)) {
    const std::string kind = kindOf(r->acceleration);
    s.apply = call("fl_random_accel",
                   ap + ", " + kind + ", dt, " + kP + ", " + kPV + ", " + rngArgs(s) + ", extra");
    s.accel =
        acc("fl_random_accel_acc", ap + ", " + kind + ", " + kP + ", " + rngArgs(s) + ", extra");
    return true;
  }
  if (const auto* r = std::get_if<RandomDisplace>(&act)) {
    s.apply = call("fl_random_displace", ap + ", " + kindOf(r->displacement) + ", dt, " + kPP +
                                             ", " + rngArgs(s) + ", extra");
    return true;
  }
  if (const auto* r = std::get_if<RandomVelocity>(&act)) {
    s.apply = call("fl_random_set",
                   ap + ", " + kindOf(r->velocity) + ", " + kPV + ", " + rngArgs(s) + ", extra");
    return true;
  }
  if (const auto* r = std::get_if<RandomRotVelocity>(&act)) {
    s.apply = call("fl_random_set", ap + ", " + kindOf(r->rotVelocity) + ", &rotx, &roty, &rotz, " +
                                        rngArgs(s) + ", extra");
    return true;
  }
  if (std::holds_alternative<Turbulence>(act)) {
    s.apply = call("fl_turbulence", apDt + ", time, " + kP + ", " + kPV);
    s.accel = acc("fl_turbulence_acc", ap + ", t, " + kP);
    return true;
  }
  if (std::holds_alternative<ElectricField>(act)) {
    s.apply = call("fl_electric", apDt + ", " + kP + ", " + kPV + ", charge, mass");
    s.accel = acc("fl_electric_acc", ap + ", " + kP + ", charge, mass");
    return true;
  }
  if (std::holds_alternative<MagneticField>(act)) {
    s.apply = call("fl_magnetic", apDt + ", " + kP + ", " + kPV + ", charge, mass");
    s.accel = acc("fl_magnetic_acc", ap + ", " + kP + ", " + kV + ", charge, mass");
    return true;
  }
  if (std::holds_alternative<SampledField>(act)) {
    s.apply = call("fl_sampled_field", ap + ", extra, dt, " + kP + ", " + kPV);
    s.accel = acc("fl_sampled_field_acc", ap + ", extra, " + kP + ", " + kV);
    return true;
  }
  if (std::holds_alternative<TargetVelocity>(act)) {
    s.apply = call("fl_target3", apDt + ", " + kPV);
    return true;
  }
  if (std::holds_alternative<TargetRotVelocity>(act)) {
    s.apply = call("fl_target3", apDt + ", &rotx, &roty, &rotz");
    return true;
  }
  if (std::holds_alternative<TargetColor>(act)) {
    s.apply = call("fl_target_color", apDt + ", &r, &g, &b, &a");
    return true;
  }
  if (std::holds_alternative<TargetSize>(act)) {
    s.apply = call("fl_target_size", apDt + ", &size");
    return true;
  }
  if (std::holds_alternative<SpeedClamp>(act)) {
    s.apply = call("fl_speed_clamp", ap + ", " + kPV);
    return true;
  }
  // Multiply scales the birth value, Replace sets the curve's (actions_more.hpp).
  if (const auto* c = std::get_if<ColorOverLife>(&act)) {
    if (c->mode == OverLifeMode::Multiply) {
      s.apply = call("fl_color_over_life_scaled",
                     ap + ", extra, age, life, birthr, birthg, birthb, birtha, &r, &g, &b, &a");
    } else {
      s.apply = call("fl_color_over_life", ap + ", extra, age, life, &r, &g, &b, &a");
    }
    return true;
  }
  if (const auto* c = std::get_if<SizeOverLife>(&act)) {
    if (c->mode == OverLifeMode::Multiply) {
      s.apply = call("fl_size_over_life_scaled", ap + ", extra, age, life, birthsize, &size");
    } else {
      s.apply = call("fl_size_over_life", ap + ", extra, age, life, &size");
    }
    return true;
  }
  return false;
}

bool packForceAction(const Action& act, ActionPack& p) {
  const float dt = p.dt;
  float* f = p.p.f;
  cl::fl_u32* u = p.p.u;
  // f[at] = the step's dt, f[at + 1] = exp(-rate·dt) as the CPU makes it (fl_decay).
  auto decay = [&](int at, float rate) {
    f[at] = dt;
    f[at + 1] = std::exp(-rate * dt);
  };
  // Targets: f[0..3] the target, [4] rate, [5..6] its decay.
  auto target = [&](float x, float y, float z, float w, float rate) {
    f[0] = x;
    f[1] = y;
    f[2] = z;
    f[3] = w;
    f[4] = rate;
    decay(5, rate);
  };
  if (const auto* g = std::get_if<Gravity>(&act)) {
    putVec(f, 0, g->acceleration);
    putFalloff(f, g->falloff);
    return true;
  }
  // Damping and RotDamping: f[0..2] exp(-rate·dt), f[3..5] rate (Exact reads these), f[6] dt.
  auto damping = [&](Vec3 rate) {
    putVec(f, 0, Vec3(std::exp(-rate.x * dt), std::exp(-rate.y * dt), std::exp(-rate.z * dt)));
    putVec(f, 3, rate);
    f[6] = dt;
  };
  if (const auto* d = std::get_if<Damping>(&act)) {
    damping(d->rate);
    putFalloff(f, d->falloff);
    return true;
  }
  if (const auto* d = std::get_if<RotDamping>(&act)) {
    damping(d->rate);
    return true;
  }
  if (const auto* o = std::get_if<OrbitPoint>(&act)) {
    putVec(f, 0, o->center);
    f[3] = o->magnitude;
    f[4] = o->epsilon;
    f[5] = o->maxRadius;
    return true;
  }
  if (const auto* o = std::get_if<OrbitLine>(&act)) {
    putVec(f, 0, o->point);
    putVec(f, 3, glm::normalize(o->axis));  // as the CPU normalises it, per block
    f[6] = o->magnitude;
    f[7] = o->epsilon;
    f[8] = o->maxRadius;
    return true;
  }
  if (const auto* v = std::get_if<Vortex>(&act)) {
    putVec(f, 0, v->center);
    putVec(f, 3, glm::normalize(v->axis));
    f[6] = v->aroundSpeed;
    f[7] = v->coreRadius;
    f[8] = v->tightness;
    f[9] = v->inSpeed;
    f[10] = v->upSpeed;
    f[11] = v->responsiveness;
    f[12] = v->maxRadius;
    decay(13, v->responsiveness);
    return true;
  }
  if (const auto* j = std::get_if<Jet>(&act)) {
    putVec(f, 0, j->center);
    f[3] = j->radius;
    p.p.domain = packSampled(j->acceleration, p);
    return true;
  }
  if (const auto* e = std::get_if<Explosion>(&act)) {
    putVec(f, 0, e->center);
    f[3] = e->speed;
    f[4] = e->magnitude;
    f[5] = 1.0f / (2.0f * e->stddev * e->stddev);  // apply()
    f[6] = e->epsilon;
    f[7] = e->time;
    f[8] = 2 * e->stddev * e->stddev;  // accumulate()
    return true;
  }
  if (const auto* r = std::get_if<RandomAccel>(&act)) {
    p.p.domain = packSampled(r->acceleration, p);
    putFalloff(f, r->falloff);
    return true;
  }
  if (const auto* r = std::get_if<RandomDisplace>(&act)) {
    p.p.domain = packSampled(r->displacement, p);
    return true;
  }
  if (const auto* r = std::get_if<RandomVelocity>(&act)) {
    p.p.domain = packSampled(r->velocity, p);
    return true;
  }
  if (const auto* r = std::get_if<RandomRotVelocity>(&act)) {
    p.p.domain = packSampled(r->rotVelocity, p);
    return true;
  }
  if (const auto* t = std::get_if<Turbulence>(&act)) {
    f[0] = t->amplitude;
    f[1] = t->frequency;
    putVec(f, 2, t->drift);
    u[0] = cl::fl_u32(t->octaves);
    putFalloff(f, t->falloff);
    return true;
  }
  if (const auto* e = std::get_if<ElectricField>(&act)) {
    putVec(f, 0, e->field);
    putFalloff(f, e->falloff);
    return true;
  }
  if (const auto* m = std::get_if<MagneticField>(&act)) {
    const float B = glm::length(m->field);
    putVec(f, 0, B > 0.0f ? m->field / B : Vec3(0.0f));
    f[3] = B;
    putVec(f, 4, m->field);
    putFalloff(f, m->falloff);
    return true;
  }
  if (const auto* sf = std::get_if<SampledField>(&act)) {
    const VectorField& field = *sf->field;
    putVec(f, 0, field.origin);
    f[3] = field.voxelSize;
    f[4] = sf->strength;
    f[5] = sf->responsiveness;
    decay(6, sf->responsiveness);
    u[0] = cl::fl_u32(p.extra.size());
    u[1] = cl::fl_u32(field.dims.x);
    u[2] = cl::fl_u32(field.dims.y);
    u[3] = cl::fl_u32(field.dims.z);
    u[4] = sf->mode == SampledField::Mode::Velocity ? 1u : 0u;
    for (const Vec3& v : field.data) p.extra.insert(p.extra.end(), {v.x, v.y, v.z});
    putFalloff(f, sf->falloff);
    return true;
  }
  if (const auto* t = std::get_if<TargetVelocity>(&act)) {
    target(t->velocity.x, t->velocity.y, t->velocity.z, 0.0f, t->rate);
    return true;
  }
  if (const auto* t = std::get_if<TargetRotVelocity>(&act)) {
    target(t->rotVelocity.x, t->rotVelocity.y, t->rotVelocity.z, 0.0f, t->rate);
    return true;
  }
  if (const auto* t = std::get_if<TargetColor>(&act)) {
    target(t->color.x, t->color.y, t->color.z, t->alpha, t->rate);
    return true;
  }
  if (const auto* t = std::get_if<TargetSize>(&act)) {
    target(t->size, 0.0f, 0.0f, 0.0f, t->rate);
    return true;
  }
  if (const auto* c = std::get_if<SpeedClamp>(&act)) {
    f[0] = c->minSpeed;
    f[1] = c->maxSpeed;
    return true;
  }
  if (const auto* c = std::get_if<ColorOverLife>(&act)) {
    u[0] = cl::fl_u32(p.extra.size());
    u[1] = cl::fl_u32(c->keys.size());
    for (const auto& k : c->keys)
      p.extra.insert(p.extra.end(), {k.t, k.color.r, k.color.g, k.color.b, k.color.a});
    return true;
  }
  if (const auto* c = std::get_if<SizeOverLife>(&act)) {
    u[0] = cl::fl_u32(p.extra.size());
    u[1] = cl::fl_u32(c->keys.size());
    for (const auto& k : c->keys) p.extra.insert(p.extra.end(), {k.t, k.size});
    return true;
  }
  return false;
}

}  // namespace flurry::detail::ocl
