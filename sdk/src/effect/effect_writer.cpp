// The effect-file writer (saveEffect): an Effect back to JSON, each action and part through
// its descriptor (descriptors.hpp), so that load -> save -> load gives the same effect.
#include <string>

#include "effect/descriptors.hpp"
#include "effect/effect_parts.hpp"
#include "effect/json_writer.hpp"
#include "flurry/effect.hpp"

namespace flurry {

using detail::index;
using detail::join;

namespace {

using jsonio::ojson;
using jsonio::write;
using jsonio::writeFields;
using jsonio::Writer;

ojson writeAction(Writer w, const Action& a, const std::string& path) {
  return std::visit(
      [&](const auto& x) -> ojson {
        using A = std::decay_t<decltype(x)>;
        if constexpr (desc::Described<A>) {
          ojson o = ojson::object();
          o["type"] = desc::Describe<A>::name;
          writeFields(w, o, x);
          return o;
        } else {
          throw InvalidArgument(path, std::string("a ") + actionName(a) +
                                          " runs C++ code and cannot be saved in an effect file");
        }
      },
      a);
}

ojson writeGroup(Writer w, const EffectGroup& g, const std::string& path) {
  ojson o = ojson::object();
  o["name"] = g.name;
  o["capacity"] = std::uint64_t(g.capacity);
  if (!g.emitters.empty()) o["emitters"] = write(w, g.emitters);
  if (!g.primeEmitters.empty()) o["primeEmitters"] = write(w, g.primeEmitters);
  if (!g.deathEmitters.empty()) o["deathEmitters"] = write(w, g.deathEmitters);
  ojson actions = ojson::array();
  for (std::size_t i = 0; i < g.actions.size(); ++i)
    actions.push_back(writeAction(w, g.actions.actions()[i], index(join(path, "actions"), i)));
  o["actions"] = std::move(actions);
  if (g.actions.integrator() != Integrator::SemiImplicitEuler)
    o["integrator"] = integratorName(g.actions.integrator());
  const Substeps& sub = g.actions.substeps();
  const Substeps subDefault;
  if (sub.maxStep != subDefault.maxStep || sub.maxDistance != subDefault.maxDistance ||
      sub.maxSubsteps != subDefault.maxSubsteps) {
    ojson so = ojson::object();
    so["maxStep"] = write(w, sub.maxStep);
    so["maxDistance"] = write(w, sub.maxDistance);
    so["maxSubsteps"] = sub.maxSubsteps;
    o["substeps"] = std::move(so);
  }
  const HairOptions hairDefault;
  if (g.hair.enabled) {
    ojson ho = ojson::object();
    if (g.hair.every != hairDefault.every) ho["every"] = g.hair.every;
    if (g.hair.maxVertices != hairDefault.maxVertices) ho["maxVertices"] = g.hair.maxVertices;
    o["hair"] = ho.empty() ? ojson(true) : std::move(ho);
  }
  if (g.budget != BudgetPolicy::DropNewest)
    o["budget"] = g.budget == BudgetPolicy::DropOldest ? "dropOldest" : "scaleEmission";
  if (g.trail.length > 0) {
    const TrailOptions trailDefault;
    ojson to = ojson::object();
    to["length"] = g.trail.length;
    if (g.trail.width != trailDefault.width) to["width"] = write(w, g.trail.width);
    if (g.trail.taper != trailDefault.taper) to["taper"] = write(w, g.trail.taper);
    if (g.trail.fade != trailDefault.fade) to["fade"] = write(w, g.trail.fade);
    o["trail"] = std::move(to);
  }
  if (g.require.bits() != 0) {
    ojson r = ojson::array();
    for (int i = 0; i < int(Attribute::Count); ++i)
      if (g.require.has(Attribute(i))) r.push_back(std::string(attributeName(Attribute(i))));
    o["require"] = std::move(r);
  }
  return o;
}

}  // namespace

std::string saveEffect(const Effect& fx) {
  const Writer w;
  ojson o = ojson::object();
  o["version"] = 1;
  o["name"] = fx.name;
  if (!fx.description.empty()) o["description"] = fx.description;
  o["dt"] = write(w, fx.dt);
  o["seed"] = fx.seed;
  o["frames"] = fx.frames;
  if (fx.space == Space::Local) o["space"] = "local";
  ojson groups = ojson::array();
  for (std::size_t i = 0; i < fx.groups.size(); ++i)
    groups.push_back(writeGroup(w, fx.groups[i], index("groups", i)));
  o["groups"] = std::move(groups);
  if (!fx.render.empty() && fx.render != "{}") {
    try {
      o["render"] = ojson::parse(fx.render);
    } catch (const ojson::exception& e) {
      throw InvalidArgument("render", std::string("not JSON: ") + e.what());
    }
  }
  std::string out;
  jsonio::print(o, out, 0);
  return out + "\n";
}

}  // namespace flurry
