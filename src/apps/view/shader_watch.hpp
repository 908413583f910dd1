#pragma once
// --watch: notices edited GLSL under shaders/, recompiles every stage file with the glslang library and
// registers the results as shader overrides, so the renderer can rebuild its pipelines without a restart.
#include <filesystem>
#include <map>
#include <string>

namespace rtr::view {

class ShaderWatcher {
 public:
  explicit ShaderWatcher(std::filesystem::path dir);
  // True when something changed since the last call and all stage files recompiled; on a compile error
  // returns false and sets `error` (glslang's "file:line: message"), leaving the old shaders in place.
  bool poll(std::string& error);

 private:
  std::map<std::filesystem::path, std::filesystem::file_time_type> scan() const;
  std::filesystem::path dir_;
  std::map<std::filesystem::path, std::filesystem::file_time_type> seen_;
};

}  // namespace rtr::view
