// Deflectors, absorbers, blockers, 2-D constraints and the actions that read neighbours on
// the device: the calls the fused act kernel makes (kernels/surfaces.cl) and the constants
// they read.
#include <cmath>
#include <string>

#include "codegen.hpp"
#include "emission.hpp"

namespace flurry::detail::ocl {

namespace {

// Which planar piece a Bounce surface is (FL_PIECE_*), or -1 for a solid.
int pieceOf(const Domain& d) {
  const auto& s = d.shape();
  if (std::holds_alternative<PlaneDomain>(s)) return 0;
  if (std::holds_alternative<RectangleDomain>(s)) return 1;
  if (std::holds_alternative<TriangleDomain>(s)) return 2;
  if (std::holds_alternative<DiscDomain>(s)) return 3;
  if (std::holds_alternative<LineDomain>(s)) return 4;
  return -1;
}

// As kernels.hpp apply(Bounce) prepares them. f[]: [0..2] plane point, [3..5] unit normal,
// [6] restitution, [7] 1 - friction, [8] cutoff^2, then by surface: rectangle/triangle
// [10..12] dual u, [13..15] dual v | disc [10] outer^2, [11] inner^2 | segment [10..12] its
// direction, [13] its length^2 | sphere [0..2] center, [9] |C|_1 + R, [10] R, [11] R^2,
// [12] 1/R; the surface itself in `domain` (boxes, and the integrators' guard).
void packBounce(const Bounce& a, cl::FlActionParams& p) {
  p.domain = packDomain(a.surface);
  float* f = p.f;
  f[6] = a.restitution;
  f[7] = 1.0f - a.friction;
  f[8] = a.cutoff * a.cutoff;
  const auto& shape = a.surface.shape();
  auto plane = [&](Vec3 P, Vec3 N) {
    putVec(f, 0, P);
    putVec(f, 3, N);
  };
  if (const auto* pl = std::get_if<PlaneDomain>(&shape)) {
    plane(pl->point, pl->normal);
  } else if (const auto* r = std::get_if<RectangleDomain>(&shape)) {
    const Vec3 cu = glm::cross(r->v, r->normal), cv = glm::cross(r->normal, r->u);
    const Vec3 du = cu / glm::dot(r->u, cu), dv = cv / glm::dot(r->v, cv);
    plane(r->origin, r->normal);
    putVec(f, 10, du);
    putVec(f, 13, dv);
  } else if (const auto* t = std::get_if<TriangleDomain>(&shape)) {
    const Vec3 e1 = t->p1 - t->p0, e2 = t->p2 - t->p0;
    const Vec3 c1 = glm::cross(e2, t->normal), c2 = glm::cross(t->normal, e1);
    const Vec3 d1 = c1 / glm::dot(e1, c1), d2 = c2 / glm::dot(e2, c2);
    plane(t->p0, t->normal);
    putVec(f, 10, d1);
    putVec(f, 13, d2);
  } else if (const auto* d = std::get_if<DiscDomain>(&shape)) {
    plane(d->center, d->normal);
    f[10] = d->outerRadius * d->outerRadius;
    f[11] = d->innerRadius * d->innerRadius;
  } else if (const auto* ln = std::get_if<LineDomain>(&shape)) {
    // 2-D: a wall standing on the group's plane, its normal in that plane.
    const Vec3 dir = ln->p1 - ln->p0;
    plane(ln->p0, glm::normalize(glm::cross(dir, a.planeNormal)));
    putVec(f, 10, dir);
    f[13] = glm::dot(dir, dir);
  } else if (const auto* s = std::get_if<SphereDomain>(&shape)) {
    const Vec3 C = s->center;
    const float R = s->outerRadius;
    putVec(f, 0, C);
    f[9] = std::abs(C.x) + std::abs(C.y) + std::abs(C.z) + R;
    f[10] = R;
    f[11] = R * R;
    f[12] = 1.0f / R;
  }
}

// The kind literal of a region the device tests. The calls pass the list's `extra` as the
// table where a mesh's or union's data is (packRegion), read for those kinds only.
std::string kindOf(const Domain& d) {
  return std::to_string(d.shape().index()) + "u";
}

// A region, obstacle or velocity domain: a mesh's or union's data into `extra`.
cl::FlDomain packRegion(const Domain& d, ActionPack& p) {
  return ShapePacker{p.extra, {}, {}}.pack(d);
}

// Gravitate, Follow, Match*: f[0] magnitude (rate), f[1] epsilon, f[2] maxRadius^2.
void packPull(float magnitude, float epsilon, float maxRadius, float* f) {
  f[0] = magnitude;
  f[1] = epsilon;
  f[2] = maxRadius * maxRadius;
}

const char* kSnapArgs = "snap, snapStride, snapN, i";

}  // namespace

std::string bounceOnCurve(const Bounce& b, const std::string& params, const std::string& acc) {
  const int piece = pieceOf(b.surface);
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
    else if (pieceOf(b->surface) >= 0)
      s.apply =
          "fl_bounce_planar(" + ap + ", " + std::to_string(pieceOf(b->surface)) + ", dt, " + pv;
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
    s.apply = "fl_constrain2d(" + ap + ", " + pv;
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

bool packSurfaceAction(const Action& act, ActionPack& p) {
  float* f = p.p.f;
  if (const auto* b = std::get_if<Bounce>(&act)) {
    packBounce(*b, p.p);
    return true;
  }
  if (const auto* k = std::get_if<Sink>(&act)) {
    p.p.domain = packRegion(k->region, p);
    f[0] = k->passThrough;
    return true;
  }
  if (const auto* k = std::get_if<SinkVelocity>(&act)) {
    p.p.domain = packRegion(k->velocity, p);
    return true;
  }
  if (const auto* b = std::get_if<Block>(&act)) {
    p.p.domain = packRegion(b->region, p);
    return true;
  }
  if (const auto* k = std::get_if<Avoid>(&act)) {
    p.p.domain = packRegion(k->obstacle, p);
    f[0] = k->magnitude;
    f[1] = k->epsilon;
    f[2] = k->lookAhead;
    return true;
  }
  if (const auto* k = std::get_if<Constrain2D>(&act)) {
    putVec(f, 0, k->point);
    putVec(f, 3, glm::normalize(k->normal));
    return true;
  }
  if (const auto* k = std::get_if<Gravitate>(&act)) {
    packPull(k->magnitude, k->epsilon, k->maxRadius, f);
    return true;
  }
  if (const auto* k = std::get_if<Follow>(&act)) {
    packPull(k->magnitude, k->epsilon, k->maxRadius, f);
    return true;
  }
  const MatchVelocity* mv = std::get_if<MatchVelocity>(&act);
  const auto* mr = std::get_if<MatchRotVelocity>(&act);
  if (mv || mr) {
    // actions_more.hpp approach(rate, dt) for the step's dt; sub-steps compute their own.
    const float rate = mv ? mv->magnitude : mr->magnitude;
    packPull(rate, p.dt, mv ? mv->maxRadius : mr->maxRadius, f);
    f[3] = 1.0f - std::exp(-rate * p.dt);
    return true;
  }
  return false;
}

}  // namespace flurry::detail::ocl
