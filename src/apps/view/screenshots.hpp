#pragma once
// The window's screenshots: --screenshot FILE after --frames frames (then the viewer quits), and the
// panel's button (a numbered PNG beside the scene, encoded off the render thread, never overwriting).
#include <cstdint>
#include <filesystem>
#include <future>
#include <string>

#include "core/image.hpp"
#include "options.hpp"
#include "view_frames.hpp"
#include "view_state.hpp"

namespace rtr::view {

// `scene`'s file name without its extensions, numbered: the first free NAME-N.png beside the scene.
std::string saveShot(const std::filesystem::path& scene, ImageRGBA8 image);

class Screenshots {
 public:
  explicit Screenshots(const ViewOptions& o) : path_(o.screenshot), force_(o.force), frames_(std::max(1, o.frames)) {}
  // Decides what this frame reads back; `busy`: the frame's read-back is taken (the error map's capture).
  void plan(ViewState& app, const ViewFrames& frames, uint64_t frameNumber, bool busy);
  bool readBack() const { return cli_ || panel_; }
  // After the frame: writes --screenshot (true: written, the viewer quits) or queues the panel's PNG.
  bool save(ImageRGBA8& shot, const std::string& scenePath);
  // A finished panel save: its outcome in the panel's message and on stderr.
  void collect(ViewState& app);

 private:
  std::string path_;
  bool force_;
  int frames_;
  bool cli_ = false, panel_ = false;
  std::future<std::string> saving_;
};

}  // namespace rtr::view
