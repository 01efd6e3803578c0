// Deflectors, absorbers, blockers, 2-D constraints and the actions that read neighbours on
// the device: the calls the fused act kernel makes (kernels/surfaces.cl) and the constants
// they read.
#include <cmath>
#include <string>

#include "codegen.hpp"

namespace flurry::detail::ocl {

namespace {

// Which piece a planar Bounce surface is (FL_PIECE_*), or -1 for the sphere.
int pieceOf(const Domain& d) {
  const auto& s = d.shape();
  if (std::holds_alternative<PlaneDomain>(s)) return 0;
  if (std::holds_alternative<RectangleDomain>(s)) return 1;
  if (std::holds_alternative<TriangleDomain>(s)) return 2;
  if (std::holds_alternative<DiscDomain>(s)) return 3;
  return -1;
}

// As kernels.hpp apply(Bounce) prepares them. f[]: [0..2] plane point, [3..5] unit normal,
// [6] restitution, [7] 1 - friction, [8] cutoff^2, [9] scale (|P.x|+|P.y|+|P.z|, sphere
// |C|_1 + R), then by surface: rectangle/triangle [10..12] dual u, [13..15] dual v |
// disc [10] outer^2, [11] inner^2 | sphere [10] R, [11] R^2, [12] 1/R (center in [0..2]).
void packBounce(const Bounce& a, float* f) {
  f[6] = a.restitution;
  f[7] = 1.0f - a.friction;
  f[8] = a.cutoff * a.cutoff;
  const auto& shape = a.surface.shape();
  auto plane = [&](Vec3 P, Vec3 N) {
    putVec(f, 0, P);
    putVec(f, 3, N);
    f[9] = std::abs(P.x) + std::abs(P.y) + std::abs(P.z);
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

}  // namespace

bool generateSurfaceAction(const Action& act, ActionSource& s) {
  const std::string& ap = s.in.params;
  if (const auto* b = std::get_if<Bounce>(&act)) {
    s.reads.insert({Attribute::Position, Attribute::Velocity});
    s.writes.insert({Attribute::Position, Attribute::Velocity});
    const int piece = pieceOf(b->surface);
    const bool sphere = std::holds_alternative<SphereDomain>(b->surface.shape());
    if ((piece < 0 && !sphere) || b->inside)
      notOnDevice(std::string("Bounce ") + (b->inside ? "inside a " : "on a ") + b->surface.name());
    if (piece < 0)
      s.apply = "fl_bounce_sphere(" + ap + ", dt, &px, &py, &pz, &vx, &vy, &vz);\n";
    else
      s.apply = "fl_bounce_planar(" + ap + ", " + std::to_string(piece) +
                ", dt, &px, &py, &pz, &vx, &vy, &vz);\n";
    return true;
  }
  if (const auto* k = std::get_if<Sink>(&act)) {
    if (k->mode != Sink::Mode::Inside && k->mode != Sink::Mode::Outside)
      notOnDevice("a Sink in Enter, Leave or Hit mode");
    const bool killInside = k->mode == Sink::Mode::Inside ? k->killInside : !k->killInside;
    s.reads.insert(Attribute::Position);
    const bool pass = k->passThrough > 0.0f;
    if (pass) s.reads.insert(Attribute::Id);
    s.apply = "fl_sink(" + ap + ", " + std::to_string(k->region.shape().index()) + "u, " +
              (killInside ? "1" : "0") + ", " + (pass ? "1" : "0") + ", px, py, pz, " +
              (pass ? "id" : "0u") + ", " + s.in.code + ", &dead, seedLo, seedHi, step, " +
              s.in.stream + ");\n";
    return true;
  }
  return false;
}

bool packSurfaceAction(const Action& act, ActionPack& p) {
  if (const auto* b = std::get_if<Bounce>(&act)) {
    packBounce(*b, p.p.f);
    return true;
  }
  if (const auto* k = std::get_if<Sink>(&act)) {
    p.p.domain = packDomain(k->region);
    p.p.f[0] = k->passThrough;
    return true;
  }
  return false;
}

}  // namespace flurry::detail::ocl
