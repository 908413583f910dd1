#pragma once
// One error type for every user-facing failure: the message names the file and the place.
#include <new>
#include <stdexcept>
#include <string>
#include <system_error>

namespace rtr {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The command as given cannot be carried out (a bad option value, an unknown output format): the tools
// exit with 2 for these, 1 for any other Error.
struct UsageError : Error {
  using Error::Error;
};

// An output exists and --force was not given: a usage-level refusal, so the same exit 2.
struct OutputExists : UsageError {
  using UsageError::UsageError;
};

// "file:12: what" for a line, "file: byte 123: what" or "file: mesh 'x': what" for any other place —
// whatever locates the fault for a person.
inline Error fileError(const std::string& file, const std::string& place, const std::string& what) {
  const bool line = !place.empty() && place.find_first_not_of("0123456789") == std::string::npos;
  return Error(file + (place.empty() ? "" : (line ? ":" : ": ") + place) + ": " + what);
}

// Runs fn; running out of memory in it (std::bad_alloc, or a thread that cannot be started) becomes an
// Error naming the stage and its file: stage("reading " + file, [&] { return load(file); }).
template <class Fn>
auto stage(const std::string& what, Fn&& fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (const std::bad_alloc&) { throw Error("out of memory while " + what); } catch (const std::system_error& e) {
    throw Error("while " + what + ": " + e.what());
  }
}

}  // namespace rtr
