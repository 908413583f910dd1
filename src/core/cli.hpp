#pragma once
// The command-line convention of every rtr tool, in one place:
//  - exit status 0 success, 1 failure while working (bad input file, I/O), 2 usage error (bad option
//    value, unknown output format, an output that exists without --force); said in every --help footer;
//  - --version (project version, git commit at configure time, build type);
//  - every number range-checked, NaN and infinity rejected, with a message naming the option and value.
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>
#include <glm/vec3.hpp>

#include "core/camera.hpp"
#include "core/enum_names.hpp"
#include "core/error.hpp"

namespace rtr::cli {

enum ExitCode : int { kExitOk = 0, kExitFailure = 1, kExitUsage = 2 };

std::string version(const std::string& tool);  // "rtr-view 0.1 (git 1a2b3c4, RelWithDebInfo)"

// Adds --version and the exit-status footer, then parses. Returns -1 to go on, else the exit status to
// return at once (0 after --help or --version, 2 after a parse or validation error, already reported).
int parse(CLI::App& app, int argc, char** argv);
// Reports `e` on stderr as "TOOL: error: ..." and returns its exit status (2 for rtr::UsageError).
int fail(const std::string& tool, const std::exception& e);
// parse, then body, with every exception reported through fail.
int run(CLI::App& app, int argc, char** argv, const std::function<int()>& body);

// Validators for CLI11's ->check(): finite numbers in [lo, hi], or (lo, hi) where `open`.
CLI::Validator number(double lo, double hi, bool open = false);
CLI::Validator integer(long long lo, long long hi);

// A validator that accepts the names of enum E's table (core/enum_names.hpp), its error listing them.
template <class E>
CLI::Validator oneOf() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        return enumFromName<E>(text) ? std::string() : "'" + text + "': expected " + enumChoices<E>();
      },
      "{" + enumChoices<E>("|") + "}");
}
// The value named by `text` for an option checked with oneOf<E>(); an rtr::UsageError if none is.
template <class E>
E enumOption(const std::string& option, const std::string& text) {
  if (const auto v = enumFromName<E>(text)) return *v;
  throw UsageError(option + " '" + text + "': expected " + enumChoices<E>());
}

// Option values that CLI11 cannot check alone. Each throws rtr::UsageError naming the option.
struct Size {
  uint32_t width, height;
};
Size parseSize(const std::string& option, const std::string& text, uint32_t max = 16384);
// "x,y,z", or one value for all three where `scalarAllowed` (a grey colour).
glm::vec3 parseVec3(const std::string& option, const std::string& text, bool scalarAllowed = false);
// parseVec3 of a colour: no component negative.
glm::vec3 parseColor(const std::string& option, const std::string& text, bool scalarAllowed = false);
CameraPose parsePose(const std::string& option, const std::string& text);
// A CLI11 check from one of the parse functions above, so that a bad or empty value is a parse error
// (exit 2) before any work: ->check(cli::checked([](auto& t) { cli::parseColor("--light-color", t); }, "R,G,B")).
CLI::Validator checked(std::function<void(const std::string&)> parse, const std::string& what);
// An image output: a known extension, an existing writable folder, and no existing file unless `force`.
void checkImageOutput(const std::string& option, const std::filesystem::path& file, bool force);

}  // namespace rtr::cli
