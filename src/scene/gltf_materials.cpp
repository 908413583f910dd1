#include "scene/gltf_materials.hpp"

#include <algorithm>
#include <cmath>

namespace rtr::gltf {

Materials::Materials(const Json& root, Accessors& accessors, Scene& scene, std::function<void(const std::string&)> note,
                     std::function<void(const std::string&)> warn)
    : root_(root), acc_(accessors), scene_(scene), note_(std::move(note)), warn_(std::move(warn)) {
  auto list = [&](const char* key, std::vector<Json>& out) {
    if (auto a = root.get(key))
      for (size_t i = 0, n = a->size(); i < n; ++i) out.push_back((*a)[i]);
  };
  list("materials", materialsJ_);
  list("textures", texturesJ_);
  list("images", imagesJ_);
  list("samplers", samplersJ_);
  made_.resize(materialsJ_.size());
  images_.resize(imagesJ_.size());
}

uint32_t Materials::material(std::optional<uint32_t> index) {
  if (!index) {
    if (!default_) {  // the spec's default: white, fully metallic and rough
      Material m;
      m.name = "glTF default material";
      m.flags = kMaterialGltf;
      m.metalness = 1.0f;
      m.ka = glm::vec3(0.0f);
      m.kd = glm::vec3(0.0f);
      m.ks = glm::vec3(1.0f);
      default_ = uint32_t(scene_.materials.size());
      scene_.materials.push_back(m);
    }
    return *default_;
  }
  if (!made_[*index]) made_[*index] = make(materialsJ_[*index]);
  return *made_[*index];
}

SamplerDesc Materials::sampler(const Json& s) const {
  SamplerDesc d;
  auto wrap = [&](const char* key) {
    auto v = s.get(key);
    const uint64_t w = v ? v->uinteger() : 10497;
    if (w == 33071) return Wrap::ClampToEdge;
    if (w == 33648) return Wrap::MirroredRepeat;
    if (w != 10497) v->fail(std::to_string(w) + " is not a wrap mode (33071, 33648, 10497)");
    return Wrap::Repeat;
  };
  d.wrapU = wrap("wrapS");
  d.wrapV = wrap("wrapT");
  if (auto mag = s.get("magFilter")) {
    const uint64_t f = mag->uinteger();
    if (f != 9728 && f != 9729) mag->fail(std::to_string(f) + " is not a magnification filter (9728, 9729)");
    d.nearestMag = f == 9728;
  }
  if (auto min = s.get("minFilter")) {
    const uint64_t f = min->uinteger();
    if (f != 9728 && f != 9729 && (f < 9984 || f > 9987))
      min->fail(std::to_string(f) + " is not a minification filter (9728, 9729, 9984..9987)");
    d.nearestMin = f == 9728 || f == 9984 || f == 9986;
    d.nearestMip = f == 9984 || f == 9985;
  }
  return d;
}

void Materials::image(uint32_t i, Texture& t) {
  if (!images_[i]) {
    const Json& im = imagesJ_[i];
    Texture img;
    const std::string label =
        "image " + std::to_string(i) + (im.get("name") ? " (" + std::string(im.string("name", "")) + ")" : "");
    if (auto uri = im.get("uri")) {
      const std::string_view u = uri->string();
      if (u.substr(0, 5) == "data:") {
        img.bytes = std::make_shared<const std::vector<uint8_t>>(decodeDataUri(*uri, u));
        img.path = im.file() + " " + label;
      } else {
        img.path = uriToPath(u);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(scene_.baseDir / img.path, ec))
          warn_(uri->path() + ": image file '" + img.path.string() + "' does not exist");
      }
    } else if (im.get("bufferView")) {
      const auto view = acc_.view(im.index("bufferView", acc_.viewCount(), "bufferViews"));
      img.bytes = std::make_shared<const std::vector<uint8_t>>(view.begin(), view.end());
      img.path = im.file() + " " + label;
    } else {
      im.fail("has neither uri nor bufferView");
    }
    images_[i] = std::move(img);
  }
  t.path = images_[i]->path;
  t.bytes = images_[i]->bytes;
}

