#pragma once
// The environment options rtr-view and rtr-trace share, with one meaning (docs/files-and-cli.md):
//   --env FILE|sky|none, --env-intensity K, --env-rotation DEG: where the light comes from;
//   --background R,G,B (linear): what camera rays that miss see; without it, the environment where there
//   is one, else a neutral mid-grey backdrop (kDefaultBackground) on which a black model is visible.
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <glm/vec3.hpp>

#include "scene/environment.hpp"

namespace rtr::cli {

// Linear 0.18 (the photographer's middle grey, sRGB 118): neither black nor white models vanish on it.
constexpr float kDefaultBackground = 0.18f;

struct EnvironmentOptions {
  EnvironmentSettings settings;
  std::string background;  // as given; empty: not given
  // Resolved by resolve(): the colour camera misses see, and whether they see the environment instead.
  glm::vec3 backgroundColor{kDefaultBackground};
  bool showEnvironment = false;
  bool hasEnvironment() const { return settings.source != "none" && !settings.source.empty(); }
  // After parsing: fills backgroundColor and showEnvironment (throws UsageError on a bad colour).
  void resolve();
};

void addEnvironmentOptions(CLI::App& app, EnvironmentOptions& o);

}  // namespace rtr::cli
