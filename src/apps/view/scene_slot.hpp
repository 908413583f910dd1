#pragma once
// The scene on screen and everything made from it (GPU scene, frames, tracer overlay), and how it is
// replaced: dropped files load on a worker thread while frames go on, then the GPU side is rebuilt between
// frames; a mip mode change rebuilds it too; --watch reloads edited shaders.
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include "render/gpu_scene.hpp"
#include "scene/scene.hpp"
#include "shader_watch.hpp"
#include "trace_overlay.hpp"
#include "view_frames.hpp"
#include "view_state.hpp"

namespace rtr::view {

class SceneSlot {
 public:
  using Loader = std::function<Scene(const std::string& path)>;  // called on a worker thread
  // `files`: the command line's scene files, the first one loaded as `scene`; Left/Right step through them.
  SceneSlot(const vk::Context& ctx, VkSurfaceKHR surface, std::unique_ptr<Scene> scene, std::vector<std::string> files,
            bool waitTextures, Loader load);
  ~SceneSlot() { release(); }  // the device idle, children first; before the surface and the device go

  // The scene to the GPU and its frames; the pipelines of a first frame with `first` made meanwhile.
  void build(VkExtent2D extent, render::MipMode mips, const render::RenderSettings& first);
  double pipelineWaitMs() const { return pipelineWaitMs_; }  // the last build's, after its upload
  // The texture cache every scene of the slot uses (null: none); it must outlive the slot.
  void setTextureCache(TextureCache* cache) { cache_ = cache; }
  void setTextureBatch(size_t bytes) { textureBatch_ = bytes; }  // GpuScene::setUploadBudget
  // The environment every scene of the slot is lit by (kept across drops); null: none.
  void setEnvironment(std::shared_ptr<const render::EnvironmentMaps> env) {
    env_ = std::move(env);
    if (frames_) frames_->renderer().setEnvironment(env_);
  }
  // Serves drops, Left/Right, F5 and mip changes: starts loading the last dropped (or chosen) file, takes a finished load (the panel's
  // message says how it went) and rebuilds. True when a new scene came in (its camera is to be set).
  bool update(ViewState& app);

  const std::string& path() const { return path_; }
  const Scene& scene() const { return *scene_; }
  render::GpuScene& gpu() { return *gpu_; }
  ViewFrames& frames() { return *frames_; }
  TraceOverlay& traced() { return *traced_; }
  double texturesInAtMs() const { return texturesInAt_; }

 private:
  void release();
  const vk::Context& ctx_;
  VkSurfaceKHR surface_;
  bool waitTextures_;
  Loader load_;
  std::unique_ptr<Scene> scene_;
  std::vector<std::string> files_;
  size_t fileIndex_ = 0;
  std::string path_;
  TextureCache* cache_ = nullptr;
  std::unique_ptr<render::GpuScene> gpu_;
  std::shared_ptr<const render::EnvironmentMaps> env_;
  std::unique_ptr<ViewFrames> frames_;
  std::unique_ptr<TraceOverlay> traced_;
  std::future<Scene> loading_;
  std::string loadingPath_;
  size_t textureBatch_ = render::GpuScene::kDefaultUploadBudget;
  double texturesInAt_ = 0, firstTextureAt_ = 0;  // from process start; 0: not yet
  double pipelineWaitMs_ = 0;
};

// --watch: edited shaders recompiled twice a second; a failure keeps the running pipelines and is shown.
class ShaderReload {
 public:
  explicit ShaderReload(bool on);
  void update(float dt, ViewFrames& frames);
  const std::string& error() const { return error_; }

 private:
  std::unique_ptr<ShaderWatcher> watcher_;
  std::string error_;
  double timer_ = 0;
};

}  // namespace rtr::view
