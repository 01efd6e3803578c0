// The OpenCL backend's behaviour apart from parity: device choice, errors, the program
// cache, host reads and writes between steps, capacity.
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "builtin.hpp"
#include "opencl/backend.hpp"
#include "opencl/runtime.hpp"
#include "opencl_test.hpp"
#include "parity.hpp"

using namespace flurry;

namespace {

ContextOptions openclOptions(std::uint64_t seed = 3) {
  ContextOptions o;
  o.seed = seed;
  o.threads = 2;
  o.backend = Backend::OpenCL;
  return o;
}

}  // namespace

TEST(OpenCLBackend, ListsDevices) {
  FLURRY_REQUIRE_OPENCL();
  const auto devices = openclDevices();
  ASSERT_FALSE(devices.empty());
  for (const auto& d : devices) {
    EXPECT_FALSE(d.name.empty());
    EXPECT_GT(d.maxAllocation, 0u);
  }
}

TEST(OpenCLBackend, AutoPicksOpenCLWhenThereIsADevice) {
  FLURRY_REQUIRE_OPENCL();
  ContextOptions o;
  o.backend = Backend::Auto;
  Context ctx(o);
  EXPECT_EQ(ctx.backend(), Backend::OpenCL);
}

TEST(OpenCLBackend, AnUnknownDeviceNameThrowsNamingTheDevicesFound) {
  FLURRY_REQUIRE_OPENCL();
  ContextOptions o = openclOptions();
  o.device = "no-such-device-xyz";
  try {
    Context ctx(o);
    FAIL() << "expected OpenCLError";
  } catch (const OpenCLError& e) {
    EXPECT_EQ(e.code(), CL_DEVICE_NOT_FOUND);
    EXPECT_NE(std::string(e.what()).find("no-such-device-xyz"), std::string::npos);
  }
  // Auto falls back to the CPU instead, saying why through the context (never on stderr).
  o.backend = Backend::Auto;
  ::testing::internal::CaptureStderr();
  Context fallback(o);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(fallback.backend(), Backend::Cpu);
  EXPECT_NE(fallback.backendFallback().find("no-such-device-xyz"), std::string::npos)
      << fallback.backendFallback();
}

TEST(OpenCLBackend, ABuildFailureCarriesTheLogAndTheSource) {
  FLURRY_REQUIRE_OPENCL();
  auto rt = detail::ocl::Runtime::get(detail::ocl::selectDevice(""));
  const std::string bad = "__kernel void broken(__global float* x) { x[0] = undefined_thing; }";
  try {
    rt->program(bad, "");
    FAIL() << "expected OpenCLError";
  } catch (const OpenCLError& e) {
    EXPECT_EQ(e.code(), CL_BUILD_PROGRAM_FAILURE);
    EXPECT_NE(e.buildLog().find("undefined_thing"), std::string::npos) << e.buildLog();
    EXPECT_EQ(e.source(), bad);
  }
}

TEST(OpenCLBackend, TheSecondContextPaysNoCompile) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [] {
    Context ctx(openclOptions());
    samples::buildFountain(ctx, 10000, 2000, 2.0f);
    ctx.run(3);
  };
  run();
  const auto before = detail::ocl::Runtime::cacheStats();
  run();
  const auto after = detail::ocl::Runtime::cacheStats();
  EXPECT_EQ(after.builds, before.builds);
  EXPECT_EQ(after.diskHits, before.diskHits);
  EXPECT_GT(after.memoryHits, before.memoryHits);
}

