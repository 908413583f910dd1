#pragma once
// Which of a scene's textures the renderers sample, and their decoding: shared by the GPU renderer
// (render/gpu_scene.cpp) and the CPU ray tracer's PBR mode (trace/textures.cpp), so both read the same
// files into the same texels. No GPU here.
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "scene/scene.hpp"

namespace rtr {

// Texture slots the renderers sample for OBJ/MTL and course materials (the normal map is not part of the
// brief's shading model), and for glTF materials (kMaterialGltf), which add the normal map and occlusion.
constexpr TextureSlot kSampledSlots[] = {TextureSlot::BaseColor, TextureSlot::Roughness, TextureSlot::Metalness,
                                         TextureSlot::AlphaMask, TextureSlot::Emissive};
constexpr TextureSlot kGltfSampledSlots[] = {TextureSlot::BaseColor, TextureSlot::Roughness, TextureSlot::Metalness,
                                             TextureSlot::AlphaMask, TextureSlot::Emissive,  TextureSlot::NormalMap,
                                             TextureSlot::Occlusion};
std::span<const TextureSlot> sampledSlots(const Material& material);

// Scene texture indices sampled by some slot of a material drawn by a mesh that has texcoords (a mesh
// without texcoords samples nothing), each once, in order of first use.
std::vector<uint32_t> sampledTextures(const Scene& scene);

// Channels a texture is decoded to: 1 for single-channel data (R8), otherwise 4 (RGBA8).
int decodeChannels(const Texture& t);
// Whether its colour channels are sRGB-encoded (decoded to linear on read): sRGB four-channel textures.
bool decodeSrgb(const Texture& t);

// The texels shown for a texture that is missing or cannot be decoded: a 64x64 magenta/black checker of
// 8-texel cells (one channel: 255/0), so the fault is visible in every renderer.
TexelData fallbackTexels(int channels);

// One texture's texels: level 0 of Texture::baked when set, else Texture::bytes when set, else the file;
// `sourceChannel` taken for one-channel textures. Throws rtr::Error naming the file (or the image's name).
TexelData decodeTexture(const Scene& scene, const Texture& t);

// Decodes scene.textures[which[i]] for every i on all cores and hands the texels to use(i, texels) on the
// thread that decoded them (so per-texture work after decoding runs in parallel too). A texture that is
// missing or cannot be decoded gets fallbackTexels() and one message naming its file to `warn` (default:
// "warning: ..." on stderr; calls are serialised). `fellBack`, when given, gets one entry per texture, set
// (before use() is called for it) where the checker stands in.
void decodeTextures(const Scene& scene, std::span<const uint32_t> which, const std::function<void(size_t, TexelData&&)>& use,
                    const std::function<void(const std::string&)>& warn = {}, std::vector<uint8_t>* fellBack = nullptr);

// Whether a mesh's fragments are alpha-tested (discarded where the mask's alpha < 0.5), as on the GPU: it
// has texcoords and an alpha-mask texture, and its material is alpha-masked or double-sided (the GPU's
// alpha-tested pipeline).
bool alphaTested(const Mesh& mesh, const Material& material);

}  // namespace rtr
