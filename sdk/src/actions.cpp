#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

#include "action_params.hpp"
#include "action_traits.hpp"
#include "effect/check_fields.hpp"
#include "effect/descriptors.hpp"
#include "flurry/actions.hpp"
#include "flurry/error.hpp"
#include "flurry/field.hpp"
#include "kernel_compat.hpp"

namespace flurry {

namespace {

/// The descriptor's name (effect/descriptors.hpp); Callback has none (no effect file holds it).
template <class T>
constexpr const char* nameOf() {
  if constexpr (desc::Described<T>)
    return desc::Describe<T>::name;
  else
    return "Callback";
}

// Each field against its descriptor's limit (effect/check_fields.hpp), then what no single
// field says (the Validator).

struct Validator {
  std::string where;

  void require(bool ok, const char* field, const std::string& why) const {
    if (!ok) throw InvalidArgument(where + "." + field, why);
  }
  template <class A>
  void operator()(const A&) const {}  // its fields say all
  void operator()(const SampledField& a) const {
    require(a.field != nullptr, "field", "no field given");
    a.field->validate((where + ".field").c_str());
  }
  void operator()(const SpeedClamp& a) const {
    require(a.maxSpeed >= a.minSpeed, "maxSpeed", "must be >= minSpeed");
  }
  // (Each key's fields are checked by their descriptors.)
  template <class Keys>
  void keys(const Keys& k) const {
    require(!k.empty(), "keys", "needs at least one key");
    for (std::size_t i = 1; i < k.size(); ++i)
      require(k[i].t >= k[i - 1].t, "keys", "key times must not decrease");
  }
  void operator()(const ColorOverLife& a) const { keys(a.keys); }
  void operator()(const SizeOverLife& a) const { keys(a.keys); }
  void operator()(const Bounce& a) const {
    const auto& s = a.surface.shape();
    const bool closed =
        std::holds_alternative<SphereDomain>(s) || std::holds_alternative<BoxDomain>(s);
    const bool ok = a.surface.isPlanar() || closed || std::holds_alternative<LineDomain>(s);
    if (!ok)
      throw InvalidArgument(where + ".surface",
                            std::string("a ") + a.surface.name() +
                                " cannot deflect (use a plane, rectangle, disc, triangle, sphere, "
                                "box, or a line segment in 2-D)");
    require(!a.inside || closed, "inside", "only a sphere or a box can keep particles inside");
    if (std::holds_alternative<LineDomain>(s)) {
      const auto& l = std::get<LineDomain>(s);
      const Vec3 n = glm::cross(l.p1 - l.p0, a.planeNormal);
      require(glm::dot(n, n) > 0, "planeNormal", "the segment lies along the plane's normal");
    }
  }
  void operator()(const Sink& a) const {
    require(a.mode != Sink::Mode::Hit || a.region.isPlanar(), "mode",
            "Hit needs a plane piece (plane, rectangle, disc, triangle)");
  }
  void operator()(const Callback& a) const {
    require(bool(a.function), "function", "no function given");
  }
};

using A = Attribute;

// Reads, then writes.
struct Access {
  using R = detail::AttributeAccess;
  // A force on the velocity, where the particle is.
  static R velocityForce(AttributeSet more = {}) {
    return {AttributeSet{A::Position, A::Velocity} | more, {A::Velocity}};
  }
  R operator()(const Gravity&) const { return velocityForce(); }
  R operator()(const Damping&) const { return velocityForce(); }
  R operator()(const RotDamping&) const { return {{A::RotVelocity}, {A::RotVelocity}}; }
  R operator()(const OrbitPoint&) const { return velocityForce(); }
  R operator()(const OrbitLine&) const { return velocityForce(); }
  R operator()(const Gravitate&) const { return velocityForce(); }
  R operator()(const Vortex&) const { return velocityForce(); }
  R operator()(const Jet&) const { return velocityForce({A::Id}); }
  R operator()(const Explosion&) const { return velocityForce(); }
  R operator()(const RandomAccel&) const { return velocityForce({A::Id}); }
  R operator()(const RandomDisplace&) const { return {{A::Position, A::Id}, {A::Position}}; }
  R operator()(const RandomVelocity&) const { return {{A::Id}, {A::Velocity}}; }
  R operator()(const RandomRotVelocity&) const { return {{A::Id}, {A::RotVelocity}}; }
  R operator()(const Turbulence&) const { return velocityForce(); }
  R operator()(const ElectricField&) const { return velocityForce({A::Charge, A::Mass}); }
  R operator()(const MagneticField&) const { return velocityForce({A::Charge, A::Mass}); }
  R operator()(const SampledField&) const { return velocityForce(); }
  R operator()(const Avoid&) const { return velocityForce(); }
  R operator()(const Follow&) const { return velocityForce(); }
  R operator()(const MatchVelocity&) const { return velocityForce(); }
  R operator()(const MatchRotVelocity&) const {
    return {{A::Position, A::RotVelocity}, {A::RotVelocity}};
  }
  R operator()(const TargetVelocity&) const { return {{A::Velocity}, {A::Velocity}}; }
  R operator()(const TargetRotVelocity&) const { return {{A::RotVelocity}, {A::RotVelocity}}; }
  R operator()(const TargetColor&) const { return {{A::Color}, {A::Color}}; }
  R operator()(const TargetSize&) const { return {{A::Size}, {A::Size}}; }
  R operator()(const SpeedClamp&) const { return {{A::Velocity}, {A::Velocity}}; }
  // Multiply reads the birth value: stored only for the lists that multiply.
  R operator()(const ColorOverLife& a) const {
    AttributeSet r{A::Age, A::Lifetime};
    if (a.mode == OverLifeMode::Multiply) r.insert(A::BirthColor);
    return {r, {A::Color}};
  }
  R operator()(const SizeOverLife& a) const {
    AttributeSet r{A::Age, A::Lifetime};
    if (a.mode == OverLifeMode::Multiply) r.insert(A::BirthSize);
    return {r, {A::Size}};
  }
  R operator()(const Bounce&) const {
    return {{A::Position, A::Velocity}, {A::Position, A::Velocity}};
  }
  R operator()(const Sink& a) const {
    AttributeSet r{A::Position};
    if (a.mode != Sink::Mode::Inside && a.mode != Sink::Mode::Outside) r.insert(A::Velocity);
    if (a.passThrough > 0.0f) r.insert(A::Id);  // a draw per particle
    return {r, {}};
  }
  R operator()(const SinkVelocity&) const { return {{A::Velocity}, {}}; }
  R operator()(const Block&) const { return {{A::Position, A::Visible}, {A::Visible}}; }
  R operator()(const KillOld&) const { return {{A::Age, A::Lifetime}, {}}; }
  R operator()(const Move&) const { return {{A::Position, A::Velocity}, {A::Position}}; }
  R operator()(const Constrain2D&) const {
    return {{A::Position, A::Velocity}, {A::Position, A::Velocity}};
  }
  R operator()(const CopyVertexB& a) const {
    R r;
    if (a.copyPosition) r = {{A::Position}, {A::PositionB}};
    if (a.copyVelocity) r.reads.insert(A::Velocity), r.writes.insert(A::VelocityB);
    return r;
  }
  R operator()(const Restore&) const {
    return {{A::Position, A::Velocity, A::PositionB}, {A::Position, A::Velocity}};
  }
  // Its declared lanes, all written back but the id (Position is always stored).
  R operator()(const Callback& a) const {
    AttributeSet w;
    for (int i = 0; i < int(A::Count); ++i)
      if (a.attributes.has(A(i)) && A(i) != A::Id) w.insert(A(i));
    return {a.attributes, w};
  }
};

}  // namespace

namespace detail {

int planarPiece(const Bounce& b) {
  const auto& s = b.surface.shape();
  if (std::holds_alternative<PlaneDomain>(s)) return FL_PIECE_PLANE;
  if (std::holds_alternative<RectangleDomain>(s)) return FL_PIECE_RECTANGLE;
  if (std::holds_alternative<TriangleDomain>(s)) return FL_PIECE_TRIANGLE;
  if (std::holds_alternative<DiscDomain>(s)) return FL_PIECE_DISC;
  if (std::holds_alternative<LineDomain>(s)) return FL_PIECE_SEGMENT;
  return -1;
}

cl::FlBounceParams bounceParams(const Bounce& a) {
  const auto xyz = [](Vec3 v) { return cl::FlXyz{v.x, v.y, v.z}; };
  cl::FlBounceParams b{};
  b.restitution = a.restitution;
  b.keep = 1.0f - a.friction;
  b.cutoff2 = a.cutoff * a.cutoff;
  auto plane = [&](Vec3 P, Vec3 N) {
    b.point = xyz(P);
    b.normal = xyz(N);
  };
  const auto& shape = a.surface.shape();
  if (const auto* pl = std::get_if<PlaneDomain>(&shape)) {
    plane(pl->point, pl->normal);
  } else if (const auto* r = std::get_if<RectangleDomain>(&shape)) {
    // Dual vectors give the (s, t) coordinates of a point of the plane, also for a rhombus.
    const Vec3 cu = glm::cross(r->v, r->normal), cv = glm::cross(r->normal, r->u);
    plane(r->origin, r->normal);
    b.piece.dual = {xyz(cu / glm::dot(r->u, cu)), xyz(cv / glm::dot(r->v, cv))};
  } else if (const auto* t = std::get_if<TriangleDomain>(&shape)) {
    const Vec3 e1 = t->p1 - t->p0, e2 = t->p2 - t->p0;
    const Vec3 c1 = glm::cross(e2, t->normal), c2 = glm::cross(t->normal, e1);
    plane(t->p0, t->normal);
    b.piece.dual = {xyz(c1 / glm::dot(e1, c1)), xyz(c2 / glm::dot(e2, c2))};
  } else if (const auto* d = std::get_if<DiscDomain>(&shape)) {
    plane(d->center, d->normal);
    b.piece.disc = {d->outerRadius * d->outerRadius, d->innerRadius * d->innerRadius};
  } else if (const auto* ln = std::get_if<LineDomain>(&shape)) {
    // 2-D: a wall standing on the group's plane, its normal in that plane.
    const Vec3 dir = ln->p1 - ln->p0;
    plane(ln->p0, glm::normalize(glm::cross(dir, a.planeNormal)));
    b.piece.segment = {xyz(dir), glm::dot(dir, dir)};
  } else if (const auto* s = std::get_if<SphereDomain>(&shape)) {
    const Vec3 C = s->center;
    const float R = s->outerRadius;
    b.point = xyz(C);
    b.piece.sphere = {R, R * R, 1.0f / R, std::abs(C.x) + std::abs(C.y) + std::abs(C.z) + R};
  }
  return b;
}

cl::FlActionParams actionParams(const Action& act, float dt) {
  const auto xyz = [](Vec3 v) { return cl::FlXyz{v.x, v.y, v.z}; };
  cl::FlActionParams p{};
  auto& own = p.own;
  // exp(-rate·dt) for the step length the record is made for (fl_force_decay): the kernels'
  // own exp, so that a step of another length (a newborn's) is the same function of its dt.
  auto decay = [&](float rate) { return kernel::fl_expf(-rate * dt); };
  auto falloff = [&](const Falloff& f) {
    p.falloff = {f.center.x, f.center.y, f.center.z, f.radius, f.power};
  };
  auto target = [&](float x, float y, float z, float w, float rate) {
    own.target = {{x, y, z, w}, rate, dt, decay(rate)};
  };
  auto damping = [&](Vec3 rate) {
    own.damping = {xyz(Vec3(decay(rate.x), decay(rate.y), decay(rate.z))), xyz(rate), dt};
  };
  auto match = [&](float rate, float maxRadius) {
    own.match = {rate, dt, maxRadius * maxRadius, 1.0f - decay(rate)};
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
  } else if (const auto* e = std::get_if<Explosion>(&act)) {
    const float twoVariance =
        2 * e->stddev * e->stddev;  // the acceleration's; the step its inverse
    own.explosion = {xyz(e->center), e->speed,           e->magnitude, e->epsilon,
                     e->time,        1.0f / twoVariance, twoVariance};
  } else if (const auto* ra = std::get_if<RandomAccel>(&act)) {
    falloff(ra->falloff);
  } else if (const auto* t = std::get_if<Turbulence>(&act)) {
    own.turbulence = {t->amplitude, t->frequency, xyz(t->drift), cl::fl_u32(t->octaves)};
    falloff(t->falloff);
  } else if (const auto* ef = std::get_if<ElectricField>(&act)) {
    own.electric = {xyz(ef->field)};
    falloff(ef->falloff);
  } else if (const auto* m = std::get_if<MagneticField>(&act)) {
    const Vec3 f = m->field;
    float B = glm::length(f);
    Vec3 direction = B > 0.0f ? f / B : Vec3(0.0f);
    if (std::isinf(B)) {
      // Its square overflowed (past ~1.8e19): |B| from the field scaled by its largest
      // component. (An infinite strength turned an uncharged particle by 0 * inf, a NaN.)
      const float big = std::max({std::abs(f.x), std::abs(f.y), std::abs(f.z)});
      const float l = glm::length(f / big);
      direction = f / big / l;
      B = std::min(big * l, std::numeric_limits<float>::max());
    }
    own.magnetic = {xyz(direction), B, xyz(f)};
    falloff(m->falloff);
  } else if (const auto* sf = std::get_if<SampledField>(&act)) {
    // (where the grid is, `first`, is the device's: its packer places the grid)
    const VectorField& field = *sf->field;
    own.sampledField = {xyz(field.origin),
                        field.voxelSize,
                        sf->strength,
                        sf->responsiveness,
                        dt,
                        decay(sf->responsiveness),
                        0u,
                        cl::fl_u32(field.dims.x),
                        cl::fl_u32(field.dims.y),
                        cl::fl_u32(field.dims.z),
                        sf->mode == SampledField::Mode::Velocity ? 1u : 0u};
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
  } else if (const auto* r = std::get_if<Restore>(&act)) {
    // In double, as bit patterns (params.h).
    own.restore = {std::bit_cast<cl::fl_u64>(double(r->start)),
                   std::bit_cast<cl::fl_u64>(double(r->start) + r->duration)};
  } else if (const auto* b = std::get_if<Bounce>(&act)) {
    own.bounce = bounceParams(*b);
  } else if (const auto* k = std::get_if<Sink>(&act)) {
    own.sink = {k->passThrough};
  } else if (const auto* av = std::get_if<Avoid>(&act)) {
    own.avoid = {av->magnitude, av->epsilon, av->lookAhead};
  } else if (const auto* c2 = std::get_if<Constrain2D>(&act)) {
    own.constrain2d = {xyz(c2->point), xyz(glm::normalize(c2->normal))};
  } else if (const auto* gr = std::get_if<Gravitate>(&act)) {
    own.pull = {gr->magnitude, gr->epsilon, gr->maxRadius * gr->maxRadius};
  } else if (const auto* f = std::get_if<Follow>(&act)) {
    own.pull = {f->magnitude, f->epsilon, f->maxRadius * f->maxRadius};
  } else if (const auto* mv = std::get_if<MatchVelocity>(&act)) {
    match(mv->magnitude, mv->maxRadius);
  } else if (const auto* mr = std::get_if<MatchRotVelocity>(&act)) {
    match(mr->magnitude, mr->maxRadius);
  }
  return p;
}

AttributeAccess attributeAccess(const Action& a) {
  return std::visit(Access{}, a);
}

bool movesParticles(const Action& a) {
  if (std::holds_alternative<Callback>(a)) return true;  // it may write what it did not declare
  const AttributeSet w = attributeAccess(a).writes;
  return w.has(Attribute::Position) || w.has(Attribute::Velocity);
}

bool isForce(const Action& a) {
  return std::holds_alternative<Gravity>(a) || std::holds_alternative<Damping>(a) ||
         std::holds_alternative<OrbitPoint>(a) || std::holds_alternative<OrbitLine>(a) ||
         std::holds_alternative<Gravitate>(a) || std::holds_alternative<Vortex>(a) ||
         std::holds_alternative<Jet>(a) || std::holds_alternative<Explosion>(a) ||
         std::holds_alternative<RandomAccel>(a) || std::holds_alternative<Turbulence>(a) ||
         std::holds_alternative<ElectricField>(a) || std::holds_alternative<MagneticField>(a) ||
         std::holds_alternative<SampledField>(a) || std::holds_alternative<Follow>(a);
}

void planMoves(const ActionList& list, std::vector<std::uint8_t>& gathered,
               std::vector<std::vector<std::uint32_t>>& forcesOf,
               std::vector<std::vector<std::uint32_t>>& guardsOf,
               std::vector<std::uint32_t>& curvedBy) {
  const auto& acts = list.actions();
  const Integrator integrator = list.integrator();
  gathered.assign(acts.size(), 0);
  forcesOf.resize(acts.size());
  guardsOf.resize(acts.size());
  for (auto& f : forcesOf) f.clear();
  for (auto& b : guardsOf) b.clear();
  curvedBy.assign(acts.size(), 0);
  if (integrator == Integrator::SemiImplicitEuler) return;
  // Explicit Euler moves on the straight line p + v·dt: the plain bounce is its own path.
  const bool curved = integrator == Integrator::Exact || integrator == Integrator::VelocityVerlet ||
                      integrator == Integrator::RK4;
  thread_local std::vector<std::uint32_t> pending, bounces;
  pending.clear();
  bounces.clear();
  for (std::uint32_t k = 0; k < acts.size(); ++k) {
    if (isForce(acts[k])) pending.push_back(k);
    if (std::holds_alternative<Bounce>(acts[k])) bounces.push_back(k);
    if (std::holds_alternative<Move>(acts[k])) {
      for (std::uint32_t f : pending) gathered[f] = 1;
      for (std::uint32_t b : bounces)
        if (curved && !pending.empty() && planarPiece(std::get<Bounce>(acts[b])) >= 0)
          curvedBy[b] = k + 1;
      forcesOf[k].assign(pending.begin(), pending.end());
      guardsOf[k].assign(bounces.begin(), bounces.end());
      pending.clear();
      bounces.clear();
    }
  }
}

bool hasClosedForm(const Action& a) {
  return std::holds_alternative<Gravity>(a) || std::holds_alternative<Damping>(a) ||
         std::holds_alternative<ElectricField>(a);
}

}  // namespace detail

namespace {

using detail::hasClosedForm;
using detail::isForce;

void checkExact(const std::vector<Action>& actions) {
  for (std::size_t i = 0; i < actions.size(); ++i)
    if (isForce(actions[i]) && !hasClosedForm(actions[i]))
      throw InvalidArgument("integrator",
                            "Exact needs forces with a closed form (Gravity, Damping, "
                            "ElectricField); actions[" +
                                std::to_string(i) + "] is " + actionName(actions[i]));
  for (const Action& a : actions) {
    const Falloff* f = nullptr;
    if (const auto* g = std::get_if<Gravity>(&a)) f = &g->falloff;
    if (const auto* d = std::get_if<Damping>(&a)) f = &d->falloff;
    if (const auto* e = std::get_if<ElectricField>(&a)) f = &e->falloff;
    if (f && f->radius < kInfinity)
      throw InvalidArgument("integrator", "Exact needs forces without a falloff radius");
  }
}

}  // namespace

const char* integratorName(Integrator i) {
  switch (i) {
    case Integrator::SemiImplicitEuler:
      return "SemiImplicitEuler";
    case Integrator::ExplicitEuler:
      return "ExplicitEuler";
    case Integrator::VelocityVerlet:
      return "VelocityVerlet";
    case Integrator::RK4:
      return "RK4";
    case Integrator::Exact:
      return "Exact";
  }
  return "?";
}

ActionList& ActionList::setIntegrator(Integrator integrator) {
  if (integrator == Integrator::Exact) checkExact(actions_);
  integrator_ = integrator;
  return *this;
}

ActionList& ActionList::setSubsteps(Substeps substeps) {
  if (!std::isfinite(substeps.maxStep) || substeps.maxStep < 0)
    throw InvalidArgument("substeps.maxStep", "must be finite and >= 0");
  if (!std::isfinite(substeps.maxDistance) || substeps.maxDistance < 0)
    throw InvalidArgument("substeps.maxDistance", "must be finite and >= 0");
  if (substeps.maxSubsteps < 1 || substeps.maxSubsteps > 256)
    throw InvalidArgument("substeps.maxSubsteps", "must be in [1, 256]");
  substeps_ = substeps;
  return *this;
}

std::string actionName(const Action& a) {
  return std::visit([](const auto& x) { return std::string(nameOf<std::decay_t<decltype(x)>>()); },
                    a);
}

ActionList& ActionList::add(Action action) {
  const std::string where =
      "actions[" + std::to_string(actions_.size()) + "]." + actionName(action);
  if (actions_.size() >= 250)
    throw InvalidArgument("actions", "an action list holds at most 250 actions");
  std::visit(
      [&](const auto& a) {
        if constexpr (desc::Described<std::decay_t<decltype(a)>>) desc::checkFields(a, where);
        Validator{where}(a);
      },
      action);
  if (integrator_ == Integrator::Exact) {
    std::vector<Action> next = actions_;
    next.push_back(action);
    checkExact(next);
  }
  actions_.push_back(std::move(action));
  return *this;
}

AttributeSet ActionList::attributes() const {
  AttributeSet s;
  for (const Action& a : actions_) {
    const detail::AttributeAccess use = detail::attributeAccess(a);
    s.insert(use.reads | use.writes);
  }
  return s;
}

bool ActionList::kills() const {
  for (const Action& a : actions_)
    if (std::holds_alternative<Sink>(a) || std::holds_alternative<KillOld>(a) ||
        std::holds_alternative<SinkVelocity>(a))
      return true;
  return false;
}

bool ActionList::readsNeighbours() const {
  for (const Action& a : actions_)
    if (std::holds_alternative<Gravitate>(a) || std::holds_alternative<Follow>(a) ||
        std::holds_alternative<MatchVelocity>(a) || std::holds_alternative<MatchRotVelocity>(a))
      return true;
  return false;
}

}  // namespace flurry