// The library never prints: the profile FLURRY_OPENCL_PROFILE=1 asks for goes to the log
// callback (when a group goes), and nowhere when none is set.
TEST(OpenCLBackend, TheProfileGoesToTheLogNotToStderr) {
  FLURRY_REQUIRE_OPENCL();
  ::setenv("FLURRY_OPENCL_PROFILE", "1", 1);
  auto run = [] {
    Context ctx(openclOptions());
    samples::buildFountain(ctx, 1000, 200, 2.0f);
    ctx.run(3);
  };
  const LogCallback saved = setLogCallback({});
  testing::internal::CaptureStderr();
  run();
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed.find("profile"), std::string::npos) << printed;
  std::mutex m;
  std::vector<std::pair<LogLevel, std::string>> got;
  setLogCallback([&](LogLevel l, std::string_view s) {
    std::lock_guard lock(m);
    got.emplace_back(l, std::string(s));
  });
  run();
  setLogCallback(saved);
  ::unsetenv("FLURRY_OPENCL_PROFILE");
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got[0].first, LogLevel::Info);
  EXPECT_EQ(got[0].second.rfind("opencl profile: ", 0), 0u) << got[0].second;
  EXPECT_NE(got[0].second.find("launches"), std::string::npos) << got[0].second;
}

TEST(OpenCLBackend, ProgramsAreCachedOnDisk) {
  FLURRY_REQUIRE_OPENCL();
  const auto dir =
      std::filesystem::temp_directory_path() / ("flurry-cl-cache-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  ::setenv("FLURRY_OPENCL_CACHE", dir.c_str(), 1);
  auto run = [] {
    Context ctx(openclOptions());
    Group& g = samples::buildFountain(ctx, 1000, 500, 1.0f);
    // A list no other test uses, so the program is not in memory yet.
    g.setActions({Gravity{Vec3(0.0f, -1.0f, 0.0f)}, Damping{Vec3(0.01f)}, Move{}, KillOld{}});
    ctx.run(2);
  };
  detail::ocl::Runtime::clearMemoryCache();
  run();  // compiles (or loads a binary PoCL cached) and writes the binary
  EXPECT_FALSE(std::filesystem::is_empty(dir));
  detail::ocl::Runtime::clearMemoryCache();
  const auto before = detail::ocl::Runtime::cacheStats();
  run();
  const auto after = detail::ocl::Runtime::cacheStats();
  ::unsetenv("FLURRY_OPENCL_CACHE");
  std::filesystem::remove_all(dir);
  EXPECT_EQ(after.builds, before.builds);
  EXPECT_EQ(after.diskHits, before.diskHits + 1);
}

// A group the host fills (the list of the host read/write tests: one program for them all),
// on backend b; `add(n, vz, life)` adds n particles along x, particle i with velocity
// (0, 1, vz·i) and lifetime life·(i % 7 or i).
struct HostGroup {
  Context ctx;
  Group& g;
  explicit HostGroup(Backend b)
      : ctx([b] {
          ContextOptions o = openclOptions();
          o.backend = b;
          return o;
        }()),
        g(ctx.createGroup("g", 1000)) {
    g.setActions({Gravity{Vec3(0.0f, -1.0f, 0.0f)}, Move{}, KillOld{}});
  }
  void add(int n, float vz, float life, bool cycle = false) {
    for (int i = 0; i < n; ++i) {
      Particle p;
      p.position = Vec3(float(i), 0.0f, 0.0f);
      p.velocity = Vec3(0.0f, 1.0f, vz * float(i));
      p.lifetime = life * float(cycle ? i % 7 : i);
      g.add(p);
    }
  }
};

// Particles added and edited by the host between steps reach the device, and the device's
// particles come back when the host reads them.
TEST(OpenCLBackend, HostReadsAndWritesBetweenSteps) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [](Backend b) {
    HostGroup h(b);
    Context& ctx = h.ctx;
    Group& g = h.g;
    h.add(100, 0.0f, 0.05f);
    ctx.run(10);
    EXPECT_LT(g.size(), 100u);                // some died of age
    auto y = g.lane(Attribute::Position, 1);  // writable: the device must take it
    for (float& v : y) v += 100.0f;
    ctx.run(10);
    Particle extra;
    extra.lifetime = 100.0f;
    g.add(extra);
    ctx.run(5);
    std::map<std::uint32_t, Vec3> out;
    for (std::size_t i = 0; i < g.size(); ++i) out[g.particle(i).id] = g.particle(i).position;
    return std::make_pair(out, g.stats().killedByAge);
  };
  const auto cpu = run(Backend::Cpu);
  const auto cl = run(Backend::OpenCL);
  EXPECT_EQ(cpu.second, cl.second);
  ASSERT_EQ(cpu.first.size(), cl.first.size());
  for (const auto& [id, p] : cpu.first) {
    ASSERT_TRUE(cl.first.count(id)) << id;
    // Not bitwise: GCC contracts the CPU's AVX2/AVX-512 fused pass into FMAs.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(p[c], cl.first.at(id)[c], 1e-4f) << id;
  }
}

