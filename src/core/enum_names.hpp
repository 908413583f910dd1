#pragma once
// One table per enum for parsing and printing: an enum E declares, in its own namespace,
//   constexpr std::array<rtr::EnumName<E>, N> enumNames(E) { return {{{E::A, "a"}, {E::B, "b"}}}; }
// and every tool, the panel and the reports print with enumName(v), parse with enumFromName<E>(text),
// and list the choices (help texts, errors) with enumChoices<E>(). A name is written once, here.
#include <optional>
#include <string>
#include <string_view>

namespace rtr {

template <class E>
struct EnumName {
  E value;
  const char* name;
};

template <class E>
const char* enumName(E value) {
  for (const EnumName<E>& e : enumNames(E{}))
    if (e.value == value) return e.name;
  return "?";
}

template <class E>
std::optional<E> enumFromName(std::string_view name) {
  for (const EnumName<E>& e : enumNames(E{}))
    if (name == e.name) return e.value;
  return std::nullopt;
}

// "a, b or c" (for messages); with a separator, "a|b|c".
template <class E>
std::string enumChoices(const char* separator = nullptr) {
  const auto& table = enumNames(E{});
  std::string out;
  for (size_t i = 0; i < table.size(); ++i) {
    if (i) out += separator ? separator : i + 1 == table.size() ? " or " : ", ";
    out += table[i].name;
  }
  return out;
}

}  // namespace rtr