uint32_t Materials::texture(const Json& info, TextureSlot slot, Material& mat, bool srgb, uint8_t channels,
                            uint8_t sourceChannel) {
  const uint32_t ti = info.index("index", texturesJ_.size(), "textures");
  const Json& tj = texturesJ_[ti];
  if (!tj.get("source")) {
    note_(tj.path() + ": a texture with no PNG/JPEG source (an image extension rtr does not read) is left out");
    return kNoTexture;
  }
  const uint32_t img = tj.index("source", imagesJ_.size(), "images");
  const uint32_t samplerIndex = tj.get("sampler") ? tj.index("sampler", samplersJ_.size(), "samplers") : 0xFFFFFFFFu;
  UvTransform& uv = mat.uv[uint32_t(slot)];
  uv.texCoord = uint32_t(info.uinteger("texCoord", 0));
  if (auto ext = info.get("extensions"); ext && ext->get("KHR_texture_transform")) {
    const Json tt = ext->at("KHR_texture_transform");
    float off[2] = {0, 0}, scale[2] = {1, 1};
    tt.numbers("offset", off);
    tt.numbers("scale", scale);
    uv.offset = {off[0], off[1]};
    uv.scale = {scale[0], scale[1]};
    uv.rotation = float(tt.number("rotation", 0.0));
    if (tt.get("texCoord")) uv.texCoord = uint32_t(tt.uinteger("texCoord", 0));
  }
  if (uv.texCoord > 1) { info.fail("texCoord " + std::to_string(uv.texCoord) + ": rtr reads TEXCOORD_0 and TEXCOORD_1 only"); }
  const auto key = std::make_tuple(img, samplerIndex, srgb, channels, sourceChannel);
  if (auto it = textures_.find(key); it != textures_.end()) return mat.textures[uint32_t(slot)] = it->second;
  Texture t;
  image(img, t);
  t.srgb = srgb;
  t.channels = channels;
  t.sourceChannel = sourceChannel;
  if (samplerIndex != 0xFFFFFFFFu) t.sampler = sampler(samplersJ_[samplerIndex]);
  const uint32_t id = uint32_t(scene_.textures.size());
  scene_.textures.push_back(std::move(t));
  textures_[key] = id;
  return mat.textures[uint32_t(slot)] = id;
}

uint32_t Materials::make(const Json& j) {
  Material m;
  m.flags = kMaterialGltf;
  m.name = j.get("name") ? std::string(j.string("name", "")) : "material " + j.path().substr(11);
  m.metalness = 1.0f;  // the spec's defaults
  m.roughness = 1.0f;
  float base[4] = {1, 1, 1, 1};
  auto pbr = j.get("pbrMetallicRoughness");
  if (pbr) {
    pbr->numbers("baseColorFactor", base);
    m.metalness = float(pbr->number("metallicFactor", 1.0));
    m.roughness = float(pbr->number("roughnessFactor", 1.0));
  }
  m.baseColor = {base[0], base[1], base[2]};
  m.opacity = base[3];
  const std::string_view mode = j.string("alphaMode", "OPAQUE");
  if (mode == "MASK") m.flags |= kMaterialAlphaMasked;
  else if (mode == "BLEND") m.flags |= kMaterialBlend;
  else if (mode != "OPAQUE") j.at("alphaMode").fail("'" + std::string(mode) + "' is not OPAQUE, MASK or BLEND");
  m.alphaCutoff = float(j.number("alphaCutoff", 0.5));
  if (j.boolean("doubleSided", false)) m.flags |= kMaterialDoubleSided;
  float emissive[3] = {0, 0, 0};
  j.numbers("emissiveFactor", emissive);
  m.emissive = {emissive[0], emissive[1], emissive[2]};
  if (auto ext = j.get("extensions")) {
    if (auto es = ext->get("KHR_materials_emissive_strength")) m.emissive *= float(es->number("emissiveStrength", 1.0));
    if (ext->get("KHR_materials_unlit")) m.flags |= kMaterialUnlit;
  }
  if (pbr) {
    if (auto t = pbr->get("baseColorTexture")) {
      texture(*t, TextureSlot::BaseColor, m, true, 4, 0);
      // The mask is the base colour's alpha: the slot the renderers alpha-test takes that channel.
      if ((m.flags & (kMaterialAlphaMasked | kMaterialBlend)) && m.texture(TextureSlot::BaseColor) != kNoTexture) {
        texture(*t, TextureSlot::AlphaMask, m, false, 1, 4);
      }
    }
    if (auto t = pbr->get("metallicRoughnessTexture")) {
      texture(*t, TextureSlot::Roughness, m, false, 1, 2);
      texture(*t, TextureSlot::Metalness, m, false, 1, 3);
    }
  }
  if (auto t = j.get("normalTexture")) {
    texture(*t, TextureSlot::NormalMap, m, false, 4, 0);
    m.normalScale = float(t->number("scale", 1.0));
  }
  if (auto t = j.get("occlusionTexture")) {
    texture(*t, TextureSlot::Occlusion, m, false, 1, 1);
    m.occlusionStrength = float(t->number("strength", 1.0));
  }
  if (auto t = j.get("emissiveTexture")) texture(*t, TextureSlot::Emissive, m, true, 4, 0);
  // The classic (Blinn-Phong) factors the tracer's course mode reads, approximated from the PBR ones.
  m.kd = m.baseColor * (1.0f - m.metalness);
  m.ks = glm::mix(glm::vec3(0.04f), m.baseColor, m.metalness);
  m.ka = glm::vec3(0.0f);
  m.ke = m.emissive;
  const float a = std::max(m.roughness * m.roughness, 1e-3f);
  m.ns = std::clamp(2.0f / (a * a) - 2.0f, 1.0f, 10000.0f);
  const uint32_t id = uint32_t(scene_.materials.size());
  scene_.materials.push_back(std::move(m));
  return id;
}

}  // namespace rtr::gltf