TEST(OpenCLBackend, ClearAndRequireBetweenSteps) {
  FLURRY_REQUIRE_OPENCL();
  Context ctx(openclOptions());
  Group& g = samples::buildFountain(ctx, 20000, 3000, 1.0f);
  ctx.run(20);
  EXPECT_GT(g.size(), 0u);
  g.clear();
  EXPECT_EQ(g.size(), 0u);
  ctx.run(5);
  const std::size_t n = g.size();
  EXPECT_GT(n, 0u);
  g.require({Attribute::Color, Attribute::Size});  // new lanes: the device reallocates
  ctx.run(5);
  EXPECT_GT(g.size(), n);
  EXPECT_GT(g.particle(0).size, 0.0f);
}

// What the device does not run yet is a clear error, not a silent difference; the group steps
// on. (Death and collision events, sub-emitters on them, trails and a particle budget run on
// the device: OpenCLCore.DeathEventsAsOnTheCpu, CollisionEventsAsOnTheCpu,
// SubEmittersOnDeathCollisionAndBirthAsOnTheCpu, TrailsAsOnTheCpu, AParticleBudgetAsOnTheCpu.)
TEST(OpenCLBackend, WhatTheDeviceDoesNotRunIsAClearError) {
  FLURRY_REQUIRE_OPENCL();
  Context ctx(openclOptions());
  Group& g = samples::buildFountain(ctx, 2000, 3000, 0.2f);
  // A trail in hair mode: refused when the group steps.
  Group& hairy = ctx.createGroup("hairy", 1000);
  hairy.setHair({.enabled = true});
  hairy.setTrail({.length = 4});
  try {
    ctx.step();
    FAIL() << "a trail in hair mode stepped on the device";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("trail"), std::string::npos) << e.what();
  }
  ctx.destroyGroup(hairy);
  ctx.run(5);
  EXPECT_GT(g.size(), 0u);
}

// A group larger than one device buffer may be: a clear error, and the group stays usable.
TEST(OpenCLBackend, TooLargeForTheDeviceIsAClearError) {
  FLURRY_REQUIRE_OPENCL();
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "maps gigabytes of host lanes, which AddressSanitizer makes take ~10 s";
#endif
  Context ctx(openclOptions());
  const auto dev = detail::ocl::selectDevice("");
  const std::size_t capacity = std::size_t(dev.info.maxAllocation / 4 + 1);
  if (capacity > 0xFFFFFFF0u) GTEST_SKIP() << "the device allows buffers larger than any group";
  Group& g = ctx.createGroup("huge", capacity);  // host lanes: untouched virtual memory
  g.setActions({Move{}});
  g.add(Particle{});  // not idle: the step needs the device's buffers
  try {
    ctx.step();
    FAIL() << "expected OpenCLError";
  } catch (const OpenCLError& e) {
    EXPECT_NE(std::string(e.what()).find("capacity"), std::string::npos) << e.what();
  }
  EXPECT_EQ(g.size(), 1u);  // the host's particles are kept
}

