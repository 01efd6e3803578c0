#include "flurry/interop.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <string>

#include "flurry/error.hpp"

namespace flurry {

namespace {

bool isUIntAttribute(Attribute a) {
  return a == Attribute::Id || a == Attribute::Visible;
}

std::uint32_t alignUp(std::uint32_t v, std::uint32_t a) {
  return (v + a - 1) / a * a;
}

// Particle's defaults, per component, for attributes a group does not store.
float defaultComponent(Attribute a, int c) {
  const Particle d;
  switch (a) {
    case Attribute::Position:
      return d.position[c];
    case Attribute::Velocity:
      return d.velocity[c];
    case Attribute::Color:
      return d.color[c];
    case Attribute::Size:
      return d.size;
    case Attribute::Mass:
      return d.mass;
    case Attribute::Age:
      return d.age;
    case Attribute::Lifetime:
      return d.lifetime;
    case Attribute::PrevPosition:
      return d.prevPosition[c];
    case Attribute::Up:
      return d.up[c];
    case Attribute::RotVelocity:
      return d.rotVelocity[c];
    case Attribute::Charge:
      return d.charge;
    case Attribute::Visible:
      return 1.0f;
    case Attribute::UserData:
      return d.userData;
    case Attribute::BirthColor:
      return d.color[c];
    case Attribute::BirthSize:
      return d.size;
    default:
      return 0.0f;
  }
}

void validate(const PackLayout& layout) {
  if (layout.stride == 0) throw InvalidArgument("layout.stride", "must be > 0");
  for (std::size_t i = 0; i < layout.fields.size(); ++i) {
    const PackField& f = layout.fields[i];
    const std::string name = "layout.fields[" + std::to_string(i) + "]";
    if (f.attribute >= Attribute::Count)
      throw InvalidArgument(name + ".attribute", "not an attribute");
    if (f.format == PackFormat::UInt32 && !isUIntAttribute(f.attribute))
      throw InvalidArgument(name + ".format", "UInt32 is for id and visible only, not " +
                                                  std::string(attributeName(f.attribute)));
    const std::uint32_t bytes = packedBytes(f.format) * componentCount(f.attribute);
    if (std::uint64_t(f.offset) + bytes > layout.stride)
      throw InvalidArgument(name + ".offset",
                            "field ends at byte " + std::to_string(f.offset + bytes) +
                                ", past the stride " + std::to_string(layout.stride));
    if (packedBytes(f.format) == 4 && (f.offset % 4 != 0 || layout.stride % 4 != 0))
      throw InvalidArgument(name + ".offset",
                            "4-byte components need 4-byte aligned offset and stride");
  }
}

// Writes component values v[k] (k over the selected particles) into the strided output.
template <typename Get>
void writeField(std::byte* out, std::uint32_t stride, std::uint32_t offset, PackFormat format,
                std::size_t n, Get get) {
  std::byte* dst = out + offset;
  switch (format) {
    case PackFormat::Float32:
      for (std::size_t k = 0; k < n; ++k, dst += stride) {
        const float v = float(get(k));
        std::memcpy(dst, &v, 4);
      }
      break;
    case PackFormat::UNorm8:
      for (std::size_t k = 0; k < n; ++k, dst += stride) {
        const float v = std::clamp(float(get(k)), 0.0f, 1.0f);
        *dst = std::byte(std::uint8_t(std::lround(v * 255.0f)));
      }
      break;
    case PackFormat::UInt32:
      for (std::size_t k = 0; k < n; ++k, dst += stride) {
        const std::uint32_t v = std::uint32_t(get(k));
        std::memcpy(dst, &v, 4);
      }
      break;
  }
}

}  // namespace

PackLayout PackLayout::interleaved(std::initializer_list<std::pair<Attribute, PackFormat>> fields) {
  PackLayout l;
  std::uint32_t at = 0;
  for (const auto& [a, fmt] : fields) {
    const std::uint32_t size = packedBytes(fmt);
    at = alignUp(at, size);
    l.fields.push_back({a, fmt, at});
    at += size * componentCount(a);
  }
  l.stride = alignUp(std::max<std::uint32_t>(at, 1), 4);
  return l;
}

PackLayout PackLayout::instances() {
  return interleaved({{Attribute::Position, PackFormat::Float32},
                      {Attribute::Size, PackFormat::Float32},
                      {Attribute::Color, PackFormat::Float32}});
}

AttributeSet PackLayout::attributes() const {
  AttributeSet s;
  for (const PackField& f : fields)
    if (f.attribute != Attribute::Visible) s.insert(f.attribute);
  return s;
}

std::size_t packParticles(const Group& group, const PackLayout& layout, std::span<std::byte> out,
                          const PackOptions& options) {
  validate(layout);
  const std::size_t size = group.size();
  if (out.size() < size * layout.stride)
    throw InvalidArgument("out", "holds " + std::to_string(out.size()) + " bytes, " +
                                     std::to_string(size * layout.stride) + " needed");
  const AttributeSet stored = group.attributes();
  // What it reads, back from a device in one transfer: nothing else crosses.
  AttributeSet reads{Attribute::Position};
  if (options.skipHidden) reads.insert(Attribute::Visible);
  for (const PackField& f : layout.fields) reads.insert(f.attribute);
  group.fetch(reads);
  auto px = group.lane(Attribute::Position, 0);
  auto py = group.lane(Attribute::Position, 1);
  auto pz = group.lane(Attribute::Position, 2);

  // The kept particles, in drawing order. The identity order is the common case (nothing
  // hidden, no sort) and then needs no index list.
  std::vector<std::uint32_t> order;
  bool identity = true;
  const bool hide = options.skipHidden && stored.has(Attribute::Visible);
  if (hide || !options.blockers.empty() || options.sortFromEye) {
    identity = false;
    order.reserve(size);
    std::span<const std::uint32_t> vis;
    if (hide) vis = group.visible();
    for (std::size_t i = 0; i < size; ++i) {
      if (hide && vis[i] == 0) continue;
      const Vec3 p(px[i], py[i], pz[i]);
      bool blocked = false;
      for (const Domain& b : options.blockers)
        if (b.contains(p)) {
          blocked = true;
          break;
        }
      if (!blocked) order.push_back(std::uint32_t(i));
    }
    if (options.sortFromEye) {
      const Vec3 e = *options.sortFromEye;
      std::vector<float> d2(size);
      for (std::uint32_t i : order) {
        const Vec3 p(px[i] - e.x, py[i] - e.y, pz[i] - e.z);
        d2[i] = glm::dot(p, p);
      }
      std::stable_sort(order.begin(), order.end(),
                       [&](std::uint32_t a, std::uint32_t b) { return d2[a] > d2[b]; });
    }
  }
  const std::size_t n = identity ? size : order.size();
  auto index = [&](std::size_t k) -> std::size_t { return identity ? k : order[k]; };

  for (const PackField& f : layout.fields) {
    const std::uint32_t cb = packedBytes(f.format);
    for (int c = 0; c < componentCount(f.attribute); ++c) {
      const std::uint32_t offset = f.offset + cb * std::uint32_t(c);
      if (!stored.has(f.attribute)) {
        const float v = defaultComponent(f.attribute, c);
        writeField(out.data(), layout.stride, offset, f.format, n, [v](std::size_t) { return v; });
      } else if (isUIntAttribute(f.attribute)) {
        auto lane = f.attribute == Attribute::Id ? group.ids() : group.visible();
        writeField(out.data(), layout.stride, offset, f.format, n,
                   [&](std::size_t k) { return lane[index(k)]; });
      } else {
        auto lane = group.lane(f.attribute, c);
        writeField(out.data(), layout.stride, offset, f.format, n,
                   [&](std::size_t k) { return lane[index(k)]; });
      }
    }
  }
  return n;
}

std::size_t trailStrands(const Group& group, Strands& out, const PackOptions& options) {
  out.clear();
  const TrailOptions& look = group.trail();
  if (look.length == 0) return 0;
  const std::size_t size = group.size();
  const AttributeSet stored = group.attributes();
  const bool hide = options.skipHidden && stored.has(Attribute::Visible);
  AttributeSet reads{Attribute::Position};
  if (hide) reads.insert(Attribute::Visible);
  if (stored.has(Attribute::Color)) reads.insert(Attribute::Color);
  if (look.width == 0.0f && stored.has(Attribute::Size)) reads.insert(Attribute::Size);
  group.fetch(reads);
  std::span<const float> color[4], radius;
  if (stored.has(Attribute::Color))
    for (int c = 0; c < 4; ++c) color[c] = group.lane(Attribute::Color, c);
  if (look.width == 0.0f && stored.has(Attribute::Size)) radius = group.lane(Attribute::Size);
  std::span<const std::uint32_t> vis;
  if (hide) vis = group.visible();
  const Particle defaults;
  Vec3 points[TrailOptions::kMaxLength];
  for (std::size_t i = 0; i < size; ++i) {
    if (hide && vis[i] == 0) continue;
    const std::size_t n = group.trail(i, points);
    if (n < 2) continue;
    bool blocked = false;
    for (const Domain& b : options.blockers) blocked = blocked || b.contains(points[0]);
    if (blocked) continue;
    const Vec4 c = color[0].empty() ? defaults.color
                                    : Vec4(color[0][i], color[1][i], color[2][i], color[3][i]);
    const float r = look.width > 0.0f ? look.width : radius.empty() ? defaults.size : radius[i];
    for (std::size_t k = 0; k < n; ++k) {
      const float along = float(k) / float(n - 1);  // 0 at the particle, 1 at the oldest
      out.position.push_back(points[k]);
      out.radius.push_back(r * (1.0f + (look.taper - 1.0f) * along));
      out.color.emplace_back(Vec3(c), c.a * (1.0f + (look.fade - 1.0f) * along));
    }
    out.start.push_back(std::uint32_t(out.position.size()));
  }
  return out.size();
}

std::vector<std::byte> packParticles(const Group& group, const PackLayout& layout,
                                     const PackOptions& options) {
  std::vector<std::byte> bytes(std::size_t(group.size()) * layout.stride);
  const std::size_t n = packParticles(group, layout, bytes, options);
  bytes.resize(n * layout.stride);
  return bytes;
}

}  // namespace flurry
