// One of every leaf shape (every Domain but a mesh and a union), with a hole, a shell, a
// tilted normal or a slanted axis where the shape has one: for the tests that go through
// every shape.
#pragma once

#include <vector>

#include "flurry/domain.hpp"

inline std::vector<flurry::Domain> leafShapes() {
  using flurry::Domain;
  using flurry::Vec3;
  return {
      Domain::point(Vec3(0.1f, 0.2f, 0.3f)),
      Domain::line(Vec3(-1.0f, 0.0f, 0.0f), Vec3(1.0f, 0.5f, 0.0f)),
      Domain::triangle(Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f), Vec3(0.0f, 1.0f, 1.0f)),
      Domain::plane(Vec3(0.0f, 0.5f, 0.0f), Vec3(0.0f, 1.0f, 0.0f)),
      Domain::rectangle(Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f), Vec3(0.2f, 0.0f, 1.0f)),
      Domain::disc(Vec3(0.0f), Vec3(0.3f, 1.0f, 0.0f), 1.0f, 0.4f),
      Domain::box(Vec3(-1.0f), Vec3(1.0f, 2.0f, 3.0f)),
      Domain::sphere(Vec3(0.0f, 1.0f, 0.0f), 1.0f, 0.5f),
      Domain::sphere(Vec3(0.0f), 2.0f, 2.0f),
      Domain::cylinder(Vec3(0.0f), Vec3(0.0f, 2.0f, 1.0f), 0.5f, 0.2f),
      Domain::cone(Vec3(0.0f), Vec3(0.0f, 3.0f, 0.0f), 1.0f, 0.5f),
      Domain::cone(Vec3(0.0f), Vec3(1.0f, 3.0f, 0.0f), 1.0f, 1.0f),
      Domain::blob(Vec3(0.0f, 1.0f, 0.0f), 0.5f),
  };
}
