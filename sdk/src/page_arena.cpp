#include "page_arena.hpp"

#include <sys/mman.h>

#include <cstdlib>
#include <mutex>
#include <new>
#include <unordered_map>
#include <vector>

namespace flurry::detail {

namespace {

[[maybe_unused]] constexpr std::size_t kPage = std::size_t(2) << 20;
constexpr std::size_t kLine = 64;

#if defined(__SANITIZE_ADDRESS__)
#define FLURRY_ARENA_OFF 1  // AddressSanitizer checks each piece only from the heap
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FLURRY_ARENA_OFF 1
#endif
#endif

struct Arena {
  std::mutex mutex;
  char* next = nullptr;  ///< the unused rest of the newest page
  char* end = nullptr;
  std::unordered_map<std::size_t, std::vector<void*>> freed;  ///< by rounded size
  std::vector<void*> pages;  ///< all of them, kept for the process's life
};

[[maybe_unused]] Arena& arena() {
  // Never destroyed: groups of a static Context may give pieces back after static teardown.
  static Arena* a = new Arena;
  return *a;
}

std::size_t rounded(std::size_t bytes) {
  return (bytes + kLine - 1) / kLine * kLine;
}

}  // namespace

void* arenaAllocate(std::size_t bytes) {
  bytes = rounded(bytes == 0 ? 1 : bytes);
#ifdef FLURRY_ARENA_OFF
  if (void* p = std::aligned_alloc(kLine, bytes)) return p;
  throw std::bad_alloc();
#else
  Arena& a = arena();
  const std::lock_guard lock(a.mutex);
  if (auto it = a.freed.find(bytes); it != a.freed.end() && !it->second.empty()) {
    void* p = it->second.back();
    it->second.pop_back();
    return p;
  }
  if (std::size_t(a.end - a.next) < bytes) {
    // The rest of the old page stays unused: at most a piece's size, a few percent of it.
    void* page = std::aligned_alloc(kPage, kPage);
    if (!page) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
    madvise(page, kPage, MADV_HUGEPAGE);  // a hint; without it only speed is lost
#endif
    a.pages.push_back(page);
    a.next = static_cast<char*>(page);
    a.end = a.next + kPage;
  }
  void* p = a.next;
  a.next += bytes;
  return p;
#endif
}

void arenaFree(void* piece, std::size_t bytes) noexcept {
  if (!piece) return;
#ifdef FLURRY_ARENA_OFF
  (void)bytes;
  std::free(piece);
#else
  Arena& a = arena();
  const std::lock_guard lock(a.mutex);
  try {
    a.freed[rounded(bytes == 0 ? 1 : bytes)].push_back(piece);
  } catch (...) {
    // No room to remember it: the piece is lost to reuse, nothing else.
  }
#endif
}

}  // namespace flurry::detail
