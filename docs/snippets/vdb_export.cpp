// docs/snippets/vdb_export.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>
#include <flurry/vdb.hpp>

#include <cstdio>

int main() {
  flurry::Context ctx({.dt = 1.0 / 24});
  flurry::Group& smoke = ctx.createGroup("smoke", 10'000);
  flurry::Emitter chimney;
  chimney.shape = flurry::Domain::disc({0, 0, 0}, {0, 1, 0}, 0.3f);
  chimney.rate = 500;
  chimney.types[0].velocity = flurry::Domain::cone({0, 0, 0}, {0, 1.5f, 0}, 0.4f);
  chimney.types[0].size = 0.1f;  // radius: the fog voxel will be 0.05
  smoke.addEmitter(chimney);
  smoke.setActions({flurry::Turbulence{}, flurry::Move{}, flurry::KillOld{}});
  // Store what the files carry besides positions and ids (v, Cd, pscale, age).
  smoke.require({flurry::Attribute::Velocity, flurry::Attribute::Color, flurry::Attribute::Size,
                 flurry::Attribute::Age});

  // A sequence, written on a background thread: out/smoke.0001.vdb ... smoke.0048.vdb.
  flurry::vdb::SequenceWriter writer({.folder = "out", .name = "smoke"});
  for (int frame = 1; frame <= 48; ++frame) {
    ctx.step();
    writer.write(smoke, frame, ctx.time());  // copies the particles and returns
  }
  flurry::vdb::ExportCost cost = writer.finish();  // waits; throws the first error
  flurry::vdb::FileStats last = writer.last();

  std::printf("%zu files, %.1f MB; the last: %zu points, fog voxel %g\n", cost.files,
              cost.bytes / 1e6, last.points, last.fogVoxelSize);
  return cost.files == 48 && last.points == smoke.size() && last.fogVoxelSize == 0.05f ? 0 : 1;
}
