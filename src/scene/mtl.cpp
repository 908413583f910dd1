#include "scene/mtl.hpp"

#include <algorithm>

#include "core/error.hpp"
#include "scene/text.hpp"

namespace rtr {

uint32_t flagsFromName(std::string_view name) {
  uint32_t f = 0;
  constexpr std::string_view kDouble = ".DoubleSided";
  if (name.size() >= kDouble.size() && name.substr(name.size() - kDouble.size()) == kDouble) f |= kMaterialDoubleSided;
  if (name.find("light") != std::string_view::npos) f |= kMaterialLight;
  return f;
}

SlotFormat slotFormat(TextureSlot slot) {
  switch (slot) {
    case TextureSlot::BaseColor: return {true, 4};
    case TextureSlot::Roughness: return {false, 1};
    case TextureSlot::Metalness: return {false, 1};
    case TextureSlot::AlphaMask: return {true, 4};
    case TextureSlot::NormalMap: return {false, 3};
    case TextureSlot::Emissive: return {true, 4};
    default: return {false, 4};
  }
}

namespace {

struct MtlParser {
  const std::string& file;
  const std::function<void(const std::string&)>& warn;
  size_t line = 0;
  std::vector<MtlMaterial> out;
  std::vector<std::string> warnedKeys;

  Error error(const std::string& what) const { return fileError(file, std::to_string(line), what); }

  MtlMaterial& current(std::string_view key) {
    if (out.empty()) throw error("'" + std::string(key) + "' before any 'newmtl'");
    return out.back();
  }

  float scalar(std::string_view key, std::string_view rest) {
    float v = 0;
    switch (text::nextFloat(rest, v)) {
      case text::NumResult::Ok: return v;
      case text::NumResult::Missing: throw error("'" + std::string(key) + "' needs a number");
      case text::NumResult::NotFinite: throw error("'" + std::string(key) + "' value is not finite");
      default: throw error("'" + std::string(key) + "' value is not a number");
    }
  }

  // "r g b", or one value meaning grey.
  glm::vec3 colour(std::string_view key, std::string_view rest) {
    std::string_view r = text::trim(rest);
    if (r.substr(0, 8) == "spectral" || r.substr(0, 3) == "xyz")
      throw error("'" + std::string(key) + "': only r g b colours are supported");
    glm::vec3 c;
    c.x = scalar(key, rest);
    float v = 0;
    text::nextToken(rest);
    auto g = text::nextFloat(rest, v);
    if (g == text::NumResult::Missing) return glm::vec3(c.x);
    if (g != text::NumResult::Ok) throw error("'" + std::string(key) + "' green is not a finite number");
    c.y = v;
    if (text::nextFloat(rest, v) != text::NumResult::Ok) throw error("'" + std::string(key) + "' needs 1 or 3 numbers");
    c.z = v;
    return c;
  }

  // A map line: options ("-bm 1", "-s u v w", ...) are skipped; the rest is the file name.
  std::string mapFile(std::string_view key, std::string_view rest) {
    rest = text::trim(rest);
    while (!rest.empty() && rest.front() == '-') {
      std::string_view opt = text::nextToken(rest);
      if (opt == "-blendu" || opt == "-blendv" || opt == "-cc" || opt == "-clamp" || opt == "-imfchan" || opt == "-type") {
        text::nextToken(rest);  // one word argument
      } else {
        for (;;) {  // numeric arguments, as many as there are
          std::string_view save = rest;
          float v;
          if (text::nextFloat(rest, v) != text::NumResult::Ok) { rest = save; break; }
        }
      }
      rest = text::trim(rest);
    }
    if (rest.empty()) throw error("'" + std::string(key) + "' names no file");
    if (rest.size() >= 32768) throw error("texture file name too long");
    if (!text::validUtf8(rest)) throw error("texture file name is not valid UTF-8");
    std::string name(rest);
    std::replace(name.begin(), name.end(), '\\', '/');  // files exported on Windows
    return name;
  }

  void onLine(std::string_view l) {
    std::string_view rest = l;
    std::string_view key = text::nextToken(rest);
    if (key.empty() || key[0] == '#') return;
    if (key == "newmtl") {
      std::string_view name = text::trim(rest);
      if (name.empty()) throw error("'newmtl' without a name");
      if (name.size() >= 32768) throw error("material name too long");
      if (!text::validUtf8(name)) throw error("material name is not valid UTF-8");
      MtlMaterial m;
      m.material.name = std::string(name);
      m.material.flags = flagsFromName(name);
      out.push_back(std::move(m));
      return;
    }
    auto slot = [&](TextureSlot s) -> std::string& { return current(key).maps[uint32_t(s)]; };
    Material* m = nullptr;
    auto mat = [&]() -> Material& { if (!m) m = &current(key).material; return *m; };
    if (key == "Kd") { glm::vec3 c = colour(key, rest); mat().kd = c; mat().baseColor = c; }
    else if (key == "Ka") mat().ka = colour(key, rest);
    else if (key == "Ks") mat().ks = colour(key, rest);
    else if (key == "Ke") { glm::vec3 c = colour(key, rest); mat().ke = c; mat().emissive = c; }
    else if (key == "Ns") mat().ns = scalar(key, rest);
    else if (key == "Pr") mat().roughness = scalar(key, rest);
    else if (key == "Pm") mat().metalness = scalar(key, rest);
    else if (key == "N_mirr") mat().mirror = scalar(key, rest);
    else if (key == "N_ior") mat().ior = scalar(key, rest);
    else if (key == "N_transp") mat().transparency = scalar(key, rest);
    else if (key == "map_Kd") slot(TextureSlot::BaseColor) = mapFile(key, rest);
    else if (key == "map_Pr") slot(TextureSlot::Roughness) = mapFile(key, rest);
    else if (key == "map_Pm") slot(TextureSlot::Metalness) = mapFile(key, rest);
    else if (key == "map_d") { slot(TextureSlot::AlphaMask) = mapFile(key, rest); mat().flags |= kMaterialAlphaMasked; }
    else if (key == "norm") slot(TextureSlot::NormalMap) = mapFile(key, rest);
    else if (key == "map_Ke") slot(TextureSlot::Emissive) = mapFile(key, rest);
    else if (key == "Ni" || key == "d" || key == "Tr" || key == "Tf" || key == "illum" || key == "map_Ka" ||
             key == "map_Ks" || key == "map_Ns" || key == "map_bump" || key == "bump" || key == "map_Bump") {
      current(key);  // known to the wider MTL world; not used by our scenes
    } else {
      std::string k(key);
      if (std::find(warnedKeys.begin(), warnedKeys.end(), k) == warnedKeys.end()) {
        warnedKeys.push_back(k);
        if (warn) warn(file + ":" + std::to_string(line) + ": unknown MTL key '" + k + "' ignored");
      }
    }
  }
};

}  // namespace

std::vector<MtlMaterial> parseMtl(std::string_view src, const std::string& file,
                                  const std::function<void(const std::string&)>& warn) {
  MtlParser p{file, warn};
  while (!src.empty()) {
    size_t nl = src.find('\n');
    std::string_view l = src.substr(0, nl);
    src.remove_prefix(nl == std::string_view::npos ? src.size() : nl + 1);
    ++p.line;
    p.onLine(l);
  }
  return std::move(p.out);
}

}  // namespace rtr
