#pragma once
// One error type for every user-facing failure: the message names the file and the place.
#include <stdexcept>
#include <string>

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

// "file: at byte 123: what" / "file:12: what" — the place is whatever locates the fault for a person.
inline Error fileError(const std::string& file, const std::string& place, const std::string& what) {
  return Error(file + (place.empty() ? "" : ":" + place) + ": " + what);
}

}  // namespace rtr
