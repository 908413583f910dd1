#include "apps/common/cache_options.hpp"

#include <string>

namespace rtr::cli {

void addCacheOptions(CLI::App& app, bool& noCache, const char* more) {
  app.add_flag("--no-cache", noCache,
               std::string("neither read nor write the texture cache (decoded, mipped textures of OBJ and glTF files: "
                           "$XDG_CACHE_HOME/rtr/textures or ~/.cache/rtr/textures; RTR_TEXTURE_CACHE=DIR|off, "
                           "RTR_TEXTURE_CACHE_MB=N, default ") +
                   std::to_string(kTextureCacheDefaultMiB) + ")" + more);
}

std::unique_ptr<TextureCache> textureCache(bool noCache) { return noCache ? nullptr : TextureCache::fromEnvironment(); }

}  // namespace rtr::cli
