// Valid JSON for the action fields that hold a grid or a list of keys, which the descriptor
// tests (test_effect_descriptors, test_random_effects) write as they are.
#pragma once

#include <memory>
#include <type_traits>
#include <vector>

#include "flurry/actions.hpp"
#include "flurry/field.hpp"

namespace flurry::test {

/// T is a field type written from a fixed sample (listedSample).
template <class T>
inline constexpr bool kListed = std::is_same_v<T, std::shared_ptr<const VectorField>> ||
                                std::is_same_v<T, std::vector<ColorOverLife::Key>> ||
                                std::is_same_v<T, std::vector<SizeOverLife::Key>>;

/// A valid value of a kListed field type, as JSON.
template <class T>
constexpr const char* listedSample() {
  static_assert(kListed<T>);
  if constexpr (std::is_same_v<T, std::shared_ptr<const VectorField>>)
    return R"({"origin": [-1, 0, -1], "voxelSize": 2, "dims": [2, 1, 1],
               "data": [[0, 1, 0], [1, 0, 0]]})";
  else if constexpr (std::is_same_v<T, std::vector<ColorOverLife::Key>>)
    return R"([{"t": 0, "color": [1, 0.5, 0]}, {"t": 0.5, "color": [0, 0, 1, 0.5]}])";
  else
    return R"([{"t": 0.25, "size": 2}, {"t": 1, "size": 0.5}])";
}

}  // namespace flurry::test
