// The built-in sprite bitmaps, made procedurally, and PNG sprites.
#pragma once

#include "flurry/render.hpp"

namespace flurry::detail {

/// A white RGBA bitmap whose alpha is the shape (Disc, Spark, Snowflake), `size` square; or,
/// for Sprite::Image, the PNG at `path`. Rows bottom to top, as GL textures want them.
Image spriteBitmap(Sprite sprite, const std::string& path, int size = 128);

}  // namespace flurry::detail
