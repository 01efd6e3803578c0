#include "codegen.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <type_traits>

#include "../action_params.hpp"
#include "../action_traits.hpp"
#include "../shape_math.hpp"
#include "emission.hpp"
#include "flurry/callback.hpp"
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
  bool isUint;
};

// The canonical lane order; the lanes are named by kCallbackVariables (emit.cl uses them).
constexpr AttrInfo kAttrs[] = {
    {Attribute::Position, "POSITION", false},
    {Attribute::Velocity, "VELOCITY", false},
    {Attribute::Color, "COLOR", false},
    {Attribute::Size, "SIZE", false},
    {Attribute::Mass, "MASS", false},
    {Attribute::Age, "AGE", false},
    {Attribute::Lifetime, "LIFETIME", false},
    {Attribute::Id, "ID", true},
    {Attribute::PrevPosition, "PREV_POSITION", false},
    {Attribute::Up, "UP", false},
    {Attribute::RotVelocity, "ROT_VELOCITY", false},
    {Attribute::Charge, "CHARGE", false},
    {Attribute::Visible, "VISIBLE", true},
    {Attribute::UserData, "USER_DATA", false},
    {Attribute::PositionB, "POSITION_B", false},
    {Attribute::VelocityB, "VELOCITY_B", false},
    {Attribute::BirthColor, "BIRTH_COLOR", false},
    {Attribute::BirthSize, "BIRTH_SIZE", false},
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

// The frame the CPU's sampler draws discs, cylinders and cones in (kernels/domain.h), so the
// device samples them with the very same one.
void basis(Vec3 n, Vec3& b1, Vec3& b2) {
  kernel::fl_basis(n, &b1, &b2);
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
        out.push_back({i.attribute, c, kCallbackVariables[std::size_t(i.attribute)][c].data()});
  return out;
}

cl::FlDomain packDomain(const Domain& d) {
  // Meshes and unions need a data table: emission.hpp ShapePacker packs them with it (for
  // emitters, and actions' regions and sampled domains). Nothing else takes them (validation
  // refuses them as a Bounce surface); refused here rather than packed wrong.
  if (d.shape().index() > FL_DOMAIN_BLOB)
    throw Error(std::string("OpenCL backend: a ") + d.name() +
                " domain here does not run on the device yet; use Backend::Cpu");
  cl::FlDomain o{};
  o.kind = cl::fl_u32(d.shape().index());
  float* v = o.v;
  std::visit(
      [&](const auto& s) {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, PointDomain>) {
          putVec(v, 0, s.p);
        } else if constexpr (std::is_same_v<T, LineDomain>) {
          putVec(v, 0, s.p0);
          putVec(v, 3, s.p1);
        } else if constexpr (std::is_same_v<T, TriangleDomain>) {
          putVec(v, 0, s.p0);
          putVec(v, 3, s.p1);
          putVec(v, 6, s.p2);
          putVec(v, 9, s.normal);  // for Emitter::normalSpeed
        } else if constexpr (std::is_same_v<T, PlaneDomain>) {
          putVec(v, 0, s.point);
          putVec(v, 3, s.normal);
        } else if constexpr (std::is_same_v<T, RectangleDomain>) {
          putVec(v, 0, s.origin);
          putVec(v, 3, s.u);
          putVec(v, 6, s.v);
          putVec(v, 9, s.normal);
        } else if constexpr (std::is_same_v<T, DiscDomain>) {
          Vec3 e1, e2;
          basis(s.normal, e1, e2);
          putVec(v, 0, s.center);
          putVec(v, 3, e1);
          putVec(v, 6, e2);
          v[9] = s.outerRadius;
          v[10] = s.innerRadius;
          putVec(v, 11, s.normal);
        } else if constexpr (std::is_same_v<T, BoxDomain>) {
          putVec(v, 0, s.min);
          putVec(v, 3, s.max);
        } else if constexpr (std::is_same_v<T, SphereDomain>) {
          putVec(v, 0, s.center);
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
          basis(kernel::fl_normalize(axis), e1, e2);
          putVec(v, 0, origin);
          putVec(v, 3, axis);
          putVec(v, 6, e1);
          putVec(v, 9, e2);
          v[12] = s.outerRadius;
          v[13] = s.innerRadius;
        } else if constexpr (std::is_same_v<T, BlobDomain>) {
          putVec(v, 0, s.center);
          v[3] = s.stddev;
        }
      },
      d.shape());
  return o;
}

[[noreturn]] void notOnDevice(const std::string& what) {
  throw Error("OpenCL backend: " + what + " does not run on the device yet; use Backend::Cpu");
}

namespace {

// What of an action lives in the device's storage, beside its record: the packed form of the
// domain it samples or tests (a mesh's or union's data into `extra`, which the calls pass),
// a grid's or a curve's floats and where they start.
void packStorage(const Action& act, cl::FlActionParams& p, std::vector<float>& extra) {
  auto shape = [&](const Domain& d) { p.domain = ShapePacker{extra, {}, {}}.pack(d); };
  if (const auto* b = std::get_if<Bounce>(&act)) {
    p.domain = packDomain(b->surface);  // boxes, and the integrators' guard
  } else if (const auto* k = std::get_if<Sink>(&act)) {
    shape(k->region);
  } else if (const auto* sv = std::get_if<SinkVelocity>(&act)) {
    shape(sv->velocity);
  } else if (const auto* bl = std::get_if<Block>(&act)) {
    shape(bl->region);
  } else if (const auto* av = std::get_if<Avoid>(&act)) {
    shape(av->obstacle);
  } else if (const auto* j = std::get_if<Jet>(&act)) {
    shape(j->acceleration);
  } else if (const auto* ra = std::get_if<RandomAccel>(&act)) {
    shape(ra->acceleration);
  } else if (const auto* rp = std::get_if<RandomDisplace>(&act)) {
    shape(rp->displacement);
  } else if (const auto* rv = std::get_if<RandomVelocity>(&act)) {
    shape(rv->velocity);
  } else if (const auto* rr = std::get_if<RandomRotVelocity>(&act)) {
    shape(rr->rotVelocity);
  } else if (const auto* sf = std::get_if<SampledField>(&act)) {
    p.own.sampledField.first = cl::fl_u32(extra.size());
    for (const Vec3& v : sf->field->data) extra.insert(extra.end(), {v.x, v.y, v.z});
  } else if (const auto* co = std::get_if<ColorOverLife>(&act)) {
    p.own.curve = {cl::fl_u32(extra.size()), cl::fl_u32(co->keys.size())};
    for (const auto& k : co->keys)
      extra.insert(extra.end(), {k.t, k.color.r, k.color.g, k.color.b, k.color.a});
  } else if (const auto* so = std::get_if<SizeOverLife>(&act)) {
    p.own.curve = {cl::fl_u32(extra.size()), cl::fl_u32(so->keys.size())};
    for (const auto& k : so->keys) extra.insert(extra.end(), {k.t, k.size});
  }
}

}  // namespace

