#include "screenshots.hpp"

#include <cstdio>

#include "core/error.hpp"

namespace rtr::view {

std::string saveShot(const std::filesystem::path& scene, ImageRGBA8 image) {
  const std::filesystem::path dir = std::filesystem::absolute(scene).parent_path();
  std::string base = scene.filename().string();
  base = base.substr(0, base.find('.'));
  for (int n = 1;; ++n) {
    const std::filesystem::path out = dir / (base + "-" + std::to_string(n) + ".png");
    try {
      saveImage(out, image, {Replace::No, true});
      return out.string();
    } catch (const OutputExists&) {  // never overwrites: the next number
    }
  }
}

void Screenshots::plan(ViewState& app, const ViewFrames& frames, uint64_t frameNumber, bool busy) {
  cli_ = !path_.empty() && frameNumber + 1 == uint64_t(frames_);
  if (cli_ && !frames.canReadBack()) throw Error("this surface's images cannot be read back for --screenshot");
  panel_ = std::exchange(app.screenshotRequested, false) && !busy;
  if (panel_ && !frames.canReadBack()) {
    app.message = "this surface's images cannot be read back for a screenshot", app.messageIsError = true;
    panel_ = false;
  }
}

bool Screenshots::save(ImageRGBA8& shot, const std::string& scenePath) {
  if (cli_) {
    saveImage(path_, shot, {force_ ? Replace::Yes : Replace::No, true});
    std::printf("%s\n", std::filesystem::absolute(path_).c_str());
  }
  if (panel_) {
    if (saving_.valid()) saving_.wait();  // one encode at a time
    saving_ = std::async(std::launch::async, saveShot, std::filesystem::path(scenePath), std::move(shot));
  }
  return cli_;
}

void Screenshots::collect(ViewState& app) {
  if (!saving_.valid() || saving_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  try {
    app.message = "saved " + saving_.get(), app.messageIsError = false;
  } catch (const std::exception& ex) { app.message = std::string("screenshot failed: ") + ex.what(), app.messageIsError = true; }
  std::fprintf(stderr, "rtr-view: %s\n", app.message.c_str());
}

}  // namespace rtr::view
