#include "scene/mtl.hpp"

#include <algorithm>
#include <cmath>

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
    case TextureSlot::Occlusion: return {false, 1};
    default: return {false, 4};
  }
}

float roughnessFromNs(float ns) { return std::pow(2.0f / (std::max(ns, 0.0f) + 2.0f), 0.25f); }

namespace {

struct MtlParser {
  const std::string& file;
  const std::function<void(const std::string&)>& warn;
  size_t line = 0;
  std::vector<MtlMaterial> out;
  std::vector<std::string> warnedKeys;
  std::vector<uint8_t> givenPr, givenNs;  // per material: whether the MTL set Pr / Ns

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
          if (text::nextFloat(rest, v) != text::NumResult::Ok) {
            rest = save;
            break;
          }
        }
      }
      rest = text::trim(rest);
    }
    if (rest.empty()) throw error("'" + std::string(key) + "' names no file");
    if (rest.size() >= 32768) throw error("texture file name too long");  // names are bytes, any encoding
    std::string name(rest);
    std::replace(name.begin(), name.end(), '\\', '/');  // files exported on Windows
    return name;
  }

  void onLine(std::string_view l) {
    std::string_view rest = l;
    std::string_view key = text::nextToken(rest);
    if (key.empty() || key[0] == '#') return;
    if (key == "newmtl") {
      std::string_view name = text::trim(rest);  // bytes in any encoding
      if (name.empty() && warn)
        warn(file + ":" + std::to_string(line) + ": 'newmtl' without a name (usable as 'usemtl' with no name)");
      if (name.size() >= 32768) throw error("material name too long");
      givenPr.push_back(0);
      givenNs.push_back(0);
      MtlMaterial m;
      m.material.name = std::string(name);
      m.material.flags = flagsFromName(name);
      out.push_back(std::move(m));
      return;
    }
    auto slot = [&](TextureSlot s) -> std::string& { return current(key).maps[uint32_t(s)]; };
    Material* m = nullptr;
    auto mat = [&]() -> Material& {
      if (!m) m = &current(key).material;
      return *m;
    };
    if (key == "Kd") {
      glm::vec3 c = colour(key, rest);
      mat().kd = c;
      mat().baseColor = c;
    } else if (key == "Ka") mat().ka = colour(key, rest);
    else if (key == "Ks") mat().ks = colour(key, rest);
    else if (key == "Ke") {
      glm::vec3 c = colour(key, rest);
      mat().ke = c;
      mat().emissive = c;
    } else if (key == "Ns") {
      mat().ns = scalar(key, rest);
      givenNs.back() = 1;
    } else if (key == "Pr") {
      mat().roughness = scalar(key, rest);
      givenPr.back() = 1;
    } else if (key == "Pm") mat().metalness = scalar(key, rest);
    else if (key == "N_mirr") mat().mirror = scalar(key, rest);
    else if (key == "N_ior") mat().ior = scalar(key, rest);
    else if (key == "N_transp" || key == "Tr") mat().transparency = scalar(key, rest);
    else if (key == "d") mat().transparency = 1.0f - scalar(key, rest);  // dissolve: 1 is opaque
    else if (key == "map_Kd") slot(TextureSlot::BaseColor) = mapFile(key, rest);
    else if (key == "map_Pr") slot(TextureSlot::Roughness) = mapFile(key, rest);
    else if (key == "map_Pm") slot(TextureSlot::Metalness) = mapFile(key, rest);
    else if (key == "map_d") {
      slot(TextureSlot::AlphaMask) = mapFile(key, rest);
      mat().flags |= kMaterialAlphaMasked;
    } else if (key == "norm") slot(TextureSlot::NormalMap) = mapFile(key, rest);
    else if (key == "map_Ke") slot(TextureSlot::Emissive) = mapFile(key, rest);
    else if (key == "Ni" || key == "Tf" || key == "illum" || key == "map_Ka" || key == "map_Ks" || key == "map_Ns" ||
             key == "map_bump" || key == "bump" || key == "map_Bump") {
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
    if (p.line == 1 && l.substr(0, 3) == "\xEF\xBB\xBF") l.remove_prefix(3);  // UTF-8 byte order mark
    p.onLine(l);
  }
  // Classic MTL onto the PBR model (docs/obj-mtl.md).
  for (size_t i = 0; i < p.out.size(); ++i) {
    Material& m = p.out[i].material;
    if (!p.givenPr[i] && p.givenNs[i]) m.roughness = roughnessFromNs(m.ns);
    // Exporters often write Kd 0 0 0 beside a map_Kd; viewers then show the texture, not black.
    if (m.baseColor == glm::vec3(0.0f) && !p.out[i].maps[uint32_t(TextureSlot::BaseColor)].empty()) m.baseColor = glm::vec3(1.0f);
  }
  return std::move(p.out);
}

}  // namespace rtr
