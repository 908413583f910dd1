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

#include "core/camera.hpp"
#include "scene/load.hpp"
#include "scene/obj.hpp"
#include "scene/scene.hpp"

namespace rtr {

struct BakeOptions {
  std::filesystem::path input, output;
  bool force = false;                     // overwrite an existing output and texture files
  std::optional<CameraPose> view;         // stored as the default view (.rtrscene only)
  std::optional<std::filesystem::path> mtl;  // the OBJ's MTL instead of its mtllib lines (LoadOptions::mtl)
  std::vector<Light> lights;              // stored with the scene (.rtrscene only); empty: none stored
  float creaseDeg = LoadOptions{}.creaseDeg;  // --crease: normals made for faces without them split at this angle
  glm::mat3 up{1.0f};                     // --up: the rotation that turns the model's up axis to +Y
  std::function<void(const std::string&)> warn;
  std::function<void(const std::string&)> note;  // glTF: what the reader chose on its own (LoadOptions::note)
  std::function<void(const char* phase, double fraction)> progress;
  unsigned threads = 0;
  bool lod = true;                        // --no-lod: no cluster hierarchy (.rtrscene's CLOD chunk)
};

struct BakeReport {
  ObjStats obj;
  bool gltf = false;                      // read as glTF (obj stays empty)
  size_t meshes = 0, materials = 0, textures = 0, fallbackTextures = 0, embeddedTextures = 0;
  size_t triangles = 0, instances = 0;
  uint64_t outputBytes = 0;
  double parseSeconds = 0, weldSeconds = 0, textureSeconds = 0, clusterSeconds = 0, lodSeconds = 0, writeSeconds = 0, totalSeconds = 0;
};

// Throws rtr::Error naming the file and place; on failure nothing it created is left behind.
BakeReport bake(const BakeOptions& options);

// The texture plan for an output named `sceneName`: paths become "<sceneName>-tex/<file name>" (an image
// held in memory: "<sceneName>-tex/<hash of its bytes>.png|.jpg"); textures that share a file and are
// sampled alike become one. Ids: .rtrscene in the input's order; with `courseFallbacks` at first appearance
// (materials in order, slots in course order), missing baseColor/roughness/metalness/emissive slots
// pointing at fallback textures (docs/formats.md).
struct TexturePlan {
  Scene scene;                                       // the scene to encode (shares nothing with the input)
  std::vector<std::filesystem::path> sources;        // per texture of `scene`: the file to copy; empty otherwise
  std::vector<std::shared_ptr<const std::vector<uint8_t>>> bytes;  // per texture: the image to write, or null
};
TexturePlan planTextures(const Scene& in, const std::string& sceneName, bool courseFallbacks);

}  // namespace rtr