void packActions(const ActionList& actions, float dt, std::vector<cl::FlActionParams>& out,
                 std::vector<float>& extra) {
  out.assign(std::max<std::size_t>(actions.size(), 1), cl::FlActionParams{});
  extra.clear();
  for (std::size_t k = 0; k < actions.size(); ++k) {
    const Action& a = actions.actions()[k];
    out[k] = actionParams(a, dt);  // the record, as the CPU's pass makes it
    packStorage(a, out[k], extra);
  }
  if (extra.empty()) extra.push_back(0.0f);  // a buffer is never empty
}

namespace {

// The gathered forces' accelerations at the state named by prefix `pre` and time `t`, into
// pre + "ax" ... (integrate.hpp evaluate()).
std::string evaluate(const std::vector<std::string>& accels, const std::string& pre,
                     const std::string& t, const std::string& out) {
  std::string s = "{ const float px = " + pre + "px, py = " + pre + "py, pz = " + pre +
                  "pz, vx = " + pre + "vx, vy = " + pre + "vy, vz = " + pre +
                  "vz;\n  const fl_real t = " + t +
                  ";\n  float ax = 0.0f, ay = 0.0f, az = 0.0f;\n  (void)t;\n";
  for (const std::string& a : accels) s += "  " + a;
  s += "  " + out + "ax = ax; " + out + "ay = ay; " + out + "az = az; }\n";
  return s;
}

// Move by an integrator other than semi-implicit Euler over the forces `accels` (in list
// order), as integrate.hpp integrate() does it: the per-axis updates are kernels/integrate.h.
// dampingParams[j]: the params of force j when it is a Damping (Exact takes its rates), else "".
std::string integrateMove(Integrator integrator, const std::vector<std::string>& accels,
                          const std::vector<std::string>& dampingParams, bool prev, bool age) {
  std::ostringstream c;
  c << "{ /* integrator */\n";
  if (prev) c << "prevx = px; prevy = py; prevz = pz;\n";
  // The state at the step's start, under names the forces' code can shadow px.. with.
  c << "const float c_px = px, c_py = py, c_pz = pz, c_vx = vx, c_vy = vy, c_vz = vz;\n"
       "float a0ax, a0ay, a0az;\n";
  switch (integrator) {
    case Integrator::ExplicitEuler:
      c << evaluate(accels, "c_", "time", "a0");
      for (const char* d : {"x", "y", "z"})
        c << "fl_euler_explicit(a0a" << d << ", dt, &p" << d << ", &v" << d << ");\n";
      break;
    case Integrator::VelocityVerlet:
      c << evaluate(accels, "c_", "time", "a0");
      c << "float p1px, p1py, p1pz, p1vx, p1vy, p1vz, a1ax, a1ay, a1az;\n";
      for (const char* d : {"x", "y", "z"})
        c << "fl_verlet_predict(p" << d << ", v" << d << ", a0a" << d << ", dt, &p1p" << d
          << ", &p1v" << d << ");\n";
      c << evaluate(accels, "p1", "time + (fl_real)dt", "a1");
      for (const char* d : {"x", "y", "z"})
        c << "fl_verlet_finish(p1p" << d << ", a0a" << d << ", a1a" << d << ", dt, &p" << d
          << ", &v" << d << ");\n";
      break;
    case Integrator::RK4: {
      c << "float sppx = 0.0f, sppy = 0.0f, sppz = 0.0f, spvx = 0.0f, spvy = 0.0f, spvz = "
           "0.0f;\n"
           "float stpx = px, stpy = py, stpz = pz, stvx = vx, stvy = vy, stvz = vz;\n";
      const char* h[4] = {"0.0f", "0.5f", "0.5f", "1.0f"};
      const char* w[4] = {"1.0f", "2.0f", "2.0f", "1.0f"};
      for (int k = 0; k < 4; ++k) {
        c << "{ float a1ax, a1ay, a1az;\n"
          << evaluate(accels, "st", std::string("time + (fl_real)(") + h[k] + " * dt)", "a1")
          << "const float next = " << (k < 3 ? std::string(h[k + 1]) + " * dt" : "0.0f") << ";\n";
        for (const char* d : {"x", "y", "z"})
          c << "fl_rk4_stage(p" << d << ", v" << d << ", stv" << d << ", a1a" << d << ", " << w[k]
            << ", next, &spp" << d << ", &spv" << d << ", &stp" << d << ", &stv" << d << ");\n";
        c << "}\n";
      }
      for (const char* d : {"x", "y", "z"})
        c << "fl_rk4_finish(spp" << d << ", spv" << d << ", dt, &p" << d << ", &v" << d << ");\n";
      break;
    }
    case Integrator::Exact: {
      // Constant acceleration with per-axis linear drag: Damping's rates go to k.
      std::vector<std::string> constant;
      c << "float kx = 0.0f, ky = 0.0f, kz = 0.0f;\n";
      for (std::size_t j = 0; j < accels.size(); ++j)
        if (dampingParams[j].empty()) constant.push_back(accels[j]);
      c << evaluate(constant, "c_", "time", "a0");
      for (std::size_t j = 0; j < accels.size(); ++j)
        if (!dampingParams[j].empty()) {
          const std::string& d = dampingParams[j];
          const std::string k = d + "->own.damping.rate.";
          c << "kx += " << k << "x; ky += " << k << "y; kz += " << k << "z;\n";
        }
      for (const char* d : {"x", "y", "z"})
        c << "fl_exact_step(a0a" << d << ", k" << d << ", dt, &p" << d << ", &v" << d << ");\n";
      break;
    }
    case Integrator::SemiImplicitEuler:
      break;
  }
  if (age) c << "age += dt;\n";
  c << "}\n";
  return c.str();
}

}  // namespace

