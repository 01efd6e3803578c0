#include "builtin.hpp"

#include <algorithm>
#include <filesystem>

namespace flurry::samples {

const std::vector<Sample>& builtinSamples() {
  static const std::vector<Sample> samples = [] {
    std::vector<Sample> out;
    for (const detail::EmbeddedEffect* e = detail::kEmbeddedEffects; e->file; ++e) {
      Sample s;
      s.file = e->file;
      s.json = std::string_view(e->data, e->size);
      s.name = std::filesystem::path(s.file).stem().string();
      try {
        auto fx = std::make_shared<Effect>(parseEffect(s.json, s.file));
        s.name = fx->name;
        s.description = fx->description;
        s.effect = fx;
      } catch (const Error& err) {
        // Listed rather than hidden, so that a broken built-in is noticed (tests load each).
        s.description = std::string("(does not load: ") + err.what() + ")";
      }
      const std::shared_ptr<const Effect> fx = s.effect;
      const std::string what = s.description;
      s.build = [fx, what](Context& ctx, std::size_t capacity) {
        if (!fx) throw Error(what);
        fx->build(ctx, capacity);
      };
      out.push_back(std::move(s));
    }
    std::sort(out.begin(), out.end(),
              [](const Sample& a, const Sample& b) { return a.name < b.name; });
    return out;
  }();
  return samples;
}

const Sample* findSample(const std::string& name) {
  for (const auto& s : builtinSamples())
    if (s.name == name) return &s;
  return nullptr;
}

Effect loadEffectOrSample(const std::string& nameOrPath, const EffectLoadOptions& options) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const bool isFile = fs::is_regular_file(nameOrPath, ec);
  const bool looksLikePath =
      nameOrPath.ends_with(".json") || nameOrPath.find('/') != std::string::npos;
  if (isFile || looksLikePath) return loadEffect(nameOrPath, options);
  if (const Sample* s = findSample(nameOrPath)) {
    // Parsed again so that the caller's options (a field resolver) apply.
    return parseEffect(s->json, s->file, options);
  }
  // A folder that is not a built-in's name: say so rather than "no such file".
  if (fs::is_directory(nameOrPath, ec)) throw EffectError(nameOrPath, "", "is a directory");
  std::string names, near;
  std::size_t best = std::string::npos;
  for (const Sample& s : builtinSamples()) {
    names += (names.empty() ? "" : ", ") + s.name;
    // A cheap nearness: shared prefix length (the loader's Levenshtein is internal).
    std::size_t k = 0;
    while (k < s.name.size() && k < nameOrPath.size() && s.name[k] == nameOrPath[k]) ++k;
    if (k >= 2 && (best == std::string::npos || k > best)) best = k, near = s.name;
  }
  throw EffectError(nameOrPath, "",
                    "no such file and no built-in effect of that name" +
                        (near.empty() ? std::string() : "; did you mean \"" + near + "\"?") +
                        " (built-in: " + names + ")");
}

Group& buildFountain(Context& ctx, std::size_t capacity, double rate, float lifetime) {
  const Sample* s = findSample("fountain");
  if (!s || !s->effect) throw Error("the built-in fountain effect does not load");
  EffectGroup g = s->effect->groups.at(0);
  Group& group = ctx.createGroup(g.name, capacity);
  Emitter e = g.emitters.at(0);
  e.rate = rate;
  e.types.at(0).lifetime = Fuzzy::percent(lifetime, 10.0f);
  group.addEmitter(e);
  group.setActions(g.actions);
  return group;
}

}  // namespace flurry::samples