TEST(OpenCLBackend, TheGeneratedKernelTouchesOnlyTheListsAttributes) {
  const ActionList list{Gravity{Vec3(0.0f, -1.0f, 0.0f)}, Move{}};
  AttributeSet stored{Attribute::Position, Attribute::Id, Attribute::Velocity, Attribute::Color,
                      Attribute::Age};
  const std::string src = detail::ocl::programSource(list, stored, true);
  const auto act = src.substr(src.find("void fl_act_one("));  // the body fl_act calls
  EXPECT_NE(act.find("l_vx"), std::string::npos);
  EXPECT_NE(act.find("l_age"), std::string::npos);  // Move ages the stored age
  EXPECT_EQ(act.find("l_r["), std::string::npos);   // color: stored, but no action uses it
  // No action kills, but the NaN guard may: kill codes are written.
  EXPECT_NE(act.find("FL_NON_FINITE_CODE"), std::string::npos);
  EXPECT_NE(act.find("fl_gravity((ap + 0)"), std::string::npos);
  EXPECT_NE(act.find("fl_move("), std::string::npos);
}

// What the backend keeps between steps (packed constants, emitter codes, the emission
// tables on the device) follows every edit between steps: a new action list of the same
// shape, a new dt, emitters edited through emitters() and through a kept reference, a
// prime emitter added (whose children need a new program: two programs in all, as each
// costs seconds to compile cold). The device matches the CPU throughout (issue #11).
TEST(OpenCLBackend, EditsBetweenStepsTakeEffect) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [](Backend b) {
    ContextOptions o = openclOptions();
    o.backend = b;
    Context ctx(o);
    Group& g = ctx.createGroup("g", 4000);
    Emitter e;
    e.shape = Domain::sphere(Vec3(0.0f), 0.5f);
    ParticleType t;
    t.velocity = Domain::point(Vec3(0.0f, 1.0f, 0.0f));
    t.lifetime = 100.0f;
    e.types = {t};
    e.rate = 120.0;
    Emitter& kept = g.addEmitter(e);
    g.setActions({Gravity{Vec3(0.0f, -1.0f, 0.0f)}, Move{}});
    ctx.run(4);
    g.setActions({Gravity{Vec3(0.0f, 3.0f, 0.0f)}, Move{}});  // same program, new constants
    ctx.run(4);
    ctx.setTimeStep(1.0 / 50.0);  // constants made with dt
    ctx.run(4);
    g.emitters()[0].shape = Domain::sphere(Vec3(5.0f, 0.0f, 0.0f), 0.5f);  // new numbers
    ctx.run(4);
    kept.position = Vec3(0.0f, 0.0f, -3.0f);  // through the reference addEmitter returned
    kept.shape = Domain::sphere(Vec3(1.0f, 0.0f, 0.0f), 0.25f);
    ctx.run(4);
    PrimeEmitter prime;  // its children's code is new to the program
    prime.rate = 20.0;
    prime.child.lifetime = 0.2f;
    prime.child.emitter.rate = 100.0;
    prime.child.emitter.shape = Domain::box(Vec3(-1.0f), Vec3(1.0f));
    prime.child.emitter.types = {t};
    g.addPrimeEmitter(prime);
    ctx.run(6);
    std::map<std::uint32_t, std::pair<Vec3, Vec3>> out;
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Particle p = g.particle(i);
      out[p.id] = {p.position, p.velocity};
    }
    return out;
  };
  const auto cpu = run(Backend::Cpu);
  const auto cl = run(Backend::OpenCL);
  ASSERT_EQ(cpu.size(), cl.size());
  for (const auto& [id, pv] : cpu) {
    ASSERT_TRUE(cl.count(id)) << id;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(pv.first[c], cl.at(id).first[c], 1e-4f) << id;
      EXPECT_NEAR(pv.second[c], cl.at(id).second[c], 1e-4f) << id;
    }
  }
}

// The host writing particles between steps sends them to the device, and nothing more: the
// program is neither built again nor fetched from the cache (issue #11).
TEST(OpenCLBackend, HostLaneAccessDoesNotRebuildTheProgram) {
  FLURRY_REQUIRE_OPENCL();
  Context ctx(openclOptions());
  Group& g = samples::buildFountain(ctx, 10000, 2000, 2.0f);
  ctx.run(3);
  auto y = g.lane(Attribute::Position, 1);  // writable: the device takes the host's copy
  for (float& v : y) v += 1.0f;
  const auto before = detail::ocl::Runtime::cacheStats();
  ctx.run(3);
  const auto after = detail::ocl::Runtime::cacheStats();
  EXPECT_EQ(after.builds, before.builds);
  EXPECT_EQ(after.diskHits, before.diskHits);
  EXPECT_EQ(after.memoryHits, before.memoryHits);
  EXPECT_GT(g.size(), 0u);
}

