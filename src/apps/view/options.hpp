#pragma once
// Command-line options of rtr-view, shared by the headless and the windowed paths.
#include <exception>
#include <future>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>

#include "core/camera.hpp"
#include "apps/common/environment_options.hpp"
#include "render/mips.hpp"
#include "render/renderer.hpp"
#include "scene/lights.hpp"
#include "scene/load.hpp"

#include "vk/context.hpp"

namespace rtr::view {

struct ViewOptions {
  std::string scene;               // the first of `files`
  std::vector<std::string> files;  // the command line's files, folders expanded (the window steps through them)
  LoadOptions load;                // --mtl, --crease
  glm::mat3 up{1.0f};              // --up: turns the model's up axis to +Y
  bool headless = false;
  uint32_t width = 1280, height = 720;
  std::optional<CameraPose> camera;
  bool fovGiven = false;  // --fov
  Lens lens;
  render::RenderSettings settings;  // settings.lights: resolved from lightOptions once the scene is loaded
  LightOptions lightOptions;
  cli::EnvironmentOptions env;  // --env, --env-intensity, --env-rotation, --env-blur, --background
  render::MipMode mips = render::MipMode::Compute;
  int frames = 1;          // frames to render before the screenshot
  std::string screenshot;  // image path (.png, .jpg, .exr, .hdr); empty: none
  bool force = false;      // overwrite an existing screenshot
  int bench = 0;           // frames to time after warm-up; 0: no benchmark
  bool watch = false;      // hot-reload shaders
  bool orbit = false;      // start in orbit camera mode (windowed)
  std::string device;
  bool validation = false;
  bool shadingGiven = false, mipsGiven = false, clipGiven = false;  // --shading-path / --mips given: no per-device default
  bool timings = false;                                             // print the start-up phases
  bool pipelineCache = true;                                        // keep compiled pipelines in the user's cache folder
  bool pipelineStats = false;                                       // --pipeline-stats: print every pipeline made
  bool textureCache = true;                                         // keep decoded, mipped textures there (--no-cache: neither)
  // The first frame waits for the textures (deterministic captures); unless given, on for --headless
  // (--screenshot, --bench), off in the window, whose frames show the factors until the textures are in.
  std::optional<bool> waitTextures;
  uint32_t textureBatchMb = 16;  // a deferred load's textures taken in per frame: MiB of staged texels (at least one)
  bool panel = true;             // the window's settings panel shown at start
  // Test-only seams of the window (hidden options): each panel widget's rectangle on stdout when it
  // changes (--test-ui), and a file whose lines are taken as dropped paths once it appears (--test-drop).
  bool testUi = false;
  std::string testDropFile;
};

constexpr uint32_t kMaxSize = 32768;  // the largest image side any Vulkan device offers today
// --size within the device's maxImageDimension2D; throws rtr::UsageError naming the limit.
void checkSizeFits(const ViewOptions& o, const vk::Context& ctx);

// The files given on the command line, each folder replaced by the scene files in it (sorted by name).
std::vector<std::string> sceneFiles(const std::vector<std::string>& given);
// The scene file as every path of the viewer loads it: --mtl, --crease, --up, both sides drawn for models
// (scene/first_look.hpp).
Scene loadForView(const ViewOptions& o, const std::string& path);
// o.scene read (loadForView) on a worker thread from construction, beside whatever this thread does
// meanwhile: the instance, the device, the window need no scene (docs/startup.md "Phases side by side").
class SceneRead {
 public:
  explicit SceneRead(const ViewOptions& o);
  // Waits for the read. `besideError`: the work beside it failed. When both failed, the scene's error is
  // thrown, the other's said in a note before it: a bad file is reported whatever the device; else the
  // one that failed is thrown. Once.
  Scene take(std::exception_ptr besideError);
  double ms() const { return ms_; }  // the read's own duration, once taken

 private:
  std::future<std::pair<Scene, double>> read_;
  double ms_ = 0;
};

// The start pose: --camera, else the scene's own view, else framing the scene (framingPose), as rtr-trace.
CameraPose startPose(const ViewOptions& o, const Scene& scene);
// The start lens: --fov, else the field of view stored with the scene's own view (a glTF camera) when
// that view is the start pose, else the default.
Lens startLens(const ViewOptions& o, const Scene& scene);
// The render settings for `scene`: o.settings with the scene's lights (scene/lights.hpp), the choice
// said once on stderr when it is not simply the scene's own lights.
render::RenderSettings sceneSettings(const ViewOptions& o, const Scene& scene);

// The Vulkan context options: the environment's (vk::optionsFromEnvironment), then the flags.
vk::ContextOptions contextOptions(const ViewOptions& o);
// --pipeline-stats: every pipeline made so far on stdout, with the driver's statistics where it gives them.
void printPipelineStats(const ViewOptions& o, const vk::Context& ctx);
// The shading path and mip mode for `ctx`'s device: the flags where given, else the per-device defaults
// (render/startup.hpp), the choice and its reason said once on stderr.
struct DeviceChoice {
  render::ShadingPath shading;
  render::MipMode mips;
  bool computeClip;  // --near-clip compute
};
DeviceChoice chooseForDevice(const ViewOptions& o, const vk::Context& ctx);

// The environment's maps (--env), prefiltered on `ctx`'s device, their build times said on stderr; null
// for --env none.
std::shared_ptr<const render::EnvironmentMaps> loadEnvironment(const ViewOptions& o, const vk::Context& ctx);
// `env` prefiltered, its build times said on stderr under `name`.
std::shared_ptr<const render::EnvironmentMaps> prefilterEnvironment(const Environment& env, const std::string& name,
                                                                    const vk::Context& ctx);

int runHeadless(const ViewOptions& o);
int runWindowed(const ViewOptions& o);

}  // namespace rtr::view
