#pragma once
// Numbers from the environment, for the settings that measuring runs set (RTR_PYRAMID_LEVELS, ...): unset or
// empty is none; anything but a whole number in range is a UsageError that names the variable.
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>

#include "core/error.hpp"

namespace rtr {

// The number in `name` in [lo, hi] (`what` says what it counts), or none where unset.
inline std::optional<uint32_t> envNumber(const char* name, uint32_t lo, uint32_t hi, const char* what) {
  const char* v = std::getenv(name);
  if (!v || !*v) return std::nullopt;
  char* end = nullptr;
  const unsigned long n = std::strtoul(v, &end, 10);
  if (*end || n < lo || n > hi || !std::isdigit(static_cast<unsigned char>(*v)))
    throw UsageError(std::string(name) + "=" + v + ": expected " + what + " from " + std::to_string(lo) + " to " +
                     std::to_string(hi));
  return uint32_t(n);
}

}  // namespace rtr
