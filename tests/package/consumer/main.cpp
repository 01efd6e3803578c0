#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <flurry/flurry.hpp>
#include <string>
#ifdef CONSUMER_RENDER
#include <flurry/render.hpp>
#endif
#ifdef CONSUMER_VDB
#include <flurry/vdb.hpp>
#endif
#ifdef CONSUMER_C
#include <flurry.h>
#endif

namespace fs = std::filesystem;

int main() {
  flurry::Context ctx;
  flurry::Group& g = ctx.createGroup("sparks", 1000);
  flurry::Emitter e;
  e.rate = 300;
  g.addEmitter(e);
  g.setActions({flurry::Gravity{}, flurry::Move{}});
  ctx.run(30);
  std::printf("consumer: %zu particles\n", g.size());
  if (g.size() != 300) return 1;
  const fs::path dir =
      fs::temp_directory_path() / ("flurry_consumer_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  int bad = 0;
#ifdef CONSUMER_RENDER
  // A PNG round trip (no display needed).
  flurry::Image img;
  img.width = 3;
  img.height = 2;
  img.rgba.assign(3 * 2 * 4, 0);
  img.pixel(2, 1)[0] = 200;
  img.pixel(2, 1)[3] = 255;
  flurry::writePng(img, dir / "x.png");
  const flurry::Image back = flurry::readPng(dir / "x.png");
  std::printf("consumer: render: PNG %dx%d read back\n", back.width, back.height);
  if (back.width != 3 || back.height != 2 || back.rgba != img.rgba) ++bad;
#endif
#ifdef CONSUMER_VDB
  const flurry::vdb::FileStats st = flurry::vdb::writeFile(dir / "x.vdb", g);
  std::printf("consumer: vdb: %zu points, %llu bytes\n", st.points,
              static_cast<unsigned long long>(st.bytes));
  if (st.points != g.size() || st.bytes == 0 || !fs::exists(dir / "x.vdb")) ++bad;
#endif
#ifdef CONSUMER_C
  // The C API, through flurry::c.
  flurry_context* c = nullptr;
  const bool cOk = flurry_abi_version() == FLURRY_C_ABI_VERSION &&
                   flurry_context_create(nullptr, &c) == FLURRY_OK;
  std::printf("consumer: c: flurry %s, ABI %d\n", flurry_version(), flurry_abi_version());
  flurry_context_destroy(c);
  if (!cOk) ++bad;
#endif
  fs::remove_all(dir);
  return bad;
}
