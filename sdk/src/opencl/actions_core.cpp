// The core actions on the device: Move, KillOld, CopyVertexB, Restore, Callback (its OpenCL
// body). Their functions are in kernels/actions.cl.
#include <regex>
#include <string>

#include "codegen.hpp"

namespace flurry::detail::ocl {

bool generateCoreAction(const Action& act, ActionSource& s) {
  const AttributeSet& stored = s.in.stored;
  if (std::holds_alternative<KillOld>(act)) {
    s.apply = "fl_kill_old(age, life, " + s.in.code + ", &dead);\n";
    return true;
  }
  if (std::holds_alternative<Move>(act)) {
    // Semi-implicit Euler; codegen.cpp writes the other integrators' Move itself.
    if (stored.has(Attribute::PrevPosition)) {
      s.writes.insert(Attribute::PrevPosition);
      s.apply += "prevx = px; prevy = py; prevz = pz;\n";
    }
    s.apply += "fl_move(dt, &px, &py, &pz, vx, vy, vz);\n";
    if (stored.has(Attribute::Age)) {
      s.reads.insert(Attribute::Age);
      s.writes.insert(Attribute::Age);
      s.apply += "age += dt;\n";
    }
    if (stored.has(Attribute::Up) && stored.has(Attribute::RotVelocity)) {
      s.reads.insert({Attribute::Up, Attribute::RotVelocity});
      s.writes.insert(Attribute::Up);
      s.apply += "fl_turn_up(dt, &upx, &upy, &upz, rotx, roty, rotz);\n";
    }
    return true;
  }
  if (const auto* c = std::get_if<CopyVertexB>(&act)) {
    if (c->copyPosition) {
      s.apply += "pbx = px; pby = py; pbz = pz;\n";
    }
    if (c->copyVelocity) {
      s.apply += "vbx = vx; vby = vy; vbz = vz;\n";
    }
    return true;
  }
  if (std::holds_alternative<Restore>(act)) {
    s.apply = "fl_restore(" + s.in.params +
              "->own.restore, dt, time, &px, &py, &pz, &vx, &vy, &vz, pbx, pby, pbz);\n";
    return true;
  }
  if (const auto* c = std::get_if<Callback>(&act)) {
    if (c->opencl.empty())
      notOnDevice(
          "a Callback without an OpenCL body (Callback::opencl; its C++ function "
          "cannot run on the device)");
    // The user's statements see the lanes it declared by their kernel names (attributeAccess:
    // all written back but the id); the block keeps its locals its own.
    // A `return` would leave the whole kernel (in fl_small, before its barriers): refused.
    static const std::regex kReturn("\\breturn\\b");
    if (std::regex_search(c->opencl, kReturn))
      throw Error(
          "OpenCL backend: Callback::opencl must not contain 'return' (it would leave "
          "the kernel); use 'break' to end the callback early");
    // do-while: a `break` or `continue` in it ends the callback, not the kernel's loop.
    s.apply = "do {\n" + c->opencl + "\n} while (0);\n";
    return true;
  }
  return false;
}

}  // namespace flurry::detail::ocl
