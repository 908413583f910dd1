#pragma once
// A JSON value of a glTF file together with its JSON pointer, so that every fault names the file and the
// place: "model.gltf: /accessors/3/byteOffset: what". A thin layer over simdjson's DOM (docs/gltf.md
// says why simdjson).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <simdjson.h>

#include "core/error.hpp"

namespace rtr::gltf {

class Json {
 public:
  Json(simdjson::dom::element e, std::string path, const std::string* file) : e_(e), path_(std::move(path)), file_(file) {}

  const std::string& path() const { return path_; }
  const std::string& file() const { return *file_; }
  simdjson::dom::element element() const { return e_; }
  [[noreturn]] void fail(const std::string& what) const { throw error(path_, what); }
  Error error(const std::string& path, const std::string& what) const {
    return Error(*file_ + ": " + (path.empty() ? "/" : path) + ": " + what);
  }

  bool isObject() const { return e_.is_object(); }
  bool isArray() const { return e_.is_array(); }

  // A member of this object: absent (or this is no object) gives nullopt.
  std::optional<Json> get(std::string_view key) const {
    simdjson::dom::object o;
    simdjson::dom::element v;
    if (e_.get_object().get(o) || o.at_key(key).get(v)) return std::nullopt;
    return Json(v, path_ + "/" + std::string(key), file_);
  }
  Json at(std::string_view key) const {
    if (!isObject()) fail("expected an object");
    if (auto v = get(key)) return *v;
    fail("'" + std::string(key) + "' is missing");
  }
  // Elements of an array member; absent gives an empty array. Not an array: an error.
  size_t size() const {
    simdjson::dom::array a;
    if (e_.get_array().get(a)) fail("expected an array");
    return a.size();
  }
  Json operator[](size_t i) const {
    simdjson::dom::array a;
    simdjson::dom::element v;
    if (e_.get_array().get(a)) fail("expected an array");
    if (a.at(i).get(v)) fail("has no element " + std::to_string(i));
    return Json(v, path_ + "/" + std::to_string(i), file_);
  }
  size_t count(std::string_view key) const {  // size of an optional array member
    auto v = get(key);
    return v ? v->size() : 0;
  }
  template <class F>  // f(key, value) for each member of an object
  void members(F&& f) const {
    simdjson::dom::object o;
    if (e_.get_object().get(o)) fail("expected an object");
    for (auto [k, v] : o) f(k, Json(v, path_ + "/" + std::string(k), file_));
  }

  // Values of this element.
  double number() const {
    double d;
    if (e_.get_double().get(d)) fail("expected a number");
    return d;
  }
  uint64_t uinteger() const {
    uint64_t u;
    if (!e_.get_uint64().get(u)) return u;
    double d;  // 3.0 is an integer too
    if (!e_.get_double().get(d) && d >= 0 && d < 1.8e19 && d == double(uint64_t(d))) return uint64_t(d);
    fail("expected a non-negative integer");
  }
  std::string_view string() const {
    std::string_view s;
    if (e_.get_string().get(s)) fail("expected a string");
    return s;
  }
  bool boolean() const {
    bool b;
    if (e_.get_bool().get(b)) fail("expected true or false");
    return b;
  }

  // Optional members with defaults.
  double number(std::string_view key, double def) const {
    auto v = get(key);
    return v ? v->number() : def;
  }
  uint64_t uinteger(std::string_view key, uint64_t def) const {
    auto v = get(key);
    return v ? v->uinteger() : def;
  }
  std::string_view string(std::string_view key, std::string_view def) const {
    auto v = get(key);
    return v ? v->string() : def;
  }
  bool boolean(std::string_view key, bool def) const {
    auto v = get(key);
    return v ? v->boolean() : def;
  }
  // An index into an array of `n` elements named `what` (e.g. "accessors").
  uint32_t index(std::string_view key, size_t n, std::string_view what) const {
    Json v = at(key);
    const uint64_t i = v.uinteger();
    if (i >= n) v.fail(std::to_string(i) + " is not one of the " + std::to_string(n) + " " + std::string(what));
    return uint32_t(i);
  }
  // A fixed-size array of numbers into `out` (absent: `out` unchanged).
  template <size_t N>
  void numbers(std::string_view key, float (&out)[N]) const {
    auto v = get(key);
    if (!v) return;
    if (v->size() != N) v->fail("expected " + std::to_string(N) + " numbers");
    for (size_t i = 0; i < N; ++i) out[i] = float((*v)[i].number());
  }

 private:
  simdjson::dom::element e_;
  std::string path_;
  const std::string* file_;
};

}  // namespace rtr::gltf
