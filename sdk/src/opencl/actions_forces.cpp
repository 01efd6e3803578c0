// Forces, random and target actions and curves over life on the device: the calls the fused
// act kernel makes (kernels/forces.cl) and the constants they read (their records are in
// kernels/params.h).
//
// Products with dt are made on the device (dt there is the sub-step's): a host-made product
// would be wrong under sub-steps. Exponentials of -rate·dt are the exception: the host packs
// fl_expf's value (kernels/math.h) together with the dt it was made for, and the device uses
// it when its dt is that one and computes the same function otherwise (bit for bit the CPU's).
#include <cmath>
#include <string>

#include "codegen.hpp"

namespace flurry::detail::ocl {

namespace {

using A = Attribute;

// A domain the device samples: its kind as a literal (fl_sample_any folds its switch on
// it); a mesh's or union's data is in the list's `extra` (codegen.cpp packStorage), which the
// calls pass.
std::string kindOf(const Domain& d) {
  return std::to_string(d.shape().index()) + "u";
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
  // The record and the falloff, passed by value to kernels/forces.h's functions.
  auto own = [&](const char* member) { return ap + "->own." + member; };
  const std::string fo = ap + "->falloff";
  if (const auto* g = std::get_if<Gravity>(&act)) {
    // Without a falloff the CPU adds a·dt, with one a·(dt·w).
    s.apply =
        g->falloff.radius < kInfinity
            ? call("fl_gravity_falloff", own("gravity") + ", " + fo + ", dt, " + kP + ", " + kPV)
            : call("fl_gravity", own("gravity") + ", dt, " + kPV);
    s.accel = acc("fl_gravity_acc", own("gravity") + ", " + fo + ", " + kP);
    return true;
  }
  if (const auto* d = std::get_if<Damping>(&act)) {
    // Without a falloff the CPU scales by the record's exp(-rate·dt).
    s.apply =
        d->falloff.radius < kInfinity
            ? call("fl_damping_falloff", own("damping") + ", " + fo + ", dt, " + kP + ", " + kPV)
            : call("fl_damping", own("damping") + ", dt, " + kPV);
    s.accel = acc("fl_damping_acc", own("damping") + ", " + fo + ", " + kP + ", " + kV);
    return true;
  }
  if (std::holds_alternative<RotDamping>(act)) {
    s.apply = call("fl_damping", own("damping") + ", dt, &rotx, &roty, &rotz");
    return true;
  }
  if (std::holds_alternative<OrbitPoint>(act)) {
    s.apply = call("fl_orbit_point", own("orbitPoint") + ", dt, " + kP + ", " + kPV);
    s.accel = acc("fl_orbit_point_acc", own("orbitPoint") + ", " + kP);
    return true;
  }
  if (std::holds_alternative<OrbitLine>(act)) {
    s.apply = call("fl_orbit_line", own("orbitLine") + ", dt, " + kP + ", " + kPV);
    s.accel = acc("fl_orbit_line_acc", own("orbitLine") + ", " + kP);
    return true;
  }
  if (std::holds_alternative<Vortex>(act)) {
    s.apply = call("fl_vortex", own("vortex") + ", dt, " + kP + ", " + kPV);
    s.accel = acc("fl_vortex_acc", own("vortex") + ", " + kP + ", " + kV);
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
    s.apply = call("fl_explosion", own("explosion") + ", dt, time, " + kP + ", " + kPV);
    s.accel = acc("fl_explosion_acc", own("explosion") + ", t, " + kP);
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
    s.apply =
        call("fl_turbulence", own("turbulence") + ", " + fo + ", dt, time, " + kP + ", " + kPV);
    s.accel = acc("fl_turbulence_acc", own("turbulence") + ", " + fo + ", t, " + kP);
    return true;
  }
  if (std::holds_alternative<ElectricField>(act)) {
    s.apply = call("fl_electric",
                   own("electric") + ", " + fo + ", dt, " + kP + ", " + kPV + ", charge, mass");
    s.accel = acc("fl_electric_acc", own("electric") + ", " + fo + ", " + kP + ", charge, mass");
    return true;
  }
  if (std::holds_alternative<MagneticField>(act)) {
    s.apply = call("fl_magnetic",
                   own("magnetic") + ", " + fo + ", dt, " + kP + ", " + kPV + ", charge, mass");
    s.accel = acc("fl_magnetic_acc",
                  own("magnetic") + ", " + fo + ", " + kP + ", " + kV + ", charge, mass");
    return true;
  }
  if (std::holds_alternative<SampledField>(act)) {
    s.apply = call("fl_grid_field", ap + ", extra, dt, " + kP + ", " + kPV);
    s.accel = acc("fl_grid_field_acc", ap + ", extra, " + kP + ", " + kV);
    return true;
  }
  if (std::holds_alternative<TargetVelocity>(act)) {
    s.apply = call("fl_target3", own("target") + ", dt, " + kPV);
    return true;
  }
  if (std::holds_alternative<TargetRotVelocity>(act)) {
    s.apply = call("fl_target3", own("target") + ", dt, &rotx, &roty, &rotz");
    return true;
  }
  if (std::holds_alternative<TargetColor>(act)) {
    s.apply = call("fl_target_color", own("target") + ", dt, &r, &g, &b, &a");
    return true;
  }
  if (std::holds_alternative<TargetSize>(act)) {
    s.apply = call("fl_target_size", own("target") + ", dt, &size");
    return true;
  }
  if (std::holds_alternative<SpeedClamp>(act)) {
    s.apply = call("fl_speed_clamp", own("speedClamp") + ", " + kPV);
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

}  // namespace flurry::detail::ocl