// A small group's one launch (fl_small) gives each work-item a run of particles on a CPU
// device and strides the work-group over them on a GPU (backend.hpp SmallLayout): each is a
// program of its own, and both step like the CPU backend, here on the device this machine
// has. (A group of at most 4096 particles that records nothing takes fl_small.)
TEST(OpenCLBackend, ASmallGroupStepsAlikeInEitherLayout) {
  FLURRY_REQUIRE_OPENCL();
  using detail::ocl::SmallLayout;
  using namespace flurry::test;
  const Build build =
      withActions({Gravity{Vec3(0.0f, -9.81f, 0.0f)},
                   Bounce{Domain::plane(Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f)), 0.4f, 0.1f, 0.0f},
                   Move{}, KillOld{}},
                  spray(Vec3(0.0f, 1.0f, 0.0f), 1500), 4000);
  const RunResult cpu = runEffect(Backend::Cpu, build, 120);
  EXPECT_GT(cpu.size, 2000u);  // several work-items' runs, and passes of the work-group
  for (const SmallLayout layout : {SmallLayout::Runs, SmallLayout::Strided}) {
    SCOPED_TRACE(layout == SmallLayout::Runs ? "runs" : "strided");
    detail::ocl::setSmallLayout(layout);
    const auto before = detail::ocl::Runtime::cacheStats();
    const RunResult cl = runEffect(Backend::OpenCL, build, 120);
    const auto after = detail::ocl::Runtime::cacheStats();
    expectSame(cpu, cl);
    EXPECT_EQ(after.memoryHits, before.memoryHits);  // not the other layout's program
  }
  detail::ocl::setSmallLayout(SmallLayout::ByDevice);
}

// fl_act and fl_small share one act function: the program holds the list's body once
// (PoCL compiles less; issue #11).
TEST(OpenCLBackend, TheActBodyIsInTheProgramOnce) {
  const ActionList list{Gravity{Vec3(0.0f, -1.0f, 0.0f)}, Move{}, KillOld{}};
  const std::string src = detail::ocl::programSource(
      list, {Attribute::Position, Attribute::Id, Attribute::Velocity, Attribute::Age}, true);
  ASSERT_NE(src.find("__kernel void fl_small("), std::string::npos);
  const auto first = src.find("fl_gravity((ap + 0)");
  ASSERT_NE(first, std::string::npos);
  EXPECT_EQ(src.find("fl_gravity((ap + 0)", first + 1), std::string::npos);
}

