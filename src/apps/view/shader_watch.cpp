#include "shader_watch.hpp"

#include <vector>

#include "core/error.hpp"
#include "vk/glsl.hpp"
#include "vk/pipeline.hpp"

namespace rtr::view {

ShaderWatcher::ShaderWatcher(std::filesystem::path dir) : dir_(std::move(dir)), seen_(scan()) {}

std::map<std::filesystem::path, std::filesystem::file_time_type> ShaderWatcher::scan() const {
  std::map<std::filesystem::path, std::filesystem::file_time_type> out;
  std::error_code ec;
  for (auto it = std::filesystem::recursive_directory_iterator(dir_, ec); !ec && it != decltype(it)(); it.increment(ec))
    if (it->is_regular_file(ec)) out[it->path()] = it->last_write_time(ec);
  return out;
}

bool ShaderWatcher::poll(std::string& error) {
  auto now = scan();
  if (now == seen_) return false;
  seen_ = now;
  // Any file may be an include of any stage: recompile every stage file, register only if all compile.
  std::vector<std::pair<std::string, vk::SpirvModule>> compiled;
  try {
    for (const auto& [path, time] : now)
      if (vk::isGlslPath(path)) compiled.emplace_back(path.filename().string(), vk::compileGlsl(path, {dir_, dir_ / "shared"}));
  } catch (const Error& e) {
    error = e.what();
    return false;
  }
  for (auto& [name, module] : compiled) vk::setShaderOverride(name, std::move(module));
  error.clear();
  return true;
}

}  // namespace rtr::view
