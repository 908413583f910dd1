// rtr-reflect: prints the interface of a pipeline's shaders, as the renderer derives its layouts from it.
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "core/error.hpp"
#include "vk/glsl.hpp"
#include "vk/reflect.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "rtr-reflect: print the interface of the shaders that form one pipeline, merged across stages.\n"
      "Inputs are SPIR-V (.spv) or GLSL (.vert/.frag/.comp, compiled with glslang for Vulkan 1.3).\n"
      "Prints entry points and stages, compute workgroup sizes, descriptor sets (binding, type, count,\n"
      "name, stages), push-constant ranges, block members with offsets and sizes, vertex inputs and\n"
      "fragment outputs. The descriptor set layouts and push-constant ranges shown are exactly those\n"
      "the renderer creates. Exit status 1 on invalid SPIR-V, a GLSL error or a cross-stage conflict."};
  std::vector<std::string> files;
  std::vector<std::string> includes;
  bool json = false, noValidate = false;
  app.add_option("shaders", files, "SPIR-V or GLSL files of one pipeline")->required()->check(CLI::ExistingFile);
  app.add_flag("--json", json, "machine-readable JSON output");
  app.add_option("-I,--include", includes, "include folder for GLSL inputs (repeatable)");
  app.add_flag("--no-validate", noValidate, "skip spirv-val style validation of SPIR-V inputs");
  CLI11_PARSE(app, argc, argv);

  try {
    std::vector<std::filesystem::path> dirs(includes.begin(), includes.end());
    std::vector<rtr::vk::SpirvModule> modules;
    for (const auto& f : files) {
      modules.push_back(rtr::vk::isGlslPath(f) ? rtr::vk::compileGlsl(f, dirs) : rtr::vk::readSpirv(f));
      if (!noValidate) rtr::vk::validateSpirv(modules.back());
    }
    const auto iface = rtr::vk::reflectPipeline(modules);
    std::cout << (json ? rtr::vk::toJson(iface) : rtr::vk::toText(iface));
    return 0;
  } catch (const rtr::Error& e) {
    std::fprintf(stderr, "rtr-reflect: %s\n", e.what());
    return 1;
  }
}