// A reader gets back only what it names: lane(), ids(), bounds() and fetch() copy their own
// attributes once per step, size() and stats() none; the values are the device's latest
// (the same as a full read), and the host's later writes still see every attribute.
// (The list and attributes of HostReadsAndWritesBetweenSteps: one program for both.)
TEST(OpenCLBackend, ReadsBackOnlyWhatIsAsked) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [](Backend b) {
    HostGroup h(b);
    Context& ctx = h.ctx;
    Group& g = h.g;
    h.add(300, 0.01f, 0.01f);
    const Group& reader = g;
    std::vector<float> seen;
    const std::uint64_t lane = 4;  // bytes per particle per component
    for (int s = 0; s < 20; ++s) {
      ctx.step();
      if (s % 3 == 0) {
        const std::uint64_t before = g.stats().bytesReadBack;
        const std::size_t n = reader.size();
        EXPECT_EQ(g.stats().bytesReadBack, before) << "size() reads no particles";
        const auto y = reader.lane(Attribute::Position, 1);
        if (b == Backend::OpenCL) {
          EXPECT_EQ(g.stats().bytesReadBack - before, 3 * lane * n);
        }
        reader.bounds();
        reader.lane(Attribute::Position, 2);
        if (b == Backend::OpenCL) {
          EXPECT_EQ(g.stats().bytesReadBack - before, 3 * lane * n);
        }
        reader.fetch({Attribute::Position, Attribute::Velocity, Attribute::Color});  // no colour
        if (b == Backend::OpenCL) {
          EXPECT_EQ(g.stats().bytesReadBack - before, 6 * lane * n);
        }
        seen.insert(seen.end(), y.begin(), y.end());
        const auto vz = reader.lane(Attribute::Velocity, 2);
        seen.insert(seen.end(), vz.begin(), vz.end());
      }
      if (s % 3 == 1) {
        // The engine's packer reads what its layout names: here positions and ages.
        const std::uint64_t before = g.stats().bytesReadBack;
        const auto layout = PackLayout::interleaved(
            {{Attribute::Position, PackFormat::Float32}, {Attribute::Age, PackFormat::Float32}});
        std::vector<std::byte> out(reader.size() * layout.stride);
        const std::size_t n = packParticles(reader, layout, out);
        if (b == Backend::OpenCL) {
          EXPECT_EQ(g.stats().bytesReadBack - before, 4 * lane * n);
        }
      }
      if (s == 10) {
        // A write after a partial read: the device must take every attribute as it is.
        auto vy = g.lane(Attribute::Velocity, 1);
        for (float& v : vy) v += 1.0f;
      }
    }
    for (std::size_t i = 0; i < reader.size(); ++i) {
      const Particle p = reader.particle(i);
      seen.insert(seen.end(), {p.position.x, p.position.y, p.velocity.y, p.age, p.lifetime});
    }
    if (b == Backend::Cpu) {
      EXPECT_EQ(g.stats().bytesReadBack, 0u);
    }
    EXPECT_GT(reader.size(), 0u);
    EXPECT_LT(reader.size(), 300u);
    return seen;
  };
  const auto cpu = run(Backend::Cpu);
  const auto cl = run(Backend::OpenCL);
  ASSERT_EQ(cpu.size(), cl.size());
  for (std::size_t i = 0; i < cpu.size(); ++i) EXPECT_NEAR(cpu[i], cl[i], 1e-4f) << i;
}

// A group with nothing alive and no emitter costs no launch on the device either: its steps
// are counted idle, as on the CPU (a few later at most: the host learns the device's count
// of a step when that step has finished), and particles the host adds end the idling.
// (The list and attributes of HostReadsAndWritesBetweenSteps: one program for both.)
TEST(OpenCLBackend, IdleGroupsCostNoLaunch) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [](Backend b) {
    HostGroup h(b);
    Context& ctx = h.ctx;
    Group& g = h.g;
    auto addSome = [&](int n) { h.add(n, 0.0f, 0.02f, true); };
    addSome(100);
    ctx.run(30);
    EXPECT_EQ(g.size(), 0u);
    addSome(50);
    ctx.run(30);
    return std::make_pair(g.stats().idleSteps, g.stats().killedByAge);
  };
  const auto cpu = run(Backend::Cpu);
  const auto cl = run(Backend::OpenCL);
  EXPECT_EQ(cpu.second, 150u);
  EXPECT_EQ(cl.second, cpu.second);
  EXPECT_GT(cpu.first, 40u);
  EXPECT_LE(cl.first, cpu.first);
  EXPECT_GE(cl.first + 2 * 5, cpu.first);  // each of the two idle spells a few steps late
}

