#include "field_math.hpp"

namespace flurry {

Vec3 VectorField::sample(Vec3 p) const {
  return detail::sampleTrilinear(*this, p);
}

}  // namespace flurry
