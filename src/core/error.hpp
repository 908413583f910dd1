#pragma once
// One error type for every user-facing failure: the message names the file and the place.
#include <stdexcept>
#include <string>

namespace rtr {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "file: at byte 123: what" / "file:12: what" — the place is whatever locates the fault for a person.
inline Error fileError(const std::string& file, const std::string& place, const std::string& what) {
  return Error(file + (place.empty() ? "" : ":" + place) + ": " + what);
}

}  // namespace rtr
