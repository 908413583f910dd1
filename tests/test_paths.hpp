#pragma once
// Where the Vulkan tests find their files, with no path of the build machine needed at run time:
// $RTR_BINARY_DIR, else the folder above the executable's bin/ (the build tree, or a bundle from
// tools/bundle_device.sh); $RTR_SOURCE_DIR, else that folder's src/ (a bundle's copy of the test data),
// else two folders above it (build/<preset> in the repository); $RTR_ASSET_DIR, else <binary dir>/assets.
// Compiled shaders: vk::shaderDir() ($RTR_SHADER_DIR, else <exe>/../shaders).
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <filesystem>
#include <string>

namespace rtr::test {

inline std::filesystem::path envOr(const char* name, const std::filesystem::path& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::filesystem::path(v) : fallback;
}

inline std::filesystem::path binaryDir() {
  return envOr("RTR_BINARY_DIR", std::filesystem::canonical("/proc/self/exe").parent_path().parent_path());
}

inline std::filesystem::path sourceDir() {
  const std::filesystem::path b = binaryDir();
  return envOr("RTR_SOURCE_DIR", std::filesystem::exists(b / "src/tests") ? b / "src" : b.parent_path().parent_path());
}

inline std::filesystem::path assetDir() { return envOr("RTR_ASSET_DIR", binaryDir() / "assets"); }

// A tool built beside the tests (rtr-reflect).
inline std::string toolPath(const std::string& name) { return (binaryDir() / "bin" / name).string(); }

// Runs that tool with `args` (shell words), `env` (env(1)'s words: NAME=value, -u NAME) in front where given;
// returns stdout and stderr together (stdout alone with `withStderr` false), the wait status in *status.
inline std::string runTool(const std::string& name, const std::string& args, int* status, const std::string& env = "",
                           bool withStderr = true) {
  const std::string cmd =
      (env.empty() ? "" : "env " + env + " ") + toolPath(name) + " " + args + (withStderr ? " 2>&1" : " 2>/dev/null");
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::string out;
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), pipe.get())) out.append(buf.data(), n);
  *status = pclose(pipe.release());
  return out;
}

// A wait status as an exit code: -1 where the process did not exit (a signal).
inline int exitCode(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : -1; }

}  // namespace rtr::test