std::uint32_t stepSubsteps(const ActionList& actions, double dt) {
  const Substeps& sub = actions.substeps();
  double n = 1;
  if (sub.maxStep > 0) n = std::max(n, std::ceil(dt / sub.maxStep));
  return std::uint32_t(std::min<double>(n, sub.maxSubsteps));
}

// One step of the list for one particle: the sub-step count, the sub-steps, the NaN guard.
// In scope: dtBits (the step's length), nsubStep, state, the lane registers, and the
// particle's own part of the step: fl_len (its length: the step's, or a newborn's time left)
// and fl_t0 (its start time) as fl_real. Everything made from dt is made from the particle's
// sub-step length, so a newborn runs the list for its own time (issue #11).
std::string stepSource(const std::string& body, const Substeps& sub, bool byDistance,
                       AttributeSet stored, bool guarded) {
  std::ostringstream s;
  if (guarded) s << "  const float fl_start_x = px, fl_start_y = py, fl_start_z = pz;\n";
  // Sub-steps as fused_pass.cpp: dt / n in double, each with its own time and streams.
  // nsubStep: by Substeps::maxStep, from the host; then by the fastest particle, which
  // fl_max_speed left in the state (its |v|^2 as float bits).
  // A list without sub-steps gets a literal 1, so the loop folds away.
  if (sub.maxStep > 0 || byDistance)
    s << "  uint nsub = nsubStep;\n";
  else
    s << "  const uint nsub = 1u; (void)nsubStep;\n";
  if (byDistance) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9e", double(sub.maxDistance));  // "2f" is no literal
    s << "  {\n    const float vmax = sqrt(as_float(state[FL_STATE_MAX_SPEED2]));\n"
         "    if (isfinite(vmax)) {\n"
         "      const fl_real m = ceil((fl_real)vmax * fl_real_from_bits(dtBits) / (fl_real)"
      << buf << "f);\n      const fl_real cap = (fl_real)" << sub.maxSubsteps
      << "u;\n      if (m > (fl_real)nsub) nsub = (uint)(m < cap ? m : cap);\n    }\n  }\n";
  }
  if (sub.maxStep > 0 || byDistance)
    s << "  const float dt = (float)(fl_len / (fl_real)nsub);\n";
  else
    s << "  const float dt = (float)fl_len;\n";
  s << ""
       "  uint dead = 0u;\n"
    // One sub-step: a block, not a loop (PoCL runs barriers in a loop less well).
    << (sub.maxStep > 0 || byDistance ? "  for (uint sub = 0u; sub < nsub; ++sub) {\n"
                                      : "  {\n    const uint sub = 0u;\n")
    << ""
       "    const fl_real time = fl_t0 + (fl_real)sub * (fl_real)dt;\n"
       "    const uint streamSub = streamBase + (sub << 8);\n"
       "    (void)time; (void)streamSub;\n"
    << body << "  }\n";
  // The NaN guard (fused_pass.cpp guardFinite): position and velocity, by their bits.
  s << "  {\n    uint bad = 0u;\n";
  for (const char* c : {"px", "py", "pz"})
    s << "    bad |= (as_uint(" << c << ") & 0x7f800000u) == 0x7f800000u;\n";
  if (stored.has(Attribute::Velocity))
    for (const char* c : {"vx", "vy", "vz"})
      s << "    bad |= (as_uint(" << c << ") & 0x7f800000u) == 0x7f800000u;\n";
  s << "    dead = bad ? FL_NON_FINITE_CODE : dead;\n  }\n";
  return s.str();
}

