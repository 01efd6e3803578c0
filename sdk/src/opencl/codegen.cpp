#include "codegen.hpp"

#include <cmath>
#include <cstring>
#include <sstream>
#include <type_traits>

#include "flurry/error.hpp"

namespace flurry::detail::ocl {

// Defined in the generated kernels_embedded.cpp (see CMakeLists.txt).
struct EmbeddedFile {
  const char* name;
  const char* text;
};
extern const EmbeddedFile kEmbeddedKernels[];
extern const unsigned kEmbeddedKernelCount;

const char* embeddedKernel(const char* name) {
  for (unsigned i = 0; i < kEmbeddedKernelCount; ++i)
    if (std::strcmp(kEmbeddedKernels[i].name, name) == 0) return kEmbeddedKernels[i].text;
  throw Error(std::string("OpenCL: no embedded kernel file named ") + name);
}

namespace {

struct AttrInfo {
  Attribute attribute;
  const char* macro;  // FL_HAS_<macro>
  const char* names[4];
  bool isUint;
};

// The canonical lane order and names; emit.cl uses these names.
constexpr AttrInfo kAttrs[] = {
    {Attribute::Position, "POSITION", {"px", "py", "pz"}, false},
    {Attribute::Velocity, "VELOCITY", {"vx", "vy", "vz"}, false},
    {Attribute::Color, "COLOR", {"r", "g", "b", "a"}, false},
    {Attribute::Size, "SIZE", {"size"}, false},
    {Attribute::Mass, "MASS", {"mass"}, false},
    {Attribute::Age, "AGE", {"age"}, false},
    {Attribute::Lifetime, "LIFETIME", {"life"}, false},
    {Attribute::Id, "ID", {"id"}, true},
    {Attribute::PrevPosition, "PREV_POSITION", {"prevx", "prevy", "prevz"}, false},
    {Attribute::Up, "UP", {"upx", "upy", "upz"}, false},
    {Attribute::RotVelocity, "ROT_VELOCITY", {"rotx", "roty", "rotz"}, false},
    {Attribute::Charge, "CHARGE", {"charge"}, false},
    {Attribute::Visible, "VISIBLE", {"vis"}, true},
    {Attribute::UserData, "USER_DATA", {"user"}, false},
};

const AttrInfo& info(Attribute a) {
  for (const auto& i : kAttrs)
    if (i.attribute == a) return i;
  return kAttrs[0];
}

std::string laneDecl(const LaneRef& l) {
  return std::string("__global ") + (info(l.attribute).isUint ? "uint" : "float") +
         "* restrict l_" + l.name;
}

// Two unit vectors completing unit n to an orthonormal basis: domain.cpp's basis(), so the
// device samples discs, cylinders and cones with the very same frame.
void basis(Vec3 n, Vec3& b1, Vec3& b2) {
  const float s = std::copysign(1.0f, n.z);
  const float a = -1.0f / (s + n.z);
  const float b = n.x * n.y * a;
  b1 = Vec3(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
  b2 = Vec3(b, s + n.y * n.y * a, -n.y);
}

void put(float* v, int at, Vec3 x) {
  v[at] = x.x;
  v[at + 1] = x.y;
  v[at + 2] = x.z;
}

// Which piece a planar Bounce surface is (FL_PIECE_*), or -1 for the sphere.
int pieceOf(const Domain& d) {
  const auto& s = d.shape();
  if (std::holds_alternative<PlaneDomain>(s)) return 0;
  if (std::holds_alternative<RectangleDomain>(s)) return 1;
  if (std::holds_alternative<TriangleDomain>(s)) return 2;
  if (std::holds_alternative<DiscDomain>(s)) return 3;
  return -1;
}

}  // namespace

std::vector<LaneRef> lanesOf(AttributeSet stored) {
  // An attribute added to the core after this table would be lost on the device: refuse it.
  for (int a = 0; a < int(Attribute::Count); ++a) {
    bool known = false;
    for (const auto& i : kAttrs) known |= i.attribute == Attribute(a);
    if (stored.has(Attribute(a)) && !known)
      throw Error("OpenCL backend: attribute '" + std::string(attributeName(Attribute(a))) +
                  "' is not stored on the device yet; use Backend::Cpu");
  }
  std::vector<LaneRef> out;
  for (const auto& i : kAttrs)
    if (stored.has(i.attribute))
      for (int c = 0; c < componentCount(i.attribute); ++c)
        out.push_back({i.attribute, c, i.names[c]});
  return out;
}

cl::FlDomain packDomain(const Domain& d) {
  if (d.shape().index() > FL_DOMAIN_BLOB)
    throw Error(std::string("OpenCL backend: a ") + d.name() +
                " domain is not supported on the device yet; use Backend::Cpu");
  cl::FlDomain o{};
  o.kind = cl::fl_u32(d.shape().index());
  float* v = o.v;
  std::visit(
      [&](const auto& s) {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, PointDomain>) {
          put(v, 0, s.p);
        } else if constexpr (std::is_same_v<T, LineDomain>) {
          put(v, 0, s.p0);
          put(v, 3, s.p1);
        } else if constexpr (std::is_same_v<T, TriangleDomain>) {
          put(v, 0, s.p0);
          put(v, 3, s.p1);
          put(v, 6, s.p2);
        } else if constexpr (std::is_same_v<T, PlaneDomain>) {
          put(v, 0, s.point);
          put(v, 3, s.normal);
        } else if constexpr (std::is_same_v<T, RectangleDomain>) {
          put(v, 0, s.origin);
          put(v, 3, s.u);
          put(v, 6, s.v);
        } else if constexpr (std::is_same_v<T, DiscDomain>) {
          Vec3 e1, e2;
          basis(s.normal, e1, e2);
          put(v, 0, s.center);
          put(v, 3, e1);
          put(v, 6, e2);
          v[9] = s.outerRadius;
          v[10] = s.innerRadius;
        } else if constexpr (std::is_same_v<T, BoxDomain>) {
          put(v, 0, s.min);
          put(v, 3, s.max);
        } else if constexpr (std::is_same_v<T, SphereDomain>) {
          put(v, 0, s.center);
          v[3] = s.outerRadius;
          v[4] = s.innerRadius;
        } else if constexpr (std::is_same_v<T, CylinderDomain> || std::is_same_v<T, ConeDomain>) {
          Vec3 origin, axis;
          if constexpr (std::is_same_v<T, CylinderDomain>) {
            origin = s.p0;
            axis = s.p1 - s.p0;
          } else {
            origin = s.apex;
            axis = s.base - s.apex;
          }
          Vec3 e1, e2;
          basis(glm::normalize(axis), e1, e2);
          put(v, 0, origin);
          put(v, 3, axis);
          put(v, 6, e1);
          put(v, 9, e2);
          v[12] = s.outerRadius;
          v[13] = s.innerRadius;
        } else if constexpr (std::is_same_v<T, BlobDomain>) {
          put(v, 0, s.center);
          v[3] = s.stddev;
        }
      },
      d.shape());
  return o;
}

namespace {

struct Packer {
  float dt;
  cl::FlActionParams& p;
  template <class A>
  void operator()(const A& a) const {
    if constexpr (std::is_same_v<A, Gravity>) {
      put(p.f, 0, Vec3(a.acceleration.x * dt, a.acceleration.y * dt, a.acceleration.z * dt));
    } else if constexpr (std::is_same_v<A, Damping>) {
      put(p.f, 0,
          Vec3(std::exp(-a.rate.x * dt), std::exp(-a.rate.y * dt), std::exp(-a.rate.z * dt)));
    } else if constexpr (std::is_same_v<A, Bounce>) {
      bounce(a);
    } else if constexpr (std::is_same_v<A, Sink>) {
      const cl::FlDomain d = packDomain(a.region);
      std::memcpy(p.f, d.v, sizeof d.v);
      p.u[0] = d.kind;
      p.f[16] = a.passThrough;
    }
    // KillOld, Move: no constants. Actions the device does not run never get here
    // (generateProgram rejects them first).
  }
  void bounce(const Bounce& a) const {
    p.f[6] = a.restitution;
    p.f[7] = 1.0f - a.friction;
    p.f[8] = a.cutoff * a.cutoff;
    const auto& shape = a.surface.shape();
    // As kernels.hpp apply(Bounce) prepares them.
    auto plane = [&](Vec3 P, Vec3 N) {
      put(p.f, 0, P);
      put(p.f, 3, N);
      p.f[9] = std::abs(P.x) + std::abs(P.y) + std::abs(P.z);
    };
    if (const auto* pl = std::get_if<PlaneDomain>(&shape)) {
      plane(pl->point, pl->normal);
    } else if (const auto* r = std::get_if<RectangleDomain>(&shape)) {
      const Vec3 cu = glm::cross(r->v, r->normal), cv = glm::cross(r->normal, r->u);
      const Vec3 du = cu / glm::dot(r->u, cu), dv = cv / glm::dot(r->v, cv);
      plane(r->origin, r->normal);
      put(p.f, 10, du);
      put(p.f, 13, dv);
    } else if (const auto* t = std::get_if<TriangleDomain>(&shape)) {
      const Vec3 e1 = t->p1 - t->p0, e2 = t->p2 - t->p0;
      const Vec3 c1 = glm::cross(e2, t->normal), c2 = glm::cross(t->normal, e1);
      const Vec3 d1 = c1 / glm::dot(e1, c1), d2 = c2 / glm::dot(e2, c2);
      plane(t->p0, t->normal);
      put(p.f, 10, d1);
      put(p.f, 13, d2);
    } else if (const auto* d = std::get_if<DiscDomain>(&shape)) {
      plane(d->center, d->normal);
      p.f[10] = d->outerRadius * d->outerRadius;
      p.f[11] = d->innerRadius * d->innerRadius;
    } else if (const auto* s = std::get_if<SphereDomain>(&shape)) {
      const Vec3 C = s->center;
      const float R = s->outerRadius;
      put(p.f, 0, C);
      p.f[9] = std::abs(C.x) + std::abs(C.y) + std::abs(C.z) + R;
      p.f[10] = R;
      p.f[11] = R * R;
      p.f[12] = 1.0f / R;
    }
  }
};

}  // namespace

void packActions(const ActionList& actions, float dt, std::vector<cl::FlActionParams>& out) {
  out.assign(std::max<std::size_t>(actions.size(), 1), cl::FlActionParams{});
  for (std::size_t k = 0; k < actions.size(); ++k)
    std::visit(Packer{dt, out[k]}, actions.actions()[k]);
}

namespace {

int fuzzyMode(const Fuzzy& f) {
  return f.spread == 0.0f ? 0 : f.distribution == Fuzzy::Distribution::Normal ? 2 : 1;
}

std::size_t kindOf(const Domain& d) {
  packDomain(d);  // throws for a kind the device cannot sample
  return d.shape().index();
}

std::string newbornCall(const Emitter& e, std::size_t t, bool oneType) {
  const ParticleType& p = e.types[t];
  std::ostringstream c;
  c << "fl_newborn(FL_LANE_ARGS, slot, id, age, at, " << (oneType ? 1 : 0)
    << ", em, types + em->typeFirst + " << t << "u, rng, " << kindOf(e.shape) << "u, "
    << kindOf(p.velocity) << "u, " << kindOf(p.color) << "u, " << kindOf(p.up) << "u, "
    << kindOf(p.rotVelocity) << "u, " << fuzzyMode(p.lifetime) << "u, " << fuzzyMode(p.alpha)
    << "u, " << fuzzyMode(p.size) << "u, " << fuzzyMode(p.mass) << "u, " << fuzzyMode(p.charge)
    << "u);";
  return c.str();
}

}  // namespace

std::string emitterSignature(const std::vector<Emitter>& emitters) {
  std::string s;
  for (const Emitter& e : emitters) {
    for (std::size_t t = 0; t < e.types.size(); ++t) s += newbornCall(e, t, e.types.size() == 1);
    s += '|';
  }
  return s;
}

GeneratedProgram generateProgram(const ActionList& actions, AttributeSet stored, bool fp64,
                                 const std::vector<Emitter>& emitters) {
  GeneratedProgram g;
  // What the act kernel loads (reads) and stores (writes).
  AttributeSet reads, writes;
  const bool prev = stored.has(Attribute::PrevPosition), age = stored.has(Attribute::Age);
  std::ostringstream body;
  for (std::size_t k = 0; k < actions.size(); ++k) {
    const Action& act = actions.actions()[k];
    const std::string ap = "&ap[" + std::to_string(k) + "]";
    const std::string code = std::to_string(k + 1) + "u";
    body << "  /* " << k << ": " << actionName(act) << " */\n  ";
    if (std::holds_alternative<Gravity>(act) || std::holds_alternative<Damping>(act)) {
      reads.insert(Attribute::Velocity);
      writes.insert(Attribute::Velocity);
      body << (std::holds_alternative<Gravity>(act) ? "fl_gravity(" : "fl_damping(") << ap
           << ", &vx, &vy, &vz);\n";
    } else if (const auto* b = std::get_if<Bounce>(&act)) {
      reads.insert({Attribute::Position, Attribute::Velocity});
      writes.insert({Attribute::Position, Attribute::Velocity});
      const int piece = pieceOf(b->surface);
      if (piece < 0 && !std::holds_alternative<SphereDomain>(b->surface.shape()))
        throw Error(std::string("OpenCL backend: Bounce on a ") + b->surface.name() +
                    " does not run on the device yet; use Backend::Cpu");
      if (piece < 0)
        body << "fl_bounce_sphere(" << ap << ", dt, &px, &py, &pz, &vx, &vy, &vz);\n";
      else
        body << "fl_bounce_planar(" << ap << ", " << piece
             << ", dt, &px, &py, &pz, &vx, &vy, &vz);\n";
    } else if (const auto* s = std::get_if<Sink>(&act)) {
      reads.insert(Attribute::Position);
      const bool pass = s->passThrough > 0.0f;
      if (pass) reads.insert(Attribute::Id);
      body << "fl_sink(" << ap << ", " << kindOf(s->region) << "u, " << (s->killInside ? 1 : 0)
           << ", " << (pass ? 1 : 0) << ", px, py, pz, " << (pass ? "id" : "0u") << ", " << code
           << ", &dead, seedLo, seedHi, step, streamBase + " << k << "u);\n";
    } else if (std::holds_alternative<KillOld>(act)) {
      reads.insert({Attribute::Age, Attribute::Lifetime});
      body << "fl_kill_old(age, life, " << code << ", &dead);\n";
    } else if (std::holds_alternative<Move>(act)) {
      reads.insert({Attribute::Position, Attribute::Velocity});
      writes.insert(Attribute::Position);
      if (prev) {
        writes.insert(Attribute::PrevPosition);
        body << "prevx = px; prevy = py; prevz = pz;\n  ";
      }
      body << "fl_move(dt, &px, &py, &pz, vx, vy, vz);\n";
      if (age) {
        reads.insert(Attribute::Age);
        writes.insert(Attribute::Age);
        body << "  age += dt;\n";
      }
      if (stored.has(Attribute::Up) && stored.has(Attribute::RotVelocity)) {
        reads.insert({Attribute::Up, Attribute::RotVelocity});
        writes.insert(Attribute::Up);
        body << "  fl_turn_up(dt, &upx, &upy, &upz, rotx, roty, rotz);\n";
      }
    } else {
      throw Error("OpenCL backend: action '" + actionName(act) + "' (actions[" + std::to_string(k) +
                  "]) does not run on the device yet; use Backend::Cpu");
    }
  }
  const bool kills = actions.kills();

  std::ostringstream s;
  s << "/* Flurry OpenCL program: generated for one action list. */\n"
    << "#pragma OPENCL FP_CONTRACT OFF\n";  // the CPU backend's float math has no FMAs
  if (fp64) s << "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n#define FL_FP64 1\n";
  const auto all = lanesOf(stored);
  for (const auto& i : kAttrs)
    if (stored.has(i.attribute)) s << "#define FL_HAS_" << i.macro << " 1\n";
  s << "#define FL_LANE_PARAMS ";
  for (std::size_t k = 0; k < all.size(); ++k) s << (k ? ", " : "") << laneDecl(all[k]);
  s << "\n#define FL_COPY_LANES(d, s) do {";
  for (const auto& l : all) s << " l_" << l.name << "[d] = l_" << l.name << "[s];";
  s << " } while (0)\n#define FL_LANE_ARGS ";
  for (std::size_t k = 0; k < all.size(); ++k) s << (k ? ", " : "") << "l_" << all[k].name;
  s << "\n";
  for (const char* f : {"params.h", "philox.h", "domain.cl", "actions.cl", "compact.cl", "emit.cl"})
    s << "/* ---- " << f << " */\n" << embeddedKernel(f) << "\n";

  // The newborns of each emitter and type, with their kinds as literals.
  s << "/* ---- generated: emission per emitter and type */\n"
       "FL_INLINE void fl_emit(FL_LANE_PARAMS, uint emitter, uint slot, uint id, float age,\n"
       "                       float3 at, __global const FlEmitter* em,\n"
       "                       __global const FlParticleType* types, FlRandom* rng) {\n"
       "  switch (emitter) {\n";
  for (std::size_t e = 0; e < emitters.size(); ++e) {
    const Emitter& em = emitters[e];
    s << "    case " << e << "u:\n";
    if (em.types.size() == 1) {
      s << "      " << newbornCall(em, 0, true) << "\n";
    } else {
      s << "      switch (fl_choose_type(em, types, rng)) {\n";
      for (std::size_t t = 0; t < em.types.size(); ++t)
        s << "        case " << t << "u: " << newbornCall(em, t, false) << " break;\n";
      s << "      }\n";
    }
    s << "      break;\n";
  }
  s << "  }\n}\n/* ---- tail.cl */\n" << embeddedKernel("tail.cl") << "\n";

  // The fused act kernel.
  const AttributeSet touched = reads | writes;
  for (const auto& l : all)
    if (touched.has(l.attribute)) g.actLanes.push_back(l);
  s << "/* ---- generated: the fused act kernel */\n__kernel void fl_act(";
  for (const auto& l : g.actLanes) s << laneDecl(l) << ", ";
  s << "__global uchar* restrict codes, __constant FlActionParams* ap,\n"
       "                     __global const uint* state, float dt, uint seedLo, uint seedHi,\n"
       "                     uint step, uint streamBase) {\n"
       "  const uint i = get_global_id(0);\n"
       "  if (i >= state[FL_STATE_SIZE]) return;\n";
  for (const auto& l : g.actLanes) {
    const char* type = info(l.attribute).isUint ? "uint" : "float";
    if (reads.has(l.attribute))
      s << "  " << type << " " << l.name << " = l_" << l.name << "[i];\n";
    else
      s << "  " << type << " " << l.name << ";\n";
  }
  s << "  uint dead = 0u;\n" << body.str();
  for (const auto& l : g.actLanes)
    if (writes.has(l.attribute)) s << "  l_" << l.name << "[i] = " << l.name << ";\n";
  if (kills) s << "  codes[i] = (uchar)dead;\n";
  s << "  (void)dead;\n}\n";
  g.source = s.str();
  // Correctly rounded division and sqrt: the CPU's are, and Bounce divides.
  g.options = "-cl-std=CL1.2 -cl-fp32-correctly-rounded-divide-sqrt";
  return g;
}

}  // namespace flurry::detail::ocl
