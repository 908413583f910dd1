// rtr-reflect: prints the interface of a pipeline's shaders, as the renderer derives its layouts from it.
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "core/cli.hpp"
#include "core/error.hpp"
#include "vk/glsl.hpp"
#include "vk/pipeline.hpp"
#include "vk/reflect.hpp"

namespace {

// The worker's address-space limit: our largest pipeline reflects in well under 200 MB; a module that
// makes SPIRV-Reflect or glslang run away is stopped here, not by the machine.
constexpr rlim_t kWorkerMemory = rlim_t(2) << 30;

std::string joined(const std::vector<std::string>& files) {
  std::string names;
  for (const auto& f : files) names += (names.empty() ? "" : ", ") + f;
  return names;
}

// "ID=VALUE", both whole numbers that fit 32 bits; a usage error naming --spec otherwise.
rtr::vk::SpecializationConstant parseSpec(const std::string& text) {
  const size_t eq = text.find('=');
  auto part = [&](const std::string& t) {
    size_t used = 0;
    unsigned long long v = 0;
    try {
      v = std::stoull(t, &used, 0);
    } catch (const std::exception&) { used = 0; }
    if (t.empty() || used != t.size() || t[0] == '-' || v > UINT32_MAX)
      throw rtr::UsageError("--spec '" + text + "': expected ID=VALUE, whole numbers of 32 bits (a bool: 0 or 1)");
    return uint32_t(v);
  };
  if (eq == std::string::npos) part("");
  return {part(text.substr(0, eq)), part(text.substr(eq + 1))};
}

int reflectAll(const std::vector<std::string>& files, const std::vector<std::string>& includes, bool json, bool noValidate,
               bool strict, const std::vector<rtr::vk::SpecializationConstant>& specs) {
  try {
    return rtr::stage("reflecting " + joined(files), [&] {
      std::vector<std::filesystem::path> dirs(includes.begin(), includes.end());
      std::vector<rtr::vk::SpirvModule> modules;
      for (const auto& f : files) {
        modules.push_back(rtr::vk::isGlslPath(f) ? rtr::vk::compileGlsl(f, dirs) : rtr::vk::readSpirv(f));
        if (noValidate) continue;
        try {
          rtr::vk::validateSpirv(modules.back());
        } catch (const rtr::Error& e) {
          if (strict) throw;
          std::fprintf(stderr, "rtr-reflect: warning: %s\n  (reflecting it anyway; --strict makes this an error)\n", e.what());
        }
      }
      for (auto& m : modules) m = rtr::vk::specialize(m, specs);
      const auto iface = rtr::vk::reflectPipeline(modules);
      std::cout << (json ? rtr::vk::toJson(iface) : rtr::vk::toText(iface));
      return 0;
    });
  } catch (const std::exception& e) { return rtr::cli::fail("rtr-reflect", e); }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rtr-reflect: print the interface of the shaders that form one pipeline, merged across stages.\n"
      "Inputs are SPIR-V (.spv) or GLSL (compiled with glslang for Vulkan 1.3; the extension names the\n"
      "stage: .vert .frag .comp .rgen .rchit ...). A module may hold several entry points.\n"
      "Prints entry points and stages, compute workgroup sizes, specialization constants, descriptor\n"
      "sets (binding, type, count, image format, name, stages), push-constant ranges, block members with\n"
      "offsets and sizes (buffer references name the block they point to), vertex inputs and fragment\n"
      "outputs. The descriptor set layouts and push-constant ranges shown are exactly those the renderer\n"
      "creates. SPIR-V that spirv-val rejects is a warning (newer compilers write what Debian's validator\n"
      "does not know yet), an error with --strict. Exit status 1 on SPIR-V that cannot be reflected, a\n"
      "GLSL error, a cross-stage conflict, or with --strict a module spirv-val rejects.",
      "rtr-reflect"};
  std::vector<std::string> files;
  std::vector<std::string> includes;
  std::vector<std::string> specTexts;
  bool json = false, noValidate = false, strict = false;
  app.add_option("shaders", files, "SPIR-V or GLSL files of one pipeline")->required()->check(CLI::ExistingFile);
  app.add_flag("--json", json, "machine-readable JSON output");
  // One folder per -I: without allow_extra_args(false) "-I a x.vert" would take x.vert as a folder too.
  app.add_option("-I,--include", includes, "include folder for GLSL inputs (repeatable)")->allow_extra_args(false);
  app.add_flag("--no-validate", noValidate, "skip spirv-val style validation of SPIR-V inputs");
  app.add_flag("--strict", strict, "a module spirv-val rejects is an error (exit 1), not a warning");
  app.add_option("--spec", specTexts,
                 "ID=VALUE: a specialization constant's value (a bool: 0 or 1), applied before reflecting as the "
                 "renderer applies it for a variant (repeatable)")
      ->allow_extra_args(false)
      ->check(rtr::cli::checked([](const std::string& t) { parseSpec(t); }, "ID=VALUE"));
  if (const int rc = rtr::cli::parse(app, argc, argv); rc >= 0) return rc;
  std::vector<rtr::vk::SpecializationConstant> specs;
  for (const std::string& t : specTexts) specs.push_back(parseSpec(t));

  // SPIRV-Reflect (third party) asserts or crashes on some modules, even ones spirv-val accepts (found
  // by fuzzing, docs/fuzzing.md). The work runs in a child process so that the tool reports such a module
  // instead of dying with it.
  // It dies with this process (SIGKILL when the parent goes, however it goes) and is bounded in memory.
  std::fflush(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(1);                               // the parent died before the line above took effect
#if !defined(__SANITIZE_ADDRESS__) && !defined(RTR_NO_WORKER_LIMIT)  // ASan reserves terabytes of shadow
    rlimit limit{};
    if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur > kWorkerMemory) {  // only ever lowered
      limit.rlim_cur = kWorkerMemory;
      ::setrlimit(RLIMIT_AS, &limit);
    }
#endif
    const int rc = reflectAll(files, includes, json, noValidate, strict, specs);
    std::cout.flush();
    std::fflush(nullptr);
    _exit(rc);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) != pid) return reflectAll(files, includes, json, noValidate, strict, specs);
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  std::fprintf(stderr,
               "rtr-reflect: error: %s: SPIRV-Reflect crashed reading it (signal %d); the module is "
               "malformed in a way SPIRV-Reflect does not check\n",
               joined(files).c_str(), WTERMSIG(status));
  return 1;
}
