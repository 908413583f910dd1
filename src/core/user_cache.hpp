#pragma once
// The user's cache folder, where rtr keeps what only saves time (compiled pipelines, decoded textures).
#include <filesystem>

namespace rtr {

// $XDG_CACHE_HOME/rtr (an absolute XDG_CACHE_HOME only), else $HOME/.cache/rtr; empty when neither is set.
std::filesystem::path userCacheDir();

}  // namespace rtr
