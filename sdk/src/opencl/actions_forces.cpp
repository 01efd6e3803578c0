// Forces, random and target actions and curves over life on the device: the calls the fused
// act kernel makes (kernels/forces.cl) and the constants they read (their records are in
// kernels/params.h).
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
  auto& own = p.p.own;
  // exp(-rate·dt) as the CPU makes it, for the step's dt (fl_force_decay).
  auto decay = [&](float rate) { return std::exp(-rate * dt); };
  auto falloff = [&](const Falloff& f) {
    p.p.falloff = {f.center.x, f.center.y, f.center.z, f.radius, f.power};
  };
  auto target = [&](float x, float y, float z, float w, float rate) {
    own.target = {{x, y, z, w}, rate, dt, decay(rate)};
  };
  auto damping = [&](Vec3 rate) {
    own.damping = {xyz(Vec3(decay(rate.x), decay(rate.y), decay(rate.z))), xyz(rate), dt};
  };
  if (const auto* g = std::get_if<Gravity>(&act)) {
    own.gravity = {xyz(g->acceleration)};
    falloff(g->falloff);
  } else if (const auto* d = std::get_if<Damping>(&act)) {
    damping(d->rate);
    falloff(d->falloff);
  } else if (const auto* rd = std::get_if<RotDamping>(&act)) {
    damping(rd->rate);
  } else if (const auto* o = std::get_if<OrbitPoint>(&act)) {
    own.orbitPoint = {xyz(o->center), o->magnitude, o->epsilon, o->maxRadius};
  } else if (const auto* ol = std::get_if<OrbitLine>(&act)) {
    // The axis normalised as the CPU normalises it, per block.
    own.orbitLine = {xyz(ol->point), xyz(glm::normalize(ol->axis)), ol->magnitude, ol->epsilon,
                     ol->maxRadius};
  } else if (const auto* v = std::get_if<Vortex>(&act)) {
    own.vortex = {xyz(v->center),
                  xyz(glm::normalize(v->axis)),
                  v->aroundSpeed,
                  v->coreRadius,
                  v->tightness,
                  v->inSpeed,
                  v->upSpeed,
                  v->maxRadius,
                  v->responsiveness,
                  dt,
                  decay(v->responsiveness)};
  } else if (const auto* j = std::get_if<Jet>(&act)) {
    own.jet = {xyz(j->center), j->radius};
    p.p.domain = packSampled(j->acceleration, p);
  } else if (const auto* e = std::get_if<Explosion>(&act)) {
    const float twoVariance = 2 * e->stddev * e->stddev;  // accumulate()'s; apply() its inverse
    own.explosion = {xyz(e->center), e->speed,           e->magnitude, e->epsilon,
                     e->time,        1.0f / twoVariance, twoVariance};
  } else if (const auto* ra = std::get_if<RandomAccel>(&act)) {
    p.p.domain = packSampled(ra->acceleration, p);
    falloff(ra->falloff);
  } else if (const auto* rp = std::get_if<RandomDisplace>(&act)) {
    p.p.domain = packSampled(rp->displacement, p);
  } else if (const auto* rv = std::get_if<RandomVelocity>(&act)) {
    p.p.domain = packSampled(rv->velocity, p);
  } else if (const auto* rr = std::get_if<RandomRotVelocity>(&act)) {
    p.p.domain = packSampled(rr->rotVelocity, p);
  } else if (const auto* t = std::get_if<Turbulence>(&act)) {
    own.turbulence = {t->amplitude, t->frequency, xyz(t->drift), cl::fl_u32(t->octaves)};
    falloff(t->falloff);
  } else if (const auto* ef = std::get_if<ElectricField>(&act)) {
    own.electric = {xyz(ef->field)};
    falloff(ef->falloff);
  } else if (const auto* m = std::get_if<MagneticField>(&act)) {
    const float B = glm::length(m->field);
    own.magnetic = {xyz(B > 0.0f ? m->field / B : Vec3(0.0f)), B, xyz(m->field)};
    falloff(m->falloff);
  } else if (const auto* sf = std::get_if<SampledField>(&act)) {
    const VectorField& field = *sf->field;
    own.sampledField = {xyz(field.origin),
                        field.voxelSize,
                        sf->strength,
                        sf->responsiveness,
                        dt,
                        decay(sf->responsiveness),
                        cl::fl_u32(p.extra.size()),
                        cl::fl_u32(field.dims.x),
                        cl::fl_u32(field.dims.y),
                        cl::fl_u32(field.dims.z),
                        sf->mode == SampledField::Mode::Velocity ? 1u : 0u};
    for (const Vec3& v : field.data) p.extra.insert(p.extra.end(), {v.x, v.y, v.z});
    falloff(sf->falloff);
  } else if (const auto* tv = std::get_if<TargetVelocity>(&act)) {
    target(tv->velocity.x, tv->velocity.y, tv->velocity.z, 0.0f, tv->rate);
  } else if (const auto* tr = std::get_if<TargetRotVelocity>(&act)) {
    target(tr->rotVelocity.x, tr->rotVelocity.y, tr->rotVelocity.z, 0.0f, tr->rate);
  } else if (const auto* tc = std::get_if<TargetColor>(&act)) {
    target(tc->color.x, tc->color.y, tc->color.z, tc->alpha, tc->rate);
  } else if (const auto* ts = std::get_if<TargetSize>(&act)) {
    target(ts->size, 0.0f, 0.0f, 0.0f, ts->rate);
  } else if (const auto* c = std::get_if<SpeedClamp>(&act)) {
    own.speedClamp = {c->minSpeed, c->maxSpeed};
  } else if (const auto* co = std::get_if<ColorOverLife>(&act)) {
    own.curve = {cl::fl_u32(p.extra.size()), cl::fl_u32(co->keys.size())};
    for (const auto& k : co->keys)
      p.extra.insert(p.extra.end(), {k.t, k.color.r, k.color.g, k.color.b, k.color.a});
  } else if (const auto* so = std::get_if<SizeOverLife>(&act)) {
    own.curve = {cl::fl_u32(p.extra.size()), cl::fl_u32(so->keys.size())};
    for (const auto& k : so->keys) p.extra.insert(p.extra.end(), {k.t, k.size});
  } else {
    return false;
  }
  return true;
}

}  // namespace flurry::detail::ocl
