// The C++ side of the Python parity test: runs a built-in effect through the C++ API and
// writes every stored lane, the strands and the statistics of every group as raw files
// (FOLDER/GROUP.ATTRIBUTE.COMPONENT, native-endian), which the test compares bitwise.
//
//   dump_effect NAME FRAMES THREADS FOLDER
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>

#include "builtin.hpp"
#include "flurry/flurry.hpp"

namespace {

template <class T>
void dump(const std::filesystem::path& path, std::span<const T> values) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(values.data()), std::streamsize(values.size_bytes()));
  if (!out) throw flurry::IoError(path.string(), "cannot write");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: dump_effect NAME FRAMES THREADS FOLDER\n");
    return 2;
  }
  try {
    const flurry::Effect fx = flurry::samples::loadEffectOrSample(argv[1]);
    flurry::ContextOptions o = fx.contextOptions();
    o.threads = unsigned(std::atoi(argv[3]));
    flurry::Context ctx(o);
    fx.build(ctx);
    ctx.run(std::size_t(std::atoi(argv[2])));
    const std::filesystem::path dir = argv[4];
    for (const flurry::Group* g : ctx.groups()) {
      const std::string base = g->name() + ".";
      for (int a = 0; a < int(flurry::Attribute::Count); ++a) {
        const auto attr = flurry::Attribute(a);
        if (!g->attributes().has(attr)) continue;
        const std::string name = base + std::string(flurry::attributeName(attr)) + ".";
        if (attr == flurry::Attribute::Id)
          dump(dir / (name + "0"), g->ids());
        else if (attr == flurry::Attribute::Visible)
          dump(dir / (name + "0"), g->visible());
        else
          for (int c = 0; c < flurry::componentCount(attr); ++c)
            dump(dir / (name + std::to_string(c)), g->lane(attr, c));
      }
      const flurry::Strands& s = g->strands();
      dump(dir / (base + "strands.position"),
           std::span<const float>(reinterpret_cast<const float*>(s.position.data()),
                                  s.position.size() * 3));
      dump(dir / (base + "strands.start"), std::span<const std::uint32_t>(s.start));
      const flurry::GroupStats& st = g->stats();
      const std::uint64_t stats[] = {st.emitted, st.killedByAge, st.absorbed, st.droppedAtCapacity,
                                     st.killedNonFinite};
      dump(dir / (base + "stats"), std::span<const std::uint64_t>(stats));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dump_effect: %s\n", e.what());
    return 1;
  }
  return 0;
}
