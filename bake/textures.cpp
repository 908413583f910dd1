#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstdio>
#include <mutex>
#include <unordered_map>

#include "bake.hpp"
#include "core/error.hpp"
#include "core/mip_reference.hpp"
#include "core/parallel.hpp"
#include "scene/baked_texels.hpp"
#include "scene/binio.hpp"
#include "scene/course.hpp"
#include "scene/mtl.hpp"
#include "scene/textures.hpp"

namespace rtr {
namespace {

// A name for an image held in memory, from its content: the same image gets the same file in every bake.
std::string contentName(const std::vector<uint8_t>& bytes) {
  const bool jpeg = bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
  char name[40];
  std::snprintf(name, sizeof name, "%016llx%s", static_cast<unsigned long long>(checksum64(bytes)), jpeg ? ".jpg" : ".png");
  return name;
}

// Textures that share a file but are sampled differently stay apart (glTF takes roughness and metalness
// from two channels of one image).
std::string key(const std::string& rel, const Texture& t) {
  const SamplerDesc& s = t.sampler;
  char k[64];
  std::snprintf(k, sizeof k, "|%d%d%d|%d%d%d%d%d", t.srgb, t.channels, t.sourceChannel, int(s.wrapU), int(s.wrapV), s.nearestMag,
                s.nearestMin, s.nearestMip);
  return rel + k;
}

}  // namespace

TexturePlan planTextures(Scene in, const std::string& sceneName, bool courseFallbacks) {
  TexturePlan plan;
  plan.scene.baseDir = in.baseDir;
  plan.scene.meshes = std::move(in.meshes);
  plan.scene.instances = std::move(in.instances);
  plan.scene.defaultView = in.defaultView;
  plan.scene.defaultFovYDeg = in.defaultFovYDeg;
  plan.scene.lights = in.lights;
  std::unordered_map<std::string, uint32_t> ids;          // destination path and sampling -> new id
  std::unordered_map<std::string, std::string> sourceOf;  // destination path -> source, to catch clashes
  const std::string folder = sceneName + "-tex/";

  auto idFor = [&](const std::string& rel, const std::filesystem::path& src, const Texture& t) {
    auto [it, added] = ids.try_emplace(key(rel, t), uint32_t(plan.scene.textures.size()));
    if (!added) return it->second;
    Texture out = t;
    out.path = rel;
    out.bytes = nullptr;
    plan.scene.textures.push_back(std::move(out));
    plan.sources.push_back(src);
    plan.bytes.push_back(t.bytes);
    auto [known, first] = sourceOf.try_emplace(rel, t.bytes ? rel : src.string());
    if (!first && known->second != (t.bytes ? rel : src.string()))
      throw Error("textures '" + known->second + "' and '" + src.string() + "' would both be copied to '" + rel +
                  "'; rename one of them");
    return it->second;
  };
  // An input texture's id in the plan: files keep their name, images in memory get one from their bytes.
  auto planned = [&](uint32_t id, const std::string& material) {
    if (id >= in.textures.size()) throw Error("material '" + material + "': texture id out of range");
    const Texture& t = in.textures[id];
    if (t.bytes) return idFor(folder + contentName(*t.bytes), {}, t);
    if (isFallbackTexture(t.path)) throw Error("texture file name '" + t.path.filename().string() + "' is reserved");
    const std::filesystem::path src = t.path.is_absolute() ? t.path : in.baseDir / t.path;
    return idFor(folder + t.path.filename().string(), src, t);
  };

  // .rtrscene: the input's textures in their order (OBJ gives them in order of first use already).
  std::vector<uint32_t> remap;
  if (!courseFallbacks)
    for (uint32_t i = 0; i < in.textures.size(); ++i) remap.push_back(planned(i, "?"));
  for (const Material& m : in.materials) {
    Material out = m;
    for (uint32_t s = 0; s < kTextureSlotCount; ++s) {
      const uint32_t id = m.textures[s];
      const TextureSlot slot = TextureSlot(s);
      if (id != kNoTexture) {
        out.textures[s] = courseFallbacks ? planned(id, m.name) : id < remap.size() ? remap[id] : planned(id, m.name);
      } else if (courseFallbacks && slot != TextureSlot::AlphaMask && slot != TextureSlot::NormalMap) {
        std::string_view name = slot == TextureSlot::BaseColor  ? kFallbackBaseColor
                                : slot == TextureSlot::Emissive ? kFallbackEmissive
                                                                : kFallbackOne;
        const SlotFormat f = slotFormat(slot);
        out.textures[s] = idFor(folder + std::string(name), {}, Texture{{}, f.srgb, f.channels});
      }
    }
    plan.scene.materials.push_back(std::move(out));
  }
  return plan;
}

std::vector<uint8_t> referenceChain(const TexelData& level0, bool srgb) {
  const MipChain chain = buildMipReference(level0, srgb ? TexelEncoding::Srgb : TexelEncoding::Unorm, MipSource::PreviousLevel);
  BakedTexels layout;
  layout.format = level0.channels == 1 ? BakedFormat::R8 : BakedFormat::Rgba8;
  layout.width = level0.width;
  layout.height = level0.height;
  const std::vector<uint64_t> at = layout.levelOffsets();
  std::vector<uint8_t> out(at.back());
  for (uint32_t l = 0; l < chain.levels.size(); ++l) {
    const std::vector<uint8_t> q = l == 0 ? level0.texels : quantizeMipLevel(chain, l);
    std::copy(q.begin(), q.end(), out.begin() + ptrdiff_t(at[l]));
  }
  return out;
}

// The chain in `format` (lossless, or each level block-compressed), its error per level added to `error`.
std::vector<uint8_t> encodeChain(const std::vector<uint8_t>& lossless, BakedFormat format, uint32_t w, uint32_t h,
                                 std::vector<LevelError>& error, unsigned threads) {
  if (format == BakedFormat::Rgba8 || format == BakedFormat::R8) return lossless;
  BakedTexels from, to;
  from.format = bakedChannels(format) == 1 ? BakedFormat::R8 : BakedFormat::Rgba8;
  to.format = format;
  from.width = to.width = w;
  from.height = to.height = h;
  const std::vector<uint64_t> src = from.levelOffsets(), dst = to.levelOffsets();
  std::vector<uint8_t> out(dst.back());
  error.resize(std::max<size_t>(error.size(), from.levels()));
  for (uint32_t l = 0; l < from.levels(); ++l) {
    const uint32_t lw = mipLevelSize(w, l), lh = mipLevelSize(h, l);
    const std::vector<uint8_t> blocks = encodeBakedLevel(format, lw, lh, lossless.data() + src[l], threads);
    std::copy(blocks.begin(), blocks.end(), out.begin() + ptrdiff_t(dst[l]));
    const std::vector<uint8_t> back = decodeBakedLevel(format, lw, lh, blocks.data());
    LevelError& e = error[l];
    for (size_t i = 0; i < back.size(); ++i) {
      const int d = std::abs(int(back[i]) - int(lossless[src[l] + i]));
      e.sumAbs += d;
      e.max = std::max(e.max, d);
    }
    e.samples += back.size();
  }
  return out;
}

void bakeTexels(TexturePlan& plan, unsigned threads, const std::string& namedIn, const std::function<void(double)>& progress,
                bool blocks, std::vector<LevelError>* bcError) {
  std::vector<std::string> errors(plan.scene.textures.size());
  std::atomic<size_t> done{0};
  std::mutex progressMutex;
  // Textures on all cores; where there are fewer textures than cores, each one's levels in pieces too.
  const size_t count = plan.scene.textures.size();
  const unsigned inner = count ? std::max<unsigned>(1, unsigned(threadCount(threads) / count)) : 1;
  parallelFor(count, threads, [&](size_t i) {
    Texture& t = plan.scene.textures[i];
    Texture src = t;  // the image it comes from: a file, bytes held in memory, or a course fallback (none here)
    src.path = plan.sources[i];
    src.bytes = plan.bytes[i];
    std::error_code ec;
    if (!src.bytes && !std::filesystem::exists(src.path, ec)) {
      errors[i] = src.path.string() + ": texture file named in the " + namedIn + " does not exist";
      return;
    }
    TexelData texels;
    try {
      texels = decodeTexture(Scene{}, src);
    } catch (const Error& e) {
      errors[i] = std::string(e.what()) + (src.bytes ? " (an image embedded in the glTF is not readable)"
                                                     : " (texture named in the " + namedIn + " is not a readable image)");
      return;
    }
    BakedFormat format = texels.channels == 1 ? BakedFormat::R8 : BakedFormat::Rgba8;
    if (blocks && format == BakedFormat::R8) format = BakedFormat::Bc4;
    if (blocks && format == BakedFormat::Rgba8) {
      bool opaque = true;
      for (size_t k = 3; k < texels.texels.size(); k += 4) opaque &= texels.texels[k] == 255;
      format = opaque ? BakedFormat::Bc1 : BakedFormat::Bc3;
    }
    const uint32_t w = texels.width, h = texels.height;
    std::vector<LevelError> error;
    t.baked = packBakedTexels(format, w, h, encodeChain(referenceChain(texels, decodeSrgb(t)), format, w, h, error, inner), 1);
    const std::lock_guard lock(progressMutex);
    if (bcError) {
      bcError->resize(std::max(bcError->size(), error.size()));
      for (size_t l = 0; l < error.size(); ++l) {
        (*bcError)[l].sumAbs += error[l].sumAbs;
        (*bcError)[l].samples += error[l].samples;
        (*bcError)[l].max = std::max((*bcError)[l].max, error[l].max);
      }
    }
    if (progress) progress(double(++done) / double(plan.scene.textures.size()));
  });
  for (const std::string& e : errors)
    if (!e.empty()) throw Error(e);
  for (size_t i = 0; i < plan.sources.size(); ++i) plan.sources[i].clear(), plan.bytes[i] = nullptr;
}

}  // namespace rtr
