#include "flurry/io.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
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

namespace {

bool allDigits(std::string_view s) {
  if (s.empty()) return false;
  for (char c : s)
    if (c < '0' || c > '9') return false;
  return true;
}

/// Whether process `pid` may still be running here (EPERM: it is, under another user).
bool processRunning(pid_t pid) {
  return pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH;
}

}  // namespace

bool isFrameFileName(std::string_view name, std::string_view base, std::string_view ext) {
  // BASE '.' ['-'] digits '.' EXT
  if (name.size() < base.size() + ext.size() + 3 || !name.starts_with(base) || !name.ends_with(ext))
    return false;
  std::string_view mid = name.substr(base.size(), name.size() - base.size() - ext.size());
  if (mid.front() != '.' || mid.back() != '.') return false;
  mid = mid.substr(1, mid.size() - 2);
  if (mid.starts_with('-')) mid.remove_prefix(1);
  return allDigits(mid);
}

std::vector<std::filesystem::path> removeStaleTemporaries(
    const std::filesystem::path& folder, const std::function<bool(std::string_view)>& isOutput) {
  namespace fs = std::filesystem;
  std::vector<fs::path> removed;
  std::error_code ec;
  fs::directory_iterator it(folder, ec);
  if (ec) return removed;
  constexpr std::string_view kTmp = ".tmp.";
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    if (ec) break;
    const std::string name = it->path().filename().string();
    const std::size_t at = name.rfind(kTmp);
    if (at == std::string::npos || at == 0) continue;
    // The PID exactly as std::to_string writes it: digits, no leading zero, in range.
    const std::string_view digits = std::string_view(name).substr(at + kTmp.size());
    if (!allDigits(digits) || digits.front() == '0') continue;
    pid_t pid = 0;
    const auto [end, err] = std::from_chars(digits.data(), digits.data() + digits.size(), pid);
    if (err != std::errc() || end != digits.data() + digits.size() || pid <= 0) continue;
    if (!isOutput(std::string_view(name).substr(0, at)) || processRunning(pid)) continue;
    std::error_code typeEc;
    if (it->symlink_status(typeEc).type() != fs::file_type::regular) continue;  // not a link
    std::error_code rmEc;
    if (fs::remove(it->path(), rmEc)) removed.push_back(it->path());
  }
  return removed;
}

void writePly(const Group& group, const std::filesystem::path& path) {
  const auto& g = detail::implOf(group);
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
