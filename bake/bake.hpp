#pragma once
// rtr-bake's work as a library (the executable, the tests and the benchmark share it):
// OBJ or glTF in, .rtrscene or .comp5892mesh (OBJ only) out, textures copied into "<scene>-tex/" beside the
// output (a glTF's embedded images written there as files).
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>

#include "core/enum_names.hpp"

#include "core/camera.hpp"
#include "core/image.hpp"
#include "scene/load.hpp"
#include "scene/obj.hpp"
#include "scene/scene.hpp"

namespace rtr {

// How an .rtrscene carries its textures: image files in "<scene>-tex/" (decoded and filtered at every
// load), or their whole mip chains as the GPU samples them inside the file (version 6's TEXS chunk).
// Bc: the same chains block-compressed (BC1 opaque colour, BC3 colour with alpha, BC4 one channel).
enum class TextureStore { Files, Lossless, Bc };
constexpr std::array<EnumName<TextureStore>, 3> enumNames(TextureStore) {
  return {{{TextureStore::Files, "files"}, {TextureStore::Lossless, "lossless"}, {TextureStore::Bc, "bc"}}};
}

// Block compression's error against the lossless texels, per mip level over every texture, every channel
// (8-bit LSB).
struct LevelError {
  double sumAbs = 0;
  uint64_t samples = 0;
  int max = 0;
};

struct BakeOptions {
  std::filesystem::path input, output;
  bool force = false;                         // overwrite an existing output and texture files
  std::optional<CameraPose> view;             // stored as the default view (.rtrscene only)
  std::optional<std::filesystem::path> mtl;   // the OBJ's MTL instead of its mtllib lines (LoadOptions::mtl)
  std::vector<Light> lights;                  // stored with the scene (.rtrscene only); empty: none stored
  float creaseDeg = LoadOptions{}.creaseDeg;  // --crease: normals made for faces without them split at this angle
  glm::mat3 up{1.0f};                         // --up: the rotation that turns the model's up axis to +Y
  std::function<void(const std::string&)> warn;
  std::function<void(const std::string&)> note;  // glTF: what the reader chose on its own (LoadOptions::note)
  std::function<void(const char* phase, double fraction)> progress;
  std::function<void(const char* step)> step;  // each phase and step as it begins (rtr-bake --profile)
  unsigned threads = 0;
  TextureStore textures = TextureStore::Files;  // .rtrscene only
  bool lod = true;                              // --no-lod: no cluster hierarchy (.rtrscene's CLOD chunk)
};

struct BakeReport {
  ObjStats obj;
  bool gltf = false;  // read as glTF (obj stays empty)
  size_t meshes = 0, materials = 0, textures = 0, fallbackTextures = 0, embeddedTextures = 0;
  size_t triangles = 0, instances = 0;
  uint64_t outputBytes = 0;
  uint64_t texelBytes = 0, storedTexelBytes = 0;  // baked textures: their chains, and as stored (zstd)
  std::vector<LevelError> bcError;                // --textures bc: per level
  double parseSeconds = 0, weldSeconds = 0, textureSeconds = 0, clusterSeconds = 0, lodSeconds = 0, writeSeconds = 0,
         totalSeconds = 0;
  // The process's CPU time (all threads) of each phase: against its wall time, how many cores it kept busy.
  double parseCpuSeconds = 0, weldCpuSeconds = 0, textureCpuSeconds = 0, clusterCpuSeconds = 0, lodCpuSeconds = 0,
         writeCpuSeconds = 0;
  // Parts of writeSeconds: the bytes made in memory (.comp5892mesh; an .rtrscene is made while written),
  // handed to the file (the rest: fsync, textures put in place).
  double encodeSeconds = 0, fileWriteSeconds = 0;
};

// Throws rtr::Error naming the file and place; on failure nothing it created is left behind.
BakeReport bake(const BakeOptions& options);

// The texture plan for an output named `sceneName`: paths become "<sceneName>-tex/<file name>" (an image
// held in memory: "<sceneName>-tex/<hash of its bytes>.png|.jpg"); textures that share a file and are
// sampled alike become one. Ids: .rtrscene in the input's order; with `courseFallbacks` at first appearance
// (materials in order, slots in course order), missing baseColor/roughness/metalness/emissive slots
// pointing at fallback textures (docs/formats.md).
struct TexturePlan {
  Scene scene;                                                     // the scene to encode (shares nothing with the input)
  std::vector<std::filesystem::path> sources;                      // per texture of `scene`: the file to copy; empty otherwise
  std::vector<std::shared_ptr<const std::vector<uint8_t>>> bytes;  // per texture: the image to write, or null
};
// `in` is taken by value: a bake moves its scene in, so that the geometry is not copied.
TexturePlan planTextures(Scene in, const std::string& sceneName, bool courseFallbacks);

// Decodes every texture of the plan (its sources or bytes; errors as a bake's, naming the file and where it
// is named: `namedIn`), filters its full mip chain with the reference filter (core/mip_reference.hpp,
// linear light, each level from the one before) and sets Texture::baked; sources and bytes are cleared.
// Textures on all cores. `progress` gets the fraction done.
// `blocks`: block-compressed, with the error per level added to `bcError`.
void bakeTexels(TexturePlan& plan, unsigned threads, const std::string& namedIn, const std::function<void(double)>& progress = {},
                bool blocks = false, std::vector<LevelError>* bcError = nullptr);
// One texture's chain as bakeTexels makes it, from decoded texels (channels 1 or 4).
std::vector<uint8_t> referenceChain(const TexelData& level0, bool srgb);

}  // namespace rtr
