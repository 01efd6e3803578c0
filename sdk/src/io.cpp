#include "flurry/io.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "flurry/error.hpp"
#include "group_impl.hpp"

namespace flurry {

void writeFileAtomic(const std::filesystem::path& path, std::span<const char> bytes) {
  namespace fs = std::filesystem;
  const fs::path tmp = path.string() + ".tmp." + std::to_string(::getpid());
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw IoError(path.string(), std::string("cannot create: ") + std::strerror(errno));
  const std::size_t written = std::fwrite(bytes.data(), 1, bytes.size(), f);
  int err = written == bytes.size() ? 0 : errno;
  if (std::fflush(f) != 0 && !err) err = errno;
  if (!err && ::fsync(::fileno(f)) != 0 && errno != EINVAL) err = errno;
  if (std::fclose(f) != 0 && !err) err = errno;
  if (err) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw IoError(path.string(), std::string("write failed: ") + std::strerror(err ? err : EIO));
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw IoError(path.string(), "rename failed: " + ec.message());
  }
}

void writePly(const Group& group, const std::filesystem::path& path) {
  const auto& g = group.impl();
  const detail::Lanes L = g.lanePointers();
  struct Column {
    const char* type;
    std::string name;
    const std::uint32_t* data;
  };
  std::vector<Column> cols;
  auto add = [&](const char* type, std::string name, const void* p) {
    if (p) cols.push_back({type, std::move(name), static_cast<const std::uint32_t*>(p)});
  };
  const char* xyz[] = {"x", "y", "z"};
  for (int c = 0; c < 3; ++c) add("float", xyz[c], L.p[c]);
  for (int c = 0; c < 3; ++c) add("float", std::string("v") + xyz[c], L.v[c]);
  const char* rgba[] = {"red", "green", "blue", "alpha"};
  for (int c = 0; c < 4; ++c) add("float", rgba[c], L.color[c]);
  add("float", "radius", L.size);
  add("float", "age", L.age);
  add("uint", "id", L.id);

  std::string header = "ply\nformat binary_little_endian 1.0\ncomment flurry group " + g.name +
                       "\nelement vertex " + std::to_string(g.size) + "\n";
  for (const auto& c : cols) header += std::string("property ") + c.type + " " + c.name + "\n";
  header += "end_header\n";
  std::vector<char> bytes(header.begin(), header.end());
  const std::size_t start = bytes.size();
  bytes.resize(start + g.size * cols.size() * 4);
  char* out = bytes.data() + start;
  for (std::size_t i = 0; i < g.size; ++i)
    for (const auto& c : cols) {
      std::memcpy(out, c.data + i, 4);  // x86 and ARM are little-endian
      out += 4;
    }
  writeFileAtomic(path, bytes);
}

}  // namespace flurry
