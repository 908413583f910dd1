#include "vk/glsl.hpp"

#include <memory>
#include <mutex>

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include "core/error.hpp"
#include "core/input_file.hpp"

namespace rtr::vk {
namespace {

constexpr uint64_t kMaxGlslBytes = uint64_t(16) << 20;

std::string readText(const std::filesystem::path& file) { return readInputFile(file, "GLSL file", kMaxGlslBytes); }

// Resolves #include "x" against the including file's folder, then the include folders.
class Includer : public glslang::TShader::Includer {
 public:
  explicit Includer(std::vector<std::filesystem::path> dirs) : dirs_(std::move(dirs)) {}
  IncludeResult* includeLocal(const char* name, const char* includer, size_t) override {
    std::vector<std::filesystem::path> where{std::filesystem::path(includer).parent_path()};
    where.insert(where.end(), dirs_.begin(), dirs_.end());
    for (const auto& d : where) {
      auto p = d / name;
      if (std::filesystem::is_regular_file(p)) {
        auto* text = new std::string(readText(p));
        return new IncludeResult(p.string(), text->data(), text->size(), text);
      }
    }
    return nullptr;
  }
  IncludeResult* includeSystem(const char* name, const char* includer, size_t depth) override {
    return includeLocal(name, includer, depth);
  }
  void releaseInclude(IncludeResult* r) override {
    if (!r) return;
    delete static_cast<std::string*>(r->userData);
    delete r;
  }

 private:
  std::vector<std::filesystem::path> dirs_;
};

// glslangValidator's file extensions.
EShLanguage stageOf(const std::filesystem::path& file) {
  static const std::pair<const char*, EShLanguage> stages[] = {
      {".vert", EShLangVertex},   {".tesc", EShLangTessControl}, {".tese", EShLangTessEvaluation}, {".geom", EShLangGeometry},
      {".frag", EShLangFragment}, {".comp", EShLangCompute},     {".rgen", EShLangRayGen},         {".rint", EShLangIntersect},
      {".rahit", EShLangAnyHit},  {".rchit", EShLangClosestHit}, {".rmiss", EShLangMiss},          {".rcall", EShLangCallable},
      {".task", EShLangTask},     {".mesh", EShLangMesh}};
  for (auto [ext, stage] : stages)
    if (file.extension() == ext) return stage;
  return EShLangCount;
}

}  // namespace

bool isGlslPath(const std::filesystem::path& file) { return stageOf(file) != EShLangCount; }

SpirvModule compileGlsl(const std::filesystem::path& file, const std::vector<std::filesystem::path>& includeDirs) {
  static std::once_flag init;
  std::call_once(init, [] { glslang::InitializeProcess(); });  // process-wide; finalised at exit by the OS
  const EShLanguage stage = stageOf(file);
  if (stage == EShLangCount)
    throw fileError(file.string(), "", "unknown shader stage: use .vert, .frag, .comp, .rgen, .rchit, ...");
  const std::string source = readText(file);
  const std::string name = file.string();
  const char* text = source.c_str();
  const char* names = name.c_str();
  const int length = int(source.size());

  glslang::TShader shader(stage);
  shader.setStringsWithLengthsAndNames(&text, &length, &names, 1);
  shader.setEnvInput(glslang::EShSourceGlsl, stage, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_3);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_6);
  Includer includer(includeDirs);
  const auto messages = EShMessages(EShMsgSpvRules | EShMsgVulkanRules);
  if (!shader.parse(GetDefaultResources(), 460, false, messages, includer))
    throw Error("GLSL compile failed:\n" + std::string(shader.getInfoLog()));
  glslang::TProgram program;
  program.addShader(&shader);
  if (!program.link(messages)) throw Error("GLSL link failed:\n" + std::string(program.getInfoLog()));
  SpirvModule out{file.filename().string(), {}};
  glslang::SpvOptions options;
  glslang::GlslangToSpv(*program.getIntermediate(stage), out.code, &options);
  return out;
}

}  // namespace rtr::vk