// PoCL's own kernel cache lives inside Flurry's (one folder to keep or clear), unless the
// user chose PoCL's folder. PoCL reads its folder when it loads: this checks what Flurry
// tells it, in a process where nothing loaded it before (ctest runs each test alone).
TEST(OpenCLBackend, PoclCacheLivesInFlurrysCache) {
  if (std::getenv("POCL_CACHE_DIR"))
    GTEST_SKIP() << "POCL_CACHE_DIR is set: the user's choice is kept";
  const auto dir = std::filesystem::temp_directory_path() / "flurry-test-pocl-cache";
  ::setenv("FLURRY_OPENCL_CACHE", dir.c_str(), 1);
  const std::string why = test::openclUnavailable();  // lists the devices: the driver loads
  ::unsetenv("FLURRY_OPENCL_CACHE");
  if (!why.empty()) GTEST_SKIP() << "OpenCL test skipped: " << why;
  if (test::openclChecks() > 1) GTEST_SKIP() << "the driver was loaded earlier in this process";
  const char* pocl = std::getenv("POCL_CACHE_DIR");
  ASSERT_NE(pocl, nullptr);
  EXPECT_EQ(std::filesystem::path(pocl), dir / "pocl");
}

// PoCL before 6 runs a kernel's work-items as vector lanes only with LLVM's SLP vectorizer
// off (runtime.cpp, letPoclVectorizeWorkItems; without it every act kernel ran one particle
// at a time): the first context on such a device turns it off, through the libLLVM the
// driver loaded, and says so in the log; another driver, a later PoCL or FLURRY_POCL_SLP=1
// leave LLVM as it is.
TEST(OpenCLBackend, PoclBefore6RunsWorkItemsAsVectorLanes) {
  const std::string why = test::openclUnavailable();
  if (!why.empty()) GTEST_SKIP() << "OpenCL test skipped: " << why;
  if (test::openclChecks() > 1)
    GTEST_SKIP() << "an OpenCL context was made earlier in this process";
  std::mutex m;
  std::vector<std::string> said;
  const LogCallback saved = setLogCallback([&](LogLevel, std::string_view s) {
    std::lock_guard lock(m);
    said.emplace_back(s);
  });
  {
    Context ctx(openclOptions());
    samples::buildFountain(ctx, 1000, 200, 2.0f);
    ctx.run(2);
  }
  setLogCallback(saved);
  const detail::ocl::Device d = detail::ocl::selectDevice("");
  const bool pocl = d.info.platform.find("Portable Computing Language") != std::string::npos;
  const bool before6 = pocl && d.cpu && std::atoi(d.info.driver.c_str()) < 6;
  const char* keep = std::getenv("FLURRY_POCL_SLP");
  const bool expected = before6 && !(keep && *keep && std::string(keep) != "0");
  bool told = false;
  for (const std::string& s : said) told |= s.find("SLP vectorizer is off") != std::string::npos;
  EXPECT_EQ(detail::ocl::poclSlpOff(), expected)
      << d.info.platform << " " << d.info.driver << " (FLURRY_POCL_SLP " << (keep ? keep : "unset")
      << ")";
  EXPECT_EQ(told, expected);
}

// An instance moved between steps: its emitter and floor follow it on the device as on the
// CPU, and the move reaches the device as constants, with no program rebuilt.
TEST(OpenCLBackend, InstanceTransformsMatchTheCpuWithoutARebuild) {
  FLURRY_REQUIRE_OPENCL();
  const Effect fx = parseEffect(R"({"name": "drop", "dt": 0.02,
    "groups": [{"name": "drop", "capacity": 4000,
      "emitters": [{"position": [0, 1, 0], "rate": 300, "types": [{"lifetime": 5,
                    "velocity": {"type": "sphere", "center": [0, -3, 0], "outerRadius": 1}}]}],
      "actions": [{"type": "Gravity"}, {"type": "Bounce", "surface": {"type": "disc",
                   "center": [0, 0, 0], "normal": [0, 1, 0], "outerRadius": 40},
                   "restitution": 0.5}, {"type": "Move"}, {"type": "KillOld"}]}]})");
  const Transform t1{Vec3(3, -2, 1), glm::angleAxis(0.4f, Vec3(0, 0, 1)), 1.5f};
  const Transform t2{Vec3(-1, 4, 2), glm::angleAxis(-0.3f, Vec3(1, 0, 0)), 0.8f};
  detail::ocl::CacheStats before{}, after{};
  auto run = [&](Backend backend) {
    ContextOptions o = fx.contextOptions();
    o.backend = backend;
    o.threads = 2;
    Context ctx(o);
    EffectInstance inst = fx.instantiate(ctx, "a");
    Group& g = *inst.groups()[0];
    inst.setTransform(t1);
    ctx.run(30);
    if (backend == Backend::OpenCL) before = detail::ocl::Runtime::cacheStats();
    inst.setTransform(t2);  // world space: the floor moves, the particles stay
    ctx.run(20);
    g.setSpace(Space::Local);
    inst.setTransform(t1);  // local space: the particles come along
    ctx.run(20);
    if (backend == Backend::OpenCL) after = detail::ocl::Runtime::cacheStats();
    return test::resultOf(g);
  };
  const test::RunResult cpu = run(Backend::Cpu), cl = run(Backend::OpenCL);
  ASSERT_GT(cpu.size, 300u);
  test::expectSame(cpu, cl);
  EXPECT_EQ(after.builds, before.builds);
  EXPECT_EQ(after.diskHits, before.diskHits);
  EXPECT_EQ(after.memoryHits, before.memoryHits);
}