// Hair mode (hair.cpp simulateHair): after the birth step (fl_act, compaction) each survivor
// runs the list to its death in one work item, recording a strand vertex every `every`
// steps, the first where the birth step left it. The group was empty before the step's
// emission, so the survivors are [0, m) and a strand's slot is its particle's id - firstId
// (the host zeroes the counts: newborns that died in their birth step make no strand).
// Kills are counted into the state per kill code; those that outlive their strand into
// FL_STATE_HAIR_ALIVE (the CPU counts them as killed by age).
std::string hairKernel(const std::string& stepCode, const std::vector<LaneRef>& all,
                       AttributeSet stored) {
  std::ostringstream s;
  s << "/* ---- generated: hair mode */\n__kernel void fl_hair(FL_LANE_PARAMS,\n"
       "    __global const FlActionParams* ap, __global uint* state,\n"
       "    __global const float* restrict extra, __global const float* restrict snap,\n"
       "    ulong dtBits, ulong timeBits, uint seedLo, uint seedHi, uint step0,\n"
       "    uint streamBase, uint nsubStep, uint snapStride, uint every, uint maxVertices,\n"
       "    __global float* restrict strandP, __global float* restrict strandC,\n"
       "    __global float* restrict strandR, __global uint* restrict strandCount) {\n"
       "  const uint i = get_global_id(0);\n"
       "  const uint m = state[FL_STATE_OLD_SIZE] - state[FL_STATE_DEAD];\n"
       "  if (i == 0u) state[FL_STATE_SIZE] = 0u; /* a hair group keeps strands, not particles */\n"
       "  if (i >= m) return;\n"
       "  const uint n = 0u, snapN = 0u;\n"
       "  (void)extra; (void)snap; (void)snapN; (void)snapStride; (void)seedLo; (void)seedHi;\n"
       "  (void)n;\n";
  for (const auto& l : all)
    s << "  " << (info(l.attribute).isUint ? "uint " : "float ") << l.name << " = l_" << l.name
      << "[i];\n";
  const bool color = stored.has(Attribute::Color), size = stored.has(Attribute::Size);
  // Strands in id order, from the first of the particles the step began with (a sub-emitter's
  // newborns, appended by the host: ids just before the step's own) to its last newborn.
  s << "  const uint strand = id - (state[FL_STATE_FIRST_ID] - (state[FL_STATE_OLD_SIZE] - "
       "state[FL_STATE_BORN]));\n"
       "  uint count = 0u;\n"
       "#define FL_RECORD() do { if (count < maxVertices) { const uint o = strand * maxVertices + "
       "count;"
       " strandP[3u * o] = px; strandP[3u * o + 1u] = py; strandP[3u * o + 2u] = pz;"
    << (color ? " strandC[4u * o] = r; strandC[4u * o + 1u] = g; strandC[4u * o + 2u] = b;"
                " strandC[4u * o + 3u] = a;"
              : " strandC[4u * o] = 1.0f; strandC[4u * o + 1u] = 1.0f; strandC[4u * o + 2u] ="
                " 1.0f; strandC[4u * o + 3u] = 1.0f;")
    << " strandR[o] = " << (size ? "size" : "0.05f") << "; ++count; } } while (0)\n"
    << "  FL_RECORD();\n"
       "  const uint maxSteps = maxVertices * every;\n"
       "  fl_real t0 = fl_real_from_bits(timeBits);\n"
       "  uint alive = 1u;\n"
       "  for (uint k = 1u; k <= maxSteps; ++k) {\n"
       "    const uint fl_step = step0 + (k - 1u);\n"
       "    uint killed;\n"
       "    {\n"
       "      const fl_real fl_len = fl_real_from_bits(dtBits), fl_t0 = t0;\n"
    << stepCode
    << "      killed = dead;\n"
       "    }\n"
       "    if (killed != 0u) {\n"
       "      atomic_inc(&state[FL_STATE_KILLS + killed - 1u]);\n"
       "      alive = 0u;\n"
       "      break;\n"
       "    }\n"
       "    if (k % every == 0u) FL_RECORD();\n"
       "    t0 += fl_real_from_bits(dtBits);\n"
       "  }\n"
       "#undef FL_RECORD\n"
       "  if (alive) atomic_inc(&state[FL_STATE_HAIR_ALIVE]);\n"
       "  strandCount[strand] = count;\n"
       "}\n";
  return s.str();
}

