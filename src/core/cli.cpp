#include "core/cli.hpp"

#include <charconv>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>

#include <unistd.h>

#include "core/error.hpp"
#include "core/image.hpp"
#include "core/version.hpp"

namespace rtr::cli {
namespace {

// The usage errors a tool can make: an existing output only where it has --force.
std::string footer(const CLI::App& app) {
  return std::string(
             "Exit status: 0 success; 1 failure while working (unreadable input, I/O error); 2 usage error "
             "(bad option value") +
         (app.get_option_no_throw("--force") ? ", unknown output format, an output that exists without --force)." : ").");
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// The whole of `text` as a finite double, or nothing: no blank before or after (strtod would skip the
// leading ones only, so ' 5' and '5 ' were not treated alike).
bool toDouble(const std::string& text, double& out) {
  if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return false;
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return *end == '\0' && std::isfinite(out);
}

}  // namespace

std::string version(const std::string& tool) { return tool + " " + kVersion + " (git " + kGitCommit + ", " + kBuildType + ")"; }

int parse(CLI::App& app, int argc, char** argv) {
  const std::string tool = app.get_name();
  app.set_version_flag("--version", version(tool), "print the version and exit");
  app.footer(footer(app));
  try {
    app.parse(argc, argv);
    return -1;
  } catch (const CLI::CallForHelp& e) { return app.exit(e); } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) { return app.exit(e); } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: error: %s\nRun with --help for the options.\n", tool.c_str(), e.what());
    return kExitUsage;
  }
}

int fail(const std::string& tool, const std::exception& e) {
  // Each stage names itself (rtr::stage); this is the last net, so that no tool prints "std::bad_alloc".
  const bool oom = dynamic_cast<const std::bad_alloc*>(&e) != nullptr;
  std::fprintf(stderr, "%s: error: %s\n", tool.c_str(), oom ? "out of memory" : e.what());
  return dynamic_cast<const UsageError*>(&e) ? kExitUsage : kExitFailure;
}

int run(CLI::App& app, int argc, char** argv, const std::function<int()>& body) {
  if (const int rc = parse(app, argc, argv); rc >= 0) return rc;
  try {
    return body();
  } catch (const std::exception& e) { return fail(app.get_name(), e); }
}

CLI::Validator number(double lo, double hi, bool open) {
  const std::string range = open ? "(" + fmt(lo) + ", " + fmt(hi) + ")" : "[" + fmt(lo) + ", " + fmt(hi) + "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double v = 0;
        if (!toDouble(text, v)) return "'" + text + "' is not a finite number";
        if (open ? (v <= lo || v >= hi) : (v < lo || v > hi)) return "'" + text + "' is outside " + range;
        return {};
      },
      "NUMBER in " + range);
}

CLI::Validator integer(long long lo, long long hi) {
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        long long v = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
        if (ec == std::errc::result_out_of_range || (ec == std::errc{} && end == text.data() + text.size() && (v < lo || v > hi)))
          return "'" + text + "' is outside " + range;
        if (ec != std::errc{} || end != text.data() + text.size() || text.empty()) return "'" + text + "' is not a whole number";
        return {};
      },
      "INTEGER in " + range);
}

Size parseSize(const std::string& option, const std::string& text, uint32_t max) {
  const std::string bad = option + " '" + text + "': ";
  const size_t x = text.find('x');
  if (x == std::string::npos) throw UsageError(bad + "expected WxH, e.g. 1920x1080");
  uint32_t v[2];
  const std::string parts[2] = {text.substr(0, x), text.substr(x + 1)};
  for (int i = 0; i < 2; ++i) {
    unsigned long long n = 0;
    const char* b = parts[i].data();
    const auto [end, ec] = std::from_chars(b, b + parts[i].size(), n);
    if (parts[i].empty() || end != b + parts[i].size() || (ec != std::errc{} && ec != std::errc::result_out_of_range))
      throw UsageError(bad + "expected WxH with whole numbers, e.g. 1920x1080");
    if (ec == std::errc::result_out_of_range || n < 1 || n > max)
      throw UsageError(bad + (i ? "height" : "width") + " must be in [1, " + std::to_string(max) + "]");
    v[i] = uint32_t(n);
  }
  return {v[0], v[1]};
}

glm::vec3 parseVec3(const std::string& option, const std::string& text, bool scalarAllowed) {
  double one = 0;
  if (scalarAllowed && text.find(',') == std::string::npos && toDouble(text, one) && std::fabs(one) <= 3.0e38)
    return glm::vec3(float(one));
  glm::vec3 v;
  size_t start = 0;
  for (int i = 0; i < 3; ++i) {
    const size_t end = i < 2 ? text.find(',', start) : text.size();
    double d = 0;
    if (end == std::string::npos || !toDouble(text.substr(start, end - start), d) || std::fabs(d) > 3.0e38)
      throw UsageError(option + " '" + text + "': expected three finite numbers x,y,z" + (scalarAllowed ? " or one" : ""));
    v[i] = float(d);
    start = end + 1;
  }
  return v;
}

glm::vec3 parseColor(const std::string& option, const std::string& text, bool scalarAllowed) {
  const glm::vec3 c = parseVec3(option, text, scalarAllowed);
  if (c.r < 0 || c.g < 0 || c.b < 0) throw UsageError(option + " '" + text + "': a colour cannot be negative");
  return c;
}

CLI::Validator checked(std::function<void(const std::string&)> parse, const std::string& what) {
  return CLI::Validator(
      [parse](std::string& text) -> std::string {
        try {
          parse(text);
          return {};
        } catch (const UsageError& e) {  // CLI11 puts the option's name in front itself
          const std::string m = e.what();
          return m.rfind("--", 0) == 0 && m.find(' ') != std::string::npos ? m.substr(m.find(' ') + 1) : m;
        }
      },
      what);
}

CameraPose parsePose(const std::string& option, const std::string& text) {
  try {
    return rtr::parsePose(text);
  } catch (const Error& e) { throw UsageError(option + ": " + e.what()); }
}

void checkImageOutput(const std::string& option, const std::filesystem::path& file, bool force) {
  try {
    imageFormatFor(file);
  } catch (const UsageError& e) { throw UsageError(option + " " + e.what()); }
  std::error_code ec;
  const std::filesystem::path dir = file.parent_path().empty() ? "." : file.parent_path();
  const std::string bad = option + " " + file.string() + ": ";
  if (!std::filesystem::exists(dir, ec)) throw UsageError(bad + "folder '" + dir.string() + "' does not exist");
  if (!std::filesystem::is_directory(dir, ec)) throw UsageError(bad + "'" + dir.string() + "' is not a folder");
  if (std::filesystem::is_directory(file, ec)) throw UsageError(bad + "is a folder");
  if (std::filesystem::exists(file, ec) && !force) throw OutputExists(bad + "exists; use --force to overwrite it");
  // Checked before any work: a read-only folder must not be found after minutes of tracing.
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw UsageError(bad + "folder '" + dir.string() + "' is not writable (" + std::strerror(errno) + ")");
}

}  // namespace rtr::cli
