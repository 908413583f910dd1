// Fuzzes SPIR-V reflection (no device): the input is one module, or two when a second SPIR-V magic number
// starts a later word (so the merge of two stages is fuzzed too). An interface, printed as text and
// JSON, or an rtr::Error. Modules pass spirv-val first, as in the renderer: SPIRV-Reflect (Debian's
// 1.3.239) itself crashes on unvalidated input (tests/fuzz/crashes/fuzz_spirv/, docs/fuzzing.md).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include "check.hpp"
#include "vk/reflect.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
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
  return 0;
}