namespace {

// What a culled action still does to stay bitwise exact (fused_pass.cpp applyCulled), or
// false when it is never culled (no finite reach: cpu_backend.cpp actionReach, by the
// action's kind; the host's reach in extra, scale >= 0, says whether it is this step).
bool culledCode(const Action& a, std::size_t k, std::string& code) {
  code.clear();
  if (const auto* b = std::get_if<Bounce>(&a)) {
    const auto& s = b->surface.shape();
    return std::holds_alternative<RectangleDomain>(s) ||
           std::holds_alternative<TriangleDomain>(s) || std::holds_alternative<DiscDomain>(s) ||
           std::holds_alternative<SphereDomain>(s) ||
           (std::holds_alternative<BoxDomain>(s) && !b->inside);
  }
  if (const auto* s = std::get_if<Sink>(&a)) {
    return s->mode != Sink::Mode::Outside;  // one that kills outside its region reaches everywhere
  }
  if (std::holds_alternative<Block>(a)) {
    // The first blocker starts from "visible" (its apply, kept in the source, defined it).
    code = "#if FL_FIRST_BLOCKER == " + std::to_string(k) + "\nvis = 1u;\n#endif\n";
    return true;
  }
  if (const auto* g = std::get_if<Gravity>(&a)) {
    if (!(g->falloff.radius < kInfinity)) return false;
    // fl_gravity_falloff with its weight +0: v + a·(dt·0) turns -0 into +0.
    const std::string acc = "(ap + " + std::to_string(k) + ")->own.gravity.acceleration.";
    code = "vx = vx + " + acc + "x * (dt * 0.0f);\nvy = vy + " + acc +
           "y * (dt * 0.0f);\nvz = vz + " + acc + "z * (dt * 0.0f);\n";
    return true;
  }
  if (const auto* d = std::get_if<Damping>(&a)) return d->falloff.radius < kInfinity;
  return false;
}

// How the work-group's bounds follow action k when it runs, without a gather (the host
// says in extra, reach [8], whether this action qualifies): a Bounce that does not speed
// particles up ends each path within the longest path (bounds [6]) of a point of the old
// one, its new start within twice; a Gravity of weight <= 1 lengthens paths by at most
// |a|·dt² (the sum of its axes in reach [9]); a slowing Damping keeps each path within its
// old one. "" for an action the bounds cannot follow: they are gathered again.
std::string followCode(const Action& a, const std::string& r) {
  const std::string lost = "    else fl_grow = INFINITY;\n";
  if (std::holds_alternative<Bounce>(a))
    return "    if (" + r + "[8] > 0.0f) fl_grow += 2.0f * fl_rmax;\n" + lost;
  if (std::holds_alternative<Gravity>(a))
    return "    if (" + r + "[8] > 0.0f) {\n      const float fl_d = " + r +
           "[9] * fl_dtmax * fl_dtmax;\n      fl_grow += fl_d;\n      fl_rmax += fl_d;\n"
           "    }\n" +
           lost;
  if (std::holds_alternative<Damping>(a))
    return "    if (!(" + r + "[8] > 0.0f)) fl_grow = INFINITY;\n";
  return "";
}

// The list's body with spatial culling. The work-group's swept bounds are gathered
// (fl_cull_put into local memory, a barrier, one work-item reduces them and decides, a
// barrier) at points chosen here: before the first action that may be culled, and again
// before the next one after an action that moves particles in a way the bounds cannot
// follow (followCode; a Move). Each gather is unconditional, under no branch but the
// sub-step loop (whose count is the same for the whole group), as PoCL needs (barriers under
// run-time branches hung it), and a barrier costs PoCL a parallel region: hence few of them.
// The deciding work-item takes every decision up to the next gather: an action whose reach
// (the host's, in extra) the bounds cannot touch, widened by how far the paths may have left
// them since (fl_grow, which it follows through the actions that run), is skipped. It leaves
// a flag per action and the list of the actions that run, so that a run of consecutive
// actions that may be culled and do nothing when culled is one loop over that list (PoCL
// runs each work-item's code on its own: 32 skipped floors were 32 tests per particle). A
// skip is counted once per work-group.
std::string cullingBody(const std::vector<Action>& acts, const std::string& body,
                        const std::vector<std::size_t>& marks, const std::vector<int>& placed) {
  const std::size_t n = acts.size();
  const std::string flags = "FL_CULL_LOCAL + ",
                    list = "FL_CULL_LOCAL + " + std::to_string(n) + "u + ";
  const std::string count = "FL_CULL_LOCAL + " + std::to_string(2 * n) + "u";
  std::vector<std::string> piece(n), follow(n), culled(n);
  std::vector<bool> cull(n), moves(n);
  for (std::size_t k = 0; k < n; ++k) {
    piece[k] = body.substr(marks[k], marks[k + 1] - marks[k]);
    // A user's callback may write global memory itself: only for live particles.
    if (std::holds_alternative<Callback>(acts[k]))
      piece[k] = "    if (fl_live) {\n" + piece[k] + "    }\n";
    const std::string r = "(extra + reachOff + " + std::to_string(k * FL_REACH_FLOATS) + "u)";
    moves[k] = placed[k] != 0 && movesParticles(acts[k]);
    follow[k] = placed[k] == 1 && moves[k] ? followCode(acts[k], r) : "";
    cull[k] = placed[k] == 1 && culledCode(acts[k], k, culled[k]);
  }
  // In a list run: may be culled, and does nothing when culled.
  const auto listed = [&](std::size_t k) { return cull[k] && culled[k].empty(); };
  std::ostringstream s;
  s << "    uint fl_na = 0u, fl_e = 0u; /* the actions that run, and the next one */\n"
       "    (void)fl_na; (void)fl_e;\n";
  bool stale = true;  // no bounds gathered since the sub-step's start or the last move
  for (std::size_t k = 0; k < n; ++k) {
    if (cull[k] && stale) {
      // The decisions up to the next gather, by one work-item.
      s << "    fl_cull_put(fl_red, fl_live, dt, px, py, pz, vx, vy, vz);\n"
           "    barrier(CLK_LOCAL_MEM_FENCE);\n"
           "    if (get_local_id(0) == 0u) {\n"
           "      float fl_box[7];\n"
           "      fl_cull_box(fl_red, fl_box);\n"
           "      /* The longest path, how far paths may have left the box since */\n"
           "      float fl_rmax = fl_box[6], fl_grow = 0.0f;\n"
           "      const float fl_dtmax = (float)(fl_real_from_bits(dtBits) / (fl_real)nsub);\n"
           "      uint fl_run, fl_skip = 0u;\n"
           "      (void)fl_rmax; (void)fl_dtmax;\n"
           "      fl_na = 0u;\n";
      for (std::size_t j = k; j < n; ++j) {
        const std::string r = "(extra + reachOff + " + std::to_string(j * FL_REACH_FLOATS) + "u)";
        if (cull[j]) {
          s << "      fl_run = !(fl_grow <= fl_cull_gap(fl_box, " << r << "));\n"
            << "      fl_red[" << flags << j << "u] = (int)fl_run;\n"
            << "      if (fl_run) {\n";
          if (listed(j)) s << "      fl_red[" << list << "fl_na++] = " << j << ";\n";
          s << follow[j] << "      } else {\n        ++fl_skip;\n      }\n";
        } else if (moves[j]) {
          if (follow[j].empty()) break;  // the next gather decides from here
          s << follow[j];
        }
      }
      s << "      fl_red[" << count << "] = (int)fl_na;\n"
        << "      if (fl_skip) atomic_add(&state[FL_STATE_CULLED], fl_skip);\n"
           "    }\n"
           "    barrier(CLK_LOCAL_MEM_FENCE);\n"
           "    fl_na = (uint)fl_red["
        << count << "];\n    fl_e = 0u;\n";
      stale = false;
    }
    if (listed(k)) {
      std::size_t last = k;
      while (last + 1 < n && listed(last + 1)) ++last;
      if (last == k) {
        s << "    if (fl_red[" << flags << k << "u]) {\n" << piece[k] << "    }\n";
      } else {
        s << "    for (; fl_e < fl_na; ++fl_e) {\n"
             "      const int fl_k = fl_red["
          << list << "fl_e];\n      if (fl_k > " << last << ") break;\n"
          << "      switch (fl_k) {\n";
        for (std::size_t j = k; j <= last; ++j)
          s << "      case " << j << ": {\n" << piece[j] << "      } break;\n";
        s << "      default: break;\n      }\n    }\n";
      }
      k = last;
    } else if (cull[k]) {
      s << "    if (fl_red[" << flags << k << "u]) {\n" << piece[k] << "    } else {\n";
      std::istringstream lines(culled[k]);
      for (std::string line; std::getline(lines, line);) s << "    " << line << "\n";
      s << "    }\n";
    } else {
      s << piece[k];
    }
    if (moves[k] && follow[k].empty()) stale = true;
  }
  return s.str();
}

}  // namespace

std::string trailProgramSource(bool fp64) {
  std::ostringstream s;
  s << "/* Flurry OpenCL program: trails. */\n";
  if (fp64) s << "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n#define FL_FP64 1\n";
  for (const char* f : {"compat_opencl.h", "math.h", "params.h", "compact.cl", "trail.cl"})
    s << "/* ---- " << f << " */\n" << embeddedKernel(f) << "\n";
  return s.str();
}

