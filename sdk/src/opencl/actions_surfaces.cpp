// Deflectors, absorbers, blockers, 2-D constraints and the actions that read neighbours on
// the device: the calls the fused act kernel makes (kernels/surfaces.cl) and the constants
// they read.
#include <cmath>
#include <string>

#include "../action_params.hpp"
#include "codegen.hpp"

namespace flurry::detail::ocl {

namespace {

// The kind literal of a region the device tests. The calls pass the list's `extra` as the
// table where a mesh's or union's data is (codegen.cpp packStorage), read for those kinds only.
std::string kindOf(const Domain& d) {
  return std::to_string(d.shape().index()) + "u";
}

const char* kSnapArgs = "snap, snapStride, snapN, i";

}  // namespace

std::string bounceOnCurve(const Bounce& b, const std::string& params, const std::string& acc) {
  const int piece = planarPiece(b);
  if (piece < 0) return "";
  return "fl_bounce_planar_accel(" + params + ", " + std::to_string(piece) + ", dt, " + acc +
         "x, " + acc + "y, " + acc + "z, &px, &py, &pz, &vx, &vy, &vz);\n";
}

bool generateSurfaceAction(const Action& act, ActionSource& s) {
  const std::string& ap = s.in.params;
  const std::string pv = "&px, &py, &pz, &vx, &vy, &vz);\n";
  if (const auto* b = std::get_if<Bounce>(&act)) {
    const auto& shape = b->surface.shape();
    const std::string in = b->inside ? "1" : "0";
    if (std::holds_alternative<SphereDomain>(shape))
      s.apply = "fl_bounce_sphere(" + ap + ", " + in + ", dt, " + pv;
    else if (std::holds_alternative<BoxDomain>(shape))
      s.apply = "fl_bounce_box(" + ap + ", " + in + ", dt, " + pv;
    else if (planarPiece(*b) >= 0)
      s.apply = "fl_bounce_planar(" + ap + ", " + std::to_string(planarPiece(*b)) + ", dt, " + pv;
    else  // validation allows no other surface
      notOnDevice(std::string("Bounce on a ") + b->surface.name());
    return true;
  }
  if (const auto* k = std::get_if<Sink>(&act)) {
    using M = Sink::Mode;
    const std::string kind = kindOf(k->region);
    if (k->mode == M::Inside || k->mode == M::Outside) {
      s.apply = "fl_sink(" + ap + ", " + kind + ", " + (k->mode == M::Inside ? "1" : "0") +
                ", px, py, pz, " + s.in.code + ", &dead, extra);\n";
    } else if (k->mode == M::Enter || k->mode == M::Leave) {
      s.apply = "fl_sink_motion(" + ap + ", " + kind + ", " + (k->mode == M::Enter ? "1" : "0") +
                ", dt, px, py, pz, vx, vy, vz, " + s.in.code + ", &dead, extra);\n";
    } else {  // Hit: validation makes the region a plane piece
      s.apply = "fl_sink_hit(" + ap + ", " + kind + ", dt, px, py, pz, vx, vy, vz, " + s.in.code +
                ", &dead, extra);\n";
    }
    if (k->passThrough > 0.0f) {
      // Keyed by the group's streamBase (without the sub-step) and the index: once per particle.
      s.apply += "fl_sink_pass(" + ap + ", id, " + s.in.code +
                 ", &dead, seedLo, seedHi, (streamBase + " + std::to_string(s.in.index) + "u));\n";
    }
    return true;
  }
  if (const auto* k = std::get_if<SinkVelocity>(&act)) {
    s.apply = "fl_sink(" + ap + ", " + kindOf(k->velocity) + ", " + (k->killInside ? "1" : "0") +
              ", vx, vy, vz, " + s.in.code + ", &dead, extra);\n";
    return true;
  }
  if (const auto* b = std::get_if<Block>(&act)) {
    // The list's first blocker starts from "visible" (the CPU's BlockContext.firstBlocker).
    // The generator sees one action at a time; the preprocessor, reading the kernel in list
    // order, meets the first Block first and keeps its index (also when the step's code is
    // placed twice, as in hair mode).
    const std::string k = std::to_string(s.in.index);
    s.apply = "#ifndef FL_FIRST_BLOCKER\n#define FL_FIRST_BLOCKER " + k +
              "\n#endif\n#if FL_FIRST_BLOCKER == " + k + "\nvis = 1u;\n#endif\nfl_block(" + ap +
              ", " + kindOf(b->region) + ", px, py, pz, &vis, extra);\n";
    return true;
  }
  if (const auto* k = std::get_if<Avoid>(&act)) {
    s.apply = "fl_avoid(" + ap + ", " + kindOf(k->obstacle) +
              ", dt, px, py, pz, &vx, &vy, &vz, extra);\n";
    return true;
  }
  if (std::holds_alternative<Constrain2D>(act)) {
    s.apply = "fl_constrain2d(" + ap + "->own.constrain2d, " + pv;
    return true;
  }
  if (std::holds_alternative<Gravitate>(act) || std::holds_alternative<Follow>(act)) {
    const std::string fn =
        std::holds_alternative<Gravitate>(act) ? "fl_gravitate_acc(" : "fl_follow_acc(";
    const std::string acc = fn + ap + ", " + kSnapArgs + ", (float3)(px, py, pz))";
    s.apply = "fl_add_accel(" + acc + ", dt, &vx, &vy, &vz);\n";
    // integrate.hpp accumulate(): this force's acceleration, then added to the sum.
    s.accel = "{ const float3 acc = " + acc + "; ax += acc.x; ay += acc.y; az += acc.z; }\n";
    return true;
  }
  if (std::holds_alternative<MatchVelocity>(act)) {
    s.apply =
        "fl_match_toward_mean(" + ap + ", " + kSnapArgs + ", 1u, dt, px, py, pz, &vx, &vy, &vz);\n";
    return true;
  }
  if (std::holds_alternative<MatchRotVelocity>(act)) {
    s.apply = "fl_match_toward_mean(" + ap + ", " + kSnapArgs +
              ", 2u, dt, px, py, pz, &rotx, &roty, &rotz);\n";
    return true;
  }
  return false;
}

}  // namespace flurry::detail::ocl
