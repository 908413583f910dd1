#pragma once
// The cache option of both renderers' command lines (rtr-view, rtr-trace; docs/files-and-cli.md).
#include <memory>

#include <CLI/CLI.hpp>

#include "scene/texture_cache.hpp"

namespace rtr::cli {

// --no-cache: nothing is read from or written to the user's cache folder. `more`: what else it turns off.
void addCacheOptions(CLI::App& app, bool& noCache, const char* more = "");

// The texture cache (RTR_TEXTURE_CACHE, RTR_TEXTURE_CACHE_MB), or null with --no-cache or when it is off.
std::unique_ptr<TextureCache> textureCache(bool noCache);

}  // namespace rtr::cli
