#include "core/user_cache.hpp"

#include <cstdlib>

namespace rtr {

std::filesystem::path userCacheDir() {
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x == '/') return std::filesystem::path(x) / "rtr";
  if (const char* h = std::getenv("HOME"); h && *h) return std::filesystem::path(h) / ".cache" / "rtr";
  return {};
}

}  // namespace rtr
