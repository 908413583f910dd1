// Fuzzes SPIR-V reflection (no device): the input is one module, or two when a second SPIR-V magic number
// starts a later word (so the merge of two stages is fuzzed too). An interface, printed as text and
// JSON, or an rtr::Error. Modules pass spirv-val first, as in the renderer: SPIRV-Reflect (Debian's
// 1.3.239) itself crashes on unvalidated input (tests/fuzz/crashes/fuzz_spirv/, docs/fuzzing.md).
// It also asserts or dies of SIGSEGV on some modules spirv-val accepts. rtr-reflect contains that in a
// child process, and so does this target: a child killed by a signal is SPIRV-Reflect's own failure
// (counted, not reported); a failed check of ours or a sanitizer report ends the child with a non-zero
// status, which is reported. The price: libFuzzer's coverage does not see into the child, so this target
// mutates its seeds (the project's own shaders) blind (docs/fuzzing.md).
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <vector>

#include "check.hpp"
#include "vk/reflect.hpp"

namespace {

void reflectOnce(const uint8_t* data, size_t size) {
  using namespace rtr::vk;
  std::vector<uint32_t> words(size / 4);
  if (!words.empty()) std::memcpy(words.data(), data, words.size() * 4);
  size_t second = std::min<size_t>(1, words.size());
  while (second < words.size() && words[second] != 0x07230203u) ++second;
  std::vector<SpirvModule> modules{{"fuzz.spv", {words.begin(), words.begin() + second}}};
  if (second < words.size()) modules.push_back({"fuzz2.spv", {words.begin() + second, words.end()}});
  try {
    for (const SpirvModule& m : modules) validateSpirv(m);
    const PipelineInterface p = reflectPipeline(modules);
    rtr::fuzz::require(!toText(p).empty() && !toJson(p).empty(), "empty printout");
  } catch (const rtr::Error& e) {
    rtr::fuzz::require(std::strstr(e.what(), "fuzz") != nullptr || std::strstr(e.what(), "conflict") != nullptr,
                       "the error names no module");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const pid_t pid = fork();
  if (pid == 0) {
    // SPIRV-Reflect's own crashes end the child by a signal (not through libFuzzer's or ASan's handlers).
    for (int sig : {SIGABRT, SIGSEGV, SIGBUS, SIGILL, SIGFPE}) std::signal(sig, SIG_DFL);
    rtr::fuzz::exitOnBrokenInvariant = true;
    reflectOnce(data, size);
    _exit(0);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) != pid) {
    reflectOnce(data, size);  // no child: in process
    return 0;
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "fuzz_spirv: the reflecting child failed with status %d\n", WEXITSTATUS(status));
    std::abort();
  }
  return 0;
}
