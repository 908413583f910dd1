#pragma once
// Small text helpers shared by the OBJ and MTL parsers.
#include <charconv>
#include <cstdint>
#include <string_view>

namespace rtr::text {

inline bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

inline std::string_view trim(std::string_view s) {
  while (!s.empty() && isSpace(s.front())) s.remove_prefix(1);
  while (!s.empty() && isSpace(s.back())) s.remove_suffix(1);
  return s;
}

// Splits off the next whitespace-separated token of `s`.
inline std::string_view nextToken(std::string_view& s) {
  size_t i = 0;
  while (i < s.size() && isSpace(s[i])) ++i;
  size_t j = i;
  while (j < s.size() && !isSpace(s[j])) ++j;
  std::string_view t = s.substr(i, j - i);
  s.remove_prefix(j);
  return t;
}

enum class NumResult { Ok, Missing, Bad, NotFinite };

// Parses the next float token; rejects trailing junk, NaN and infinities (and out-of-range values).
inline NumResult nextFloat(std::string_view& s, float& out) {
  size_t i = 0;
  while (i < s.size() && isSpace(s[i])) ++i;
  if (i == s.size()) {
    s.remove_prefix(i);
    return NumResult::Missing;
  }
  const char* b = s.data() + i;
  const char* e = s.data() + s.size();
  if (*b == '+') ++b;  // from_chars does not take a leading '+'
  auto [p, ec] = std::from_chars(b, e, out);
  bool tokenEnds = p == e || isSpace(*p);
  if (ec != std::errc() || !tokenEnds) {
    // Tell NaN/inf apart from junk so the message says what is wrong.
    std::string_view rest(b, size_t(e - b));
    size_t k = 0;
    while (k < rest.size() && !isSpace(rest[k])) ++k;
    std::string_view tok = rest.substr(0, k);
    s = std::string_view(b + k, size_t(e - b - k));
    if (ec == std::errc::result_out_of_range) return NumResult::NotFinite;
    if (!tok.empty() && (tok[0] == '-' ? tok.substr(1) : tok).find_first_of("nNiI") == 0) return NumResult::NotFinite;
    return NumResult::Bad;
  }
  s = std::string_view(p, size_t(e - p));
  if (!(out - out == 0.0f)) return NumResult::NotFinite;  // NaN or inf spelled out
  return NumResult::Ok;
}

}  // namespace rtr::text
