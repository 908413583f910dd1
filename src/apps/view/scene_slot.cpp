#include "scene_slot.hpp"

#include <chrono>
#include <cstdio>

#include "render/startup.hpp"
#include "vk/check.hpp"
#include "vk/context.hpp"

namespace rtr::view {

SceneSlot::SceneSlot(const vk::Context& ctx, VkSurfaceKHR surface, std::unique_ptr<Scene> scene, std::vector<std::string> files,
                     bool waitTextures, Loader load)
    : ctx_(ctx),
      surface_(surface),
      waitTextures_(waitTextures),
      load_(std::move(load)),
      scene_(std::move(scene)),
      files_(std::move(files)),
      path_(files_.at(0)) {}

void SceneSlot::release() {
  VK_CHECK(vkDeviceWaitIdle(ctx_.device()));
  traced_.reset();
  frames_.reset();
  gpu_.reset();
}

void SceneSlot::build(VkExtent2D extent, render::MipMode mips, const render::RenderSettings& first) {
  render::PipelinesAhead ahead(ctx_, *scene_, first, env_ != nullptr);  // while the scene uploads
  gpu_ = std::make_unique<render::GpuScene>(ctx_, *scene_, mips, render::LoadProgress{}, render::GeometryUpload::Auto,
                                            waitTextures_ ? render::TextureLoad::Wait : render::TextureLoad::Deferred, cache_,
                                            textureBatch_);
  const auto waitStart = std::chrono::steady_clock::now();
  render::Renderer::Prepared prepared = ahead.take();
  pipelineWaitMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - waitStart).count();
  frames_ = std::make_unique<ViewFrames>(ctx_, surface_, extent, *gpu_, std::move(prepared));
  if (env_) frames_->renderer().setEnvironment(env_);
  traced_ = std::make_unique<TraceOverlay>(ctx_, *scene_);
}

bool SceneSlot::update(ViewState& app) {
  if (const int step = std::exchange(app.fileStep, 0); step && files_.size() > 1) {
    fileIndex_ = (fileIndex_ + (step > 0 ? 1 : files_.size() - 1)) % files_.size();
    app.drops.push_back(files_[fileIndex_]);
  }
  if (std::exchange(app.reloadRequested, false)) app.drops.push_back(path_);
  if (!loading_.valid() && !app.drops.empty()) {
    loadingPath_ = app.drops.back();  // several files at once: the last one
    app.drops.clear();
    app.message = "loading " + loadingPath_ + " ...", app.messageIsError = false;
    loading_ = std::async(std::launch::async, load_, loadingPath_);
  }
  std::unique_ptr<Scene> dropped;
  if (loading_.valid() && loading_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    try {  // a failing load keeps the current scene
      dropped = std::make_unique<Scene>(loading_.get());
      path_ = loadingPath_;
      app.message = "loaded " + loadingPath_, app.messageIsError = false;
    } catch (const std::exception& e) { app.message = std::string("cannot load: ") + e.what(), app.messageIsError = true; }
    std::fprintf(stderr, "rtr-view: %s\n", app.message.c_str());
  }
  const bool replaced = dropped != nullptr;
  if (dropped || std::exchange(app.remipRequested, false)) {
    const VkExtent2D e = frames_->extent();
    release();
    if (dropped) scene_ = std::move(dropped);
    build(e, app.mips, app.settings);
    if (gpu_->texturesReady())
      std::fprintf(stderr, "rtr-view: mips (%s) %.3f ms GPU\n", enumName(app.mips), gpu_->stats().mipGpuMs);
  }
  // Textures decode on worker threads; batches of those decoded upload and get their mips in submissions of
  // their own while frames go on, and are taken in between frames as each completes.
  const bool allIn = gpu_->updateTextures();
  if (gpu_->texturesIn() > 0 && firstTextureAt_ == 0) {
    firstTextureAt_ = render::msSinceProcessStart();
    std::fprintf(stderr, "rtr-view: first textures in at %.0f ms from process start\n", firstTextureAt_);
  }
  if (allIn) {
    const auto& st = gpu_->stats();
    if (texturesInAt_ == 0) texturesInAt_ = render::msSinceProcessStart();
    std::fprintf(
        stderr,
        "rtr-view: %u textures in (%u from the texture cache): decode %.0f ms (worker threads), upload and mips %.0f ms\n",
        st.textures, st.cacheHits, st.decodeMs, st.textureUploadMs);
    std::fprintf(stderr, "rtr-view: mips (%s) %.3f ms GPU\n", enumName(app.mips), st.mipGpuMs);
  }
  return replaced;
}

ShaderReload::ShaderReload(bool on) {
  if (on) watcher_ = std::make_unique<ShaderWatcher>(RTR_SHADER_SOURCE_DIR);
}

void ShaderReload::update(float dt, ViewFrames& frames) {
  timer_ += dt;
  if (!watcher_ || timer_ <= 0.5) return;
  timer_ = 0;
  std::string err;
  if (watcher_->poll(err)) {
    try {
      frames.rebuildPipelines();
      error_.clear();
      std::fprintf(stderr, "rtr-view: shaders reloaded\n");
    } catch (const std::exception& e) { err = e.what(); }
  }
  if (!err.empty()) {
    error_ = err;
    std::fprintf(stderr, "rtr-view: shader reload failed, keeping the previous pipelines:\n%s\n", err.c_str());
  }
}

}  // namespace rtr::view
