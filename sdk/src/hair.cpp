// Hair (static) mode: each particle's whole life is computed when it is born and kept as a
// strand (the seed: "the entire life ... is rendered when the particle is generated").
#include <algorithm>

#include "backend.hpp"

namespace flurry::detail {

void simulateHair(GroupImpl& g, const StepParams& sp) {
  if (g.size == 0) return;
  // The newborns move to a scratch group that runs the same action list to their deaths.
  GroupImpl h;
  h.name = g.name;
  h.index = g.index;
  h.ownSeed = g.ownSeed;  // its draws are the group's
  h.seed = g.seed;
  h.stream = g.stream;
  h.capacity = g.size;
  h.required = g.required;
  h.actions = g.actions;
  h.stats.killedByAction.assign(h.actions.size(), 0);
  h.ensureStorage();
  for (std::size_t a = 0; a < g.lanes.size(); ++a)
    for (std::size_t c = 0; c < 4; ++c)
      if (g.lanes[a][c] && h.lanes[a][c]) std::copy_n(g.lanes[a][c].u(), g.size, h.lanes[a][c].u());
  h.size = g.size;
  g.size = 0;

  // The survivors were born last, up to g.nextId - 1: the first-born of them sets the first
  // slot (not particle 0, whose place a later-born takes when the first-born died in its birth
  // step: compaction fills from the tail). Counted back from nextId, as ids wrap at 2^32.
  const std::uint32_t* ids = h.lanePointers().id;
  std::uint32_t back = 0;  // how far before the last-born the first-born survivor is
  for (std::size_t i = 0; i < h.size; ++i) back = std::max(back, g.nextId - 1u - ids[i]);
  const std::uint32_t firstId = g.nextId - 1u - back, lastId = g.nextId - 1u;
  struct Strand {
    std::vector<Vec3> p;
    std::vector<Vec4> c;
    std::vector<float> r;
  };
  // Ids of one step's newborns are consecutive: a strand's slot is id - firstId.
  std::vector<Strand> strands(lastId - firstId + 1);
  auto record = [&] {
    const Lanes L = h.lanePointers();
    for (std::size_t i = 0; i < h.size; ++i) {
      Strand& s = strands[L.id[i] - firstId];
      if (s.p.size() >= g.hair.maxVertices) continue;
      s.p.emplace_back(L.p[0][i], L.p[1][i], L.p[2][i]);
      s.c.push_back(L.color[0] ? Vec4(L.color[0][i], L.color[1][i], L.color[2][i], L.color[3][i])
                               : Vec4(1.0f));
      s.r.push_back(L.size ? L.size[i] : 0.05f);
    }
  };
  StepParams hs = sp;
  hs.time = sp.end;
  hs.end = hs.time + hs.dt;  // (its own steps, after the group's)
  record();
  const std::size_t maxSteps = std::size_t(g.hair.maxVertices) * g.hair.every;
  for (std::size_t k = 1; k <= maxSteps && h.size > 0; ++k) {
    actFused(h, hs);
    compact(h, hs);
    hs.time = hs.end;
    hs.end = hs.time + hs.dt;
    ++hs.step;
    if (k % g.hair.every == 0) record();
  }
  for (std::size_t a = 0; a < h.actions.size(); ++a)
    g.stats.killedByAction[a] += h.stats.killedByAction[a];
  g.stats.killedByAge += h.stats.killedByAge;
  g.stats.absorbed += h.stats.absorbed;
  g.stats.killedNonFinite += h.stats.killedNonFinite;
  // Particles still alive when their strand is full end there.
  g.stats.killedByAge += h.size;
  for (Strand& s : strands)
    if (s.p.size() >= 2) g.strands.add(s.p, s.c, s.r);
}

}  // namespace flurry::detail
