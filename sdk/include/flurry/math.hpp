// Vector types: GLM's, so that a game's own GLM vectors pass straight through.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace flurry {

using Vec3 = glm::vec3;
using Vec4 = glm::vec4;

}  // namespace flurry