// A move keeps the program except where its text holds a value the move scales: sub-steps
// by distance write maxDistance as a literal, so a scaled instance needs its own program.
TEST(OpenCLBackend, AScaledInstanceWithSubstepsByDistanceMatchesTheCpu) {
  FLURRY_REQUIRE_OPENCL();
  const Effect fx = parseEffect(R"({"name": "fast", "dt": 0.02,
    "groups": [{"name": "fast", "capacity": 2000,
      "emitters": [{"position": [0, 1, 0], "rate": 300, "types": [{"lifetime": 5,
                    "velocity": {"type": "sphere", "center": [0, -30, 0], "outerRadius": 5}}]}],
      "substeps": {"maxDistance": 0.05, "maxSubsteps": 16},
      "actions": [{"type": "Gravity"}, {"type": "Bounce", "surface": {"type": "disc",
                   "center": [0, 0, 0], "normal": [0, 1, 0], "outerRadius": 40},
                   "restitution": 0.5}, {"type": "Move"}, {"type": "KillOld"}]}]})");
  auto run = [&](Backend backend) {
    ContextOptions o = fx.contextOptions();
    o.backend = backend;
    o.threads = 2;
    Context ctx(o);
    EffectInstance inst = fx.instantiate(ctx, "a");
    inst.setTransform(Transform{Vec3(1, 0, 0), glm::quat(1, 0, 0, 0), 1.0f});
    ctx.run(20);
    inst.setTransform(Transform{Vec3(1, 0, 0), glm::quat(1, 0, 0, 0), 3.0f});
    ctx.run(20);
    return test::resultOf(*inst.groups()[0]);
  };
  const test::RunResult cpu = run(Backend::Cpu), cl = run(Backend::OpenCL);
  ASSERT_GT(cpu.size, 100u);
  test::expectSame(cpu, cl);
}

// A new action list of other kinds over the same stored attributes needs another program
// (the one built for the old list would run the old actions with the new constants).
TEST(OpenCLBackend, NewActionKindsOverTheSameAttributesGetTheirProgram) {
  FLURRY_REQUIRE_OPENCL();
  auto run = [&](Backend backend) {
    ContextOptions o;
    o.backend = backend;
    o.threads = 1;
    o.dt = 0.05;
    Context ctx(o);
    Group& g = ctx.createGroup("g", 2000);
    Emitter e;
    e.rate = 400;
    e.types[0].velocity = Domain::sphere(Vec3(0.0f, 2.0f, 0.0f), 1.0f);
    e.types[0].lifetime = 100.0f;
    g.addEmitter(e);
    g.setActions({Gravity{Vec3(0.0f, -9.81f, 0.0f)}, Move{}});
    ctx.run(10);
    g.setActions({Damping{Vec3(0.5f)}, Move{}});
    ctx.run(10);
    return test::resultOf(g);
  };
  const test::RunResult cpu = run(Backend::Cpu), cl = run(Backend::OpenCL);
  ASSERT_GT(cpu.size, 300u);
  test::expectSame(cpu, cl);
}