GeneratedProgram generateProgram(const ActionList& actions, AttributeSet stored, bool fp64,
                                 const std::string& emitSource, bool hair, bool cull,
                                 bool collisions) {
  GeneratedProgram g;
  g.neighbours = actions.readsNeighbours();
  // What the act kernel loads (reads) and stores (writes).
  AttributeSet reads, writes;
  const Integrator integrator = actions.integrator();
  std::ostringstream body;
  bool guarded = false;  // some Bounce is guarded: keep where each particle began the step
  const auto& acts = actions.actions();
  std::vector<ActionSource> sources(acts.size());
  for (std::size_t k = 0; k < acts.size(); ++k) {
    const Action& act = acts[k];
    ActionSource& src = sources[k];
    src.in.index = k;
    src.in.stored = stored;
    src.in.params = "(ap + " + std::to_string(k) + ")";
    src.in.code = std::to_string(k + 1) + "u";
    src.in.stream = "(streamSub + " + std::to_string(k) + "u)";
    const AttributeAccess use = attributeAccess(act);  // the CPU's, stated once
    src.reads = use.reads;
    src.writes = use.writes;
    if (!generateCoreAction(act, src) && !generateForceAction(act, src) &&
        !generateSurfaceAction(act, src))
      notOnDevice("action '" + actionName(act) + "' (actions[" + std::to_string(k) + "])");
  }
  // How each integrating Move takes the forces and Bounces before it: the CPU's plan
  // (action_traits.hpp planMoves), read here, not derived again.
  std::vector<std::uint8_t> gathered;
  std::vector<std::vector<std::uint32_t>> forcesOf, guardsOf;
  std::vector<std::uint32_t> curvedBy;
  planMoves(actions, gathered, forcesOf, guardsOf, curvedBy);
  for (std::size_t k = 0; k < acts.size(); ++k)
    if (gathered[k] && sources[k].accel.empty())
      notOnDevice(actionName(acts[k]) + " under an integrator");
  auto accelerations = [&](const std::vector<std::uint32_t>& forces) {
    std::vector<std::string> a;
    for (std::uint32_t f : forces) a.push_back(sources[f].accel);
    return a;
  };
  // Where each action's code starts in `body`, and how it was placed there: 0 evaluated by
  // the next Move (no code), 1 its own update (src.apply), 2 other code (a Move's integrator,
  // a Bounce on the curved path).
  std::vector<std::size_t> marks(acts.size() + 1, 0);
  std::vector<int> placed(acts.size(), 2);
  // Collision events: a Bounce that changed a live particle's velocity logs it, from the
  // state before it (`was`: fl_b_ on the curve, fl_c_ otherwise) and the acceleration it
  // bounced with. A newborn's sub-step began (nsub - sub) of its sub-steps before t1.
  if (collisions) reads.insert(Attribute::Id);
  auto logCollision = [&](std::size_t k, const char* was, const std::string& acc) {
    const auto& b = std::get<Bounce>(acts[k]);
    const auto& shape = b.surface.shape();
    const int solid = std::holds_alternative<SphereDomain>(shape) ? 1
                      : std::holds_alternative<BoxDomain>(shape)  ? 2
                                                                  : 0;
    const std::string w = was;
    std::ostringstream c;
    // (FL_LOG_HITS: in fl_act_one only; fl_hair runs the list without it)
    c << "#ifdef FL_LOG_HITS\n    if (i < n && dead == 0u && (vx != " << w << "vx || vy != " << w
      << "vy || vz != " << w << "vz))\n      fl_log_collision((ap + " << k << "), " << solid << ", "
      << (b.inside ? 1 : 0) << ", " << w << "px, " << w << "py, " << w << "pz, " << w << "vx, " << w
      << "vy, " << w << "vz, " << acc << ", dt,\n"
      << "          i >= n0 ? t1 - (fl_real)dt * (fl_real)(nsub - sub) : time, i, sub, " << k
      << "u, id, fl_hits, fl_hitRoom);\n#endif\n";
    return c.str();
  };
  for (std::size_t k = 0; k < acts.size(); ++k) {
    const Action& act = acts[k];
    ActionSource& src = sources[k];
    marks[k] = std::size_t(body.tellp());
    reads.insert(src.reads);
    writes.insert(src.writes);
    body << "    /* " << k << ": " << actionName(act) << " */\n";
    if (gathered[k]) {
      body << "    /* (evaluated by the next Move's integrator) */\n";
      placed[k] = 0;
      continue;
    }
    if (curvedBy[k]) {
      // A planar Bounce on the parabola of the acceleration its Move's integrator starts
      // from: the Move's forces, evaluated at the Bounce's state (fused_pass.cpp curvedBy).
      // The state under other names: the forces' code reads px.. in its own block.
      body << "    { const float fl_b_px = px, fl_b_py = py, fl_b_pz = pz, fl_b_vx = vx, "
              "fl_b_vy = vy, fl_b_vz = vz;\n    float fl_bounce_ax, fl_bounce_ay, "
              "fl_bounce_az;\n    "
           << evaluate(accelerations(forcesOf[curvedBy[k] - 1]), "fl_b_", "time", "fl_bounce_")
           << "    " << bounceOnCurve(std::get<Bounce>(act), src.in.params, "fl_bounce_a")
           << (collisions ? logCollision(k, "fl_b_", "fl_bounce_ax, fl_bounce_ay, fl_bounce_az")
                          : "")
           << "    }\n";
      continue;
    }
    if (std::holds_alternative<Move>(act) && integrator != Integrator::SemiImplicitEuler) {
      reads.insert({Attribute::Position, Attribute::Velocity});
      writes.insert({Attribute::Position, Attribute::Velocity});
      const bool prev = stored.has(Attribute::PrevPosition), age = stored.has(Attribute::Age);
      if (prev) writes.insert(Attribute::PrevPosition);
      if (age) {
        reads.insert(Attribute::Age);
        writes.insert(Attribute::Age);
      }
      std::vector<std::string> damping;
      for (std::uint32_t f : forcesOf[k])
        damping.push_back(std::holds_alternative<Damping>(acts[f]) ? sources[f].in.params : "");
      body << integrateMove(integrator, accelerations(forcesOf[k]), damping, prev, age);
      // A curved step (or its bounce) that ended behind a deflector, compared with where
      // the particle began the step, is put back (fused_pass.cpp guard).
      for (std::uint32_t b : guardsOf[k]) {
        const auto& bounce = std::get<Bounce>(acts[b]);
        body << "    fl_bounce_guard((ap + " << b << "), " << bounce.surface.shape().index()
             << "u, " << (bounce.inside ? 1 : 0)
             << ", fl_start_x, fl_start_y, fl_start_z, &px, &py, &pz, &vx, &vy, &vz, extra);\n";
        guarded = true;
      }
      continue;
    }
    placed[k] = 1;
    const bool logs = collisions && std::holds_alternative<Bounce>(act);
    if (logs)
      body << "    { const float fl_c_px = px, fl_c_py = py, fl_c_pz = pz, fl_c_vx = vx, "
              "fl_c_vy = vy, fl_c_vz = vz;\n";
    std::istringstream lines(src.apply);
    for (std::string line; std::getline(lines, line);) body << "    " << line << "\n";
    if (logs) body << logCollision(k, "fl_c_", "0.0f, 0.0f, 0.0f") << "    }\n";
  }
  marks[acts.size()] = std::size_t(body.tellp());
  // The NaN guard reads what it checks.
  if (stored.has(Attribute::Velocity)) reads.insert(Attribute::Velocity);
  reads.insert(Attribute::Position);
  const Substeps& sub = actions.substeps();
  g.substepsByDistance = sub.maxDistance > 0 && stored.has(Attribute::Velocity);
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
  for (const char* f :
       {"compat_opencl.h", "math.h", "params.h", "philox.h", "noise.h", "deflect.h", "domain.h",
        "domain.cl", "path.h", "forces.h", "integrate.h", "absorb.h", "actions.cl", "forces.cl",
        "surfaces.cl", "compact.cl", "newborn.h", "emit.cl"})
    s << "/* ---- " << f << " */\n" << embeddedKernel(f) << "\n";

  s << "/* ---- generated: emission */\n" << emitSource;
  s << "/* ---- tail.cl */\n" << embeddedKernel("tail.cl") << "\n";

  // The fused act kernel.
  const AttributeSet touched = reads | writes;
  for (const auto& l : all)
    if (touched.has(l.attribute)) g.actLanes.push_back(l);
  // The per-particle part, shared by fl_act and fl_small. A newborn (i >= n0) runs the list
  // for the part of the step it still has to live (tau, by slot), from its birth time on.
  // With culling (cull, and velocities for the swept bounds) fl_act and fl_small hold
  // barriers; without (or with no action that may be culled) the program has no trace of it.
  bool cullable = false;
  for (std::size_t k = 0; k < acts.size(); ++k) {
    std::string unused;
    cullable |= placed[k] == 1 && culledCode(acts[k], k, unused);
  }
  g.culls = cull && cullable && stored.has(Attribute::Velocity);
  // Every work-item runs the list, those past the live particles (fl_live == 0) on zeros:
  // the actions' parameters are then read under no branch, and a CPU driver's loop over the
  // work-items vectorises (a parameter read under `if (i < n)` became a gather per vector of
  // work-items on PoCL). Every work-item loads and stores its slot, unmasked (the lanes are
  // as long as the launches: allocate, backend.cpp): a masked vector store to memory out of
  // the cache cost Zen 4 five times the whole scalar kernel; past the live particles the
  // slots are free, and a birth writes every lane of its slot. Not with a user's callback,
  // which may write memory of its own, unless culling needs it (its pieces run only for live
  // particles).
  bool callback = false;
  for (const Action& a : acts) callback |= std::holds_alternative<Callback>(a);
  const bool everyone = g.culls || !callback;
  const char* live = everyone ? "fl_live && " : "";
  std::ostringstream one;
  one << "  fl_real fl_len = fl_real_from_bits(dtBits), fl_t0 = t0;\n"
         "  if ("
      << live
      << "i >= n0) {\n    const fl_real left = (fl_real)tau[i];\n"
         "    fl_len = left;\n    fl_t0 = t1 - left;\n  }\n";
  for (const auto& l : g.actLanes) {
    const char* type = info(l.attribute).isUint ? "uint" : "float";
    if (!reads.has(l.attribute))
      one << "  " << type << " " << l.name << ";\n";
    else if (everyone)
      one << "  const " << type << " fl_in_" << l.name << " = l_" << l.name << "[i];\n  " << type
          << " " << l.name << " = fl_live ? fl_in_" << l.name << " : 0;\n";
    else
      one << "  " << type << " " << l.name << " = l_" << l.name << "[i];\n";
  }
  // Hair mode (one work-item per strand, each to its own death) runs the plain list.
  const std::string stepCode = stepSource(body.str(), sub, g.substepsByDistance, stored, guarded);
  one << (g.culls ? stepSource(cullingBody(acts, body.str(), marks, placed), sub,
                               g.substepsByDistance, stored, guarded)
                  : stepCode);
  for (const auto& l : g.actLanes)
    if (writes.has(l.attribute)) one << "  l_" << l.name << "[i] = " << l.name << ";\n";
  one << "  codes[i] = (uchar)dead;\n";
  const char* actArgs =
      "__global uchar* restrict codes, __global const FlActionParams* restrict ap,\n"
      "    __global uint* state, __global const float* restrict extra,\n"
      "    __global const float* restrict snap, ulong dtBits, ulong timeBits, uint seedLo,\n"
      "    uint seedHi, uint fl_step, uint streamBase, uint nsubStep, uint snapStride,\n"
      "    __global float* restrict tau, uint births, uint capacity, ulong t1Bits,\n"
      "    uint reachOff";
  const char* hitArgs = collisions ? ", __global uint* fl_hits, uint fl_hitRoom" : "";
  // [0, n0) lived before the step, [n0, n) are its newborns (fl_birth wrote them).
  const char* actPrologue =
      "  const uint n0 = state[FL_STATE_SIZE];\n"
      "  const uint n = fl_step_range(state, births, capacity);\n"
      "  const uint snapN = n;\n"
      "  (void)extra; (void)snap; (void)snapN; (void)snapStride; (void)seedLo; (void)seedHi;\n"
      "  (void)fl_step; (void)reachOff;\n"
      "  const fl_real t0 = fl_real_from_bits(timeBits), t1 = fl_real_from_bits(t1Bits);\n";
  // The per-particle part once, as a function both kernels call: PoCL compiles the action
  // list's body once per program instead of once per kernel (cold start, issue #11).
  if (collisions) s << "#define FL_LOG_HITS 1\n";
  s << "/* ---- generated: one particle's step */\nFL_INLINE void fl_act_one(";
  for (const auto& l : g.actLanes) s << laneDecl(l) << ", ";
  s << "__global uchar* restrict codes, __global const FlActionParams* restrict ap,\n"
       "    __global uint* state, __global const float* restrict extra,\n"
       "    __global const float* restrict snap, ulong dtBits, uint seedLo, uint seedHi,\n"
       "    uint fl_step, uint streamBase, uint nsubStep, uint snapStride,\n"
       "    __global float* restrict tau, size_t i, uint n0, uint n, uint snapN, fl_real t0,\n"
       "    fl_real t1"
    << (everyone ? ", uint fl_live" : "") << (g.culls ? ", uint reachOff, __local int* fl_red" : "")
    << hitArgs
    << ") {\n"
       "  (void)state; (void)extra; (void)snap; (void)snapN; (void)snapStride; (void)seedLo;\n"
       "  (void)seedHi; (void)fl_step; (void)n;\n"
    << one.str() << "}\n";
  if (collisions) s << "#undef FL_LOG_HITS\n";
  std::string call = "fl_act_one(";
  for (const auto& l : g.actLanes) call += std::string("l_") + l.name + ", ";
  call +=
      "codes, ap, state, extra, snap, dtBits, seedLo, seedHi, fl_step, streamBase, nsubStep,\n"
      "      snapStride, tau, i, n0, n, snapN, t0, t1";
  if (everyone) call += ", i < n";
  if (g.culls) call += ", reachOff, fl_red";
  if (collisions) call += ", fl_hits, fl_hitRoom";
  call += ");\n";
  const std::string local = g.culls ? "  __local int fl_red[FL_CULL_LOCAL + " +
                                          std::to_string(2 * acts.size() + 1) +
                                          "]; /* the culling's reduction and decisions */\n"
                                    : "";
  const char* size = g.culls ? "__attribute__((reqd_work_group_size(FL_ACT_LOCAL, 1, 1))) " : "";
  s << "/* ---- generated: the fused act kernel */\n__kernel " << size << "void fl_act(";
  for (const auto& l : g.actLanes) s << laneDecl(l) << ", ";
  s << actArgs << hitArgs << ") {\n"
    << local << actPrologue << "  const size_t i = get_global_id(0);\n"
    << (everyone ? "" : "  if (i >= n) return;\n") << "  " << call << "}\n";
  // A small group's whole step in one launch of one work-group: births, act,
  // count-scan-list, tail. PoCL pays several microseconds per launch; this is one instead of
  // four.
  // Not for lists that read neighbours: their snapshot, copied before the act kernel, must
  // hold the newborns where they were born, so fl_birth runs before the copy.
  g.small = !g.substepsByDistance && !hair && !g.neighbours && !collisions;
  // Without culling, on a CPU device (FL_SMALL_RUNS: backend.cpp), each work-item takes a
  // run of FL_SMALL_RUN particles in a loop PoCL's vectoriser takes as its innermost (as
  // fl_act's loop over the work-items), with no barrier. (Passes of the work-group each
  // ending at a barrier gathered their slots: PoCL keeps a pass counter bounded by n per
  // work-item across a barrier, so the vectors of work-items it forms cannot see that their
  // slots are consecutive.) On a GPU the work-group strides over them, each pass's
  // work-items side by side in memory. With culling, whose decisions are the work-group's,
  // passes end at the culling's barriers. Without everyone running (a callback), strided.
  const std::string loop =
      everyone && !g.culls ? "#ifdef FL_SMALL_RUNS\n"
                             "  const size_t fl_from = (size_t)lid * FL_SMALL_RUN;\n"
                             "  if (fl_from < n)\n"
                             "#pragma clang loop vectorize(assume_safety)\n"
                             "  for (uint fl_k = 0u; fl_k < FL_SMALL_RUN; ++fl_k) {\n"
                             "    const size_t i = fl_from + fl_k;\n"
                             "#else\n"
                             "  for (size_t i = lid; i < n; i += lsize) {\n"
                             "#endif\n    "
      : everyone           ? "  for (uint fl_first = 0u; fl_first < n; fl_first += lsize) {\n"
                             "    const size_t i = fl_first + get_local_id(0);\n    "
                           : "  for (uint i = lid; i < n; i += lsize) {\n    ";
  if (g.small)
    s << "/* ---- generated: a small group's step */\n__kernel " << size
      << "void fl_small(FL_LANE_PARAMS, " << actArgs
      << ",\n    __global uint* tileDead, __global uint* tileOff, __global uint* holes,\n"
         "    __global uint* tail, uint tiles,\n"
         "    __global const uchar* tables, uint offEmitters, uint offTypes, uint offKeys,\n"
         "    uint offShapes, uint runCount, uint salt) {\n"
         "  const uint lid = get_local_id(0), lsize = get_local_size(0);\n"
      << local
      << "  fl_birth_body(lid, lsize, FL_LANE_ARGS, tau, state, births, capacity, tables,\n"
         "                offEmitters, offTypes, offKeys, offShapes, runCount, t1Bits, seedLo,\n"
         "                seedHi, salt);\n"
         "  barrier(CLK_GLOBAL_MEM_FENCE);\n"
         "  {\n"
      << actPrologue << loop << call
      << "  }\n  }\n"
         "  barrier(CLK_GLOBAL_MEM_FENCE);\n"
         "  if (lid == 0u) fl_scan_list_body(codes, tileDead, tileOff, holes, tail, state, "
         "births, capacity, tiles);\n"
         "  barrier(CLK_GLOBAL_MEM_FENCE);\n"
         "  fl_tail_body(lid, lsize, FL_LANE_ARGS, holes, tail, state);\n"
         "}\n";
  if (hair) {
    if (g.neighbours) notOnDevice("hair mode with actions that read neighbours");
    if (g.substepsByDistance) notOnDevice("hair mode with sub-steps by distance");
    s << hairKernel(stepCode, all, stored);
  }
  g.source = s.str();
  // Correctly rounded division and sqrt: the CPU's are, and Bounce divides.
  g.options = kProgramOptions;
  return g;
}

}  // namespace flurry::detail::ocl
